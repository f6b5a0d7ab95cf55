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
!> first `max_warnings`, then only the count), once, a disk moving farther than the alert
!> distance in a step, and once, then counted in the summary, a converged step whose contacts
!> created energy (driver_guards::creation_allowance; doc/theory.md 2.5). The initial state
!> (step 0) and the state after every step are checked as in the uncoupled runs
!> (driver_guards): the finite-element side by `check_part`, then the disks (non-finite
!> values, beyond the representable box), then tunnelling (after a step).
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
    use driver_run_dem, only: max_warnings, speed_warning, last_unconverged_warning, fclib_path, tolerance_floor_hint, &
                              fclib_moment_note, fclib_after_end_warning, fclib_no_contacts_warning, lost_bonds_warning, &
                              bonds_line, recheck_capped_text
    use driver_results_dem, only: write_fclib_local
    use dem_local_problem, only: local_problem_t
    use dem_contacts, only: status_cohesive
    use driver_guards, only: check_disks_state, largest_speed, check_walls_state, step_start_t, take_step_start, &
                             check_tunnelling, &
                             step_created_energy, step_creates_energy, energy_creation_warning, energy_creation_summary
    use driver_checkpoint, only: checkpoint_run_t, end_of_step, rest_of_last_step, step_end_t, loop_state_t, &
                                 checkpoint_create, &
                                 save_coupled, load_coupled, &
                                 save_results, load_results, save_dem_writer, load_dem_writer, &
                                 save_coupled_writer, load_coupled_writer
    use driver_simulation, only: simulation_t, report_iface
    use driver_swept_bonds, only: swept_bonds_warning
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
        !> coupling rows, and bonds swept one contact at a time.
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

    !> The state of a coupled time loop, shared by the procedures of `arlequin_run`.
    type :: coupled_loop_t
        !> Steps of the run (the step of a stop, once stopped).
        integer(i8) :: n_steps = 0
        !> The step just done (0: the initial state).
        integer(i8) :: k = 0
        !> Steps done at the start (those of the checkpoint of a restart).
        integer(i8) :: k0 = 0
        !> Largest speed of a disk at t = 0, from the deck (the guards' likely causes) [m/s].
        real(wp) :: initial_speed = 0.0_wp
        !> Steps with lost bonds warned about so far.
        integer :: lost_warnings = 0
        !> Unconverged steps so far.
        integer :: unconverged = 0
        !> Converged steps whose contacts created energy so far (the first one warned about).
        integer(i8) :: creating = 0
        !> Warnings given once: a disk faster than the alert distance, bonded coupled disks
        !> turned too far.
        logical :: speed_warned = .false., rotation_warned = .false.
        !> Whether /dem stores the contacts with each output.
        logical :: store_contacts = .false.
        !> Deck id of each particle material (for /dem).
        integer, allocatable :: material_id(:)
        !> Progress lines and the wall time of the analysis.
        type(progress_t) :: progress
        !> The disks and walls at the start of the step (guard against tunnelling).
        type(step_start_t) :: start
    end type coupled_loop_t

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
        type(coupled_loop_t) :: lp
        type(step_end_t) :: act
        integer(i8) :: k

        lp%n_steps = self%settings%n_steps
        call self%particle_output(lp%material_id, lp%store_contacts)
        lp%initial_speed = largest_speed(self%sys%dem%particles)
        if (ck%restart) then
            call restore(self, lp, out, ck, error)
        else
            call begin_new_run(self, lp, out, report, error)
        end if
        if (allocated(error)) return
        if (self%fclib_step > lp%n_steps) call report(fclib_after_end_warning(self%fclib_step, lp%n_steps))
        call lp%progress%start(lp%n_steps, self%settings%t_end, self%settings%progress_seconds)
        if (ck%restart) call lp%progress%resume(lp%k0, ck%start%wall_seconds, ck%start%runs)
        call ck%schedule%start()
        if (ck%restart .and. lp%k0 == lp%n_steps) then
            ! a checkpoint of the last step: the rest of that step's end (a run killed after it)
            lp%k = lp%k0
            act = rest_of_last_step(lp%n_steps, self%settings%output_interval)
            if (act%checkpoint) call write_checkpoint(self, lp, out, ck, error)
            if (act%store_last .and. .not. allocated(error)) call store_output(self, out, error)
            if (allocated(error)) return
        end if
        call out%begin_loop()
        do k = lp%k0 + 1, lp%n_steps
            lp%k = k
            call take_step(self, lp, out, report, error)
            if (allocated(error)) return
            call warn_after_step(self, lp, report)
            act = end_of_step(k, lp%n_steps, self%settings%output_interval, ck%schedule)
            if (act%store_first) call store_output(self, out, error)
            if (act%checkpoint .and. .not. allocated(error)) call write_checkpoint(self, lp, out, ck, error)
            if (act%store_last .and. .not. allocated(error)) call store_output(self, out, error)
            if (allocated(error)) return
            if (act%stop) then
                ! Stop request: the step just done is the last output.
                call out%stop_at(signal_name(caught_signal()), k, self%sys%fe%t)
                lp%n_steps = k
                exit
            end if
            if (quiet) cycle
            if (lp%progress%due()) call report(lp%progress%line(k, self%sys%fe%t))
        end do
        call self%dem_out%finish(out%file, self%sys%dem, lp%unconverged, error)
        if (allocated(error)) return
        call self%cpl_out%finish(out%file, error)
        if (allocated(error)) return
        call summary(self, lp, out, report)
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(lp%n_steps), lp%progress, error)
        if (allocated(error)) return
        call self%finish(out, error)
    end subroutine arlequin_run

    !> A new run: /dem, /coupling and the finite-element side begun, the initial state checked
    !> and stored, its velocities compared.
    subroutine begin_new_run(self, lp, out, report, error)
        !> The simulation (after `init`).
        class(arlequin_simulation_t), intent(inout) :: self
        !> The loop's state (`material_id`, `store_contacts` set).
        type(coupled_loop_t), intent(inout) :: lp
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Where the warning goes.
        procedure(report_iface) :: report
        !> Set on a write failure or a bad initial state.
        type(error_t), allocatable, intent(out) :: error
        call self%dem_out%begin(out%file, self%sys%dem, lp%material_id, lp%store_contacts, error)
        if (allocated(error)) return
        call self%cpl_out%begin(out%file, self%sys, error)
        if (allocated(error)) return
        call self%begin(out, error)
        if (allocated(error)) return
        lp%k = 0
        call check_step(self, lp, error)
        if (allocated(error)) return
        call store_output(self, out, error)
        if (allocated(error)) return
        call check_initial_velocities(self, report)
    end subroutine begin_new_run

    !> Restart: state, writer counters and results file from the checkpoint `ck%source`.
    subroutine restore(self, lp, out, ck, error)
        !> The simulation (after `init`).
        class(arlequin_simulation_t), intent(inout) :: self
        !> The loop's state: its counters and flags those of the checkpoint.
        type(coupled_loop_t), intent(inout) :: lp
        !> The results file, cut back to the checkpoint.
        type(results_writer_t), intent(inout) :: out
        !> The run's checkpoints (`source` closed on return).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a read failure or a damaged checkpoint.
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: ignored
        call self%dem_out%resume(self%sys%dem, lp%store_contacts)
        call self%cpl_out%resume(self%sys)
        call load_coupled(ck%source, self%sys, ck%start%step, error)
        if (.not. allocated(error)) call load_dem_writer(ck%source, self%dem_out, error)
        if (.not. allocated(error)) call load_coupled_writer(ck%source, self%cpl_out, error)
        if (.not. allocated(error)) call self%check_saved_part(ck%source, error)
        if (.not. allocated(error)) call check_results_version(out, error)
        if (.not. allocated(error)) call load_results(ck%source, out, error)
        if (.not. allocated(error)) call self%load_part(ck%source, out, error)
        call ck%source%close(ignored)
        if (allocated(error)) return
        lp%k0 = ck%start%step
        lp%unconverged = ck%start%unconverged
        lp%creating = ck%start%creating
        lp%speed_warned = ck%start%speed_warned
        lp%rotation_warned = ck%start%rotation_warned
        ! an export before the checkpoint that a killed run left unrenamed
        if (self%fclib_step > 0 .and. self%fclib_step <= lp%k0) &
            call out%adopt(fclib_path(out%final_path, self%fclib_step))
    end subroutine restore

    !> Refuse a results file of an earlier build, which lacks a series this one appends to
    !> (the supports' work of the audit, 2026-11-27), before load_results cuts or marks it:
    !> an interrupted run's partial file stays as it was.
    subroutine check_results_version(out, error)
        !> The results file being resumed.
        type(results_writer_t), intent(in) :: out
        !> Set when the file lacks the series.
        type(error_t), allocatable, intent(out) :: error
        if (out%file%exists('/coupling/energy/fe_reaction_work')) return
        call make_error(error, "restart: the results file '"//out%file%path//"' was written by an "// &
                        'earlier version of MULTICOR (its /coupling/energy has no fe_reaction_work): '// &
                        'continue it with that version, or run the deck again from the start')
    end subroutine check_results_version

    !> Step `lp%k`: the coupling step (with the FCLIB export at its step), the work after it,
    !> the guards and the per-step records of /dem and /coupling.
    subroutine take_step(self, lp, out, report, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> The loop's state.
        type(coupled_loop_t), intent(inout) :: lp
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Where a warning of the export goes.
        procedure(report_iface) :: report
        !> Set on a failure of the step, a guard or a write.
        type(error_t), allocatable, intent(out) :: error
        call take_step_start(lp%start, self%sys%dem%particles, self%sys%dem%walls, self%sys%dem%energies)
        if (lp%k == self%fclib_step) then
            call step_with_export(self, lp%k, out, report, error)
        else
            call arlequin_step(self%sys, error)
        end if
        if (.not. allocated(error)) call self%after_step(error)
        if (.not. allocated(error)) call check_step(self, lp, error)
        if (allocated(error)) then
            ! the results file is as its last output left it: kept (driver_run)
            call out%fail_at(lp%k, real(lp%k, wp)*self%settings%h)
            return
        end if
        call self%dem_out%record_step(out%file, self%sys%dem%stats, error)
        if (allocated(error)) return
        call self%cpl_out%record_step(out%file, self%sys, error)
    end subroutine take_step

    !> One step (as arlequin_step) that writes its local contact problem, the coupling
    !> rows condensed, in FCLIB's format to <results without .h5>_fclib_<step>.h5.
    subroutine step_with_export(self, k, out, report, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> The step.
        integer(i8), intent(in) :: k
        !> The results file (its companion file is registered).
        type(results_writer_t), intent(inout) :: out
        !> Where the warning of a step without contacts goes.
        procedure(report_iface) :: report
        !> Set on a failure of the step or of the export.
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
        if (.not. allocated(error) .and. lp%dim == 3) call report(fclib_moment_note(fclib_path(out%final_path, int(k))))
    end subroutine step_with_export

    !> Write a checkpoint after step `lp%k` (the buffered per-step values are written first).
    subroutine write_checkpoint(self, lp, out, ck, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> The loop's state.
        type(coupled_loop_t), intent(in) :: lp
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> The run's checkpoints.
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a write failure (the previous checkpoint stays).
        type(error_t), allocatable, intent(out) :: error
        type(h5_file_t) :: f
        call self%dem_out%flush_buffer(out%file, error)
        if (.not. allocated(error)) call self%cpl_out%flush_buffer(out%file, error)
        if (allocated(error)) return
        call checkpoint_create(f, ck%path, ck%deck_text, self%checkpoint_kind(), &
                               loop_state_t(lp%k, lp%unconverged, lp%speed_warned, .false., lp%rotation_warned, &
                                            creating=lp%creating, &
                                            wall_seconds=lp%progress%analysis_seconds(), runs=lp%progress%runs), &
                               self%sys%fe%t, &
                               out%run_id, error)
        if (.not. allocated(error)) call save_coupled(f, self%sys, error)
        if (.not. allocated(error)) call self%save_part(f, error)
        if (.not. allocated(error)) call save_dem_writer(f, self%dem_out, error)
        if (.not. allocated(error)) call save_coupled_writer(f, self%cpl_out, error)
        if (.not. allocated(error)) call save_results(f, out, error)
        call ck%finish(f, lp%k, self%sys%fe%t, error)
    end subroutine write_checkpoint

    !> Guards after step `lp%k` (k = 0: the initial state): the finite-element state, finite
    !> disk states in the box, no tunnelling in the step.
    subroutine check_step(self, lp, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The loop's state (step, and the state at its start).
        type(coupled_loop_t), intent(in) :: lp
        !> Set when a guard fails.
        type(error_t), allocatable, intent(out) :: error
        integer(i8) :: k
        k = lp%k
        call self%check_part(k, error)
        if (allocated(error)) return
        associate (sys => self%sys)
            call check_disks_state(k, sys%fe%t, sys%dem%particles, sys%dem%energies, lp%initial_speed, error)
            if (allocated(error)) return
            call check_walls_state(k, sys%fe%t, sys%dem%particles, sys%dem%walls, error)
            if (allocated(error)) return
            if (k == 0) return
            call check_tunnelling(k, sys%fe%t, self%settings%h, sys%dem%scheme%alert, lp%start, &
                                  sys%dem%particles, sys%dem%walls, sys%dem%contacts, error, &
                                  sys%dem%energies%contact_dissipation)
        end associate
    end subroutine check_step

    !> One stored output: the finite-element side, the disks, the coupling.
    subroutine store_output(self, out, error)
        !> The simulation.
        class(arlequin_simulation_t), intent(inout) :: self
        !> The results file.
        type(results_writer_t), intent(inout) :: out
        !> Set on a non-finite output or a write failure.
        type(error_t), allocatable, intent(out) :: error
        call self%store_part(out, error)
        if (allocated(error)) return
        call self%dem_out%store(out%file, self%sys%dem, error)
        if (allocated(error)) return
        call self%cpl_out%store(out%file, self%sys, error)
        if (allocated(error)) return
        call out%flush_output(error)
    end subroutine store_output

    !> The warnings after step `lp%k`: unconverged solve, lost bonds, a disk faster than the
    !> alert distance and bonded coupled disks turned too far (once each), bonds that the
    !> coupling makes redundant (after the first step).
    subroutine warn_after_step(self, lp, report)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The loop's state: its counters and flags updated.
        type(coupled_loop_t), intent(inout) :: lp
        !> Where the warnings go.
        procedure(report_iface) :: report
        if (.not. self%sys%stats%converged) call warn_unconverged(self, lp, report)
        if (self%sys%stats%converged .and. step_creates_energy(lp%start, self%sys%dem)) then
            lp%creating = lp%creating + 1
            if (lp%creating == 1) &
                call report(energy_creation_warning(lp%k, self%sys%fe%t, &
                                                    step_created_energy(lp%start, self%sys%dem%energies), &
                                                    lp%start%kinetic, self%sys%dem%energies%kinetic, &
                                                    maxval(self%sys%dem%materials%restitution), lp%unconverged))
        end if
        if (self%sys%dem%bonds_lost > 0) then
            lp%lost_warnings = lp%lost_warnings + 1
            if (lp%lost_warnings <= max_warnings) &
                call report(lost_bonds_warning(lp%k, self%sys%dem%time, self%sys%dem%bonds_lost))
            if (lp%lost_warnings == max_warnings) call report('warning: further lost bonds are only logged '// &
                                                              '(/dem/bonds, mode 5)')
        end if
        if (.not. lp%speed_warned) call check_speed(self, lp, report)
        if (.not. lp%rotation_warned) call check_rotation(self, lp, report)
        if (lp%k == 1) call check_redundant_bonds(self, report)
    end subroutine warn_after_step

    !> Warning for an unconverged step (the first max_warnings ones).
    subroutine warn_unconverged(self, lp, report)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The loop's state: its count of unconverged steps updated.
        type(coupled_loop_t), intent(inout) :: lp
        !> Where the warning goes.
        procedure(report_iface) :: report
        character(len=512) :: buf
        lp%unconverged = lp%unconverged + 1
        if (lp%unconverged > max_warnings) return
        if (self%sys%dem%stats%recheck_left > 0) then
            write (buf, '(a,i0,a,es12.4e3,a)') 'warning: step ', lp%k, ' (t = ', self%sys%fe%t, ' s): '
            call report(trim(buf)//' '// &
                        recheck_capped_text(self%sys%dem%stats%recheck_left, self%sys%dem%stats%solves))
        else
            write (buf, '(a,i0,a,es12.4e3,a,i0,a)') 'warning: step ', lp%k, ' (t = ', self%sys%fe%t, &
                ' s): the joint contact/multiplier solve did not converge in ', self%sys%stats%sweeps, ' sweeps'
            call report(trim(buf)//self%unconverged_detail()// &
                        tolerance_floor_hint(self%sys%dem%stats%siconos_floor, self%sys%dem%solver%tol))
        end if
        if (lp%unconverged == max_warnings) call report(last_unconverged_warning())
    end subroutine warn_unconverged

    !> Warning when the initial velocities of the coupled disks differ from the FE model's
    !> at their centres (beyond round-off: 1e-8 of the velocities, the rotation rows times
    !> the largest coupled radius, so that a rotation mismatch of rounding next to zero
    !> rotations does not count). The first step's
    !> multipliers remove the difference with an impulse that dissipates its energy like a
    !> plastic impact: the run goes on, but /coupling/energy/balance shows that loss (5 % to
    !> 30 % of the energy for disks given initial_velocity over a block at rest). With a
    !> mediator space the step removes only Pi e, and the warning says that the rest stays.
    subroutine check_initial_velocities(self, report)
        !> The simulation (initial state).
        class(arlequin_simulation_t), intent(in) :: self
        !> Where the warning goes.
        procedure(report_iface) :: report
        character(len=512) :: buf
        character(len=:), allocatable :: drift
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
        drift = ''
        ! a mediator space imposes only Pi e: the rest of the difference is never removed (an
        ! audit's 2 ms run: the disks 6.7e-5 m off the continuum's field, growing at 0.03 m/s)
        if (self%sys%on_nodes) drift = '; with the mediator space only the part of the difference the space '// &
                                       'sees is removed, and the disks keep drifting from the continuum''s field '// &
                                       'with the rest'
        call report(trim(buf)//': the first step glues them with an impulse that dissipates '// &
                    'energy like a plastic impact, and /coupling/energy/balance shows that loss'//drift// &
                    '; give the coupled disks the motion of the finite-element model (e.g. [particles] '// &
                    'initial_rigid with the rigid motion of [initial] rigid or [continuum] initial_velocity)')
    end subroutine check_initial_velocities

    !> Warning (once) when a disk moved farther than the alert distance in the step.
    subroutine check_speed(self, lp, report)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The loop's state: `speed_warned` set when warned.
        type(coupled_loop_t), intent(inout) :: lp
        !> Where the warning goes.
        procedure(report_iface) :: report
        character(len=:), allocatable :: line
        line = speed_warning(self%sys%dem%particles, self%settings%h, self%sys%dem%scheme%alert, &
                             self%sys%fe%t)
        if (len(line) == 0) return
        lp%speed_warned = .true.
        call report(line)
    end subroutine check_speed

    !> Warning (once) when two coupled disks joined by an intact bond have turned by more than
    !> rotation_limit. The bond keeps their distance through the rotation, the coupling
    !> (C built on the reference configuration) moves them with the linear field, which
    !> stretches the chord by about theta^2/2 of its length: the multipliers then carry a
    !> spurious axial force of about alpha E A theta^2/2 and the bending moments come out
    !> short (doc/theory.md 6.3).
    subroutine check_rotation(self, lp, report)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The loop's state: `rotation_warned` set when warned.
        type(coupled_loop_t), intent(inout) :: lp
        !> Where the warning goes.
        procedure(report_iface) :: report
        real(wp), parameter :: rotation_limit = 1.0e-2_wp
        logical, allocatable :: coupled(:)
        real(wp) :: theta
        integer :: c
        character(len=768) :: buf
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
                'axial force of about alpha E A theta^2/2, stiffens the model and shortens the bending '// &
                'moments by an amount growing as theta^2 (audits: 1 to 2 % at 0.005 to 0.01 rad, 6 to 8 % '// &
                'at 0.02 rad; doc/theory.md 6.3); to size it, run again with the loads 100 times smaller '// &
                'and scale the results by 100, or lower the load'
            lp%rotation_warned = .true.
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
    subroutine check_redundant_bonds(self, report)
        !> The simulation (bonds made).
        class(arlequin_simulation_t), intent(in) :: self
        !> Where the warning goes.
        procedure(report_iface) :: report
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
    subroutine summary(self, lp, out, report)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The loop's state (steps done, unconverged steps, progress).
        type(coupled_loop_t), intent(in) :: lp
        !> The results file (whether the run stopped).
        type(results_writer_t), intent(in) :: out
        !> Where the lines go.
        procedure(report_iface) :: report
        character(len=512) :: buf
        type(coupled_energies_t) :: en
        call self%summary_lines(lp%n_steps, lp%unconverged, report)
        if (any(self%sys%dem%materials%cohesion > 0.0_wp)) call report(bonds_line(self%sys%dem))
        en = coupled_energies(self%sys)
        write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'energy balance residual ', en%balance, &
            ' J (max over the outputs ', self%cpl_out%max_balance, ' J; external work ', &
            en%fe_external_work + en%fe_reaction_work + en%dem_external_work + en%dem_drive_work, ' J)'
        call report(trim(buf))
        if (lp%creating > 0) call report(energy_creation_summary(lp%creating, lp%n_steps))
        call report(lp%progress%summary_line(lp%n_steps, self%sys%fe%t, out%stopped()))
    end subroutine summary

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
    !> fallbacks, so warnings rather than errors. Also bonds swept one contact at a time
    !> (driver_swept_bonds).
    function arlequin_deck_warnings(self, deck) result(warnings)
        !> The simulation.
        class(arlequin_simulation_t), intent(in) :: self
        !> The validated deck.
        type(deck_t), intent(in) :: deck
        !> The warnings.
        type(string_t), allocatable :: warnings(:)
        character(len=:), allocatable :: message
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
        message = swept_bonds_warning(deck)
        if (len(message) > 0) warnings = [warnings, string_t(message)]
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
