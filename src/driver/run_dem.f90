!> Time integration of a discrete-element model (Moreau-Jean steps) with its results:
!> states, energies and contacts at the stored outputs, solver statistics at every step.
!>
!> Warnings go through the report callback: a step whose contact solve did not converge
!> (the first `max_warnings` ones, then only the count in the summary), once, a step in
!> which a disk moved farther than the alert distance (contacts may then be found late), and
!> once, then counted in the summary, a converged step whose contacts created energy
!> (driver_guards::creation_allowance; Newton's restitution, doc/theory.md 2.4), and once,
!> then counted in the summary, a step whose bonded block was given up, by its energy guard
!> or unconverged at its cap with a bond outside its cone, each reason on its own
!> (dem_bonded_block; doc/theory.md 7.10).
!> After every step the state is checked (driver_guards): a non-finite value, a disk beyond
!> the representable box, or a disk that passed through a wall or another disk stops the run
!> with an error.
module driver_run_dem
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: counted, to_str
    use core_signals, only: caught_signal, signal_name
    use io_progress, only: progress_t
    use dem_particles, only: particles_t
    use dem_moreau_jean, only: dem_system_t, mj_init, mj_step, energies_balance, mj_free_velocities, mj_detect, &
                               mj_solve, mj_end_step, mj_bonds_made
    use dem_local_problem, only: local_problem_t, local_problem_build
    use dem_nlgs, only: block_given_up_energy, block_given_up_unconverged, block_given_up_reverted
    use driver_config, only: run_config_t
    use driver_config_dem, only: dem_config_t
    use driver_results, only: results_writer_t
    use driver_results_dem, only: dem_writer_t, write_fclib_local
    use driver_guards, only: check_disks_state, largest_speed, check_walls_state, step_start_t, take_step_start, &
                             check_tunnelling, &
                             step_created_energy, step_creates_energy, energy_creation_warning, energy_creation_summary
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint, only: end_of_step, rest_of_last_step, step_end_t, checkpoint_run_t, loop_state_t, checkpoint_create, &
                                 save_dem, load_dem, save_results, load_results, save_dem_writer, load_dem_writer
    implicit none
    private
    public :: run_dem, max_warnings, report_line_iface, speed_warning, last_unconverged_warning
    public :: tolerance_floor_hint, recheck_capped_text
    public :: fclib_path, fclib_after_end_warning, fclib_no_contacts_warning, fclib_moment_note, lost_bonds_warning
    public :: bonds_line
    public :: block_given_up_warning, block_given_up_summary

    !> Unconverged steps reported one by one; later ones are only counted.
    integer, parameter :: max_warnings = 5

    abstract interface
        !> Receives one line of progress, warning or summary text.
        subroutine report_line_iface(line)
            character(len=*), intent(in) :: line
        end subroutine report_line_iface
    end interface

contains

    !> Integrate the model from t = 0 (or from a checkpoint) to the end time and write its
    !> results into `out`; write checkpoints as `ck` says, at the end and at a stop signal.
    subroutine run_dem(run, cfg, out, quiet, report, ck, error)
        !> Run settings (time step, end time, output interval, progress).
        type(run_config_t), intent(in) :: run
        !> The model (its system advances).
        type(dem_config_t), intent(inout) :: cfg
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
        type(dem_writer_t) :: writer
        type(progress_t) :: progress
        type(step_start_t) :: start
        integer(i8) :: n_steps, k, k0
        integer :: lost_warnings
        integer :: unconverged
        integer(i8) :: creating
        logical :: blocked_warned
        logical :: speed_warned
        ! largest speed of a disk at t = 0 [m/s] (the guards' likely causes)
        real(wp) :: initial_speed
        type(step_end_t) :: act
        character(len=:), allocatable :: message
        character(len=512) :: buf

        call mj_init(cfg%system, error)
        if (allocated(error)) then
            message = error%message
            call make_error(error, 'particles: '//message)
            return
        end if
        n_steps = run%n_steps
        unconverged = 0
        creating = 0
        lost_warnings = 0
        speed_warned = .false.
        blocked_warned = .false.
        k0 = 0
        ! the deck's initial state, before a restart replaces it (for the guards' causes)
        initial_speed = largest_speed(cfg%system%particles)
        if (ck%restart) then
            call restore(error)
            if (allocated(error)) return
        else
            call writer%begin(out%file, cfg%system, cfg%material_id, cfg%store_contacts, error)
            if (allocated(error)) return
            call check_disks_state(0_i8, cfg%system%time, cfg%system%particles, cfg%system%energies, initial_speed, &
                                   error)
            if (allocated(error)) return
            call store(error)
            if (allocated(error)) return
        end if
        ! An export the run never reaches would pass unnoticed (the deck's end or --end).
        if (cfg%fclib_step > n_steps) call report(fclib_after_end_warning(cfg%fclib_step, n_steps))
        call progress%start(n_steps, run%t_end, run%progress_seconds)
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
            call take_step_start(start, cfg%system%particles, cfg%system%walls, cfg%system%energies)
            if (k == cfg%fclib_step) then
                call step_with_export(error)
            else
                call mj_step(cfg%system)
            end if
            if (.not. allocated(error)) call check_step(error)
            if (allocated(error)) then
                ! the results file is as its last output left it: kept (driver_run)
                call out%fail_at(k, real(k, wp)*run%h)
                return
            end if
            call writer%record_step(out%file, cfg%system%stats, error)
            if (allocated(error)) return
            if (.not. cfg%system%stats%converged) call warn_unconverged()
            ! the first step whose bonded block was given up for each reason (the writer's counts
            ! survive a restart)
            select case (cfg%system%stats%block_given_up)
            case (block_given_up_energy)
                if (writer%n_block_given_up - writer%n_block_given_up_unconverged == 1) &
                    call report(block_given_up_warning(k, cfg%system%time, block_given_up_energy))
            case (block_given_up_unconverged)
                if (writer%n_block_given_up_unconverged == 1) &
                    call report(block_given_up_warning(k, cfg%system%time, block_given_up_unconverged))
            case (block_given_up_reverted)
                if (writer%n_block_given_up_reverted == 1) &
                    call report(block_given_up_warning(k, cfg%system%time, block_given_up_reverted))
            end select
            call check_created_energy()
            if (cfg%system%stats%n_blocked > 0 .and. .not. blocked_warned) then
                call report('warning: contacts between bodies that cannot move (fixed or imposed '// &
                            'velocities) are left out of the solve; count per step in /dem/solver/blocked')
                blocked_warned = .true.
            end if
            if (cfg%system%bonds_lost > 0) then
                lost_warnings = lost_warnings + 1
                if (lost_warnings <= max_warnings) call report(lost_bonds_warning(k, cfg%system%time, cfg%system%bonds_lost))
                if (lost_warnings == max_warnings) call report('warning: further lost bonds are only logged '// &
                                                               '(/dem/bonds, mode 5)')
            end if
            if (.not. speed_warned) call check_speed()
            act = end_of_step(k, n_steps, run%output_interval, ck%schedule)
            if (act%store_first) call store(error)
            if (act%checkpoint .and. .not. allocated(error)) call checkpoint(error)
            if (act%store_last .and. .not. allocated(error)) call store(error)
            if (allocated(error)) return
            if (act%stop) then
                ! Stop request: the step just done is the last output.
                call out%stop_at(signal_name(caught_signal()), k, cfg%system%time)
                n_steps = k
                exit
            end if
            if (quiet) cycle
            if (progress%due()) call report(progress%line(k, cfg%system%time))
        end do
        call writer%finish(out%file, cfg%system, unconverged, error)
        if (allocated(error)) return
        call summary()
        ! n_steps <= max_steps = huge(0) (driver_config)
        call out%write_summary(int(n_steps), progress, error)

    contains

        !> Restart: state, writer counters and results file from the checkpoint `ck%source`.
        subroutine restore(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            call writer%resume(cfg%system, cfg%store_contacts)
            call load_dem(ck%source, '/dem', cfg%system, ck%start%step, error)
            if (.not. allocated(error)) call load_dem_writer(ck%source, writer, error)
            if (.not. allocated(error)) call load_results(ck%source, out, error)
            call ck%source%close(ignored)
            if (allocated(error)) return
            k0 = ck%start%step
            unconverged = ck%start%unconverged
            creating = ck%start%creating
            speed_warned = ck%start%speed_warned
            blocked_warned = ck%start%blocked_warned
            ! an export before the checkpoint that a killed run left unrenamed
            if (cfg%fclib_step > 0 .and. cfg%fclib_step <= k0) call out%adopt(fclib_path(out%final_path, cfg%fclib_step))
        end subroutine restore

        !> Write a checkpoint after step k (the buffered statistics are written first).
        subroutine checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(h5_file_t) :: f
            call writer%flush_buffer(out%file, error)
            if (allocated(error)) return
            call checkpoint_create(f, ck%path, ck%deck_text, 'particles', &
                                   loop_state_t(k, unconverged, speed_warned, blocked_warned, creating=creating, &
                                                wall_seconds=progress%analysis_seconds(), runs=progress%runs), &
                                   cfg%system%time, out%run_id, error)
            if (.not. allocated(error)) call save_dem(f, '/dem', cfg%system, error)
            if (.not. allocated(error)) call save_dem_writer(f, writer, error)
            if (.not. allocated(error)) call save_results(f, out, error)
            call ck%finish(f, k, cfg%system%time, error)
        end subroutine checkpoint

        !> One step (as mj_step) that writes its local contact problem in FCLIB's format to
        !> <results without .h5>_fclib_<step>.h5.
        subroutine step_with_export(error)
            type(error_t), allocatable, intent(out) :: error
            type(local_problem_t) :: lp
            real(wp), allocatable :: vfree(:, :)
            character(len=:), allocatable :: path
            associate (sys => cfg%system)
                call mj_free_velocities(sys)
                call mj_detect(sys)
                allocate (vfree, source=sys%vel)
                call mj_solve(sys)
                call local_problem_build(sys%contacts, sys%im, vfree, lp)
                if (lp%n == 0) then
                    ! FCLIB's reader refuses a problem without contacts
                    call report(fclib_no_contacts_warning(sys%step + 1))
                else
                    call out%companion(fclib_path(out%final_path, sys%step + 1), path)
                    call write_fclib_local(path, run%title, lp, sys%step + 1, sys%time + sys%scheme%h, &
                                           sys%stats%siconos_error, error)
                    if (allocated(error)) return
                    if (lp%dim == 3) call report(fclib_moment_note(fclib_path(out%final_path, sys%step + 1)))
                end if
                call mj_end_step(sys)
            end associate
        end subroutine step_with_export

        !> Guards after a step: finite state in the box, no tunnelling.
        subroutine check_step(error)
            type(error_t), allocatable, intent(out) :: error
            associate (sys => cfg%system)
                call check_disks_state(k, sys%time, sys%particles, sys%energies, initial_speed, error)
                if (allocated(error)) return
                call check_walls_state(k, sys%time, sys%particles, sys%walls, error)
                if (allocated(error)) return
                call check_tunnelling(k, sys%time, run%h, sys%scheme%alert, start, sys%particles, &
                                      sys%walls, sys%contacts, error, sys%energies%contact_dissipation)
            end associate
        end subroutine check_step

        !> One stored output, flushed to the file.
        subroutine store(error)
            type(error_t), allocatable, intent(out) :: error
            call writer%store(out%file, cfg%system, error)
            if (allocated(error)) return
            call out%flush_output(error)
        end subroutine store

        !> Warning for an unconverged step (the first max_warnings ones).
        subroutine warn_unconverged()
            unconverged = unconverged + 1
            if (unconverged > max_warnings) return
            if (cfg%system%stats%recheck_left > 0) then
                write (buf, '(a,i0,a,es12.4e3,a)') 'warning: step ', k, ' (t = ', cfg%system%time, ' s): '
                call report(trim(buf)//' '//recheck_capped_text(cfg%system%stats%recheck_left, cfg%system%stats%solves))
            else
                write (buf, '(a,i0,a,es12.4e3,a,i0,a,es10.2e3,a,es10.2e3,a)') 'warning: step ', k, &
                    ' (t = ', cfg%system%time, ' s): the contact solver did not converge in ', &
                    cfg%system%stats%sweeps, ' sweeps (error ', cfg%system%stats%error, &
                    ' > tolerance ', cfg%system%solver%tol, ')'
                call report(trim(buf)//tolerance_floor_hint(cfg%system%stats%siconos_floor, cfg%system%solver%tol)// &
                            stall_hint(cfg%system%stats%stalled))
            end if
            if (unconverged == max_warnings) call report(last_unconverged_warning())
        end subroutine warn_unconverged

        !> Warning (once, then counted) when a converged step created energy beyond
        !> driver_guards::creation_allowance (an unconverged one has its own warning).
        subroutine check_created_energy()
            associate (sys => cfg%system)
                if (.not. sys%stats%converged) return
                if (.not. step_creates_energy(start, sys)) return
                creating = creating + 1
                if (creating > 1) return
                call report(energy_creation_warning(k, sys%time, step_created_energy(start, sys%energies), &
                                                    start%kinetic, sys%energies%kinetic, &
                                                    maxval(sys%materials%restitution), unconverged))
            end associate
        end subroutine check_created_energy

        !> Warning (once) when a disk moved farther than the alert distance in the step.
        subroutine check_speed()
            character(len=:), allocatable :: line
            line = speed_warning(cfg%system%particles, run%h, cfg%system%scheme%alert, cfg%system%time)
            if (len(line) == 0) return
            speed_warned = .true.
            call report(line)
        end subroutine check_speed

        !> Closing lines: contacts, solver effort, unconverged steps, energy balance, times.
        subroutine summary()
            associate (sys => cfg%system)
                write (buf, '(es13.5e3)') sys%time
                call report('particles: '//counted(sys%particles%n, 'disk')//', '//counted(sys%walls%n, 'wall')// &
                            ', '//counted(n_steps, 'step')//' to t = '//trim(buf)//' s')
                write (buf, '(a,i0,a,i0,a,es11.3e3,a,es11.3e3,a)') 'contacts at the end: ', &
                    sys%contacts%n, ' (', sys%stats%n_active, ' active); time in detection ', &
                    sys%time_detection, ' s, in the solver ', sys%time_solver, ' s'
                call report(trim(buf))
                if (any(sys%materials%cohesion > 0.0_wp)) call report(bonds_line(sys))
                call report('unconverged steps: '//to_str(unconverged)//' of '//to_str(n_steps)// &
                            ' (tolerance '//to_str(sys%solver%tol)//', at most '// &
                            to_str(sys%solver%max_sweeps)//' sweeps)')
                write (buf, '(a,es11.3e3,a,es11.3e3,a)') 'energy balance residual ', &
                    energies_balance(sys%energies), ' J/m (dissipated in contacts ', &
                    sys%energies%contact_dissipation, ' J/m)'
                call report(trim(buf))
                if (creating > 0) call report(energy_creation_summary(creating, n_steps))
                if (writer%n_block_given_up > writer%n_block_given_up_unconverged) &
                    call report(block_given_up_summary(writer%n_block_given_up - writer%n_block_given_up_unconverged, &
                                                       n_steps, block_given_up_energy))
                if (writer%n_block_given_up_unconverged > 0) &
                    call report(block_given_up_summary(writer%n_block_given_up_unconverged, n_steps, &
                                                       block_given_up_unconverged))
                if (writer%n_block_given_up_reverted > 0) &
                    call report(block_given_up_summary(writer%n_block_given_up_reverted, n_steps, &
                                                       block_given_up_reverted))
            end associate
            call report(progress%summary_line(n_steps, cfg%system%time, out%stopped()))
        end subroutine summary
    end subroutine run_dem
    !> Summary line of the bonds of a run with cohesion: 'bonds at t = 0: N (M ruptures since,
    !> /dem/bonds)', the ruptures counting the bonds broken and those the detection lost.
    function bonds_line(sys) result(line)
        !> The system, after its steps.
        type(dem_system_t), intent(in) :: sys
        character(len=:), allocatable :: line
        line = 'bonds at t = 0: '//to_str(mj_bonds_made(sys))//' ('//counted(sys%ruptures%n, 'rupture')// &
               ' since, /dem/bonds)'
    end function bonds_line

    !> Warning text when the fastest disk moves farther than the alert distance in one step
    !> ('' when it does not): contacts could then be found late.
    function speed_warning(p, h, alert, t) result(line)
        !> The disks.
        type(particles_t), intent(in) :: p
        !> Time step [s].
        real(wp), intent(in) :: h
        !> Alert distance [m].
        real(wp), intent(in) :: alert
        !> Current time [s].
        real(wp), intent(in) :: t
        character(len=:), allocatable :: line
        character(len=240) :: buf
        real(wp) :: vmax
        line = ''
        if (p%n == 0) return
        vmax = sqrt(maxval(p%vx(1:p%n)**2 + p%vy(1:p%n)**2))
        if (vmax*h <= alert) return
        write (buf, '(a,es12.4e3,a,es10.2e3,a,es10.2e3,a,es10.2e3,a)') 'warning: at t = ', t, &
            ' s a disk moves ', vmax*h, ' m in one step (speed ', vmax, &
            ' m/s), more than the alert distance ', alert, &
            ' m: contacts may be found late (overlaps); lower [time] step or raise [contacts] alert'
        line = trim(buf)
    end function speed_warning

    !> Warning for intact bonds that the detection of step k lost (dem_moreau_jean,
    !> log_lost_bonds): rare, each bond once, so said at every such step.
    function lost_bonds_warning(k, t, n) result(line)
        !> Step.
        integer(i8), intent(in) :: k
        !> Time at its end [s].
        real(wp), intent(in) :: t
        !> Bonds lost.
        integer, intent(in) :: n
        character(len=:), allocatable :: line
        character(len=16) :: tbuf
        write (tbuf, '(es11.4e2)') t
        line = 'warning: step '//to_str(k)//' (t = '//trim(adjustl(tbuf))//' s): '//to_str(n)// &
               ' intact bond(s) lost: their disks drifted apart beyond the alert distance ([contacts] '// &
               'alert), which a bond holding the velocity allows under spin; logged in /dem/bonds with mode 5 '// &
               '(lost); a larger alert distance or a shorter step keeps them'
    end function lost_bonds_warning

    !> Warning for the first step whose bonded block ([solver] method = block) was given up for
    !> a reason (dem_bonded_block, doc/theory.md 7.10): what happened, why, and what the
    !> settings measured on the decks of theory.md 7.10 did.
    function block_given_up_warning(k, t, reason) result(line)
        !> Step.
        integer(i8), intent(in) :: k
        !> Time at its end [s].
        real(wp), intent(in) :: t
        !> Why (nlgs_stats_t%block_given_up): block_given_up_energy, block_given_up_unconverged or
        !> block_given_up_reverted.
        integer, intent(in) :: reason
        character(len=:), allocatable :: line
        character(len=16) :: tbuf
        write (tbuf, '(es11.4e2)') t
        line = 'warning: step '//to_str(k)//' (t = '//trim(adjustl(tbuf))//' s): the bonded block ([solver] '// &
               'method = block) was given up '
        if (reason == block_given_up_reverted) then
            line = line//'unconverged at its cap, a bond of the block outside its cone, but the plain sweeps that '// &
                   'solved the step again ended unconverged too with a larger error: the step ends on the block''s '// &
                   'answer, unconverged, its bonds held (a slow convergence, not a step without solution, doc/'// &
                   'theory.md 7.10). Further such steps are only counted (total in the summary, per step in '// &
                   '/dem/solver/block_given_up as 3). A [solver] max_sweeps large enough for the block to converge '// &
                   'avoids it'
        else if (reason == block_given_up_unconverged) then
            line = line//'unconverged at its cap: the step ran out of its max_sweeps block iterations with a bond '// &
                   'of the block outside its cone, which the block cannot hold and which no pass released (a body '// &
                   'pushed into bonded disks held by their bonds: with the bonds held the step may have no '// &
                   'solution, doc/theory.md 7.10); the step was solved again by plain sweeps from zero reactions, '// &
                   'whose bonds break by their own law. Further such steps are only counted (total in the summary, '// &
                   'per step in /dem/solver/block_given_up as 2). Each costs max_sweeps block iterations before the '// &
                   'sweeps: [solver] method = nlgs spares them'
        else
            line = line//'by its energy guard: a pass created more than 0.1 of the kinetic energy, its reactions '// &
                   'carrying self-stresses of the loops of the bonded lattice, which the convergence norm does not '// &
                   'bound and which released bonds set free (doc/theory.md 7.10); the step was solved again by '// &
                   'plain sweeps from zero reactions. Further such steps are only counted (total in the summary, '// &
                   'per step in /dem/solver/block_given_up as 1). A [solver] max_sweeps large enough for every step '// &
                   'to converge avoids it (100000 on the lattice of theory.md 7.10, where 1000 did not); criterion '// &
                   '= siconos, anderson = 0 or tolerance = 1e-5 kept the block there but left its steps unconverged'
        end if
    end function block_given_up_warning

    !> Summary line of the steps whose bonded block was given up for a reason.
    function block_given_up_summary(n, n_steps, reason) result(line)
        !> Steps given up for that reason.
        integer, intent(in) :: n
        !> Steps of the run.
        integer(i8), intent(in) :: n_steps
        !> Why (nlgs_stats_t%block_given_up): block_given_up_energy, block_given_up_unconverged or
        !> block_given_up_reverted.
        integer, intent(in) :: reason
        character(len=:), allocatable :: line
        if (reason == block_given_up_reverted) then
            line = 'bonded block given up at max_sweeps and taken back (the plain sweeps ended with a larger error; '// &
                   'the block''s answer kept, unconverged): '//to_str(n)//' of '//to_str(n_steps)// &
                   ' steps (/dem/solver/block_given_up = 3)'
        else if (reason == block_given_up_unconverged) then
            line = 'bonded block given up (unconverged at max_sweeps, a bond outside its cone; solved by plain '// &
                   'sweeps): '//to_str(n)//' of '//to_str(n_steps)//' steps (/dem/solver/block_given_up = 2)'
        else
            line = 'bonded block given up (energy guard, solved by plain sweeps): '//to_str(n)//' of '// &
                   to_str(n_steps)//' steps (/dem/solver/block_given_up = 1)'
        end if
    end function block_given_up_summary

    !> Text added to an unconverged step's warning when the tolerance is more than ten times
    !> below the estimated round-off floor of the Siconos error (nlgs_stats_t%siconos_floor; 0
    !> when not estimated): '' otherwise. The estimate is a worst case, 4 to 10 times the level
    !> the sweeps reach (`test_nlgs`), so a tolerance below a tenth of it is out of reach: each
    !> step then runs to max_sweeps.
    function tolerance_floor_hint(floor, tol) result(text)
        !> Estimated floor of the error at the step's end.
        real(wp), intent(in) :: floor
        !> The tolerance of [solver].
        real(wp), intent(in) :: tol
        character(len=:), allocatable :: text
        character(len=16) :: fbuf
        text = ''
        if (.not. tol < 0.1_wp*floor) return
        write (fbuf, '(es10.2e3)') floor
        text = '; the tolerance is more than ten times below the round-off floor of the Siconos error at this '// &
               'state (estimated '//trim(adjustl(fbuf))//'; u = W r + q cancels terms far larger than u): '// &
               'no number of sweeps reaches it, raise [solver] tolerance'
    end function tolerance_floor_hint

    !> Text appended to an unconverged step's warning when its last pass stalled (the bonded
    !> block's, nlgs_stats_t%stalled): with its bonds held the problem had no solution, and
    !> the iterations ran out before the step was solved again with the bond released.
    pure function stall_hint(stalled) result(text)
        !> The step's last pass stalled.
        logical, intent(in) :: stalled
        character(len=:), allocatable :: text
        text = ''
        if (.not. stalled) return
        text = '; with its intact bonds held the step had no solution (a bond must yield, doc/theory.md 7.10) '// &
               'and no iteration was left to solve it again with the bond released: raise [solver] max_sweeps'
    end function stall_hint

    !> Why a step whose solves met their cap (dem_moreau_jean::mj_max_solves) is not converged:
    !> the impulses of its last solve still shut contacts left out of it.
    pure function recheck_capped_text(left, solves) result(text)
        !> Contacts still shut, left out (nlgs_stats_t%recheck_left).
        integer, intent(in) :: left
        !> Solves of the step (nlgs_stats_t%solves).
        integer, intent(in) :: solves
        character(len=:), allocatable :: text
        text = 'the contact solve did not converge: after '//counted(solves, 'solve')//' the contact impulses '// &
               'still shut '//counted(left, 'contact')//' left out of the solve (each solve lets in those the one '// &
               'before shut, doc/theory.md 2.4), which may overlap; lower [time] step or raise [solver] max_sweeps'
    end function recheck_capped_text

    !> Line closing the series of per-step warnings about unconverged steps.
    pure function last_unconverged_warning() result(line)
        character(len=:), allocatable :: line
        line = 'warning: further unconverged steps are only counted (total in the summary); '// &
               'raise [solver] max_sweeps or the tolerance, or lower [time] step'
    end function last_unconverged_warning

    !> File of the FCLIB export of step `step`: the results file without '.h5', then
    !> '_fclib_<step>.h5'.
    function fclib_path(results_path, step) result(path)
        !> Final path of the results file.
        character(len=*), intent(in) :: results_path
        !> The step exported.
        integer, intent(in) :: step
        character(len=:), allocatable :: path
        path = results_path
        if (len(path) > 3) then
            if (path(len(path) - 2:) == '.h5') path = path(:len(path) - 3)
        end if
        path = path//'_fclib_'//to_str(step)//'.h5'
    end function fclib_path

    !> Warning for an FCLIB export after the last step (it would pass unnoticed).
    function fclib_after_end_warning(step, n_steps) result(line)
        !> `[solver] fclib_step`.
        integer, intent(in) :: step
        !> Steps of the run.
        integer(i8), intent(in) :: n_steps
        character(len=:), allocatable :: line
        line = 'warning: [solver] fclib_step = '//to_str(step)//' is after the last step of the run ('// &
               to_str(n_steps)//'): no FCLIB problem written'
    end function fclib_after_end_warning

    !> Warning for an FCLIB export of a step without active contacts: FCLIB's reader
    !> (fclib_read_local) refuses a problem without contacts, so none is written.
    function fclib_no_contacts_warning(step) result(line)
        !> `[solver] fclib_step`.
        integer, intent(in) :: step
        character(len=:), allocatable :: line
        line = 'warning: [solver] fclib_step = '//to_str(step)//': the step has no active contact, '// &
               'no FCLIB problem written (FCLIB refuses a problem without contacts)'
    end function fclib_no_contacts_warning

    !> Note for an FCLIB export with a moment per contact (spacedim = 3): FCLIB's 3D problem is
    !> another one (a second tangent and a circular cone), so a 3D Coulomb solver must not read it.
    function fclib_moment_note(path) result(line)
        !> The file written (its final name).
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: line
        line = "note: '"//path//"' has spacedim = 3: the third component of each contact is its moment, with "// &
               "MULTICOR's cone (doc/theory.md 7.3), not a second tangent: a 3D Coulomb solver of FCLIB would "// &
               'solve another problem'
    end function fclib_moment_note
end module driver_run_dem
