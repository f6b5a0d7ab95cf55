!> The parallel setting of a run. MULTICOR's own loops split over OpenMP threads only from
!> 2 000 contacts per thread (doc/performance.md, "OpenMP"); the dense kernels of OpenBLAS,
!> inside CHOLMOD's factorisations and LAPACK, run on one thread (single_thread_blas), so
!> that a smaller run gives the same results bit for bit whatever threads it is given.
!> Checkpoints record the setting and a restart under another one says so (driver_run).
module core_threads
    use, intrinsic :: iso_c_binding, only: c_int
!$  use omp_lib, only: omp_get_max_threads
    use core_strings, only: to_str
    implicit none
    private
    public :: single_thread_blas, thread_setting

    !> Whether single_thread_blas set OpenBLAS to one thread.
    logical, save :: blas_pinned = .false.

    interface
        function multicor_blas_single_thread() bind(c, name='multicor_blas_single_thread') result(done)
            import :: c_int
            integer(c_int) :: done
        end function multicor_blas_single_thread
    end interface

contains

    !> Set OpenBLAS to one thread: the rounding of its threaded kernels depends on their
    !> count (a chaotic contact layer amplifies it to the fourth digit of its positions), and
    !> the sizes of the factorisations of a 2D run gain nothing measurable from threads. A
    !> BLAS other than OpenBLAS is left as it is (thread_setting says so).
    subroutine single_thread_blas()
        blas_pinned = multicor_blas_single_thread() == 1
    end subroutine single_thread_blas

    !> 'OpenMP threads N, OpenBLAS 1 thread' after single_thread_blas, else 'OpenMP threads
    !> N, BLAS threads its own'. N is 1 in a build without OpenMP.
    function thread_setting() result(text)
        character(len=:), allocatable :: text
        integer :: n
        n = 1
!$      n = omp_get_max_threads()
        if (blas_pinned) then
            text = 'OpenMP threads '//to_str(n)//', OpenBLAS 1 thread'
        else
            text = 'OpenMP threads '//to_str(n)//', BLAS threads its own'
        end if
    end function thread_setting
end module core_threads
