!> The parallel setting of a run, as text: the number of OpenMP threads and the OpenBLAS
!> setting. Results depend on it beyond round-off (doc/performance.md, "OpenMP": the sweeps
!> split from 4 000 active contacts; OpenBLAS threads inside CHOLMOD), so checkpoints record
!> it and a restart under another setting says so (driver_run).
module core_threads
!$  use omp_lib, only: omp_get_max_threads
    use core_strings, only: to_str
    implicit none
    private
    public :: thread_setting

contains

    !> 'OpenMP threads N, OPENBLAS_NUM_THREADS V' (V the variable's value, or 'unset': OpenBLAS
    !> then follows OMP_NUM_THREADS or the number of cores). N is 1 in a build without OpenMP.
    function thread_setting() result(text)
        character(len=:), allocatable :: text
        character(len=64) :: value
        integer :: n, length, status
        n = 1
!$      n = omp_get_max_threads()
        call get_environment_variable('OPENBLAS_NUM_THREADS', value, length, status)
        if (status == 0 .and. length > 0) then
            text = 'OpenMP threads '//to_str(n)//', OPENBLAS_NUM_THREADS '//trim(value)
        else
            text = 'OpenMP threads '//to_str(n)//', OPENBLAS_NUM_THREADS unset'
        end if
    end function thread_setting
end module core_threads
