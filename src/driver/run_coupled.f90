!> Time integration of a coupled beam/particle model (doc/theory.md section 6.8): one call of the
!> coupling step (coupling_arlequin::arlequin_step) per time step, which predicts both
!> domains, solves the multipliers jointly with the contacts and corrects both. Results: the
!> beam's fields in /fem, the disks' in /dem, the multipliers, residuals and energy audit in
!> /coupling (doc/output.md).
!>
!> `build_coupled` does everything that can fail because of the input (called before the
!> results folder is touched); `run_coupled` integrates and writes. Warnings go through the
!> report callback: steps whose contact solve did not converge (the first `max_warnings`,
!> then only the count) and, once, a disk moving farther than the alert distance in a step.
!> After every step the beam and the disks are checked as in the uncoupled runs
!> (driver_guards): non-finite values, disks beyond the representable box, tunnelling.
module driver_run_coupled
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use core_strings, only: to_str
    use core_signals, only: caught_signal, signal_name
    use io_progress, only: progress_t
    use fem_beam_config, only: beam_config_t
    use fem_beam_model, only: beam_model_t
    use coupling_arlequin, only: coupled_system_t, coupled_energies_t, build_coupled_system, &
                                 arlequin_step, coupled_energies, coupled_beam
    use driver_config, only: run_config_t
    use driver_config_dem, only: dem_config_t
    use driver_config_coupling, only: coupled_setup_t
    use driver_results, only: results_writer_t
    use driver_results_dem, only: dem_writer_t
    use driver_results_coupled, only: coupled_writer_t, write_beam_overlap
    use driver_run_dem, only: max_warnings, report_line_iface, speed_warning, last_unconverged_warning
    use driver_guards, only: check_beam_state, check_disks_state, step_start_t, take_step_start, &
                             check_tunnelling
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint, only: end_of_step, checkpoint_run_t, loop_state_t, checkpoint_create, checkpoint_commit, &
                                 checkpoint_discard, save_coupled, load_coupled, save_results, load_results, &
                                 save_dem_writer, load_dem_writer, save_coupled_writer, load_coupled_writer
    implicit none
    private
    public :: build_coupled, run_coupled

contains

    !> Build the coupled system of a deck (weighted beam, weighted disks, coupling operator,
    !> factored multiplier matrix). Errors come from the coupling library, without a deck
    !> line (the caller attaches one).
    subroutine build_coupled(run, beam, dem, setup, sys, error)
        !> Run settings (time step, Newmark beta and gamma, initial beam state).
        type(run_config_t), intent(in) :: run
        !> The beam (unweighted).
        type(beam_config_t), intent(in) :: beam
        !> The particles (unweighted, before mj_init).
        type(dem_config_t), intent(in) :: dem
        !> The coupling.
        type(coupled_setup_t), intent(in) :: setup
        !> The coupled system.
        type(coupled_system_t), intent(out) :: sys
        !> Set when the library refuses the model.
        type(error_t), allocatable, intent(out) :: error
        if (allocated(run%u0) .and. allocated(run%v0)) then
            call build_coupled_system(setup%config, beam, dem%system, sys, error, &
                                      beta=run%beta, gamma=run%gamma, fe_u0=run%u0, fe_v0=run%v0)
        else
            call build_coupled_system(setup%config, beam, dem%system, sys, error, &
                                      beta=run%beta, gamma=run%gamma)
        end if
    end subroutine build_coupled

    !> Integrate the coupled model from t = 0 (or from a checkpoint) to the end time and write
    !> its results; write checkpoints as `ck` says, at the end and at a stop signal.
    subroutine run_coupled(run, beam, dem, sys, out, quiet, report, ck, error)
        !> Run settings (end time, output interval, progress).
        type(run_config_t), intent(in) :: run
        !> The beam (mesh for the results).
        type(beam_config_t), intent(in) :: beam
        !> The particles' deck data (material ids, contact storage).
        type(dem_config_t), intent(in) :: dem
        !> The coupled system (built; it advances).
        type(coupled_system_t), intent(inout) :: sys
        !> An open results writer.
        type(results_writer_t), intent(inout) :: out
        !> No progress lines (warnings and the summary are still reported).
        logical, intent(in) :: quiet
        !> Where progress, warning and summary lines go.
        procedure(report_line_iface) :: report
        !> Checkpoints (and the one to restart from).
        type(checkpoint_run_t), intent(inout) :: ck
        !> Set on a run or write failure.
        type(error_t), allocatable, intent(out) :: error
        type(dem_writer_t) :: dem_out
        type(coupled_writer_t) :: cpl_out
        type(progress_t) :: progress
        real(wp), allocatable :: d(:, :), v(:, :), a(:, :)
        type(step_start_t) :: start
        type(beam_model_t) :: model
        integer(i8) :: n_steps, k, k0
        integer :: unconverged
        logical :: speed_warned, stop
        character(len=512) :: buf

        n_steps = run%n_steps
        ! The weighted beam (constant), to expand the free DOFs to the nodes.
        model = coupled_beam(sys)
        allocate (d(3, model%n_nodes), v(3, model%n_nodes), a(3, model%n_nodes))
        unconverged = 0
        speed_warned = .false.
        k0 = 0
        if (ck%restart) then
            call restore(error)
            if (allocated(error)) return
        else
            call out%write_mesh(beam%node_id, beam%x, beam%y, beam%conn, error)
            if (allocated(error)) return
            call dem_out%begin(out%file, sys%dem, dem%material_id, dem%store_contacts, error)
            if (allocated(error)) return
            call cpl_out%begin(out%file, sys, error)
            if (allocated(error)) return
            call write_beam_overlap(out%file, sys, error)
            if (allocated(error)) return
            k = 0
            call check_step(error)
            if (allocated(error)) return
            call store(error)
            if (allocated(error)) return
        end if
        call progress%start(n_steps, run%t_end, run%progress_seconds)
        call ck%schedule%start()
        do k = k0 + 1, n_steps
            call take_step_start(start, sys%dem%particles, sys%dem%walls)
            call arlequin_step(sys, error)
            if (allocated(error)) return
            call check_step(error)
            if (allocated(error)) return
            call dem_out%record_step(out%file, sys%dem%stats, error)
            if (allocated(error)) return
            call cpl_out%record_step(out%file, sys, error)
            if (allocated(error)) return
            if (.not. sys%stats%converged) call warn_unconverged()
            if (.not. speed_warned) call check_speed()
            call end_of_step(k, n_steps, run%output_interval, ck%schedule, store, checkpoint, stop, error)
            if (allocated(error)) return
            if (stop) then
                ! Stop request: the step just done is the last output.
                call out%stop_at(signal_name(caught_signal()), k, sys%fe%t)
                n_steps = k
                exit
            end if
            if (quiet) cycle
            if (progress%due()) call report(progress%line(k, sys%fe%t))
        end do
        call dem_out%finish(out%file, sys%dem, unconverged, error)
        if (allocated(error)) return
        call cpl_out%finish(out%file, error)
        if (allocated(error)) return
        call summary()
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(n_steps), progress%elapsed(), error)

    contains

        !> Restart: state, writer counters and results file from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            call dem_out%resume(sys%dem, dem%store_contacts)
            call cpl_out%resume(sys)
            call load_coupled(ck%source, sys, error)
            if (.not. allocated(error)) call load_dem_writer(ck%source, dem_out, error)
            if (.not. allocated(error)) call load_coupled_writer(ck%source, cpl_out, error)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            k0 = ck%start%step
            unconverged = ck%start%unconverged
            speed_warned = ck%start%speed_warned
        end subroutine restore

        !> Write a checkpoint after step k (the buffered per-step values are written first).
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call dem_out%flush_buffer(out%file, error)
            if (.not. allocated(error)) call cpl_out%flush_buffer(out%file, error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, 'coupled', &
                                   loop_state_t(k, unconverged, speed_warned, .false.), sys%fe%t, &
                                   out%run_id, error)
            if (.not. allocated(error)) call save_coupled(f, sys, error)
            if (.not. allocated(error)) call save_dem_writer(f, dem_out, error)
            if (.not. allocated(error)) call save_coupled_writer(f, cpl_out, error)
            if (.not. allocated(error)) call save_results(f, out, error)
            if (allocated(error)) then
                call checkpoint_discard(f, ck%path)
                return
            end if
            call checkpoint_commit(f, ck%path, error)
            if (allocated(error)) return
            ck%last_step = k
            ck%last_time = sys%fe%t
        end subroutine checkpoint

        !> Guards after a step: finite beam and disk states, disks in the box, no tunnelling.
        subroutine check_step(error)
            type(error_t), allocatable, intent(out) :: error
            call model%expand(sys%fe%u, d)
            call model%expand(sys%fe%v, v)
            call model%expand(sys%fe%a, a)
            call check_beam_state(k, sys%fe%t, beam%node_id, d, v, a, [sys%fe%kinetic, sys%fe%strain, &
                                                                       sys%fe%external_work, sys%fe%damping_dissipation], error)
            if (allocated(error)) return
            call check_disks_state(k, sys%fe%t, sys%dem%particles, sys%dem%energies, error)
            if (allocated(error)) return
            if (k == 0) return
            call check_tunnelling(k, sys%fe%t, run%h, sys%dem%scheme%alert, start, sys%dem%particles, &
                                  sys%dem%walls, sys%dem%contacts, error)
        end subroutine check_step

        !> One stored output of the three parts.
        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            call model%expand(sys%fe%u, d)
            call model%expand(sys%fe%v, v)
            call model%expand(sys%fe%a, a)
            call out%append_state(sys%fe%t, d, v, a, error)
            if (allocated(error)) return
            call dem_out%store(out%file, sys%dem, error)
            if (allocated(error)) return
            call cpl_out%store(out%file, sys, error)
            if (allocated(error)) return
            call out%flush(error)
        end subroutine store

        !> Warning for an unconverged step (the first max_warnings ones).
        subroutine warn_unconverged()
            unconverged = unconverged + 1
            if (unconverged > max_warnings) return
            write (buf, '(a,i0,a,es12.4e3,a,i0,a,es10.2e3,a,es10.2e3,a)') 'warning: step ', k, &
                ' (t = ', sys%fe%t, ' s): the joint contact/multiplier solve did not '// &
                'converge in ', sys%stats%sweeps, ' sweeps (error ', sys%stats%nlgs_error, &
                ' > tolerance ', sys%dem%solver%tol, '); the constraint q = C u still holds'
            call report(trim(buf))
            if (unconverged == max_warnings) call report(last_unconverged_warning())
        end subroutine warn_unconverged

        !> Warning (once) when a disk moved farther than the alert distance in the step.
        subroutine check_speed()
            character(len=:), allocatable :: line
            line = speed_warning(sys%dem%particles, run%h, sys%dem%scheme%alert, sys%fe%t)
            if (len(line) == 0) return
            speed_warned = .true.
            call report(line)
        end subroutine check_speed

        !> Closing lines: model, residuals, solver effort, energy balance, times.
        subroutine summary()
            type(coupled_energies_t) :: en
            en = coupled_energies(sys)
            write (buf, '(a,i0,a,i0,a,i0,a,i0,a,es13.5e3,a)') 'coupled run: ', &
                model%n_nodes, ' beam nodes, ', sys%dem%particles%n, ' disks (', &
                sys%op%n_points, ' coupled), ', n_steps, ' steps to t = ', sys%fe%t, ' s'
            call report(trim(buf))
            if (sys%on_nodes) then
                ! Only the projection on the mediator space is imposed: the per-disk residual
                ! from the coordinates is free in the kernel of Pi.
                write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'constraint (multipliers on '// &
                    'the nodes): max |Pi (q - C u)| = ', cpl_out%max_position, &
                    ' m (per disk, from the coordinates ', cpl_out%max_coordinate, &
                    ' m), max velocity residual ', cpl_out%max_velocity, ' m/s'
            else
                write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'constraint: max |q - C u| = ', &
                    cpl_out%max_position, ' m (from the coordinates ', cpl_out%max_coordinate, &
                    ' m), max velocity residual ', cpl_out%max_velocity, ' m/s'
            end if
            call report(trim(buf))
            call report('unconverged steps: '//to_str(unconverged)//' of '//to_str(n_steps)// &
                        ' (tolerance '//to_str(sys%dem%solver%tol)//', at most '// &
                        to_str(sys%dem%solver%max_sweeps)//' sweeps)')
            write (buf, '(a,es11.3e3,a,es11.3e3,a,es11.3e3,a)') 'energy balance residual ', &
                en%balance, ' J (max over the outputs ', cpl_out%max_balance, &
                ' J; external work ', en%fe_external_work + en%dem_external_work + &
                en%dem_drive_work, ' J)'
            call report(trim(buf))
            call report(progress%summary_line(n_steps, sys%fe%t))
        end subroutine summary
    end subroutine run_coupled
end module driver_run_coupled
