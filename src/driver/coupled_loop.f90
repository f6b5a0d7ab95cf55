!> The time loop of the Arlequin-coupled runs (doc/theory.md section 6.8), shared by the beam
!> and disks (driver_simulation_coupled) and the 2D continuum and disks
!> (driver_simulation_coupled2d): one call of the coupling step (coupling_coupled_step's
!> arlequin_step) per time step, which predicts both domains, solves the multipliers jointly
!> with the contacts and corrects both.
!>
!> `arlequin_simulation_t` runs the loop and writes what the two kinds share: the disks in
!> /dem, the multipliers, residuals and energy audit in /coupling (doc/output.md), the
!> checkpoints (driver_checkpoint::save_coupled, under the kind of `checkpoint_kind`), the
!> stop at a signal, the progress lines and the summary's closing lines. Its extensions write
!> the finite-element side through the hooks: `begin` (mesh and static data of a new run),
!> `check_part` (guard of the finite-element state), `after_step`, `store_part` (one stored
!> output), `unconverged_detail` and `summary_lines` (report text), and, when they hold more
!> than the coupled system, `save_part` / `load_part` (checkpoints) and `finish`.
!>
!> Warnings go through the report callback: steps whose joint solve did not converge (the
!> first `max_warnings`, then only the count) and, once, a disk moving farther than the alert
!> distance in a step. The initial state (step 0) and the state after every step are checked
!> as in the uncoupled runs (driver_guards): the finite-element side by `check_part`, then the
!> disks (non-finite values, beyond the representable box), then tunnelling (after a step).
module driver_coupled_loop
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_signals, only: caught_signal, signal_name
    use io_progress, only: progress_t
    use core_strings, only: string_t, counted, to_str
    use io_deck, only: deck_t
    use io_hdf5_file, only: h5_file_t
    use coupling_coupled_step, only: coupled_system_t, coupled_energies_t, arlequin_step, coupled_energies, &
                                     velocity_mismatch_t, velocity_mismatch
    use driver_results, only: results_writer_t
    use driver_results_dem, only: dem_writer_t
    use driver_results_coupled, only: coupled_writer_t
    use driver_run_dem, only: max_warnings, speed_warning, last_unconverged_warning, fclib_path, &
                              fclib_after_end_warning, fclib_no_contacts_warning, lost_bonds_warning
    use driver_results_dem, only: write_fclib_local
    use dem_local_problem, only: local_problem_t
    use dem_contacts, only: status_cohesive
    use driver_guards, only: check_disks_state, check_walls_state, step_start_t, take_step_start, check_tunnelling
    use driver_checkpoint, only: checkpoint_run_t, end_of_step, step_end_t, loop_state_t, checkpoint_create, &
                                 save_coupled, load_coupled, &
                                 save_results, load_results, save_dem_writer, load_dem_writer, &
                                 save_coupled_writer, load_coupled_writer
    use driver_simulation, only: simulation_t, report_iface
    implicit none
    private
    public :: arlequin_simulation_t

    !> A finite-element model and particles glued in an overlap, integrated by one time loop.
    type, abstract, extends(simulation_t) :: arlequin_simulation_t
        !> The coupled system (built by `init`; it advances).
        type(coupled_system_t), allocatable :: sys
        !> Writer of /dem.
        type(dem_writer_t) :: dem_out
        !> Writer of /coupling (its maxima of the residuals feed the summary).
        type(coupled_writer_t) :: cpl_out
        !> Step whose local contact problem (coupling rows condensed) is written in FCLIB's
        !> format (`[solver] fclib_step`; 0: none), set by `init`.
        integer :: fclib_step = 0
    contains
        !> See `simulation_t%run`: the coupled time loop.
        procedure :: run => arlequin_run
        !> See `simulation_t%has_time_loop`: yes.
        procedure :: has_time_loop => arlequin_has_time_loop
        !> See `simulation_t%check_deck`: both models' keywords are used.
        procedure :: check_deck => arlequin_check_deck
        !> See `simulation_t%deck_warnings`: the solver settings that do not act on the
        !> coupling rows.
        procedure :: deck_warnings => arlequin_deck_warnings
        !> Material ids of the disks and whether contacts are stored (for /dem).
        procedure(particle_output_iface), deferred :: particle_output
        !> Static data of a new run (mesh, overlap), after /dem and /coupling are begun.
        procedure(begin_iface), deferred :: begin
        !> Guard of the finite-element state after step `k` (k = 0: the initial state).
        procedure(check_part_iface), deferred :: check_part
        !> Work after each step, before the guards (default: none).
        procedure :: after_step => no_after_step
        !> The finite-element side of one stored output (before the disks and /coupling).
        procedure(store_part_iface), deferred :: store_part
        !> Text after '... did not converge in N sweeps' of an unconverged step's warning.
        procedure(unconverged_detail_iface), deferred :: unconverged_detail
        !> Summary lines before the energy balance: model, constraint residuals, unconverged steps.
        procedure(summary_lines_iface), deferred :: summary_lines
        !> More of a checkpoint than the coupled system and the writers (default: none).
        procedure :: save_part => no_save_part
        !> Check what `save_part` wrote, before the results file is touched (default: none).
        procedure :: check_saved_part => no_check_saved_part
        !> Read back what `save_part` wrote, after the results file is restored (default: none).
        procedure :: load_part => no_load_part
        !> Last writes after the summary (default: none).
        procedure :: finish => no_finish
        !> Summary line 'coupled run: <model>, N disks (M coupled), K steps to t = T s'.
        procedure, non_overridable :: run_line
        !> Summary line of the constraint residuals (position, from the coordinates, velocity).
        procedure, non_overridable :: constraint_line
    end type arlequin_simulation_t

    abstract interface
        !> The particle deck data the /dem writer needs.
        subroutine particle_output_iface(self, material_id, store_contacts)
            import :: arlequin_simulation_t
            !> The simulation (after `init`).
            class(arlequin_simulation_t), intent(in) :: self
            !> Deck id of each particle material.
            integer, allocatable, intent(out) :: material_id(:)
            !> Whether the contacts are stored with each output.
            logical, intent(out) :: store_contacts
        end subroutine particle_output_iface

        !> Write the static data of a new run into the results file.
        subroutine begin_iface(self, out, error)
            import :: arlequin_simulation_t, results_writer_t, error_t
            !> The simulation (after `init`).
            class(arlequin_simulation_t), intent(inout) :: self
            !> The results file.
            type(results_writer_t), intent(inout) :: out
            !> Set on a write failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine begin_iface

        !> Error when the finite-element state after step `k` is not finite.
        subroutine check_part_iface(self, k, error)
            import :: arlequin_simulation_t, error_t, i8
            !> The simulation.
            class(arlequin_simulation_t), intent(in) :: self
            !> Steps done.
            integer(i8), intent(in) :: k
            !> Set at the first non-finite value.
            type(error_t), allocatable, intent(out) :: error
        end subroutine check_part_iface

        !> Store the finite-element side of one output.
        subroutine store_part_iface(self, out, error)
            import :: arlequin_simulation_t, results_writer_t, error_t
            !> The simulation.
            class(arlequin_simulation_t), intent(inout) :: self
            !> The results file.
            type(results_writer_t), intent(inout) :: out
            !> Set on a non-finite output or a write failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine store_part_iface

        !> The end of an unconverged step's warning.
        function unconverged_detail_iface(self) result(text)
            import :: arlequin_simulation_t
            !> The simulation.
            class(arlequin_simulation_t), intent(in) :: self
            !> Text after 'sweeps'.
            character(len=:), allocatable :: text
        end function unconverged_detail_iface

        !> Report the summary lines of the model.
        subroutine summary_lines_iface(self, n_steps, unconverged, report)
            import :: arlequin_simulation_t, report_iface, i8
            !> The simulation.
            class(arlequin_simulation_t), intent(in) :: self
            !> Steps done.
            integer(i8), intent(in) :: n_steps
            !> Unconverged steps.
            integer, intent(in) :: unconverged
            !> Where the lines go.
            procedure(report_iface) :: report
        end subroutine summary_lines_iface
    end interface

contains

    !> Integrate the coupled model from t = 0 (or from a checkpoint) to the end time and write
    !> its results; write checkpoints as `ck` says, at the end and at a stop signal.
    subroutine arlequin_run(self, out, quiet, report, ck, error)
        !> The simulation (after `init`).
        class(arlequin_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines (warnings and the summary are still reported).
        logical, intent(in) :: quiet
        !> Where progress, warning and summary lines go.
        procedure(report_iface) :: report
        !> Checkpoints (and the one to restart from).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        type(progress_t) :: progress
        type(step_start_t) :: start
        integer(i8) :: n_steps, k, k0
        integer :: lost_warnings
        integer :: unconverged
        logical :: speed_warned, rotation_warned, store_contacts
        type(step_end_t) :: act
        integer, allocatable :: material_id(:)
        character(len=512) :: buf

        n_steps = self%settings%n_steps
        unconverged = 0
        lost_warnings = 0
        speed_warned = .false.
        rotation_warned = .false.
        k0 = 0
        call self%particle_output(material_id, store_contacts)
        if (ck%restart) then
            call restore(error)
            if (allocated(error)) return
        else
            call self%dem_out%begin(out%file, self%sys%dem, material_id, store_contacts, error)
            if (allocated(error)) return
            call self%cpl_out%begin(out%file, self%sys, error)
            if (allocated(error)) return
            call self%begin(out, error)
            if (allocated(error)) return
            k = 0
            call check_step(error)
            if (allocated(error)) return
            call store(error)
            if (allocated(error)) return
            call check_initial_velocities()
        end if
        if (self%fclib_step > n_steps) call report(fclib_after_end_warning(self%fclib_step, n_steps))
        call progress%start(n_steps, self%settings%t_end, self%settings%progress_seconds)
        if (ck%restart) call progress%resume(k0, ck%start%wall_seconds, ck%start%runs)
        call ck%schedule%start()
        do k = k0 + 1, n_steps
            call take_step_start(start, self%sys%dem%particles, self%sys%dem%walls, &
                                 self%sys%dem%energies%contact_dissipation)
            if (k == self%fclib_step) then
                call step_with_export(error)
            else
                call arlequin_step(self%sys, error)
            end if
            if (allocated(error)) return
            call self%after_step(error)
            if (allocated(error)) return
            call check_step(error)
            if (allocated(error)) return
            call self%dem_out%record_step(out%file, self%sys%dem%stats, error)
            if (allocated(error)) return
            call self%cpl_out%record_step(out%file, self%sys, error)
            if (allocated(error)) return
            if (.not. self%sys%stats%converged) call warn_unconverged()
            if (self%sys%dem%bonds_lost > 0) then
                lost_warnings = lost_warnings + 1
                if (lost_warnings <= max_warnings) call report(lost_bonds_warning(k, self%sys%dem%time, self%sys%dem%bonds_lost))
                if (lost_warnings == max_warnings) call report('warning: further lost bonds are only logged '// &
                                                               '(/dem/bonds, mode 5)')
            end if
            if (.not. speed_warned) call check_speed()
            if (.not. rotation_warned) call check_rotation()
            if (k == 1) call check_redundant_bonds()
            act = end_of_step(k, n_steps, self%settings%output_interval, ck%schedule)
            if (act%store_first) call store(error)
            if (act%checkpoint .and. .not. allocated(error)) call checkpoint(error)
            if (act%store_last .and. .not. allocated(error)) call store(error)
            if (allocated(error)) return
            if (act%stop) then
                ! Stop request: the step just done is the last output.
                call out%stop_at(signal_name(caught_signal()), k, self%sys%fe%t)
                n_steps = k
                exit
            end if
            if (quiet) cycle
            if (progress%due()) call report(progress%line(k, self%sys%fe%t))
        end do
        call self%dem_out%finish(out%file, self%sys%dem, unconverged, error)
        if (allocated(error)) return
        call self%cpl_out%finish(out%file, error)
        if (allocated(error)) return
        call summary()
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(n_steps), progress, error)
        if (allocated(error)) return
        call self%finish(out, error)

    contains

        !> One step (as arlequin_step) that writes its local contact problem, the coupling
        !> rows condensed, in FCLIB's format to <results without .h5>_fclib_<step>.h5.
        subroutine step_with_export(error)
            type(error_t), allocatable, intent(out) :: error
            type(local_problem_t) :: lp
            character(len=:), allocatable :: path
            call arlequin_step(self%sys, error, lp)
            if (allocated(error)) return
            if (lp%n == 0) then
                ! FCLIB's reader refuses a problem without contacts
                call report(fclib_no_contacts_warning(int(k)))
                return
            end if
            call out%companion(fclib_path(out%final_path, int(k)), path)
            call write_fclib_local(path, self%settings%title, lp, int(k), self%sys%fe%t, &
                                   self%sys%dem%stats%siconos_error, error)
        end subroutine step_with_export

        !> Restart: state, writer counters and results file from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            call self%dem_out%resume(self%sys%dem, store_contacts)
            call self%cpl_out%resume(self%sys)
            call load_coupled(ck%source, self%sys, ck%start%step, error)
            if (.not. allocated(error)) call load_dem_writer(ck%source, self%dem_out, error)
            if (.not. allocated(error)) call load_coupled_writer(ck%source, self%cpl_out, error)
            if (.not. allocated(error)) call self%check_saved_part(ck%source, error)
            if (.not. allocated(error)) call check_results_version(error)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            if (.not. allocated(error)) call self%load_part(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            k0 = ck%start%step
            unconverged = ck%start%unconverged
            speed_warned = ck%start%speed_warned
            rotation_warned = ck%start%rotation_warned
            ! an export before the checkpoint that a killed run left unrenamed
            if (self%fclib_step > 0 .and. self%fclib_step <= k0) &
                call out%adopt(fclib_path(out%final_path, self%fclib_step))
        end subroutine restore

        !> Refuse a results file of an earlier build, which lacks a series this one appends to
        !> (the supports' work of the audit, 2026-11-27), before load_results cuts or marks it:
        !> an interrupted run's partial file stays as it was.
        subroutine check_results_version(error)
            type(error_t), allocatable, intent(out) :: error
            if (out%file%exists('/coupling/energy/fe_reaction_work')) return
            call make_error(error, "restart: the results file '"//out%file%path//"' was written by an "// &
                            'earlier version of MULTICOR (its /coupling/energy has no fe_reaction_work): '// &
                            'continue it with that version, or run the deck again from the start')
        end subroutine check_results_version

        !> Write a checkpoint after step k (the buffered per-step values are written first).
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call self%dem_out%flush_buffer(out%file, error)
            if (.not. allocated(error)) call self%cpl_out%flush_buffer(out%file, error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, self%checkpoint_kind(), &
                                   loop_state_t(k, unconverged, speed_warned, .false., rotation_warned, &
                                                wall_seconds=progress%analysis_seconds(), runs=progress%runs), &
                                   self%sys%fe%t, &
                                   out%run_id, error)
            if (.not. allocated(error)) call save_coupled(f, self%sys, error)
            if (.not. allocated(error)) call self%save_part(f, error)
            if (.not. allocated(error)) call save_dem_writer(f, self%dem_out, error)
            if (.not. allocated(error)) call save_coupled_writer(f, self%cpl_out, error)
            if (.not. allocated(error)) call save_results(f, out, error)
            call ck%finish(f, k, self%sys%fe%t, error)
        end subroutine checkpoint

        !> Guards after step k (k = 0: the initial state): the finite-element state, finite disk
        !> states in the box, no tunnelling in the step.
        subroutine check_step(error)
            type(error_t), allocatable, intent(out) :: error
            call self%check_part(k, error)
            if (allocated(error)) return
            associate (sys => self%sys)
                call check_disks_state(k, sys%fe%t, sys%dem%particles, sys%dem%energies, error)
                if (allocated(error)) return
                call check_walls_state(k, sys%fe%t, sys%dem%particles, sys%dem%walls, error)
                if (allocated(error)) return
                if (k == 0) return
                call check_tunnelling(k, sys%fe%t, self%settings%h, sys%dem%scheme%alert, start, &
                                      sys%dem%particles, sys%dem%walls, sys%dem%contacts, error, &
                                      sys%dem%energies%contact_dissipation)
            end associate
        end subroutine check_step

        !> One stored output: the finite-element side, the disks, the coupling.
        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            call self%store_part(out, error)
            if (allocated(error)) return
            call self%dem_out%store(out%file, self%sys%dem, error)
            if (allocated(error)) return
            call self%cpl_out%store(out%file, self%sys, error)
            if (allocated(error)) return
            call out%flush(error)
        end subroutine store

        !> Warning for an unconverged step (the first max_warnings ones).
        subroutine warn_unconverged()
            unconverged = unconverged + 1
            if (unconverged > max_warnings) return
            write (buf, '(a,i0,a,es12.4e3,a,i0,a)') 'warning: step ', k, ' (t = ', self%sys%fe%t, &
                ' s): the joint contact/multiplier solve did not converge in ', self%sys%stats%sweeps, ' sweeps'
            call report(trim(buf)//self%unconverged_detail())
            if (unconverged == max_warnings) call report(last_unconverged_warning())
        end subroutine warn_unconverged

        !> Warning when the initial velocities of the coupled disks differ from the FE model's
        !> at their centres (beyond round-off: 1e-8 of the velocities, the rotation rows times
        !> the largest coupled radius, so that a rotation mismatch of rounding next to zero
        !> rotations does not count). The first step's
        !> multipliers remove the difference with an impulse that dissipates its energy like a
        !> plastic impact: the run goes on, but /coupling/energy/balance shows that loss (5 % to
        !> 30 % of the energy for disks given initial_velocity over a block at rest).
        subroutine check_initial_velocities()
            real(wp), parameter :: relative = 1.0e-8_wp
            type(velocity_mismatch_t) :: m
            m = velocity_mismatch(self%sys)
            if (hypot(m%translation, m%radius*m%rotation) <= &
                relative*hypot(m%translation_scale, m%radius*m%rotation_scale)) return
            write (buf, '(a,es10.3e3,a,es10.3e3,a,es10.3e3,a,es10.3e3,a,i0,a)') &
                'warning: the initial velocities of the coupled disks differ from the finite-element '// &
                'model''s at their centres (|G v - C v| = ', m%translation, ' m/s against ', &
                m%translation_scale, ' m/s, rotations ', m%rotation, ' rad/s against ', m%rotation_scale, &
                ' rad/s; disk ', m%disk, ' the most)'
            call report(trim(buf)//': the first step glues them with an impulse that dissipates '// &
                        'energy like a plastic impact, and /coupling/energy/balance shows that loss; give '// &
                        'the coupled disks the motion of the finite-element model (e.g. [particles] '// &
                        'initial_rigid with the rigid motion of [initial] rigid or [continuum] initial_velocity)')
        end subroutine check_initial_velocities

        !> Warning (once) when a disk moved farther than the alert distance in the step.
        subroutine check_speed()
            character(len=:), allocatable :: line
            line = speed_warning(self%sys%dem%particles, self%settings%h, self%sys%dem%scheme%alert, &
                                 self%sys%fe%t)
            if (len(line) == 0) return
            speed_warned = .true.
            call report(line)
        end subroutine check_speed

        !> Warning (once) when two coupled disks joined by an intact bond have turned by more than
        !> rotation_limit. The bond keeps their distance through the rotation, the coupling
        !> (C built on the reference configuration) moves them with the linear field, which
        !> stretches the chord by about theta^2/2 of its length: the multipliers then carry a
        !> spurious axial force of about alpha E A theta^2/2 and the bending moments come out
        !> short (doc/theory.md 6.3).
        subroutine check_rotation()
            real(wp), parameter :: rotation_limit = 1.0e-2_wp
            logical, allocatable :: coupled(:)
            real(wp) :: theta
            integer :: c
            associate (p => self%sys%dem%particles, cs => self%sys%dem%contacts)
                if (p%n == 0 .or. size(self%sys%coupled) == 0) return
                allocate (coupled(p%n), source=.false.)
                coupled(self%sys%coupled) = .true.
                theta = 0.0_wp
                do c = 1, cs%n
                    if (cs%status(c) /= status_cohesive .or. cs%i1(c) <= 0) cycle
                    if (.not. (coupled(cs%i1(c)) .and. coupled(cs%i2(c)))) cycle
                    theta = max(theta, abs(p%rot(cs%i1(c))), abs(p%rot(cs%i2(c))))
                end do
                if (theta <= rotation_limit) return
                write (buf, '(a,es12.4e3,a,es10.2e3,a,es8.1e2,a)') 'warning: at t = ', self%sys%fe%t, &
                    ' s bonded coupled disks have turned by ', theta, ' rad (more than ', rotation_limit, &
                    '): the linear coupling stretches their bonds by about theta^2/2, which adds an '// &
                    'axial force of about alpha E A theta^2/2 and shortens the bending moments by a few % '// &
                    '(doc/theory.md 6.3); lower the load or treat the results as approximate'
                rotation_warned = .true.
                call report(trim(buf))
            end associate
        end subroutine check_rotation

        !> Warning (after the first step, when the bonds are made) when intact bonds join
        !> coupled disks across the beam's axis with a multiplier per coupled dof (every layer
        !> of a stack glued: [coupling] max_offset = 0, the default). The beam's sections do not
        !> deform, so between two such disks the coupling leaves only the beam's bending and
        !> stretching over a disk pitch: the bonds and the coupling rows are nearly redundant,
        !> and any disagreement of their targets (the linear field's stretch, doc/theory.md 6.3;
        !> round-off) loads them with a self-stress that grows from step to step and can break
        !> bonds (doc/theory.md 7.10, "Least norm"; measured in
        !> tests/regression/decks/coupled_glued_layers.dat: |lambda| of 1e4 N under 5 N).
        subroutine check_redundant_bonds()
            integer, allocatable :: point(:)
            integer :: c, n, p
            if (self%sys%on_nodes) return
            associate (pa => self%sys%dem%particles, cs => self%sys%dem%contacts, op => self%sys%op)
                if (pa%n == 0 .or. size(self%sys%coupled) == 0) return
                allocate (point(pa%n), source=0)
                point(self%sys%coupled) = [(p, p=1, size(self%sys%coupled))]
                n = 0
                do c = 1, cs%n
                    if (cs%status(c) /= status_cohesive .or. cs%i1(c) <= 0) cycle
                    if (point(cs%i1(c)) == 0 .or. point(cs%i2(c)) == 0) cycle
                    ! across the axis by more than half the smaller disk: another layer
                    if (op%rigid_distance(point(cs%i1(c)), point(cs%i2(c))) > &
                        0.5_wp*min(pa%radius(cs%i1(c)), pa%radius(cs%i2(c)))) n = n + 1
                end do
            end associate
            if (n == 0) return
            call report('warning: '//counted(n, 'intact bond')//' join coupled disks at different distances '// &
                        'from the beam axis (several layers glued): the beam''s sections do not deform, so '// &
                        'these bonds and the coupling rows are nearly redundant and carry a self-stress that '// &
                        'grows with any disagreement of their targets and can break bonds (doc/theory.md 7.10); '// &
                        'glue one layer ([coupling] max_offset) or use [coupling] multipliers = nodes')
        end subroutine check_redundant_bonds

        !> Closing lines: the model's (size, residuals, solver effort), energy balance, times.
        subroutine summary()
            type(coupled_energies_t) :: en
            call self%summary_lines(n_steps, unconverged, report)
            en = coupled_energies(self%sys)
            write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'energy balance residual ', en%balance, &
                ' J (max over the outputs ', self%cpl_out%max_balance, ' J; external work ', &
                en%fe_external_work + en%fe_reaction_work + en%dem_external_work + en%dem_drive_work, ' J)'
            call report(trim(buf))
            call report(progress%summary_line(n_steps, self%sys%fe%t, out%stopped()))
        end subroutine summary
    end subroutine arlequin_run

    !> 'coupled run: <model>, N disks (M coupled), K steps to t = T s'.
    function run_line(self, model, n_steps) result(line)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> Size of the finite-element model, e.g. '11 beam nodes'.
        character(len=*), intent(in) :: model
        !> Steps done.
        integer(i8), intent(in) :: n_steps
        !> The line.
        character(len=:), allocatable :: line
        character(len=512) :: buf
        write (buf, '(es13.5e3)') self%sys%fe%t
        line = 'coupled run: '//model//', '//counted(self%sys%dem%particles%n, 'disk')//' ('// &
               to_str(self%sys%op%n_points)//' coupled), '//counted(n_steps, 'step')//' to t = '//trim(buf)//' s'
    end function run_line

    !> '<residual> = P m (<coordinates> C m), max velocity residual V m/s': the largest
    !> residuals over the outputs.
    function constraint_line(self, residual, coordinates) result(line)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> What the position residual is, e.g. 'constraint: max |q - C u|'.
        character(len=*), intent(in) :: residual
        !> How the residual from the coordinates is taken, e.g. 'from the coordinates'.
        character(len=*), intent(in) :: coordinates
        !> The line.
        character(len=:), allocatable :: line
        character(len=512) :: buf
        write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') residual//' = ', self%cpl_out%max_position, &
            ' m ('//coordinates//' ', self%cpl_out%max_coordinate, ' m), max velocity residual ', &
            self%cpl_out%max_velocity, ' m/s'
        line = trim(buf)
    end function constraint_line

    !> True: the coupled steps.
    pure logical function arlequin_has_time_loop(self)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        arlequin_has_time_loop = .true.
    end function arlequin_has_time_loop

    !> No error: a coupled deck uses the keywords of both models.
    subroutine arlequin_check_deck(self, deck, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
    end subroutine arlequin_check_deck

    !> Warnings for the solver settings that a coupled run accepts and does not use, as
    !> 'warning: file:line: ...': `method = coarse` (a coupled run sweeps as with `nlgs`) and
    !> `cold_start = hydrostatic` (its estimate leaves out the coupling rows); documented
    !> fallbacks, so warnings rather than errors.
    function arlequin_deck_warnings(self, deck) result(warnings)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The warnings.
        type(string_t), allocatable :: warnings(:)
        allocate (warnings(0))
        if (set_to('method', 'coarse')) &
            warnings = [warnings, string_t('warning: '//deck%file//':'//to_str(deck%line('solver', 'method'))// &
                                           ': [solver] method = coarse has no effect in a coupled run: '// &
                                           'the coarse correction does not act on the coupling rows, and the run '// &
                                           'sweeps as with method = nlgs')]
        if (set_to('cold_start', 'hydrostatic')) &
            warnings = [warnings, string_t('warning: '//deck%file//':'//to_str(deck%line('solver', 'cold_start'))// &
                                           ': [solver] cold_start = hydrostatic has no effect in a coupled run: '// &
                                           'the hydrostatic estimate leaves out the coupling rows, and a step without '// &
                                           'reactions starts from zero')]
    contains
        ! whether the deck itself sets [solver] keyword to value
        logical function set_to(keyword, value)
            character(len=*), intent(in) :: keyword, value
            set_to = .false.
            if (deck%has('solver', keyword)) set_to = deck%get_word('solver', keyword) == value
        end function set_to
    end function arlequin_deck_warnings

    !> No work after a step.
    subroutine no_after_step(self, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
    end subroutine no_after_step

    !> Nothing to add to a checkpoint.
    subroutine no_save_part(self, f, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The checkpoint being written.
        type(h5_file_t), intent(inout) :: f
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
    end subroutine no_save_part

    !> Nothing more to check in a checkpoint.
    subroutine no_check_saved_part(self, f, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The checkpoint (open).
        type(h5_file_t), intent(inout) :: f
        !> Set when a value is damaged.
        type(error_t), allocatable, intent(out) :: error
    end subroutine no_check_saved_part

    !> Nothing to read back from a checkpoint.
    subroutine no_load_part(self, f, out, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> The checkpoint (open).
        type(h5_file_t), intent(inout) :: f
        !> The results file (restored).
        type(results_writer_t), intent(inout) :: out
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
    end subroutine no_load_part

    !> No writes after the summary.
    subroutine no_finish(self, out, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> The results file (summary written).
        type(results_writer_t), intent(inout) :: out
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
    end subroutine no_finish
end module driver_coupled_loop
