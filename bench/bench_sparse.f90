!> Speed and memory of the sparse direct solver (core_sparse, SuiteSparse CHOLMOD) against the
!> band Cholesky of LAPACK (core_linalg, dpbtrf/dpbtrs).
!>
!> The matrix is the 2D 5-point Laplacian on an n x n grid of unknowns (Dirichlet boundary,
!> N = n^2 unknowns, 4 on the diagonal, -1 to each neighbour), numbered row by row so that its
!> bandwidth is n. For each n (default 100, 300, 1000; or the n given as arguments): assembly
!> from triplets and compression, symbolic analysis, numerical factorisation, a second
!> factorisation with new values and the same pattern (the analysis reused), and one solve
!> with b = 1, for CHOLMOD's default ordering, AMD and METIS; then the band Cholesky where its
!> storage (two (n+1) x N arrays) stays below 4 GB and its n^4 flops below 2e11. Times are
!> wall-clock seconds, best of 3 repetitions for N <= 1e5, one run above; the factorisation is
!> also given in CPU seconds of the process (less sensitive to other jobs on a shared machine).
!> Printed per case: ordering, nnz of the lower triangle of A (for the band: stored band
!> entries), nnz(L), flops of one factorisation, peak memory (CHOLMOD's count; for the band:
!> the matrix and its factor), the times and the relative residual |b - A x| / |b|.
!> Run: cmake --build <build> --target bench_sparse &&
!>      OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 <build>/bench/bench_sparse [n ...]
program bench_sparse
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, compiler_version
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use core_sparse, only: sparse_matrix_t, sparse_solver_t, sparse_stats_t, sparse_order_auto, &
                           sparse_order_amd, sparse_order_metis
    use core_linalg, only: band_spd_t
    implicit none

    !> Band storage limit [bytes] and flop limit of the band factorisation.
    real(wp), parameter :: band_max_bytes = 4.0e9_wp, band_max_flops = 2.0e11_wp
    integer, allocatable :: grids(:)
    character(len=32) :: arg
    integer :: k, ios

    if (command_argument_count() > 0) then
        allocate (grids(command_argument_count()))
        do k = 1, size(grids)
            call get_command_argument(k, arg)
            read (arg, *, iostat=ios) grids(k)
            if (ios /= 0 .or. grids(k) < 2) then
                write (error_unit, '(a)') 'bench_sparse: arguments are grid sizes n >= 2 (got '//trim(arg)//')'
                error stop 2
            end if
        end do
    else
        grids = [100, 300, 1000]
    end if
    write (output_unit, '(a)') '# sparse direct solver benchmark: 2D 5-point Laplacian on n x n grids'
    write (output_unit, '(a)') '# compiler: '//compiler_version()
    write (output_unit, '(a)') '# times in seconds (wall clock); flops of one factorisation; memory in MB'
    write (output_unit, '(a6,1x,a8,1x,a8,1x,a9,1x,a9,1x,a9,1x,a8,7(1x,a8),1x,a9)') &
        'n', 'N', 'method', 'nnz(A)', 'nnz(L)', 'flops', 'mem', 't_asm', 't_anal', 't_fact', 'cpu_fact', &
        't_refac', 't_solve', 'residual'
    do k = 1, size(grids)
        call sparse_case(grids(k), sparse_order_auto, 'auto')
        call sparse_case(grids(k), sparse_order_amd, 'amd')
        call sparse_case(grids(k), sparse_order_metis, 'metis')
        call band_case(grids(k))
    end do

contains

    !> Wall-clock time [s].
    function wall() result(t)
        real(wp) :: t
        integer(i8) :: count, rate
        call system_clock(count, rate)
        t = real(count, wp)/real(rate, wp)
    end function wall

    !> CPU time of the process [s].
    function cpu() result(t)
        real(wp) :: t
        call cpu_time(t)
    end function cpu

    !> Repetitions of the timed steps for N unknowns.
    pure integer function repetitions(n_unknowns)
        integer, intent(in) :: n_unknowns
        repetitions = merge(3, 1, n_unknowns <= 100000)
    end function repetitions

    !> Add the 5-point Laplacian (+ shift on the diagonal) of an n x n grid to a matrix
    !> (unknown (i, j) is number i + (j - 1) n).
    subroutine add_laplacian(a, n, shift)
        type(sparse_matrix_t), intent(inout) :: a
        integer, intent(in) :: n
        real(wp), intent(in) :: shift
        integer :: i, j, p
        do j = 1, n
            do i = 1, n
                p = i + (j - 1)*n
                call a%add(p, p, 4.0_wp + shift)
                if (i < n) call a%add(p + 1, p, -1.0_wp)
                if (j < n) call a%add(p + n, p, -1.0_wp)
            end do
        end do
    end subroutine add_laplacian

    !> Stop with the message of an unexpected error.
    subroutine check(error, what)
        type(error_t), allocatable, intent(in) :: error
        character(len=*), intent(in) :: what
        if (allocated(error)) then
            write (error_unit, '(a)') 'bench_sparse: '//what//': '//error%message
            error stop 1
        end if
    end subroutine check

    !> One CHOLMOD run on the n x n grid with the given ordering.
    subroutine sparse_case(n, ordering, name)
        integer, intent(in) :: n, ordering
        character(len=*), intent(in) :: name
        type(sparse_matrix_t) :: a
        type(sparse_solver_t) :: solver
        type(sparse_stats_t) :: stats
        type(error_t), allocatable :: error
        real(wp), allocatable :: b(:), x(:), r(:)
        real(wp) :: t0, c0, t_asm, t_anal, t_fact, c_fact, t_refac, t_solve
        integer :: nn, rep
        nn = n*n
        t0 = wall()
        call a%init(nn, 3_i8*nn)
        call add_laplacian(a, n, 0.0_wp)
        call a%finalize(error)
        call check(error, 'finalize')
        t_asm = wall() - t0
        t0 = wall()
        call solver%analyse(a, error, ordering=ordering)
        call check(error, 'analyse')
        t_anal = wall() - t0
        t_fact = huge(1.0_wp)
        c_fact = huge(1.0_wp)
        do rep = 1, repetitions(nn)
            t0 = wall()
            c0 = cpu()
            call solver%factor(a, error)
            call check(error, 'factor')
            c_fact = min(c_fact, cpu() - c0)
            t_fact = min(t_fact, wall() - t0)
        end do
        ! New values, same pattern (a shifted operator, as a Newmark matrix K + c M would be).
        call a%zero_values()
        call add_laplacian(a, n, 1.0e-3_wp)
        t_refac = huge(1.0_wp)
        do rep = 1, repetitions(nn)
            t0 = wall()
            call solver%factor(a, error)
            call check(error, 'refactor')
            t_refac = min(t_refac, wall() - t0)
        end do
        allocate (b(nn), x(nn), r(nn))
        b = 1.0_wp
        t_solve = huge(1.0_wp)
        do rep = 1, repetitions(nn)
            t0 = wall()
            call solver%solve(b, x, error)
            call check(error, 'solve')
            t_solve = min(t_solve, wall() - t0)
        end do
        r = b
        call a%matvec(x, r, error, alpha=-1.0_wp, beta=1.0_wp)
        call check(error, 'matvec')
        stats = solver%stats()
        write (output_unit, '(i6,1x,i8,1x,a8,1x,i9,1x,es9.3,1x,es9.3,1x,f8.1,6(1x,f8.3),1x,es9.2)') &
            n, nn, 'cm-'//name, a%nnz(), stats%nnz_factor, stats%flops, stats%memory_peak/1.0e6_wp, &
            t_asm, t_anal, t_fact, c_fact, t_refac, t_solve, norm2(r)/norm2(b)
        if (name == 'auto') write (output_unit, '(a,a,a,l1)') '#   auto chose ordering ', stats%ordering, &
            ', supernodal ', stats%supernodal
    end subroutine sparse_case

    !> LAPACK band Cholesky on the same matrix (natural numbering, kd = n), when it fits.
    subroutine band_case(n)
        integer, intent(in) :: n
        type(band_spd_t) :: a
        type(error_t), allocatable :: error
        real(wp), allocatable :: b(:), x(:), r(:)
        real(wp) :: t0, c0, t_asm, t_fact, c_fact, t_solve, bytes, flops
        integer :: nn, i, j, p, rep
        nn = n*n
        bytes = 2*8.0_wp*(n + 1)*real(nn, wp)
        flops = real(nn, wp)*real(n, wp)**2
        if (bytes > band_max_bytes .or. flops > band_max_flops) then
            write (output_unit, '(i6,1x,i8,1x,a8,a,f0.1,a,es8.2,a)') n, nn, 'band', &
                '   skipped: storage ', bytes/1.0e9_wp, ' GB, ', flops, ' flops'
            return
        end if
        t0 = wall()
        call a%init(nn, n)
        do j = 1, n
            do i = 1, n
                p = i + (j - 1)*n
                call a%add(p, p, 4.0_wp)
                if (i < n) call a%add(p, p + 1, -1.0_wp)
                if (j < n) call a%add(p, p + n, -1.0_wp)
            end do
        end do
        t_asm = wall() - t0
        t_fact = huge(1.0_wp)
        c_fact = huge(1.0_wp)
        do rep = 1, repetitions(nn)
            t0 = wall()
            c0 = cpu()
            call a%factor(error)
            call check(error, 'band factor')
            c_fact = min(c_fact, cpu() - c0)
            t_fact = min(t_fact, wall() - t0)
        end do
        allocate (b(nn), x(nn), r(nn))
        b = 1.0_wp
        t_solve = huge(1.0_wp)
        do rep = 1, repetitions(nn)
            x = b
            t0 = wall()
            call a%solve(x, error)
            call check(error, 'band solve')
            t_solve = min(t_solve, wall() - t0)
        end do
        r = b
        call a%matvec(x, r, alpha=-1.0_wp, beta=1.0_wp)
        ! The band factor holds (kd+1) N entries; the flops are those of dpbtrf, N kd^2.
        write (output_unit, '(i6,1x,i8,1x,a8,1x,i9,1x,es9.3,1x,es9.3,1x,f8.1,1x,f8.3,1x,a8,2(1x,f8.3),1x,a8,1x,f8.3,1x,es9.2)') &
            n, nn, 'band', int(a%kd + 1, i8)*nn, real(a%kd + 1, wp)*nn, flops, bytes/1.0e6_wp, t_asm, '-', &
            t_fact, c_fact, '-', t_solve, norm2(r)/norm2(b)
    end subroutine band_case
end program bench_sparse
