!> Beam (finite-element frame) runs: static, modal or dynamic analysis of a [beam] deck
!> without [particles].
module driver_simulation_beam
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_constants, only: two_pi
    use core_error, only: error_t, make_error, make_input_error
    use core_signals, only: caught_signal, signal_name
    use core_strings, only: to_str
    use io_deck, only: deck_t
    use io_progress, only: progress_t
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t, build_beam_model
    use fem_static, only: solve_static
    use fem_modal, only: solve_modal, mode_axial_fraction, mode_kind, dominant_fraction
    use fem_newmark, only: time_integrator_t, newmark_t, central_difference_t, model_out_of_range
    use driver_config, only: run_config_t, build_config
    use driver_results, only: results_writer_t
    use driver_checkpoint, only: end_of_step, step_end_t, checkpoint_run_t, loop_state_t, checkpoint_create, &
                                 save_integrator, load_integrator, save_results, load_results
    use io_hdf5_file, only: h5_file_t
    use driver_guards, only: check_beam_state
    use driver_simulation, only: simulation_t, report_iface
    implicit none
    private
    public :: beam_simulation_t, check_initial_energy

    !> A planar frame run.
    type, extends(simulation_t) :: beam_simulation_t
        !> Frame description from the deck.
        type(beam_config_t) :: beam
        !> Assembled model.
        type(beam_model_t) :: model
        !> Time integrator (dynamic analysis).
        class(time_integrator_t), allocatable :: integ
        !> Circular frequencies [rad/s] (modal analysis, solved by `init`: its failures are
        !> input errors).
        real(wp), allocatable :: omega(:)
        !> Mass-normalised mode shapes on the free DOFs (n_free, n_modes) (modal analysis).
        real(wp), allocatable :: shapes(:, :)
    contains
        !> See `simulation_t%init`.
        procedure :: init => beam_init
        !> See `simulation_t%describe`.
        procedure :: describe => beam_describe
        !> See `simulation_t%run`.
        procedure :: run => beam_run
        !> See `simulation_t%checkpoint_kind`.
        procedure :: checkpoint_kind => beam_checkpoint_kind
    end type beam_simulation_t

contains

    !> Configuration, model and integrator; everything that can fail because of the input.
    subroutine beam_init(self, deck, report, error)
        !> The simulation.
        class(beam_simulation_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go (none for beams).
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: message
        integer :: line
        call build_config(deck, self%settings, self%beam, error)
        if (allocated(error)) return
        call build_beam_model(self%beam, self%model, error)
        if (allocated(error)) then
            error%message = deck%file//': '//error%message
            return
        end if
        ! A static solve needs supports that stop every rigid-body motion: the error names the
        ! first `fix` of the deck (the supports as a whole; the message names the part), or
        ! the first `line` when there is none.
        if (self%settings%analysis == 'static') call self%model%check_supports(error)
        if (allocated(error)) then
            message = error%message
            line = deck%line('beam', 'fix')
            if (line == 0) line = deck%line('beam', 'line')
            call make_input_error(error, deck%file, line, 'fix', message)
            return
        end if
        if (self%settings%analysis == 'modal') then
            call solve_modal(self%model, self%settings%n_modes, self%omega, self%shapes, error)
            if (.not. allocated(error)) then
                if (.not. (all(ieee_is_finite(self%omega)) .and. all(ieee_is_finite(self%shapes)))) &
                    call make_error(error, 'modal analysis: a frequency or a mode shape is not finite; '// &
                                    'likely cause: a stiffness, density or section far too large or too small')
            end if
            if (allocated(error)) then
                message = error%message
                call make_input_error(error, deck%file, deck%line('beam', 'section'), 'section', message)
            end if
        end if
        if (self%settings%analysis == 'dynamic') then
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
        end if
    end subroutine beam_init

    !> 'static analysis'.
    function beam_describe(self) result(text)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> Summary.
        character(len=:), allocatable :: text
        text = self%settings%analysis//' analysis'
    end function beam_describe

    !> The finite-element analysis, results into `out`.
    subroutine beam_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(beam_simulation_t), intent(inout) :: self
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
        if (.not. ck%restart) call out%write_mesh(self%beam%node_id, self%beam%x, self%beam%y, self%beam%conn, error)
        if (allocated(error)) return
        select case (self%settings%analysis)
        case ('static')
            call run_static(self%model, out, report, error)
        case ('modal')
            call run_modal(self%settings, self%model, self%omega, self%shapes, out, report, error)
        case ('dynamic')
            call run_dynamic(self%settings, self%model, self%beam%node_id, self%integ, out, quiet, report, ck, &
                             error)
        end select
    end subroutine beam_run

    !> The kinetic energy 1/2 v.M v of the [initial] velocities and the strain energy
    !> 1/2 u.K u of the [initial] displacements must be finite: a velocity of 1e300 m/s or a
    !> displacement of 1e300 m stopped the run at step 0 on a value that is not finite.
    subroutine check_initial_energy(deck, run, model, error)
        !> The deck (for messages).
        type(deck_t), intent(in) :: deck
        !> Run settings (initial displacements and velocities).
        type(run_config_t), intent(in) :: run
        !> The beam model (weighted in a coupled run).
        type(beam_model_t), intent(in) :: model
        !> Set when an energy is not finite.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: u0(:), v0(:)
        character(len=:), allocatable :: keyword
        integer :: at
        call model%restrict(run%v0, v0)
        if (.not. ieee_is_finite(model%kinetic_energy(v0))) then
            keyword = 'velocity'
            at = deck%line('initial', 'velocity')
            if (at == 0) then
                keyword = 'rigid'
                at = deck%line('initial', 'rigid')
            end if
            call make_input_error(error, deck%file, at, keyword, 'the kinetic energy 1/2 v.M v of the [initial] '// &
                                  'velocities is beyond the range of double precision (largest velocity '// &
                                  to_str(maxval(abs(v0)))//'): check their values (and the sections'' densities)')
            return
        end if
        call model%restrict(run%u0, u0)
        if (.not. ieee_is_finite(model%strain_energy(u0))) then
            call make_input_error(error, deck%file, deck%line('initial', 'displacement'), 'displacement', &
                                  'the strain energy 1/2 u.K u of the [initial] displacements is beyond the range '// &
                                  'of double precision (largest displacement '//to_str(maxval(abs(u0)))// &
                                  '): check their values (and the sections'' stiffness)')
        end if
    end subroutine check_initial_energy

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

    subroutine run_modal(run, model, omega, shapes, out, report, error)
        type(run_config_t), intent(in) :: run
        type(beam_model_t), intent(in) :: model
        real(wp), intent(in) :: omega(:), shapes(:, :)
        type(results_writer_t), intent(inout) :: out
        procedure(report_iface) :: report
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: full(:, :, :), fraction(:)
        character(len=160) :: buf
        character(len=:), allocatable :: kinds
        character(len=5) :: share
        integer :: k
        allocate (full(3, model%n_nodes, run%n_modes), fraction(run%n_modes))
        kinds = ''
        do k = 1, run%n_modes
            call model%expand(shapes(:, k), full(:, :, k))
            fraction(k) = mode_axial_fraction(model, shapes(:, k))
            kinds = trim(kinds//' '//mode_kind(fraction(k)))
            write (buf, '(a,i3,a,es15.7e3,a,es15.7e3,a)') 'mode ', k, ': omega = ', omega(k), &
                ' rad/s, f = ', omega(k)/two_pi, ' Hz, '//mode_kind(fraction(k))
            if (fraction(k) >= 0) then
                write (share, '(f5.1)') 100*fraction(k)
                buf = trim(buf)//' (axial strain energy '//trim(adjustl(share))//' %)'
            end if
            call report(trim(buf))
        end do
        call out%write_modal(omega, full, error)
        if (allocated(error)) return
        call out%write_modal_kinds(fraction, adjustl(kinds), dominant_fraction, error)
    end subroutine run_modal

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
        call ck%schedule%start()
        do k = k0 + 1, n_steps
            call integ%step(model, error)
            if (allocated(error)) return
            call check(k, error)
            if (allocated(error)) return
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
        write (buf, '(a,i0,a,es13.5e3,a,es11.3e3)') 'dynamic run: ', n_steps, ' steps to t = ', &
            integ%t, ' s; energy balance residual ', integ%energy_balance()
        call report(trim(buf))
        call report(progress%summary_line(n_steps, stopped=out%stopped()))
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(n_steps), progress%elapsed(), error)
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
            call checkpoint_create(f, ck%path, ck%deck_text, 'beam', loop_state_t(k, 0, .false., .false.), &
                                   integ%t, out%run_id, error)
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
            call out%append_state(integ%t, d, v, a, error)
            if (allocated(error)) return
            call out%append_energy(integ%t, integ%kinetic, integ%strain, integ%external_work, &
                                   integ%damping_dissipation, error)
            if (allocated(error)) return
            call out%flush(error)
        end subroutine store
    end subroutine run_dynamic

    !> 'beam' for a dynamic analysis (static and modal ones write no checkpoint).
    function beam_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(beam_simulation_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = ''
        if (self%settings%analysis == 'dynamic') kind = 'beam'
    end function beam_checkpoint_kind
end module driver_simulation_beam
