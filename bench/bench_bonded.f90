!> Bonded structures: the direct bonded block (`[solver] method = block`, dem_bonded_block)
!> against the plain NLGS (issue 8, part 1).
!>
!> Case 1, clamped bonded row: 50 touching disks (R = 1 cm, 2500 kg/m^3) along x, bonds
!> locking opening, sliding and rotation (sigma = 1e6 Pa, mu_b = 1, e_b = R/2), disk 1
!> clamped, a tip load P = 3 N/m along y, one step (h = 1e-4 s) from rest at tolerance 1e-10.
!> Printed per method: sweeps (NLGS) or block iterations, converged, time of the step, and
!> the largest error against the closed form r_n = 0, r_t = -P h, M_k = -P R (2(N - k) - 1) h
!> (relative to P h, and to P R (2N - 1) h for the moments).
!> Case 2, reference stack: the deck input/bending_stack.dat (beam + 49 bonded disks, Arlequin
!> coupling; path given as the first argument, default input/bending_stack.dat from the
!> current folder) with the tolerance 1e-10 and a cap of 10^5 sweeps: 1000 steps with the
!> block, and the first nlgs_steps (default 5, second argument) steps with the NLGS (1000
!> steps of it at 1e-10 would take hours; 0 skips the NLGS in both cases). Printed: sweeps or block iterations per step (mean
!> and max), converged fraction, wall time per step of the whole coupled step and of the DEM
!> solve (laws, frames, block set-up and factorisation, iterations), wall and CPU time of all
!> the steps (the CPU time is the figure to trust on a loaded machine), and the block's counts
!> (analyses, factorisations, kept factors, refinements, releases).
!> Run: cmake --build <build> --target bench_bonded && OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
!>      <build>/bench/bench_bonded [deck [nlgs_steps]]   (--help or -h: the usage, nothing run)
!> A deck that does not exist, or that does not read, stops the program with a message and exit
!> code 1 before anything is timed; a malformed command line with the usage and exit code 2.
!> The set-up's announcements (a module procedure: an internal one passed as an argument needs
!> a trampoline at -O0).
module bench_bonded_report
    use, intrinsic :: iso_fortran_env, only: output_unit
    implicit none
    private
    public :: report_line
contains
    !> Lines the set-up announces (a long one), printed as they come.
    subroutine report_line(line)
        !> The line.
        character(len=*), intent(in) :: line
        write (output_unit, '(a)') line
    end subroutine report_line
end module bench_bonded_report

program bench_bonded
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, compiler_version
    use bench_bonded_report, only: report_line
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use io_deck_schema, only: multicor_schema
    use io_deck, only: deck_t, read_deck
    use dem_particles, only: particles_add_disks, particles_fix, particles_add_load, dof_x, dof_y, dof_rot
    use dem_materials, only: materials_init, materials_set_pair, materials_set_bond, bond_e_default
    use dem_moreau_jean, only: dem_system_t, mj_init, mj_step
    use dem_solve_method, only: solve_method_t, sweeps_method_t
    use dem_bonded_block, only: bonded_block_method_t
    use driver_config, only: run_config_t, build_config
    use driver_config_dem, only: dem_config_t, build_dem_config
    use driver_config_coupling, only: coupled_setup_t, build_coupling_config
    use driver_simulation_coupled, only: build_coupled
    use fem_beam_config, only: beam_config_t
    use coupling_arlequin, only: coupled_system_t, arlequin_step
    implicit none

    character(len=512) :: arg
    character(len=:), allocatable :: deck_path
    integer :: nlgs_steps, ios
    logical :: exists
    type(deck_t) :: checked
    type(error_t), allocatable :: deck_error
    deck_path = 'input/bending_stack.dat'
    if (command_argument_count() >= 1) then
        call get_command_argument(1, arg)
        select case (trim(arg))
        case ('--help', '-h')
            call print_usage(output_unit)
            stop
        end select
        if (arg(1:1) == '-') call usage_error('unknown option '''//trim(arg)//'''')
        deck_path = trim(arg)
    end if
    if (command_argument_count() > 2) call usage_error('at most two arguments, a deck and nlgs_steps')
    nlgs_steps = 5
    if (command_argument_count() >= 2) then
        call get_command_argument(2, arg)
        read (arg, *, iostat=ios) nlgs_steps
        if (ios /= 0 .or. nlgs_steps < 0) call usage_error('nlgs_steps must be an integer >= 0 (got '''// &
                                                           trim(arg)//''')')
    end if
    inquire (file=deck_path, exist=exists)
    if (.not. exists) call fail('cannot open the deck '''//deck_path//''': no such file (give the path of '// &
                                'the reference stack''s deck as the first argument; without one, '// &
                                'input/bending_stack.dat is read from the current folder)')
    ! a deck that does not read stops here, before the clamped row is timed
    call read_deck(deck_path, multicor_schema(), checked, deck_error)
    if (allocated(deck_error)) call fail(deck_error%message)
    write (output_unit, '(a)') '# bonded block against NLGS (1 core); compiler: '//compiler_version()
    write (output_unit, '(a)') '# clamped bonded row, 50 disks, tip load, one step from rest, tol 1e-10'
    write (output_unit, '(a)') '# method  iterations  converged  time[s]  err_rn/Ph  err_rt/Ph  err_M/(PR(2N-1)h)'
    call clamped_row(bonded_block_method_t())
    if (nlgs_steps > 0) call clamped_row(sweeps_method_t())
    write (output_unit, '(a)') '# reference stack '//deck_path//', tol 1e-10, cap 1e5 sweeps'
    write (output_unit, '(a)') '# method  steps  iter_mean  iter_max  converged  step[ms]  dem_solver[ms]  '// &
        'total[s]  cpu[s]  analyses  factorisations  kept  refinements  releases'
    call reference_stack(deck_path, bonded_block_method_t(), 1000)
    if (nlgs_steps > 0) call reference_stack(deck_path, sweeps_method_t(), nlgs_steps)

contains

    !> Case 1 with the given method.
    subroutine clamped_row(method)
        class(solve_method_t), intent(in) :: method
        integer, parameter :: n = 50
        real(wp), parameter :: r = 0.01_wp, p = 3.0_wp, h = 1.0e-4_wp, rho = 2500.0_wp
        type(dem_system_t) :: sys
        type(error_t), allocatable :: error
        integer(i8) :: c0, c1, rate
        real(wp) :: ern, ert, erm
        integer :: k, d, j
        call materials_init(sys%materials, 1, error)
        call materials_set_pair(sys%materials, 1, 1, 0.0_wp, 0.0_wp, 1.0e6_wp, error)
        call materials_set_bond(sys%materials, 1, 1, 1.0_wp, bond_e_default, error)
        sys%scheme%h = h
        sys%scheme%alert = 0.25_wp*r
        sys%solver%tol = 1.0e-10_wp
        sys%solver%max_sweeps = 1000000
        allocate (sys%method, source=method)
        call particles_add_disks(sys%particles, [(2.0_wp*r*(k - 1), k=1, n)], spread(0.0_wp, 1, n), &
                                 spread(r, 1, n), [rho], error)
        do d = dof_x, dof_rot
            call particles_fix(sys%particles, 1, d, error)
        end do
        call particles_add_load(sys%particles, n, dof_y, p, error)
        call mj_init(sys, error)
        if (allocated(error)) call fail('the clamped row''s set-up failed: '//error%message)
        call system_clock(c0, rate)
        call mj_step(sys)
        call system_clock(c1)
        ern = 0.0_wp
        ert = 0.0_wp
        erm = 0.0_wp
        do j = 1, sys%contacts%n
            k = sys%contacts%i1(j)
            ern = max(ern, abs(sys%contacts%r(1, j))/(p*h))
            ert = max(ert, abs(sys%contacts%r(2, j) + p*h)/(p*h))
            erm = max(erm, abs(sys%contacts%r(3, j) + p*r*(2*(n - k) - 1)*h)/(p*r*(2*n - 1)*h))
        end do
        write (output_unit, '(a6,i12,l11,es9.2,3es11.2)') name(method), sys%stats%sweeps, sys%stats%converged, &
            real(c1 - c0, wp)/real(rate, wp), ern, ert, erm
    end subroutine clamped_row

    !> Case 2 with the given method, `steps` steps.
    subroutine reference_stack(path, method, steps)
        character(len=*), intent(in) :: path
        class(solve_method_t), intent(in) :: method
        integer, intent(in) :: steps
        type(deck_t) :: deck
        type(run_config_t) :: run
        type(beam_config_t) :: beam
        type(dem_config_t) :: dem
        type(coupled_setup_t) :: setup
        type(coupled_system_t), allocatable :: sys
        type(error_t), allocatable :: error
        integer(i8) :: c0, c1, rate
        integer :: k, it_max, n_conv
        real(wp) :: it_sum, t_total, t_solver0, cpu0, cpu1
        call read_deck(path, multicor_schema(), deck, error)
        if (.not. allocated(error)) call build_config(deck, run, beam, error)
        if (.not. allocated(error)) call build_dem_config(deck, run, beam%functions, dem, error)
        if (.not. allocated(error)) call build_coupling_config(deck, run, beam, dem, setup, error)
        if (allocated(error)) call fail(error%message)
        dem%system%solver%tol = 1.0e-10_wp
        dem%system%solver%max_sweeps = 100000
        deallocate (dem%system%method)
        allocate (dem%system%method, source=method)
        allocate (sys)
        call build_coupled(run, beam, dem, setup, sys, report_line, error)
        if (allocated(error)) call fail(error%message)
        it_sum = 0.0_wp
        it_max = 0
        n_conv = 0
        t_solver0 = sys%dem%time_solver
        call cpu_time(cpu0)
        call system_clock(c0, rate)
        do k = 1, steps
            call arlequin_step(sys, error)
            if (allocated(error)) call fail('step failed: '//error%message)
            it_sum = it_sum + sys%dem%stats%sweeps
            it_max = max(it_max, sys%dem%stats%sweeps)
            if (sys%dem%stats%converged) n_conv = n_conv + 1
        end do
        call system_clock(c1)
        call cpu_time(cpu1)
        t_total = real(c1 - c0, wp)/real(rate, wp)
        select type (m => sys%dem%method)
        type is (bonded_block_method_t)
            associate (c => m%block%counts)
                write (output_unit, '(a6,i7,f11.1,i10,f11.3,2f10.3,2f10.3,5i8)') name(method), steps, it_sum/steps, &
                    it_max, real(n_conv, wp)/steps, 1.0e3_wp*t_total/steps, &
                    1.0e3_wp*(sys%dem%time_solver - t_solver0)/steps, t_total, cpu1 - cpu0, c%analyses, &
                    c%factorisations, c%reuses, c%refinements, c%releases
            end associate
        class default
            write (output_unit, '(a6,i7,f11.1,i10,f11.3,2f10.3,2f10.3)') name(method), steps, it_sum/steps, it_max, &
                real(n_conv, wp)/steps, 1.0e3_wp*t_total/steps, 1.0e3_wp*(sys%dem%time_solver - t_solver0)/steps, &
                t_total, cpu1 - cpu0
        end select
    end subroutine reference_stack

    !> The usage, on `unit`.
    subroutine print_usage(unit)
        !> Where it is written.
        integer, intent(in) :: unit
        write (unit, '(a)') 'usage: bench_bonded [deck [nlgs_steps]]', &
            '       bench_bonded --help', &
            'The bonded block ([solver] method = block) against plain NLGS, at the tolerance 1e-10:', &
            'a clamped bonded row of 50 disks (one step from rest, against the closed form), then the', &
            'reference stack deck: 1 000 steps with the block and the first nlgs_steps with NLGS.', &
            '  deck        the reference stack''s deck (default: input/bending_stack.dat, from the', &
            '              current folder)', &
            '  nlgs_steps  steps of the deck with NLGS (default 5); 0 skips NLGS in both cases', &
            'For the one-core figures of doc/performance.md ("Bonded block"), run with', &
            'OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1.'
    end subroutine print_usage

    !> A malformed command line: the message and the usage on standard error, exit code 2.
    subroutine usage_error(message)
        !> What is wrong.
        character(len=*), intent(in) :: message
        write (error_unit, '(a)') 'bench_bonded: '//message
        call print_usage(error_unit)
        stop 2, quiet = .true.
    end subroutine usage_error

    !> An error of the run (a deck missing or that does not read, a failed step): the message
    !> on standard error, exit code 1, no backtrace.
    subroutine fail(message)
        !> What went wrong.
        character(len=*), intent(in) :: message
        write (error_unit, '(a)') 'bench_bonded: '//message
        stop 1, quiet = .true.
    end subroutine fail

    !> Name of a method.
    pure function name(method) result(s)
        class(solve_method_t), intent(in) :: method
        character(len=6) :: s
        select type (method)
        type is (bonded_block_method_t)
            s = 'block'
        class default
            s = 'nlgs'
        end select
    end function name
end program bench_bonded
