!> Runs one deck: read and validate, build the model, run the analysis, write the results.
!>
!> Dispatch: a deck with [beam] and no [particles] is a finite-element run (static, modal or
!> dynamic); a deck with [particles] and no [beam] is a discrete-element run (driver_run_dem);
!> a deck with both is a coupled (Arlequin) run and needs a [coupling] section
!> (driver_config_coupling, driver_run_coupled); [coupling] without both models is an error.
!>
!> Everything that can fail because of the input is checked before the results folder is
!> touched; the HDF5 file is written as '<name>.h5.partial' and renamed only on success, so
!> earlier results stay intact when a run fails.
!>
!> Guards (driver_guards): before anything is built, the model's memory estimate is checked
!> against the available memory; disks and walls must lie in the box the detection can
!> represent; after every time step the state must be finite (and, for particles, no disk
!> may tunnel through a wall or another disk). One run at a time writes a results folder: a
!> lock file (io_lock) is held while writing and removed on every way out.
module driver_run
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str
    use io_lock, only: lock_t, lock_acquire, lock_release
    use io_memory, only: available_memory
    use core_signals, only: caught_signal, signal_name, install_signal_handlers
    use io_deck_schema, only: multicor_schema
    use io_deck, only: deck_t, read_deck
    use io_paths, only: stem, mkdir_p, file_exists
    use io_progress, only: progress_t
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t, build_beam_model
    use fem_static, only: solve_static
    use fem_modal, only: solve_modal
    use fem_newmark, only: time_integrator_t, newmark_t, central_difference_t
    use driver_config, only: run_config_t, build_config
    use driver_config_dem, only: dem_config_t, build_dem_config, deck_has_particles, &
                                 deck_has_beam, check_particle_keywords_unused, check_beam_keywords_unused
    use driver_run_dem, only: run_dem
    use driver_config_coupling, only: coupled_setup_t, deck_has_coupling, build_coupling_config
    use driver_run_coupled, only: build_coupled, run_coupled
    use coupling_arlequin, only: coupled_system_t
    use driver_results, only: results_writer_t
    use driver_guards, only: check_beam_state, check_memory
    use dem_detection, only: coordinate_limit
    implicit none
    private
    public :: run_options_t, run_deck, report_iface

    !> Command-line options of one run.
    type :: run_options_t
        !> Path of the deck.
        character(len=:), allocatable :: deck_path
        !> Results folder ('' = results/<deck name>).
        character(len=:), allocatable :: output_dir
        !> Validate only.
        logical :: check_only = .false.
        !> No progress lines.
        logical :: quiet = .false.
    end type run_options_t

    abstract interface
        !> Receives one line of progress or summary text.
        subroutine report_iface(line)
            character(len=*), intent(in) :: line
        end subroutine report_iface
    end interface

contains

    !> Read, check and run a deck; write results unless only checking.
    !>
    !> From the opening of the results file on, SIGTERM, SIGINT and SIGUSR1 stop a time loop
    !> after the step under way: that step is stored, the file is closed as
    !> '<name>.h5.partial' with /summary finished = 0, and `error` says what was saved
    !> (`stopped_by` is then the signal number).
    subroutine run_deck(opts, report, error, stopped_by)
        !> What to run and where to write.
        type(run_options_t), intent(in) :: opts
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> Set on any input or run error, and when a signal stopped the run.
        type(error_t), allocatable, intent(out) :: error
        !> Signal that stopped the run early (0: none).
        integer, intent(out), optional :: stopped_by
        type(deck_t) :: deck
        type(run_config_t) :: run
        type(beam_config_t) :: beam
        type(beam_model_t) :: model
        type(dem_config_t) :: dem
        type(coupled_setup_t) :: coupling
        type(coupled_system_t), allocatable :: coupled_sys
        class(time_integrator_t), allocatable :: integ
        type(results_writer_t) :: out
        type(lock_t) :: lock
        character(len=:), allocatable :: dir, path, message, warning
        logical :: particles, coupled
        integer :: i
        character(len=32) :: tbuf

        if (present(stopped_by)) stopped_by = 0
        call read_deck(opts%deck_path, multicor_schema(), deck, error)
        if (allocated(error)) return
        particles = deck_has_particles(deck)
        coupled = particles .and. deck_has_beam(deck)
        call check_sections(error)
        if (allocated(error)) return
        ! A coupled deck uses the keywords of both models.
        if (particles .and. .not. coupled) then
            call check_beam_keywords_unused(deck, error)
        else if (.not. particles) then
            call check_particle_keywords_unused(deck, error)
        end if
        if (allocated(error)) return
        call check_model_size(error)
        if (allocated(error)) return
        call build_config(deck, run, beam, error)
        if (allocated(error)) return
        if (particles) then
            call build_dem_config(deck, run, beam%functions, dem, error)
            if (allocated(error)) return
            call check_coordinates(error)
            if (allocated(error)) return
        end if
        if (coupled) then
            call build_coupling(error)
            if (allocated(error)) return
        else if (.not. particles) then
            call build_fe(error)
            if (allocated(error)) return
        end if
        if (opts%check_only) then
            if (coupled) then
                call report(opts%deck_path//': deck is valid (coupled '//run%analysis// &
                            ' analysis, '//to_str(size(beam%x))//' beam nodes, '// &
                            to_str(dem%system%particles%n)//' disks, '// &
                            to_str(coupled_sys%op%n_points)//' coupled)')
            else if (particles) then
                call report(opts%deck_path//': deck is valid ('//run%analysis//' analysis, '// &
                            to_str(dem%system%particles%n)//' disks, '//to_str(dem%system%walls%n)// &
                            ' walls)')
            else
                call report(opts%deck_path//': deck is valid ('//run%analysis//' analysis)')
            end if
            return
        end if

        dir = 'results/'//stem(opts%deck_path)
        if (allocated(opts%output_dir)) dir = opts%output_dir
        call mkdir_p(dir, error)
        if (allocated(error)) return
        path = dir//'/'//stem(opts%deck_path)//'.h5'
        call lock_acquire(lock, dir, warning, error)
        if (allocated(error)) return
        if (len(warning) > 0) call report(warning)
        ! Until here a signal kills the program at once (nothing is written yet).
        call install_signal_handlers(error)
        if (.not. allocated(error)) call write_results(error)
        call lock_release(lock)
        if (allocated(error)) return
        call report('results written to '//path)

    contains

        !> Run the analysis into '<path>.partial', renamed to `path` on success (the caller
        !> holds the folder's lock).
        subroutine write_results(error)
            type(error_t), allocatable, intent(out) :: error
            call out%open(path, opts%deck_path, deck%text, run%title, run%analysis, error)
            if (allocated(error)) return
            if (coupled) then
                call run_coupled(run, beam, dem, coupled_sys, out, opts%quiet, report, error)
            else if (particles) then
                call run_dem(run, dem, out, opts%quiet, report, error)
            else
                call run_fe(error)
            end if
            if (allocated(error)) then
                call out%abort()
                error%message = deck%file//': '//error%message
                return
            end if
            if (out%stopped()) then
                call out%close_unfinished(error)
                if (allocated(error)) return
                if (present(stopped_by)) stopped_by = caught_signal()
                write (tbuf, '(es16.8e3)') out%stop_time
                call report('stopped: '//out%stop_reason)
                call report('saved: every output up to t = '//trim(adjustl(tbuf))//' s (the last one '// &
                            'at the stop) in '//out%partial_path//' (/summary finished = 0)')
                if (file_exists(path)) call report('the earlier result '//path//' is left as it was')
                call report('to continue: run the deck again (restart from a checkpoint is not '// &
                            'available yet)')
                call make_error(error, deck%file//': run stopped by '//signal_name(caught_signal())// &
                                '; results so far in '//out%partial_path)
                return
            end if
            call out%close(error)
        end subroutine write_results

        !> Refuse a model whose memory estimate exceeds the available memory, from the
        !> numbers of disks, nodes and elements the deck asks for (before allocating them).
        subroutine check_model_size(error)
            type(error_t), allocatable, intent(out) :: error
            integer(i8) :: n_disks, n_nodes, n_elements, m
            integer :: k
            character(len=:), allocatable :: message
            n_disks = deck%count('particles', 'disk')
            n_nodes = deck%count('beam', 'node')
            n_elements = deck%count('beam', 'element')
            do k = 1, size(deck%entries)
                associate (e => deck%entries(k))
                    select case (e%section//' '//e%keyword)
                    case ('particles row', 'particles deposit')
                        n_disks = n_disks + e%int(1)
                    case ('particles square_lattice', 'particles hex_lattice')
                        n_disks = n_disks + int(e%int(1), i8)*int(e%int(2), i8)
                    case ('beam line')
                        m = e%int(6)
                        n_nodes = n_nodes + m + 1
                        n_elements = n_elements + m
                    end select
                end associate
            end do
            if (n_disks > huge(0)) then
                call make_error(error, deck%file//': the deck asks for '//to_str(n_disks)// &
                                ' disks, more than a run can number ('//to_str(huge(0))//')')
                return
            end if
            call check_memory(n_disks, n_nodes, n_elements, available_memory(), error)
            if (allocated(error)) then
                message = error%message
                call make_error(error, deck%file//': '//message)
            end if
        end subroutine check_model_size

        !> Disks and walls must lie in the box the contact detection can represent.
        subroutine check_coordinates(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: limit
            integer :: k
            associate (p => dem%system%particles, w => dem%system%walls)
                if (p%n == 0) return
                limit = coordinate_limit(minval(p%radius(1:p%n)))
                do k = 1, p%n
                    if (max(abs(p%x(k)), abs(p%y(k))) <= limit) cycle
                    call make_input_error(error, deck%file, dem%disk_line(k), '', 'disk '// &
                                          to_str(k)//' at ('//num(p%x(k))//', '//num(p%y(k))// &
                                          ') m lies beyond the box the run can represent: |x|, |y| <= '// &
                                          num(limit)//' m (4.5e9 times the smallest radius, at most '// &
                                          '1e100 m; coordinates are then known to 1e-6 of the radius)')
                    return
                end do
                do k = 1, w%n
                    if (max(abs(w%x1(k)), abs(w%y1(k)), abs(w%x2(k)), abs(w%y2(k))) <= limit) cycle
                    call make_input_error(error, deck%file, dem%wall_line(k), 'wall', 'wall '// &
                                          to_str(k)//' has an end beyond the box the run can represent: '// &
                                          '|x|, |y| <= '//num(limit)//' m (4.5e9 times the smallest '// &
                                          'disk radius, at most 1e100 m): shorten it')
                    return
                end do
            end associate
        end subroutine check_coordinates

        !> A real with 3 significant digits.
        function num(x) result(text)
            real(wp), intent(in) :: x
            character(len=:), allocatable :: text
            character(len=24) :: buf
            write (buf, '(es11.3e3)') x
            text = trim(adjustl(buf))
        end function num

        !> Which kind of run: [beam] and [particles] need [coupling], and [coupling] needs
        !> both.
        subroutine check_sections(error)
            type(error_t), allocatable, intent(out) :: error
            integer :: k
            if (coupled .and. .not. deck_has_coupling(deck)) then
                call make_input_error(error, deck%file, deck%line('run', 'analysis'), '', &
                                      'this deck has both [beam] and [particles]: coupled runs need a '// &
                                      '[coupling] section (at least overlap = s_fe s_particle and thickness; '// &
                                      'doc/input.md), or run the beam and the particles apart')
            else if (.not. coupled .and. deck_has_coupling(deck)) then
                do k = 1, size(deck%entries)
                    if (deck%entries(k)%section == 'coupling') exit
                end do
                call make_input_error(error, deck%file, deck%entries(k)%line, &
                                      deck%entries(k)%keyword, '[coupling] glues particles to a beam, and this '// &
                                      'deck has no '//trim(merge('[particles]', '[beam]     ',.not. particles))// &
                                      ': remove [coupling] or add the missing model')
            end if
        end subroutine check_sections

        !> Coupling description and coupled system; everything that can fail because of the
        !> input (library errors are attached to the [coupling] overlap line).
        subroutine build_coupling(error)
            type(error_t), allocatable, intent(out) :: error
            call build_coupling_config(deck, run, beam, dem, coupling, error)
            if (allocated(error)) return
            do i = 1, size(coupling%warnings)
                call report(coupling%warnings(i)%s)
            end do
            allocate (coupled_sys)
            call build_coupled(run, beam, dem, coupling, coupled_sys, error)
            if (allocated(error)) then
                message = error%message
                call make_input_error(error, deck%file, coupling%overlap_line, 'overlap', message)
            end if
        end subroutine build_coupling

        !> Beam model and integrator; everything that can fail because of the input.
        subroutine build_fe(error)
            type(error_t), allocatable, intent(out) :: error
            call build_beam_model(beam, model, error)
            ! A static solve needs supports that stop every rigid-body motion.
            if (.not. allocated(error) .and. run%analysis == 'static') &
                call model%check_supports(error)
            if (allocated(error)) then
                error%message = deck%file//': '//error%message
                return
            end if
            if (run%analysis == 'dynamic') then
                call make_integrator(run, model, integ, error)
                if (allocated(error)) then
                    ! The integrator only refuses a time step (stability limit).
                    message = error%message
                    call make_input_error(error, deck%file, deck%line('time', 'step'), 'step', &
                                          message)
                end if
            end if
        end subroutine build_fe

        !> The finite-element analysis, results into `out`.
        subroutine run_fe(error)
            type(error_t), allocatable, intent(out) :: error
            call out%write_mesh(beam%node_id, beam%x, beam%y, beam%conn, error)
            if (allocated(error)) return
            select case (run%analysis)
            case ('static')
                call run_static(model, out, report, error)
            case ('modal')
                call run_modal(run, model, out, report, error)
            case ('dynamic')
                call run_dynamic(run, model, beam%node_id, integ, out, opts%quiet, report, error)
            end select
        end subroutine run_fe
    end subroutine run_deck

    !> Build the time integrator the deck asks for (refuses an unstable explicit step).
    subroutine make_integrator(run, model, integ, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        class(time_integrator_t), allocatable, intent(out) :: integ
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u0(:), v0(:)
        select case (run%scheme)
        case ('central_difference')
            allocate (central_difference_t :: integ)
        case default
            allocate (newmark_t :: integ)
            select type (integ)
            type is (newmark_t)
                integ%beta = run%beta
                integ%gamma = run%gamma
            end select
        end select
        call model%restrict(run%u0, u0)
        call model%restrict(run%v0, v0)
        call integ%init(model, run%h, 0.0_wp, u0, v0, error)
    end subroutine make_integrator

    subroutine run_static(model, out, report, error)
        type(beam_model_t), intent(in) :: model
        type(results_writer_t), intent(inout) :: out
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u(:), d(:, :), r(:, :)
        character(len=120) :: buf
        call solve_static(model, 0.0_wp, u, error)
        if (allocated(error)) return
        allocate (d(3, model%n_nodes), r(3, model%n_nodes))
        call model%expand(u, d)
        call model%reactions(u, 0.0_wp, r)
        if (.not. (all(ieee_is_finite(d)) .and. all(ieee_is_finite(r)))) then
            call make_error(error, 'static solution: a displacement or a reaction is not finite; '// &
                            'likely cause: a load or a stiffness far too large or too small (check the '// &
                            'magnitudes in [beam])')
            return
        end if
        call out%write_static(d, r, error)
        if (allocated(error)) return
        write (buf, '(a,es13.5e3,a)') 'static solution: max |displacement| = ', &
            maxval(abs(d(1:2, :))), ' m'
        call report(trim(buf))
    end subroutine run_static

    subroutine run_modal(run, model, out, report, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        type(results_writer_t), intent(inout) :: out
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: omega(:), shapes(:, :), full(:, :, :)
        real(wp), parameter :: two_pi = 6.283185307179586476925286766559_wp
        character(len=120) :: buf
        integer :: k
        call solve_modal(model, run%n_modes, omega, shapes, error)
        if (allocated(error)) return
        if (.not. (all(ieee_is_finite(omega)) .and. all(ieee_is_finite(shapes)))) then
            call make_error(error, 'modal analysis: a frequency or a mode shape is not finite; '// &
                            'likely cause: a stiffness, density or section far too large or too small '// &
                            '(check the magnitudes in [beam])')
            return
        end if
        allocate (full(3, model%n_nodes, run%n_modes))
        do k = 1, run%n_modes
            call model%expand(shapes(:, k), full(:, :, k))
            write (buf, '(a,i3,a,es15.7e3,a,es15.7e3,a)') 'mode ', k, ': omega = ', omega(k), &
                ' rad/s, f = ', omega(k)/two_pi, ' Hz'
            call report(trim(buf))
        end do
        call out%write_modal(omega, full, error)
    end subroutine run_modal

    subroutine run_dynamic(run, model, node_id, integ, out, quiet, report, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: node_id(:)
        class(time_integrator_t), intent(inout) :: integ
        type(results_writer_t), intent(inout) :: out
        logical, intent(in) :: quiet
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        type(progress_t) :: progress
        real(wp), allocatable :: d(:, :), v(:, :), a(:, :)
        integer(i8) :: n_steps, k
        character(len=160) :: buf

        n_steps = run%n_steps
        allocate (d(3, model%n_nodes), v(3, model%n_nodes), a(3, model%n_nodes))
        call progress%start(n_steps, run%t_end, run%progress_seconds)
        call check(0_i8, error)
        if (allocated(error)) return
        call store(error)
        if (allocated(error)) return
        do k = 1, n_steps
            call integ%step(model, error)
            if (allocated(error)) return
            call check(k, error)
            if (allocated(error)) return
            if (mod(k, int(run%output_interval, i8)) == 0 .or. k == n_steps) then
                call store(error)
                if (allocated(error)) return
            end if
            if (k < n_steps .and. caught_signal() /= 0) then
                ! Stop request: the step just done is the last output.
                if (mod(k, int(run%output_interval, i8)) /= 0) call store(error)
                if (allocated(error)) return
                call out%stop_at(signal_name(caught_signal()), k, integ%t)
                n_steps = k
                exit
            end if
            if (.not. quiet .and. progress%due()) call report(progress%line(k, integ%t))
        end do
        write (buf, '(a,i0,a,es13.5e3,a,es11.3e3)') 'dynamic run: ', n_steps, ' steps to t = ', &
            integ%t, ' s; energy balance residual ', integ%energy_balance()
        call report(trim(buf))
        call report(progress%summary_line(n_steps))
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(n_steps), progress%elapsed(), error)
    contains
        !> Guard after step k (0: the initial state).
        subroutine check(k, error)
            integer(i8), intent(in) :: k
            type(error_t), allocatable, intent(out) :: error
            call model%expand(integ%u, d)
            call model%expand(integ%v, v)
            call model%expand(integ%a, a)
            call check_beam_state(k, integ%t, node_id, d, v, a, [integ%kinetic, integ%strain, &
                                                                 integ%external_work, integ%damping_dissipation], error)
        end subroutine check

        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            call model%expand(integ%u, d)
            call model%expand(integ%v, v)
            call model%expand(integ%a, a)
            call out%append_state(integ%t, d, v, a, error)
            if (allocated(error)) return
            call out%append_energy(integ%t, integ%kinetic, integ%strain, integ%external_work, &
                                   integ%damping_dissipation, error)
            if (allocated(error)) return
            call out%flush(error)
        end subroutine store
    end subroutine run_dynamic
end module driver_run
