!> Dynamic analysis of a frame: time integration (Newmark or central differences) from the
!> [initial] state, with checkpoints and restarts.
module driver_simulation_beam_dynamic
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_input_error
    use core_signals, only: caught_signal, signal_name
    use io_deck, only: deck_t
    use io_progress, only: progress_t
    use fem_beam_model, only: beam_model_t
    use fem_newmark, only: time_integrator_t, make_time_integrator, model_out_of_range
    use driver_config, only: run_config_t
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: end_of_step, rest_of_last_step, step_end_t, checkpoint_run_t, loop_state_t, checkpoint_create, &
                                 save_integrator, load_integrator, save_results, load_results
    use io_hdf5_file, only: h5_file_t
    use driver_guards, only: check_beam_state
    use driver_simulation, only: report_iface
    use driver_simulation_beam, only: beam_simulation_t, beam_setup, check_initial_energy
    use driver_displacement_scale, only: largest_displacement, model_extent, large_displacement_warning
    implicit none
    private
    public :: beam_dynamic_t

    !> A dynamic frame run.
    type, extends(beam_simulation_t) :: beam_dynamic_t
        !> Time integrator.
        class(time_integrator_t), allocatable :: integ
    contains
        !> See `simulation_t%init`: the initial energies and the integrator.
        procedure :: init => dynamic_init
        !> See `simulation_t%run`.
        procedure :: run => dynamic_run
        !> See `simulation_t%checkpoint_kind`: 'beam'.
        procedure :: checkpoint_kind => dynamic_checkpoint_kind
        !> See `simulation_t%has_time_loop`: yes.
        procedure :: has_time_loop => dynamic_has_time_loop
    end type beam_dynamic_t

contains

    !> Settings and model, then the initial state and the integrator (a refused time step or a
    !> model no step resolves are input errors).
    subroutine dynamic_init(self, deck, report, error)
        !> The simulation.
        class(beam_dynamic_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go (none for beams).
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: message
        call beam_setup(self, deck, error)
        if (allocated(error)) return
        call check_initial_energy(deck, self%settings, self%model, error)
        if (allocated(error)) return
        call make_integrator(self%settings, self%model, self%integ, error)
        if (allocated(error)) then
            ! The integrator refuses a time step (stability limit, round-off), or a model
            ! whose highest frequency no step resolves (its sections).
            message = error%message
            if (index(message, model_out_of_range) == 1) then
                call make_input_error(error, deck%file, deck%line('beam', 'section'), 'section', message)
            else
                call make_input_error(error, deck%file, deck%line('time', 'step'), 'step', message)
            end if
        end if
    end subroutine dynamic_init

    !> The mesh (not at a restart: the file has it), then the time steps.
    subroutine dynamic_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(beam_dynamic_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines.
        logical, intent(in) :: quiet
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> Checkpoints (and the one to restart from).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        if (.not. ck%restart) call self%write_mesh(out, error)
        if (allocated(error)) return
        call run_dynamic(self%settings, self%model, self%beam%node_id, self%integ, out, quiet, report, ck, error)
    end subroutine dynamic_run

    !> 'beam'.
    function dynamic_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(beam_dynamic_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'beam'
    end function dynamic_checkpoint_kind

    !> True: the Newmark or central-difference steps.
    pure logical function dynamic_has_time_loop(self)
        !> The simulation.
        class(beam_dynamic_t), intent(in) :: self
        dynamic_has_time_loop = .true.
    end function dynamic_has_time_loop

    !> Build the time integrator the deck asks for (refuses an unstable explicit step).
    subroutine make_integrator(run, model, integ, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        class(time_integrator_t), allocatable, intent(out) :: integ
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u0(:), v0(:)
        call make_time_integrator(run%scheme, run%beta, run%gamma, integ, error)
        if (allocated(error)) return
        call model%restrict(run%u0, u0)
        call model%restrict(run%v0, v0)
        call integ%init(model, run%h, 0.0_wp, u0, v0, error)
    end subroutine make_integrator

    subroutine run_dynamic(run, model, node_id, integ, out, quiet, report, ck, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: node_id(:)
        class(time_integrator_t), intent(inout) :: integ
        type(results_writer_t), intent(inout) :: out
        logical, intent(in) :: quiet
        procedure(report_iface) :: report
        type(checkpoint_run_t), intent(inout) :: ck
        type(error_t), allocatable, intent(out) :: error
        type(progress_t) :: progress
        real(wp), allocatable :: d(:, :), v(:, :), a(:, :)
        integer(i8) :: n_steps, k, k0
        type(step_end_t) :: act
        character(len=160) :: buf
        character(len=:), allocatable :: warning
        ! Largest displacement of the stored states, their mean translation removed [m].
        real(wp) :: u_max

        u_max = 0.0_wp
        n_steps = run%n_steps
        allocate (d(3, model%n_nodes), v(3, model%n_nodes), a(3, model%n_nodes))
        call progress%start(n_steps, run%t_end, run%progress_seconds)
        k0 = 0
        if (ck%restart) then
            call restore(error)
            if (allocated(error)) return
        else
            call check(0_i8, error)
            if (allocated(error)) return
            call store(error)
            if (allocated(error)) return
        end if
        if (ck%restart) call progress%resume(k0, ck%start%wall_seconds, ck%start%runs)
        call ck%schedule%start()
        if (ck%restart .and. k0 == n_steps) then
            ! a checkpoint of the last step: the rest of that step's end (a run killed after it)
            k = k0
            act = rest_of_last_step(n_steps, run%output_interval)
            if (act%checkpoint) call checkpoint(error)
            if (act%store_last .and. .not. allocated(error)) call store(error)
            if (allocated(error)) return
        end if
        call out%begin_loop()
        do k = k0 + 1, n_steps
            call integ%step(model, error)
            if (.not. allocated(error)) call check(k, error)
            if (allocated(error)) then
                ! the results file is as its last output left it: kept (driver_run)
                call out%fail_at(k, real(k, wp)*run%h)
                return
            end if
            act = end_of_step(k, n_steps, run%output_interval, ck%schedule)
            if (act%store_first) call store(error)
            if (act%checkpoint .and. .not. allocated(error)) call checkpoint(error)
            if (act%store_last .and. .not. allocated(error)) call store(error)
            if (allocated(error)) return
            if (act%stop) then
                ! Stop request: the step just done is the last output.
                call out%stop_at(signal_name(caught_signal()), k, integ%t)
                n_steps = k
                exit
            end if
            if (.not. quiet) then
                if (progress%due()) call report(progress%line(k, integ%t))
            end if
        end do
        write (buf, '(a,i0,a,es13.5e3,a,es11.3e3,a)') 'dynamic run: ', n_steps, ' steps to t = ', &
            integ%t, ' s; energy balance residual ', integ%energy_balance(), ' J'
        call report(trim(buf)//run%balance_note())
        warning = large_displacement_warning(u_max, model_extent(model%x, model%y), &
                                             '[beam] section, load, distributed, gravity, line, node, [initial]')
        if (len(warning) > 0) call report(warning)
        call report(progress%summary_line(n_steps, stopped=out%stopped()))
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(n_steps), progress, error)
    contains
        !> Restart: integrator state and results file from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            call load_integrator(ck%source, '/fe', integ, ck%start%step, error)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            k0 = ck%start%step
        end subroutine restore

        !> Write a checkpoint after step k.
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call out%flush(error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, 'beam', &
                                   loop_state_t(k, 0, .false., .false., wall_seconds=progress%analysis_seconds(), &
                                                runs=progress%runs), integ%t, out%run_id, error)
            if (.not. allocated(error)) call save_integrator(f, '/fe', integ, error)
            if (.not. allocated(error)) call save_results(f, out, error)
            call ck%finish(f, k, integ%t, error)
        end subroutine checkpoint

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
            call out%beam%append_state(out%file, integ%t, d, v, a, error)
            if (allocated(error)) return
            ! a free body's translation strains nothing: only the rest counts
            u_max = max(u_max, largest_displacement(d(1:2, :) - spread(sum(d(1:2, :), dim=2)/size(d, 2), 2, size(d, 2))))
            call out%beam%append_energy(out%file, integ%t, integ%kinetic, integ%strain, integ%external_work, &
                                        integ%damping_dissipation, error)
            if (allocated(error)) return
            call out%flush_output(error)
        end subroutine store
    end subroutine run_dynamic
end module driver_simulation_beam_dynamic
