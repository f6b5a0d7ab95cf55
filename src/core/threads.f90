!> The parallel setting of a run. MULTICOR's own loops split over OpenMP threads only from
!> 2 000 contacts per thread (doc/performance.md, "OpenMP"); the dense kernels of OpenBLAS,
!> inside CHOLMOD's factorisations and LAPACK, run on one thread (single_thread_blas), so
!> that a smaller run gives the same results bit for bit whatever threads it is given.
!> Checkpoints record the setting and a restart under another one says so (driver_run).
module core_threads
    use, intrinsic :: iso_c_binding, only: c_int
!$  use omp_lib, only: omp_get_max_threads, omp_set_num_threads
    use core_strings, only: to_str
    implicit none
    private
    public :: single_thread_blas, thread_setting, openmp_part

    interface
        function multicor_blas_single_thread() bind(c, name='multicor_blas_single_thread') result(done)
            import :: c_int
            integer(c_int) :: done
        end function multicor_blas_single_thread
        function multicor_blas_threads() bind(c, name='multicor_blas_threads') result(n)
            import :: c_int
            integer(c_int) :: n
        end function multicor_blas_threads
    end interface

contains

    !> Set OpenBLAS to one thread: the rounding of its threaded kernels depends on their
    !> count (a chaotic contact layer amplifies it to the fourth digit of its positions), and
    !> the sizes of the factorisations of a 2D run gain nothing measurable from threads. A
    !> BLAS other than OpenBLAS is left as it is (thread_setting says so). OpenBLAS built with
    !> OpenMP sets the OpenMP count to one as well: it is restored, so that MULTICOR's own
    !> loops keep the threads they were given (OpenBLAS stays on one: a count of one makes
    !> it run serially whatever OpenMP's).
    subroutine single_thread_blas()
        integer :: n, done
        n = 1
!$      n = omp_get_max_threads()
        done = multicor_blas_single_thread()
!$      if (omp_get_max_threads() /= n) call omp_set_num_threads(n)
    end subroutine single_thread_blas

    !> 'OpenMP threads N, OpenBLAS M thread(s)' (M as OpenBLAS reports it: 1 after
    !> single_thread_blas), or 'OpenMP threads N, BLAS threads its own' with a BLAS other than
    !> OpenBLAS. N is 1 in a build without OpenMP.
    function thread_setting() result(text)
        character(len=:), allocatable :: text
        integer :: n, m
        n = 1
!$      n = omp_get_max_threads()
        m = multicor_blas_threads()
        text = 'OpenMP threads '//to_str(n)//', '
        if (m == 1) then
            text = text//'OpenBLAS 1 thread'
        else if (m > 1) then
            text = text//'OpenBLAS '//to_str(m)//' threads'
        else
            text = text//'BLAS threads its own'
        end if
    end function thread_setting

    !> The OpenMP part of a setting of thread_setting ('OpenMP threads N'): the part that
    !> decides a run's results once OpenBLAS runs on one thread. A setting of an earlier
    !> build ('OpenMP threads N, OPENBLAS_NUM_THREADS V') gives its own.
    pure function openmp_part(setting) result(part)
        !> A setting as recorded in a checkpoint.
        character(len=*), intent(in) :: setting
        character(len=:), allocatable :: part
        integer :: comma
        comma = index(setting, ',')
        if (comma == 0) then
            part = setting
        else
            part = setting(:comma - 1)
        end if
    end function openmp_part
end module core_threads
