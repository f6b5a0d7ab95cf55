!> Speed and memory of the discrete-element kernel (issue 3, "Speed").
!>
!> For N = 1e3, 1e4, 1e5 disks: a dense random packing at rest in a box under gravity
!> (bench_packing: sequential deposition with rolling, radii uniform in [0.8, 1.2] mm, seed 42
!> or --packing-seed S,
!> box about as high as wide, floor and two side walls; radii then enlarged by 1e-6 so that
!> every contact of the deposit starts closed), density 2500 kg/m^3, mu = 0.5, e = 0,
!> h = 1 ms, theta = 1/2, alert 5 % of the mean radius, NLGS tolerance
!> 1.666e-4 (LMGC90's default), at most 200 sweeps. The packing is built (timed apart, not
!> part of the figures), n_settle steps are run (the warm start fills up), then n_steps steps
!> are timed one by one; at the end the detection alone is timed again on the last
!> configuration of each N, the sizes taking turns (time_detection). Printed per N:
!>   contacts found by the detection (gap <= alert) and active in the solver (bonded, predicted
!>   gap within a round-off allowance of closing, or loaded at the previous step), sweeps per
!>   step, wall-clock time per step of the detection (broad + narrow phase + warm-start
!>   matching) and of the solver (laws, frames, NLGS sweeps, residual):
!>   median and best over the timed steps, and median and best of the repeated detection
!>   (per call);
!>   solver contact updates per second = active contacts x sweeps / solver time of a step
!>   (median and best over the timed steps); bytes per particle = every array of the system (disks,
!>   walls, contacts, previous contact list, detection grid, work arrays) at its allocated size,
!>   divided by N; and the detection scaling ratio t(1e5)/t(1e4). The line closing each N
!>   also counts the timed steps solved more than once (the re-check of the rule of
!>   activation, doc/theory.md 2.4), as a comment line after the Siconos deposit's figures does.
!> With the argument `--convergence`, prints instead the sweeps one step needs to reach the
!> tolerance from a cold start (no warm start, cap 50000) on packings of 250 to 16000 disks:
!> what limits the solver on tall static packings.
!> Options: --sizes N... (the packings to run), --anderson M (Anderson depth; default 5 as in
!> the decks, 0: plain sweeps), --anderson-after K (plain sweeps before the Anderson steps;
!> default 10, `[solver] anderson_after`), --anderson-sweeps P (sweeps per Anderson step;
!> default 2, `[solver] anderson_sweeps`), --relaxation W,
!> --check-every K (safeguard period of the over-relaxation), --criterion siconos, --tol T
!> (tolerance of the packings, default 1.666e-4), --settle-tol T (of their settling steps,
!> default the same), --steps K (timed steps; default at least 8 and about 2e5 disk-steps),
!> --max-sweeps C (cap of the timed steps), --forward (no alternating sweeps), --settle S (steps
!> before timing, default 10), --settle-anderson M and --settle-sweeps C (solver of those
!> steps, default the timed one), --verbose (sweeps, Siconos error, solver ms of every timed
!> step), --hydrostatic (cold start from the hydrostatic estimate, `[solver] cold_start`),
!> --method nlgs|block|coarse (`[solver] method`; default nlgs), --coarse-every K and
!> --coarse-size M (`[solver] coarse_every`, `coarse_size`), --settle-method M (method of the
!> settling steps, default the timed one). With --verbose the coarse corrections of each
!> step are printed after the solver time.
!> The Siconos error of every timed step is printed too (mean and max).
!> Speeds are sqrt(vx**2 + vy**2), not hypot: the vectorised hypot of glibc 2.36
!> (_ZGVbN2vv_hypot_sse4) raises the invalid flag on some of the final speeds of the 2000-disk
!> deposit (a Release build with -ffpe-trap=invalid stops there), and gfortran then printed an
!> IEEE_INVALID_FLAG note at exit.
!> With `--siconos N` (200 or 2000), runs instead the deposit compared with Siconos
!> (siconos_deposit); --csv FILE and --deck FILE write its layout as CSV and as a deck, --seed S
!> draws other radii (default 8, the layout of input/siconos_deposit_*.dat): the deposit is
!> chaotic, so a change of the solver that moves the stopping points is judged over many seeds.
!> --scheme multicor|siconos chooses the rule of activation of the contacts (`[time]
!> contact_scheme`, doc/theory.md 2.6): with --siconos the default is siconos, so that the
!> deposit is the discrete problem Siconos 4.4 integrates; otherwise multicor, the deck default.
!> Run: cmake --build <build> --target bench_dem && OMP_NUM_THREADS=1 <build>/bench/bench_dem
program bench_dem
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit, compiler_version, compiler_options
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use core_sort, only: sort_in_place
    use core_threads, only: thread_setting
    use dem_particles, only: particles_add_disks
    use dem_walls, only: walls_add
    use dem_materials, only: materials_init, materials_set_pair
    use dem_detection, only: detect_contacts
    use dem_moreau_jean, only: dem_system_t, mj_init, mj_step, dem_system_bytes
    use dem_activation, only: activation_siconos_t, activation_predicted_t
    use dem_nlgs, only: nlgs_config_t
    use dem_nlgs_criterion, only: lmgc90_criterion_t, siconos_criterion_t
    use dem_solve_method, only: sweeps_method_t
    use dem_bonded_block, only: bonded_block_method_t
    use dem_coarse, only: coarse_correction_t
    use dem_cold_start, only: hydrostatic_start_t
    use bench_packing, only: deposit_disks, deposit_width, staggered_layout
    implicit none

    !> Figures of one N.
    type :: case_t
        !> Disks, contacts found, active contacts (last step), disks stuck in the deposition.
        integer :: n = 0, contacts = 0, active = 0, stuck = 0
        !> Box width and deposit height [m], packing fraction, build time [s].
        real(wp) :: width = 0.0_wp, height = 0.0_wp, solid_fraction = 0.0_wp, t_build = 0.0_wp
        !> Mean and max speed after the timed steps / (g h).
        real(wp) :: v_mean = 0.0_wp, v_max = 0.0_wp
        !> Sweeps per step: mean and max; fraction of converged steps.
        real(wp) :: sweeps = 0.0_wp, converged = 0.0_wp
        integer :: sweeps_max = 0
        !> Detection per step [s]: median and best over the steps, and over the repetitions.
        real(wp) :: det_med = 0.0_wp, det_best = 0.0_wp, rep_med = 0.0_wp, rep_best = 0.0_wp
        !> Solver per step [s]: median and best.
        real(wp) :: sol_med = 0.0_wp, sol_best = 0.0_wp
        !> Contact updates per second: median and best over the timed steps.
        real(wp) :: rate = 0.0_wp, rate_best = 0.0_wp
        !> Bytes per particle.
        real(wp) :: bytes = 0.0_wp
        !> Siconos error at the end of the step: mean and max over the timed steps.
        real(wp) :: sic_mean = 0.0_wp, sic_max = 0.0_wp
    end type case_t

    integer, allocatable :: sizes(:)
    !> Steps before timing (the warm start fills up).
    integer :: n_settle = 10
    !> Timed steps of a packing (--steps; 0: at least 8, and about 2e5 disk-steps).
    integer :: n_timed = 0
    real(wp), parameter :: radius_mean = 1.0e-3_wp, gravity = 9.81_wp, step = 1.0e-3_wp
    !> Rounds of the interleaved detection timing.
    integer, parameter :: n_rounds = 30
    type(case_t), allocatable :: res(:)
    type(dem_system_t), allocatable :: systems(:)
    character(len=256) :: arg, val
    !> Solver options from the command line (see the header).
    real(wp) :: relaxation = 1.0_wp
    !> Tolerance of the timed steps and of the settling steps (--tol, --settle-tol; 0: the
    !> timed one).
    real(wp) :: tol = 1.666e-4_wp, settle_tol = 0.0_wp
    !> Stopping criterion (--criterion; the Siconos deposit's default is siconos).
    character(len=7) :: criterion = 'lmgc90'
    integer :: max_sweeps = 200, check_every = 10, settle_sweeps = 0, iarg
    integer :: anderson = 5, settle_anderson = -1, anderson_after = 10, anderson_sweeps = 2
    logical :: convergence = .false., sizes_given = .false., verbose = .false., symmetric = .true.
    logical :: hydrostatic = .false., criterion_given = .false.
    !> Global strategy (`[solver] method`; of the settling steps, -1: the same) and the
    !> coarse correction (`coarse_every`, `coarse_size`).
    !> Codes of `--method`: nlgs, block, and coarse, the sweeps with dem_coarse's correction.
    integer, parameter :: method_nlgs = 1, method_block = 2, method_coarse = 3
    integer :: method = method_nlgs, settle_method = -1
    integer :: coarse_every = 10, coarse_size = 400
    !> Siconos deposit (--siconos N): disks, and the files of the layout (empty: not written).
    integer :: siconos_n = 0
    !> Seed of the deposit's radii (--seed; 8 is the layout of the decks and of the CSV compared
    !> with Siconos).
    integer :: layout_seed = 8
    !> Seed of the random packings' deposition (--packing-seed; 42 is the packing of the
    !> tables of doc/performance.md).
    integer :: packing_seed = 42
    character(len=256) :: csv_path = '', deck_path = ''
    !> Rule of activation (--scheme, `[time] contact_scheme`): multicor or siconos; '' for the
    !> default of the mode (siconos for --siconos, the deposit compared with Siconos 4.4 on
    !> the same discrete problem; multicor otherwise).
    character(len=16) :: scheme_word = ''
    integer :: k
    sizes = [1000, 10000, 100000]
    iarg = 1
    do while (iarg <= command_argument_count())
        call get_command_argument(iarg, arg)
        call get_command_argument(iarg + 1, val)
        select case (arg)
        case ('--convergence')
            convergence = .true.
            iarg = iarg - 1
        case ('--relaxation')
            call read_real_value(arg, val, relaxation)
        case ('--tol')
            call read_real_value(arg, val, tol)
            if (.not. tol > 0.0_wp) call usage_error('--tol needs a tolerance > 0')
        case ('--settle-tol')
            call read_real_value(arg, val, settle_tol)
            if (.not. settle_tol > 0.0_wp) call usage_error('--settle-tol needs a tolerance > 0')
        case ('--max-sweeps')
            call read_int_value(arg, val, max_sweeps)
        case ('--forward')
            symmetric = .false.
            iarg = iarg - 1
        case ('--verbose')
            verbose = .true.
            iarg = iarg - 1
        case ('--anderson')
            call read_int_value(arg, val, anderson)
        case ('--anderson-after')
            call read_int_value(arg, val, anderson_after)
        case ('--anderson-sweeps')
            call read_int_value(arg, val, anderson_sweeps)
            if (anderson_sweeps < 1) call usage_error('--anderson-sweeps needs an integer >= 1')
        case ('--siconos')
            call read_int_value(arg, val, siconos_n)
        case ('--seed')
            call read_int_value(arg, val, layout_seed)
        case ('--packing-seed')
            call read_int_value(arg, val, packing_seed)
        case ('--scheme')
            if (val /= 'multicor' .and. val /= 'siconos') &
                call usage_error('--scheme takes multicor or siconos, got '''//trim(val)//'''')
            scheme_word = trim(val)
        case ('--csv')
            csv_path = val
        case ('--deck')
            deck_path = val
        case ('--hydrostatic')
            hydrostatic = .true.
            iarg = iarg - 1
        case ('--settle-anderson')
            call read_int_value(arg, val, settle_anderson)
        case ('--settle')
            call read_int_value(arg, val, n_settle)
        case ('--steps')
            call read_int_value(arg, val, n_timed)
            if (n_timed < 1) call usage_error('--steps needs an integer >= 1')
        case ('--settle-sweeps')
            call read_int_value(arg, val, settle_sweeps)
        case ('--method')
            method = method_code(val)
        case ('--settle-method')
            settle_method = method_code(val)
        case ('--coarse-every')
            call read_int_value(arg, val, coarse_every)
        case ('--coarse-size')
            call read_int_value(arg, val, coarse_size)
        case ('--check-every')
            call read_int_value(arg, val, check_every)
        case ('--criterion')
            criterion_given = .true.
            if (val /= 'siconos' .and. val /= 'lmgc90') &
                call usage_error('--criterion takes lmgc90 or siconos, got '''//trim(val)//'''')
            criterion = trim(val)
        case ('--sizes')
            sizes = [integer ::]
            sizes_given = .true.
            do while (iarg + 1 <= command_argument_count())
                call get_command_argument(iarg + 1, val)
                if (val(1:1) == '-') exit
                sizes = [sizes, 0]
                call read_int_value(arg, val, sizes(size(sizes)))
                iarg = iarg + 1
            end do
            iarg = iarg - 1
        case ('--help', '-h')
            call print_usage(output_unit)
            stop
        case default
            call usage_error('unknown argument '''//trim(arg)//'''')
        end select
        iarg = iarg + 2
    end do
    if (siconos_n > 0) then
        if (len_trim(scheme_word) == 0) scheme_word = 'siconos'
        write (output_unit, '(a)') '# threads:  '//thread_setting()
        write (output_unit, '(a)') '# compiler: '//compiler_version()
        call siconos_deposit(siconos_n)
        stop
    end if
    write (output_unit, '(a)') '# DEM kernel benchmark: dense random packing in a box under gravity'
    write (output_unit, '(a)') '# threads:  '//thread_setting()
    write (output_unit, '(a)') '# compiler: '//compiler_version()
    write (output_unit, '(a)') '# options:  '//compiler_options()
    write (output_unit, '(a, f0.3, a, i0, a)') '# solver: relaxation ', relaxation, &
        ', criterion '//trim(criterion)//', cap ', max_sweeps, ' sweeps'
    if (convergence) then
        call cold_start_sweeps()
    else
        allocate (systems(size(sizes)), res(size(sizes)))
        do k = 1, size(sizes)
            call run_case(systems(k), sizes(k), res(k))
        end do
        call time_detection(systems, res)
        call print_table(res)
    end if
contains

    !> The rule of activation of --scheme (none: mj_init's default, MULTICOR's rule).
    subroutine set_scheme(sys)
        type(dem_system_t), intent(inout) :: sys
        if (allocated(sys%scheme%activation)) deallocate (sys%scheme%activation)
        select case (scheme_word)
        case ('siconos')
            allocate (activation_siconos_t :: sys%scheme%activation)
        case ('multicor')
            allocate (activation_predicted_t :: sys%scheme%activation)
        end select
    end subroutine set_scheme

    !> Code of a `--method` value.
    integer function method_code(word) result(code)
        character(len=*), intent(in) :: word
        select case (word)
        case ('nlgs')
            code = method_nlgs
        case ('block')
            code = method_block
        case ('coarse')
            code = method_coarse
        case default
            call usage_error('--method takes nlgs, block or coarse, got '''//trim(word)//'''')
        end select
    end function method_code

    !> The strategy of a method code: the sweeps (method_nlgs), the bonded block
    !> (method_block; a block in use keeps its factor), or the sweeps with the coarse
    !> correction of --coarse-every and --coarse-size (method_coarse).
    subroutine set_method(sys, code)
        type(dem_system_t), intent(inout) :: sys
        integer, intent(in) :: code
        if (allocated(sys%solver%correction)) deallocate (sys%solver%correction)
        if (code == method_coarse) &
            allocate (sys%solver%correction, source=coarse_correction_t(every=coarse_every, aggregate=coarse_size))
        if (allocated(sys%method)) then
            if (code == method_block) then
                select type (m => sys%method)
                type is (bonded_block_method_t)
                    return
                end select
            end if
            deallocate (sys%method)
        end if
        if (code == method_block) then
            allocate (bonded_block_method_t :: sys%method)
        else
            allocate (sweeps_method_t :: sys%method)
        end if
    end subroutine set_method

    !> The stopping criterion named `word` (lmgc90 or siconos).
    subroutine set_criterion(solver, word)
        type(nlgs_config_t), intent(inout) :: solver
        character(len=*), intent(in) :: word
        if (allocated(solver%criterion)) deallocate (solver%criterion)
        if (word == 'siconos') then
            allocate (siconos_criterion_t :: solver%criterion)
        else
            allocate (lmgc90_criterion_t :: solver%criterion)
        end if
    end subroutine set_criterion

    !> The integer value of option `option`.
    subroutine read_int_value(option, text, value)
        character(len=*), intent(in) :: option, text
        integer, intent(out) :: value
        integer :: ios
        read (text, *, iostat=ios) value
        if (ios /= 0 .or. len_trim(text) == 0) call usage_error(trim(option)//' takes an integer, got '''//trim(text)//'''')
    end subroutine read_int_value

    !> The real value of option `option`.
    subroutine read_real_value(option, text, value)
        character(len=*), intent(in) :: option, text
        real(wp), intent(out) :: value
        integer :: ios
        read (text, *, iostat=ios) value
        if (ios /= 0 .or. len_trim(text) == 0) call usage_error(trim(option)//' takes a number, got '''//trim(text)//'''')
    end subroutine read_real_value

    !> The options (the header of this file).
    subroutine print_usage(unit)
        integer, intent(in) :: unit
        write (unit, '(a)') 'usage: bench_dem [--sizes N...] [--settle S] [--max-sweeps C] [--anderson M] [--anderson-after K]', &
            '         [--anderson-sweeps P] [--relaxation W --check-every K] [--criterion lmgc90|siconos] [--forward]', &
            '         [--hydrostatic] [--method nlgs|block|coarse] [--coarse-every K] [--coarse-size M]', &
            '         [--settle-anderson M] [--settle-sweeps C] [--settle-method M] [--scheme multicor|siconos]', &
            '         [--tol T] [--settle-tol T] [--steps K] [--packing-seed S] [--verbose]', &
            '       bench_dem --convergence', &
            '       bench_dem --siconos 200|2000 [--seed S] [--scheme siconos|multicor] [--csv FILE] [--deck FILE]', &
            '         [--anderson M] [--anderson-after K] [--anderson-sweeps P] [--forward] [--verbose]', &
            'Options and figures: the header of bench/bench_dem.f90 and doc/performance.md.'
    end subroutine print_usage

    !> A bad command line: the message and the usage on standard error, exit code 2.
    subroutine usage_error(message)
        character(len=*), intent(in) :: message
        write (error_unit, '(a)') 'bench_dem: '//message
        call print_usage(error_unit)
        stop 2, quiet = .true.
    end subroutine usage_error

    !> Build, settle, time and measure one case (the system is kept for time_detection).
    subroutine run_case(sys, n, c)
        type(dem_system_t), intent(out) :: sys
        integer, intent(in) :: n
        type(case_t), intent(out) :: c
        real(wp), allocatable :: t_det(:), t_sol(:), rate(:)
        integer :: s, n_steps, sweeps, n_conv, corrections, resolved, solves_max
        real(wp) :: before_det, before_sol, sic
        ! at least 8 steps, and ~2e5 disk-steps for the small cases (unless --steps)
        n_steps = max(8, 200000/n)
        if (n_timed > 0) n_steps = n_timed
        call build(sys, n, c)
        if (settle_sweeps > 0) sys%solver%max_sweeps = settle_sweeps
        if (settle_tol > 0.0_wp) sys%solver%tol = settle_tol
        if (settle_anderson >= 0) sys%solver%anderson = settle_anderson
        if (settle_method >= 0) call set_method(sys, settle_method)
        do s = 1, n_settle
            call mj_step(sys)
        end do
        sys%solver%max_sweeps = max_sweeps
        sys%solver%tol = tol
        sys%solver%anderson = anderson
        sys%solver%anderson_after = anderson_after
        sys%solver%anderson_sweeps = anderson_sweeps
        call set_method(sys, method)
        allocate (t_det(n_steps), t_sol(n_steps), rate(n_steps))
        sweeps = 0
        n_conv = 0
        corrections = 0
        resolved = 0
        solves_max = 1
        sic = 0.0_wp
        do s = 1, n_steps
            before_det = sys%time_detection
            before_sol = sys%time_solver
            call mj_step(sys)
            t_det(s) = sys%time_detection - before_det
            t_sol(s) = sys%time_solver - before_sol
            rate(s) = real(sys%stats%updates, wp)/max(t_sol(s), tiny(1.0_wp))
            sweeps = sweeps + sys%stats%sweeps
            c%sweeps_max = max(c%sweeps_max, sys%stats%sweeps)
            if (sys%stats%converged) n_conv = n_conv + 1
            sic = sic + sys%stats%siconos_error
            if (verbose) write (output_unit, '(a, i4, a, i6, l2, es11.3, f10.2, i5)') '# step ', s, ' sweeps', &
                sys%stats%sweeps, sys%stats%converged, sys%stats%siconos_error, 1.0e3_wp*t_sol(s), &
                sys%stats%corrections
            corrections = corrections + sys%stats%corrections
            if (sys%stats%solves > 1) resolved = resolved + 1
            solves_max = max(solves_max, sys%stats%solves)
            c%sic_max = max(c%sic_max, sys%stats%siconos_error)
        end do
        c%sic_mean = sic/n_steps
        c%contacts = sys%contacts%n
        c%active = sys%stats%n_active
        c%sweeps = real(sweeps, wp)/n_steps
        c%converged = real(n_conv, wp)/n_steps
        c%det_med = median(t_det)
        c%det_best = minval(t_det)
        c%sol_med = median(t_sol)
        c%sol_best = minval(t_sol)
        c%rate = median(rate)
        c%rate_best = maxval(rate)
        c%bytes = real(dem_system_bytes(sys), wp)/sys%particles%n
        associate (p => sys%particles)
            c%v_mean = sum(sqrt(p%vx(1:p%n)**2 + p%vy(1:p%n)**2))/p%n/(gravity*step)
            c%v_max = maxval(sqrt(p%vx(1:p%n)**2 + p%vy(1:p%n)**2))/(gravity*step)
        end associate
        write (output_unit, '(a, i0, a, f0.1, a, f0.2, a, f0.2, a, f0.3, 3(a, i0))') '# N = ', c%n, ' done (', &
            sum(t_det) + sum(t_sol), ' s timed); sweeps/step ', c%sweeps, ', coarse corrections/step ', &
            real(corrections, wp)/n_steps, ', converged ', c%converged, '; solved more than once ', resolved, &
            ' of ', n_steps, ' steps, at most ', solves_max
        flush (output_unit)
    end subroutine run_case

    !> The detection alone, again on the configuration of the last step of each system (it
    !> finds the same list), in interleaved rounds so that the load of a shared machine hits
    !> every size alike: per round, each size is timed over max(1, 1e5/N) calls. Median and
    !> best per call over the rounds.
    subroutine time_detection(systems, res)
        type(dem_system_t), intent(inout) :: systems(:)
        type(case_t), intent(inout) :: res(:)
        real(wp), allocatable :: t(:, :)
        integer(i8) :: t0, t1, clock_rate
        integer :: round, k, call_no, calls
        allocate (t(n_rounds, size(systems)))
        do round = 1, n_rounds
            do k = 1, size(systems)
                associate (sys => systems(k))
                    calls = max(1, 100000/sys%particles%n)
                    call system_clock(t0, clock_rate)
                    do call_no = 1, calls
                        call detect_contacts(sys%detector, sys%xm, sys%ym, sys%particles%radius, &
                                             sys%scheme%alert, sys%wx1, sys%wy1, sys%wx2, sys%wy2, &
                                             sys%contacts)
                    end do
                    call system_clock(t1)
                    t(round, k) = real(t1 - t0, wp)/real(clock_rate, wp)/calls
                end associate
            end do
        end do
        do k = 1, size(systems)
            res(k)%rep_med = median(t(:, k))
            res(k)%rep_best = minval(t(:, k))
        end do
    end subroutine time_detection

    !> Sweeps of the first step (reactions start at zero) until the tolerance, for packings of
    !> increasing height: the weight has to travel from the top layer to the floor.
    subroutine cold_start_sweeps()
        integer, allocatable :: cold_sizes(:)
        type(dem_system_t) :: sys
        type(case_t) :: c
        integer :: k
        cold_sizes = [250, 1000, 4000, 16000]
        if (sizes_given) cold_sizes = sizes
        write (output_unit, '(a,es10.4,a)') '# first step from rest, no warm start, tolerance ', tol, &
            ', cap 50000 sweeps; height/d: deposit height in mean diameters'
        write (output_unit, '(a)') '#      N  height/d  active  sweeps  converged  solve[s]  updates/s' &
            //'   v_mean[g h]'
        do k = 1, size(cold_sizes)
            call build(sys, cold_sizes(k), c)
            sys%solver%max_sweeps = 50000
            call mj_step(sys)
            associate (p => sys%particles)
                write (output_unit, '(i8, f10.0, i8, i8, l11, f10.2, es11.3, f14.3)') c%n, &
                    c%height/(2.0_wp*radius_mean), sys%stats%n_active, sys%stats%sweeps, &
                    sys%stats%converged, sys%time_solver, real(sys%stats%updates, wp)/sys%time_solver, &
                    sum(sqrt(p%vx(1:p%n)**2 + p%vy(1:p%n)**2))/p%n/(gravity*step)
            end associate
            flush (output_unit)
        end do
    end subroutine cold_start_sweeps

    !> The gravity deposit compared with Siconos 4.4 NSGS (doc/performance.md, "Deposit
    !> against Siconos"): N = 200 (10 x 20) or 2000 (40 x 50) disks on the staggered lattice
    !> of staggered_layout (mean radius 1 cm, seed 8 or --seed, density 2500 kg/m^3), box with a floor
    !> and two side walls, mu = 0.3, e = 0, theta = 1/2, h = 2 ms, alert 5 mm, tolerance 1e-4
    !> on the Siconos error (--criterion lmgc90 for the other norm), cap 10^4 sweeps, 1 s
    !> (500 steps) from rest. Writes the layout
    !> to --csv and --deck when given, then prints per step (with --verbose) and in total:
    !> time per step (whole step, and the solver), sweeps, Siconos error, converged steps,
    !> and the final pile: highest disk top max(y + r), centre-of-mass height, mean speed.
    subroutine siconos_deposit(n)
        integer, intent(in) :: n
        real(wp), parameter :: rmean = 0.01_wp, rho = 2500.0_wp, mu = 0.3_wp, h = 2.0e-3_wp
        real(wp), parameter :: t_end = 1.0_wp, alert = 5.0e-3_wp, tol = 1.0e-4_wp
        integer, parameter :: cap = 10000
        type(dem_system_t) :: sys
        type(error_t), allocatable :: error
        real(wp), allocatable :: x(:), y(:), radius(:), t_step(:), t_sol(:)
        real(wp) :: width, top, sic, sic_max, before_sol
        integer(i8) :: c0, c1, rate
        integer :: n_row, n_rows, n_steps, s, sweeps, sweeps_max, n_conv, resolved, solves_max
        select case (n)
        case (200)
            n_row = 10
            n_rows = 20
        case (2000)
            n_row = 40
            n_rows = 50
        case default
            call usage_error('--siconos takes 200 or 2000')
        end select
        call staggered_layout(n_row, n_rows, rmean, layout_seed, x, y, radius, width)
        top = maxval(y + radius) + 5.0_wp*rmean
        if (len_trim(csv_path) > 0) call write_csv(trim(csv_path), x, y, radius, width)
        if (len_trim(deck_path) > 0) call write_deck(trim(deck_path), n_row, n_rows, x, y, radius, width, top)
        call particles_add_disks(sys%particles, x, y, radius, [rho], error)
        if (allocated(error)) error stop 'bench_dem: invalid disks'
        call walls_add(sys%walls, 0.0_wp, 0.0_wp, width, 0.0_wp, error)
        call walls_add(sys%walls, 0.0_wp, 0.0_wp, 0.0_wp, top, error)
        call walls_add(sys%walls, width, 0.0_wp, width, top, error)
        if (allocated(error)) error stop 'bench_dem: invalid walls'
        call materials_init(sys%materials, 1, error)
        if (.not. allocated(error)) call materials_set_pair(sys%materials, 1, 1, mu, 0.0_wp, 0.0_wp, error)
        if (allocated(error)) error stop 'bench_dem: invalid material'
        sys%particles%gravity = [0.0_wp, -gravity]
        sys%scheme%h = h
        sys%scheme%alert = alert
        sys%solver%tol = tol
        sys%solver%max_sweeps = cap
        if (criterion_given) then
            call set_criterion(sys%solver, criterion)
        else
            call set_criterion(sys%solver, 'siconos')
        end if
        sys%solver%relaxation = relaxation
        sys%solver%anderson = anderson
        sys%solver%anderson_after = anderson_after
        sys%solver%anderson_sweeps = anderson_sweeps
        if (hydrostatic) allocate (hydrostatic_start_t :: sys%solver%start)
        sys%solver%symmetric = symmetric
        call set_method(sys, method)
        call set_scheme(sys)
        call mj_init(sys, error)
        if (allocated(error)) error stop 'bench_dem: invalid setup'
        n_steps = nint(t_end/h)
        allocate (t_step(n_steps), t_sol(n_steps))
        sweeps = 0
        sweeps_max = 0
        resolved = 0
        solves_max = 1
        n_conv = 0
        sic = 0.0_wp
        sic_max = 0.0_wp
        write (output_unit, '(a, i0, a, i0, a, i0, a, f0.4, a, i0, a)') '# deposit against Siconos: N = ', n, ' (', &
            n_row, ' x ', n_rows, '), box width ', width, ' m, mean radius 1 cm, seed ', layout_seed, &
            ', mu 0.3, e 0, h 2 ms, 500 steps, contact scheme '//trim(scheme_word)
        write (output_unit, '(a, es9.2, a, i0, a, 3(i0, a), l1)') '# criterion '//sys%solver%criterion%name()// &
            ', tolerance ', tol, ', cap ', cap, ' sweeps, anderson ', anderson, &
            ' after ', anderson_after, ' sweeps, ', anderson_sweeps, ' sweeps per step, hydrostatic ', hydrostatic
        if (verbose) write (output_unit, '(a)') '# step  active  sweeps  conv  siconos_error  step[ms]  top[m]'
        do s = 1, n_steps
            before_sol = sys%time_solver
            call system_clock(c0, rate)
            call mj_step(sys)
            call system_clock(c1)
            t_step(s) = real(c1 - c0, wp)/real(rate, wp)
            t_sol(s) = sys%time_solver - before_sol
            sweeps = sweeps + sys%stats%sweeps
            sweeps_max = max(sweeps_max, sys%stats%sweeps)
            if (sys%stats%solves > 1) resolved = resolved + 1
            solves_max = max(solves_max, sys%stats%solves)
            if (sys%stats%converged) n_conv = n_conv + 1
            sic = sic + sys%stats%siconos_error
            sic_max = max(sic_max, sys%stats%siconos_error)
            if (verbose) write (output_unit, '(i6, i8, i8, l6, es15.3, f10.3, f9.5)') s, sys%stats%n_active, &
                sys%stats%sweeps, sys%stats%converged, sys%stats%siconos_error, 1.0e3_wp*t_step(s), &
                maxval(sys%particles%y(1:n) + sys%particles%radius(1:n))
        end do
        write (output_unit, '(a)') '#      N  steps  step[ms](mean,median,best)  solver[ms](mean)  ' &
            //'sweeps(mean,max)  conv  siconos(mean,max)  top[m]  y_centre_of_mass[m]  v_mean[m/s]'
        associate (p => sys%particles)
            write (output_unit, '(i8, i7, 3f9.3, f10.3, f10.1, i7, f7.3, 2es10.2, f9.5, f12.6, es12.3)') n, n_steps, &
                1.0e3_wp*sum(t_step)/n_steps, 1.0e3_wp*median(t_step), 1.0e3_wp*minval(t_step), &
                1.0e3_wp*sum(t_sol)/n_steps, real(sweeps, wp)/n_steps, sweeps_max, real(n_conv, wp)/n_steps, &
                sic/n_steps, sic_max, maxval(p%y(1:n) + p%radius(1:n)), sum(p%mass(1:n)*p%y(1:n))/sum(p%mass(1:n)), &
                sum(sqrt(p%vx(1:n)**2 + p%vy(1:n)**2))/n
        end associate
        write (output_unit, '(3(a, i0))') '# solved more than once (the rule''s re-check, doc/theory.md 2.4): ', &
            resolved, ' of ', n_steps, ' steps, at most ', solves_max
    end subroutine siconos_deposit

    !> The layout as CSV: a header of comment lines (box, material), then x, y, radius,
    !> mass and moment of inertia per unit thickness of each disk.
    subroutine write_csv(path, x, y, radius, width)
        character(len=*), intent(in) :: path
        real(wp), intent(in) :: x(:), y(:), radius(:), width
        real(wp), parameter :: pi = 3.141592653589793238462643383279502884_wp, rho = 2500.0_wp
        integer :: n
        integer :: u, k
        n = size(x)
        open (newunit=u, file=path, status='replace', action='write')
        write (u, '(a, i0, a, es24.16e2, a)') '# MULTICOR deposit against Siconos: ', n, &
            ' disks; box: floor y = 0, side walls x = 0 and x = ', width, ' m'
        write (u, '(a)') '# density 2500 kg/m^3 per unit thickness, mu = 0.3, e = 0, gravity 9.81 m/s^2, ' &
            //'h = 2 ms, theta = 1/2, 500 steps; mass = 2500 pi r^2, inertia = mass r^2 / 2'
        write (u, '(a)') 'x,y,radius,mass,inertia'
        do k = 1, n
            write (u, '(es24.16e2, 4(",", es24.16e2))') x(k), y(k), radius(k), rho*pi*radius(k)**2, &
                0.5_wp*rho*pi*radius(k)**4
        end do
        close (u)
    end subroutine write_csv

    !> The same problem as a MULTICOR deck (explicit disk records, so that it does not
    !> depend on a generator).
    subroutine write_deck(path, n_row, n_rows, x, y, radius, width, top)
        character(len=*), intent(in) :: path
        integer, intent(in) :: n_row, n_rows
        real(wp), intent(in) :: x(:), y(:), radius(:), width, top
        integer :: n
        integer :: u, k
        n = size(x)
        open (newunit=u, file=path, status='replace', action='write')
        write (u, '(a, i0, a)') '# MULTICOR deck: gravity deposit of ', n, ' disks, the layout compared with' &
            //' Siconos 4.4 NSGS'
        write (u, '(a)') '# (doc/performance.md, "Deposit against Siconos"). Written by'
        if (layout_seed == 8 .and. scheme_word == 'siconos') then
            write (u, '(a, i0, a)') '#   build-release/bench/bench_dem --siconos ', n, ' --deck <this file>'
        else if (scheme_word == 'siconos') then
            write (u, '(a, i0, a, i0, a)') '#   build-release/bench/bench_dem --siconos ', n, ' --seed ', layout_seed, &
                ' --deck <this file>'
        else
            write (u, '(a, i0, a, i0, a)') '#   build-release/bench/bench_dem --siconos ', n, ' --seed ', layout_seed, &
                ' --scheme '//trim(scheme_word)//' --deck <this file>'
        end if
        write (u, '(a, i0, a, i0, a)') '# Staggered lattice of ', n_row, ' x ', n_rows, &
            ' disks, pitch 2.5 R (R = 1 cm), every other row shifted by'
        write (u, '(a, i0, a)') '# half a pitch, radii uniform in [0.8 R, 1.2 R] (seed ', layout_seed, &
            ' of dem_random); the disks start at rest,'
        write (u, '(a)') '# apart, and fall under gravity into a pile. mu = 0.3, e = 0, h = 2 ms, tolerance ' &
            //'1e-4 on the'
        write (u, '(a)') '# Siconos error. Coordinates with 17 significant digits: read back, they are the ' &
            //'doubles of the'
        write (u, '(a)') '# benchmark. Per unit thickness, SI units. Contact scheme '//trim(scheme_word)// &
            ' ([time] contact_scheme;'
        write (u, '(a)') '# siconos: the discrete problem of Siconos 4.4, doc/theory.md 2.6).'
        write (u, '(a)') ''
        write (u, '(a)') '[run]'
        write (u, '(a, i0, a)') 'title    = Gravity deposit of ', n, ' disks (layout compared with Siconos)'
        write (u, '(a)') 'analysis = dynamic'
        write (u, '(a)') ''
        write (u, '(a)') '[particles]'
        write (u, '(a)') 'material = 1 2500'
        write (u, '(a)') 'gravity  = 0 -9.81'
        write (u, '(a)') '#          x  y  radius  material'
        do k = 1, n
            write (u, '(a, 3(es24.16e2, 1x), a)') 'disk     = ', x(k), y(k), radius(k), '1'
        end do
        write (u, '(a)') ''
        write (u, '(a)') '[walls]'
        write (u, '(a, es24.16e2, a)') 'wall     = 0 0 ', width, ' 0  # floor'
        write (u, '(a, es24.16e2, a)') 'wall     = 0 0 0 ', top, '  # left side'
        write (u, '(a, 3(es24.16e2, 1x), es24.16e2, a)') 'wall     = ', width, 0.0_wp, width, top, &
            '  # right side'
        write (u, '(a)') ''
        write (u, '(a)') '[contacts]'
        write (u, '(a)') 'law      = 1 1 0.3 0 0'
        write (u, '(a)') 'alert    = 5e-3'
        write (u, '(a)') '# (the benchmark''s alert distance: the fastest landings of the 2 000-disk deposit, about'
        write (u, '(a)') '# 2.5 m/s, move a disk 5 mm in one step, and the run warns once that contacts may be'
        write (u, '(a)') '# found late; the comparison with Siconos keeps the setting)'
        write (u, '(a)') ''
        write (u, '(a)') '[solver]'
        write (u, '(a)') 'tolerance  = 1e-4'
        write (u, '(a)') 'criterion  = siconos'
        write (u, '(a)') 'max_sweeps = 10000'
        write (u, '(a)') ''
        write (u, '(a)') '[time]'
        write (u, '(a)') 'step     = 2e-3'
        write (u, '(a)') 'end      = 1.0'
        write (u, '(a)') 'contact_scheme = '//trim(scheme_word)
        write (u, '(a)') ''
        write (u, '(a)') '[output]'
        write (u, '(a)') 'interval = 50'
        close (u)
    end subroutine write_deck

    !> Random packing of n disks in a box, walls, law, scheme.
    subroutine build(sys, n, c)
        type(dem_system_t), intent(out) :: sys
        integer, intent(in) :: n
        type(case_t), intent(inout) :: c
        real(wp), parameter :: pi = 3.141592653589793238462643383279502884_wp
        real(wp), parameter :: rmin = 0.8_wp*radius_mean, rmax = 1.2_wp*radius_mean
        real(wp), allocatable :: x(:), y(:), radius(:)
        type(error_t), allocatable :: error
        integer(i8) :: t0, t1, clock_rate
        real(wp) :: width, top
        call system_clock(t0, clock_rate)
        width = deposit_width(n, rmin, rmax, 1.0_wp)
        call deposit_disks(n, width, rmin, rmax, packing_seed, x, y, radius, c%stuck)
        call system_clock(t1)
        c%n = n
        c%t_build = real(t1 - t0, wp)/real(clock_rate, wp)
        c%width = width
        c%height = maxval(y + radius)
        ! solid fraction below the height where the surface roughness starts (90 % of the top)
        c%solid_fraction = sum(pi*radius**2, mask=y + radius < 0.9_wp*c%height)/(width*0.9_wp*c%height)
        call particles_add_disks(sys%particles, x, y, (1.0_wp + 1.0e-6_wp)*radius, [2500.0_wp], error)
        if (allocated(error)) error stop 'bench_dem: invalid disks'
        top = c%height + 10.0_wp*rmax
        call walls_add(sys%walls, 0.0_wp, 0.0_wp, width, 0.0_wp, error)
        call walls_add(sys%walls, 0.0_wp, 0.0_wp, 0.0_wp, top, error)
        call walls_add(sys%walls, width, 0.0_wp, width, top, error)
        if (allocated(error)) error stop 'bench_dem: invalid walls'
        call materials_init(sys%materials, 1, error)
        if (allocated(error)) error stop 'bench_dem: invalid material table'
        call materials_set_pair(sys%materials, 1, 1, 0.5_wp, 0.0_wp, 0.0_wp, error)
        if (allocated(error)) error stop 'bench_dem: invalid material pair'
        sys%particles%gravity = [0.0_wp, -gravity]
        sys%scheme%h = step
        sys%scheme%alert = 0.05_wp*radius_mean
        sys%solver%tol = tol
        sys%solver%max_sweeps = max_sweeps
        sys%solver%relaxation = relaxation
        sys%solver%check_every = check_every
        sys%solver%anderson = anderson
        sys%solver%anderson_after = anderson_after
        sys%solver%anderson_sweeps = anderson_sweeps
        if (hydrostatic) allocate (hydrostatic_start_t :: sys%solver%start)
        sys%solver%symmetric = symmetric
        call set_method(sys, method)
        call set_criterion(sys%solver, criterion)
        call set_scheme(sys)
        call mj_init(sys, error)
        if (allocated(error)) error stop 'bench_dem: invalid setup'
    end subroutine build

    !> The tables of figures and the detection scaling ratio.
    subroutine print_table(res)
        type(case_t), intent(in) :: res(:)
        integer :: k
        write (output_unit, '(a)') '#'
        write (output_unit, '(a)') '# packing: box width x height [mm], solid fraction (below 90 % of ' &
            //'the height), build time [s], disks left stuck, contacts per disk; mean and max speed ' &
            //'after the timed steps [g h]'
        write (output_unit, '(a)') '#      N   width  height  solid  build[s] stuck  contacts/disk' &
            //'   v_mean   v_max'
        do k = 1, size(res)
            associate (c => res(k))
                write (output_unit, '(i8, 2f8.1, f7.3, f10.3, i6, f15.2, 2f9.2)') c%n, &
                    1.0e3_wp*c%width, 1.0e3_wp*c%height, c%solid_fraction, c%t_build, c%stuck, &
                    real(c%contacts, wp)/c%n, c%v_mean, c%v_max
            end associate
        end do
        write (output_unit, '(a)') '#'
        write (output_unit, '(a)') '# times per step [ms]: median and best over the timed steps; ' &
            //'detect(rep): the detection alone repeated on one configuration, sizes interleaved'
        write (output_unit, '(a)') '#      N  contacts    active  sweeps(mean,max)  conv   detect(step)' &
            //'     detect(rep)      solve(step)   updates/s(step)       bytes/disk'
        do k = 1, size(res)
            associate (c => res(k))
                write (output_unit, '(i8, 2i10, f9.1, i6, f7.2, 2(f9.2, f7.2), f10.1, f8.1, 2es11.3, &
                    &f10.0)') &
                    c%n, c%contacts, c%active, c%sweeps, c%sweeps_max, c%converged, 1.0e3_wp*c%det_med, &
                    1.0e3_wp*c%det_best, 1.0e3_wp*c%rep_med, 1.0e3_wp*c%rep_best, 1.0e3_wp*c%sol_med, &
                    1.0e3_wp*c%sol_best, c%rate, c%rate_best, c%bytes
            end associate
        end do
        write (output_unit, '(a)') '#'
        write (output_unit, '(a)') '#      N  siconos error (mean, max over the timed steps)'
        do k = 1, size(res)
            write (output_unit, '(i8, 2es11.3)') res(k)%n, res(k)%sic_mean, res(k)%sic_max
        end do
        if (size(res) >= 3) then
            write (output_unit, '(a, 4(f6.2, a))') '# detection time 1e5 / 1e4: ', &
                res(3)%rep_best/res(2)%rep_best, ' (repeated, best), ', res(3)%rep_med/res(2)%rep_med, &
                ' (repeated, median), ', res(3)%det_best/res(2)%det_best, ' (steps, best), ', &
                res(3)%det_med/res(2)%det_med, ' (steps, median)'
        end if
    end subroutine print_table

    !> Median of a sample.
    real(wp) function median(a) result(m)
        real(wp), intent(in) :: a(:)
        real(wp), allocatable :: s(:)
        integer :: n
        allocate (s, source=a)
        n = size(s)
        call sort_in_place(s)
        m = s((n + 1)/2)
        if (mod(n, 2) == 0) m = 0.5_wp*(s(n/2) + s(n/2 + 1))
    end function median
end program bench_dem
