!> Dynamic analysis of a 2D continuum: the integrators of fem_newmark on the continuum as a
!> `dynamic_operator_t`, from rest with the deck's initial velocity field, with the energy
!> audit of the whole body, checkpoints and restart as the beam's (driver_checkpoint: the
!> integrator's state and the results file's record counts).
module driver_simulation_continuum_dynamic
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: to_str
    use core_signals, only: caught_signal, signal_name
    use io_deck, only: deck_t, deck_entry_t
    use io_progress, only: progress_t
    use fem_continuum_dynamics, only: continuum_audit_t
    use fem_newmark, only: time_integrator_t, make_time_integrator, model_out_of_range
    use driver_results, only: results_writer_t
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint, only: checkpoint_run_t, end_of_step, rest_of_last_step, step_end_t, loop_state_t, checkpoint_create, &
                                 save_integrator, load_integrator, save_results, load_results, &
                                 read_finite_attribute
    use driver_results_continuum, only: continuum_writer_t
    use driver_simulation, only: report_iface
    use driver_simulation_continuum, only: continuum_simulation_t, continuum_setup, check_density
    use driver_displacement_scale, only: largest_displacement, model_extent, large_displacement_warning
    implicit none
    private
    public :: continuum_dynamic_t

    !> A dynamic continuum run.
    type, extends(continuum_simulation_t) :: continuum_dynamic_t
        !> Time integrator.
        class(time_integrator_t), allocatable :: integ
        !> Energy audit of the whole body (prescribed dofs and their reactions included).
        type(continuum_audit_t) :: audit
    contains
        !> See `simulation_t%init`: the densities and the integrator.
        procedure :: init => dynamic_init
        !> See `simulation_t%run`.
        procedure :: run => dynamic_run
        !> See `simulation_t%checkpoint_kind`: 'continuum'.
        procedure :: checkpoint_kind => dynamic_checkpoint_kind
        !> See `simulation_t%has_time_loop`: yes.
        procedure :: has_time_loop => dynamic_has_time_loop
    end type continuum_dynamic_t

contains

    !> The continuum from the deck, then its densities and the integrator (a refused time step
    !> or a model no step resolves are input errors).
    subroutine dynamic_init(self, deck, report, error)
        !> The simulation.
        class(continuum_dynamic_t), intent(inout) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Where warnings go.
        procedure(report_iface) :: report
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        type(deck_entry_t) :: e
        call continuum_setup(self, deck, error)
        if (allocated(error)) return
        call check_density(deck, error)
        if (allocated(error)) return
        call make_integrator(error)

    contains

        !> Newmark or central difference from rest with the initial velocity field.
        subroutine make_integrator(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: u0(:), v0(:), v_all(:)
            character(len=:), allocatable :: message
            integer, allocatable :: eq(:)
            real(wp) :: vx, vy, omega, xc, yc
            integer :: a, n, c
            ! The rotation about (xc, yc) is optional (omega, xc and yc together, the schema checks):
            ! absent, it reads as 0.
            e = deck%record('continuum', 'initial_velocity', 1)
            vx = deck%get_real('continuum', 'initial_velocity', 'vx')
            vy = deck%get_real('continuum', 'initial_velocity', 'vy')
            omega = e%real('omega')
            xc = e%real('xc')
            yc = e%real('yc')
            allocate (v_all(self%model%dof_count()))
            do a = 1, self%model%mesh%node_count()
                v_all(2*a - 1) = vx - omega*(self%model%mesh%x(2, a) - yc)
                v_all(2*a) = vy + omega*(self%model%mesh%x(1, a) - xc)
            end do
            call self%model%equations(eq, n)
            allocate (u0(n), v0(n))
            u0 = 0.0_wp
            do c = 1, size(eq)
                if (eq(c) > 0) v0(eq(c)) = v_all(c)
            end do
            ! A speed whose kinetic energy overflows would stop the run at its initial state,
            ! on an energy that is not finite, blaming loads or moduli.
            if (.not. ieee_is_finite(self%ops%kinetic_energy(v0))) then
                call make_input_error(error, deck%file, e%line, 'initial_velocity', 'the kinetic energy '// &
                                      '1/2 v.M v of this initial velocity is beyond the range of double precision '// &
                                      '(largest nodal speed '//to_str(maxval(abs(v_all)))//' m/s): check vx, vy '// &
                                      'and omega, and the densities of [continuum] material')
                return
            end if
            call make_time_integrator(self%settings%scheme, self%settings%beta, self%settings%gamma, self%integ, error)
            if (allocated(error)) return
            call self%integ%init(self%ops, self%settings%h, 0.0_wp, u0, v0, error)
            if (.not. allocated(error)) return
            message = error%message
            if (index(message, model_out_of_range) == 1) then
                ! no time step resolves the model: its materials
                call make_input_error(error, deck%file, deck%line('continuum', 'material'), 'material', message)
            else
                call make_input_error(error, deck%file, deck%line('time', 'step'), 'step', message)
            end if
        end subroutine make_integrator
    end subroutine dynamic_init

    !> Time steps with outputs every [output] interval; results into `out` (driver_run adds the
    !> XDMF file).
    subroutine dynamic_run(self, out, quiet, report, ck, error)
        !> The simulation.
        class(continuum_dynamic_t), intent(inout) :: self
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
        type(continuum_writer_t) :: writer
        ! Steps done, and at the start of the loop (a checkpoint's at a restart).
        integer(i8) :: k, k0
        ! Progress lines and the wall time of the analysis (checkpointed).
        type(progress_t) :: progress
        ! Largest displacement of the stored states, their mean translation removed [m].
        real(wp) :: u_max
        u_max = 0.0_wp
        ! At a restart the file has the mesh and the series already (restore).
        if (.not. ck%restart) then
            call writer%begin(out%file, self%model, error)
            if (.not. allocated(error)) call writer%begin_series(out%file, error)
        end if
        if (allocated(error)) return
        call run_dynamic(error)

    contains

        !> What makes a step's state blow up: the stability limit only for a conditionally
        !> stable scheme (central differences, or Newmark with 2 beta < gamma; the integrator
        !> says, `time_integrator_t%conditionally_stable`).
        function likely_cause() result(cause)
            character(len=:), allocatable :: cause
            if (self%integ%conditionally_stable()) then
                cause = 'a time step above the stability limit of the scheme, or loads far too large'
            else
                cause = 'loads, moduli or densities far out of range (this Newmark scheme is '// &
                        'unconditionally stable: the time step is not the cause)'
            end if
        end function likely_cause

        !> Time steps with outputs every [output] interval, checkpoints as `ck` says (from a
        !> checkpoint's state at a restart).
        subroutine run_dynamic(error)
            type(error_t), allocatable, intent(out) :: error
            integer(i8) :: n_steps
            type(step_end_t) :: act
            character(len=200) :: buf
            character(len=:), allocatable :: warning
            n_steps = self%settings%n_steps
            call progress%start(n_steps, self%settings%t_end, self%settings%progress_seconds)
            k0 = 0
            if (ck%restart) then
                call restore(error)
            else
                call self%audit%start(self%ops, self%model, self%integ)
                call store(error)
            end if
            if (allocated(error)) return
            if (ck%restart) call progress%resume(k0, ck%start%wall_seconds, ck%start%runs)
            call ck%schedule%start()
            if (ck%restart .and. k0 == n_steps) then
                ! a checkpoint of the last step: the rest of that step's end (a run killed after it)
                k = k0
                act = rest_of_last_step(n_steps, self%settings%output_interval)
                if (act%checkpoint) call checkpoint(error)
                if (act%store_last .and. .not. allocated(error)) call store(error)
                if (allocated(error)) return
            end if
            call out%begin_loop()
            do k = k0 + 1, n_steps
                call self%integ%step(self%ops, error)
                if (allocated(error)) then
                    ! the results file is as its last output left it: kept (driver_run)
                    call out%fail_at(k, real(k, wp)*self%settings%h)
                    return
                end if
                call self%audit%advance(self%ops, self%model, self%integ)
                ! State and energy accounts (a checkpoint may follow: it must hold finite values).
                if (.not. (all(ieee_is_finite(self%integ%u)) .and. all(ieee_is_finite(self%integ%v)) .and. &
                           all(ieee_is_finite([self%integ%kinetic, self%integ%strain, self%integ%external_work, &
                                               self%integ%damping_dissipation, self%audit%balance()])))) then
                    write (buf, '(a,i0,a,es13.5e3,a)') 'continuum: the state is not finite after step ', k, &
                        ' (t = ', self%integ%t, ' s); likely cause:'
                    call make_error(error, trim(buf)//' '//likely_cause())
                    call out%fail_at(k, real(k, wp)*self%settings%h)
                    return
                end if
                act = end_of_step(k, n_steps, self%settings%output_interval, ck%schedule)
                if (act%store_first) call store(error)
                if (act%checkpoint .and. .not. allocated(error)) call checkpoint(error)
                if (act%store_last .and. .not. allocated(error)) call store(error)
                if (allocated(error)) return
                if (act%stop) then
                    ! Stop request: the step just done is the last output.
                    call out%stop_at(signal_name(caught_signal()), k, self%integ%t)
                    n_steps = k
                    exit
                end if
                if (.not. quiet) then
                    if (progress%due()) call report(progress%line(k, self%integ%t))
                end if
            end do
            write (buf, '(a,i0,a,es13.5e3,a,es11.3e3,a)') 'dynamic run: ', n_steps, ' steps to t = ', &
                self%integ%t, ' s; energy balance residual ', self%audit%balance(), ' J'
            call report(trim(buf)//self%settings%balance_note())
            associate (x => self%model%mesh%x)
                warning = large_displacement_warning(u_max, model_extent(x(1, :), x(2, :)), &
                                                     '[continuum] material, load, traction, gravity, '// &
                                                     'displacement, initial_velocity, mesh')
            end associate
            if (len(warning) > 0) call report(warning)
            call report(progress%summary_line(n_steps, stopped=out%stopped()))
            call out%write_summary(int(n_steps), progress, error)
        end subroutine run_dynamic

        !> Restart: integrator state, results file and writer from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            real(wp), allocatable :: totals(:)
            call load_integrator(ck%source, '/fe', self%integ, ck%start%step, error)
            if (.not. allocated(error)) call read_finite_attribute(ck%source, '/fe', 'continuum_audit', totals, 4, error)
            if (.not. allocated(error)) call self%audit%resume(self%ops, self%model, self%integ, totals)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            call writer%resume(out%file, self%model%mesh, error)
            k0 = ck%start%step
        end subroutine restore

        !> Write a checkpoint after step k.
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call out%flush(error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, self%checkpoint_kind(), &
                                   loop_state_t(k, 0, .false., .false., wall_seconds=progress%analysis_seconds(), &
                                                runs=progress%runs), self%integ%t, out%run_id, error)
            if (.not. allocated(error)) call save_integrator(f, '/fe', self%integ, error)
            if (.not. allocated(error)) call f%write_attribute('/fe', 'continuum_audit', self%audit%totals(), error)
            if (.not. allocated(error)) call save_results(f, out, error)
            call ck%finish(f, k, self%integ%t, error)
        end subroutine checkpoint

        !> Store the current state and energies.
        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: u(:), v(:), stress(:, :), szz(:), vm(:)
            real(wp) :: energies(5)
            character(len=200) :: buf
            integer :: n
            u = self%model%expand(self%integ%u, self%integ%t)
            v = self%model%expand(self%integ%v, self%integ%t, 1)
            n = self%model%mesh%node_count()
            call self%model%centre_stresses(u, stress, error)
            if (allocated(error)) return
            call self%model%stress_measures(stress, szz, vm)
            associate (g => self%integ, au => self%audit)
                energies = [au%kinetic, au%strain, au%load_work, au%damping, au%balance()]
                ! (von Mises squares the stresses: it is not finite beyond 1e154 Pa)
                if (.not. (all(ieee_is_finite(stress)) .and. all(ieee_is_finite(vm)) .and. &
                           all(ieee_is_finite(energies)))) then
                    write (buf, '(a,es13.5e3,a)') 'continuum: a stress or an energy is not finite at t = ', g%t, &
                        ' s; likely cause: loads or moduli far too large or too small'
                    call make_error(error, trim(buf))
                    ! a guard: nothing of this output is written yet (kept by driver_run when in the loop)
                    call out%fail_at(k, g%t)
                    return
                end if
                call writer%store(out%file, g%t, reshape(u, [2, n]), reshape(v, [2, n]), stress, szz, vm, error)
                if (allocated(error)) return
                ! a free body's translation strains nothing: only the rest counts
                associate (un => reshape(u, [2, n]))
                    u_max = max(u_max, largest_displacement(un - spread(sum(un, dim=2)/n, 2, n)))
                end associate
                call writer%store_energy(out%file, g%t, energies(1), energies(2), energies(3), energies(4), &
                                         energies(5), error, au%reaction_work, au%reaction_resultant)
            end associate
            if (allocated(error)) return
            call out%flush_output(error)
        end subroutine store
    end subroutine dynamic_run

    !> 'continuum'.
    function dynamic_checkpoint_kind(self) result(kind)
        !> The simulation.
        class(continuum_dynamic_t), intent(in) :: self
        !> Kind of run of its checkpoints.
        character(len=:), allocatable :: kind
        kind = 'continuum'
    end function dynamic_checkpoint_kind

    !> True: the Newmark or central-difference steps.
    pure logical function dynamic_has_time_loop(self)
        !> The simulation.
        class(continuum_dynamic_t), intent(in) :: self
        dynamic_has_time_loop = .true.
    end function dynamic_has_time_loop
end module driver_simulation_continuum_dynamic
