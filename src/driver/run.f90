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
module driver_run
    use, intrinsic :: iso_fortran_env, only: int64
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str
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
        character(len=:), allocatable :: dir, path, message
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
        call build_config(deck, run, beam, error)
        if (allocated(error)) return
        if (particles) then
            call build_dem_config(deck, run, beam%functions, dem, error)
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
        ! Until here a signal kills the program at once (nothing is written yet).
        call install_signal_handlers(error)
        if (allocated(error)) return
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
        if (allocated(error)) return
        call report('results written to '//path)

    contains

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
                call run_dynamic(run, model, integ, out, opts%quiet, report, error)
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
        call out%write_static(d, r, error)
        if (allocated(error)) return
        write (buf, '(a,es12.5,a)') 'static solution: max |displacement| = ', &
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
        allocate (full(3, model%n_nodes, run%n_modes))
        do k = 1, run%n_modes
            call model%expand(shapes(:, k), full(:, :, k))
            write (buf, '(a,i3,a,es14.7,a,es14.7,a)') 'mode ', k, ': omega = ', omega(k), &
                ' rad/s, f = ', omega(k)/two_pi, ' Hz'
            call report(trim(buf))
        end do
        call out%write_modal(omega, full, error)
    end subroutine run_modal

    subroutine run_dynamic(run, model, integ, out, quiet, report, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        class(time_integrator_t), intent(inout) :: integ
        type(results_writer_t), intent(inout) :: out
        logical, intent(in) :: quiet
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        type(progress_t) :: progress
        real(wp), allocatable :: d(:, :), v(:, :), a(:, :)
        integer :: n_steps, k
        character(len=160) :: buf

        ! Whole steps up to the end time (the last one may end slightly after it).
        n_steps = ceiling(run%t_end/run%h*(1.0_wp - 1.0e-12_wp))
        allocate (d(3, model%n_nodes), v(3, model%n_nodes), a(3, model%n_nodes))
        call progress%start(n_steps, run%t_end, run%progress_seconds)
        call store(error)
        if (allocated(error)) return
        do k = 1, n_steps
            call integ%step(model, error)
            if (allocated(error)) return
            if (mod(k, run%output_interval) == 0 .or. k == n_steps) then
                call store(error)
                if (allocated(error)) return
            end if
            if (k < n_steps .and. caught_signal() /= 0) then
                ! Stop request: the step just done is the last output.
                if (mod(k, run%output_interval) /= 0) call store(error)
                if (allocated(error)) return
                call out%stop_at(signal_name(caught_signal()), int(k, int64), integ%t)
                n_steps = k
                exit
            end if
            if (.not. quiet .and. progress%due()) call report(progress%line(k, integ%t))
        end do
        write (buf, '(a,i0,a,es12.5,a,es10.3)') 'dynamic run: ', n_steps, ' steps to t = ', &
            integ%t, ' s; energy balance residual ', integ%energy_balance()
        call report(trim(buf))
        call report(progress%summary_line(n_steps))
        call out%write_summary(n_steps, progress%elapsed(), error)
    contains
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
