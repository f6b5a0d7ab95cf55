!> Runs one deck: read and validate, build the model, run the analysis, write the results.
!>
!> Dispatch: `driver_simulations` picks the kind of run from the deck's sections (beam,
!> particles, coupled, ...), an extension of `simulation_t` (driver_simulation), which builds
!> the model (`init`), describes it (`describe`) and runs it (`run`).
!>
!> Everything that can fail because of the input is checked before the results folder is
!> touched; the HDF5 file is written as '<name>.h5.partial' and renamed only on success, so
!> earlier results stay intact when a run fails, and a results folder the failed run created
!> is removed again when it is left empty.
!>
!> Guards (driver_guards): before anything is built, the model's memory estimate is checked
!> against the available memory; disks and walls must lie in the box the detection can
!> represent; after every time step the state must be finite (and, for particles, no disk
!> may tunnel through a wall or another disk). One run at a time writes a results folder: a
!> lock file (io_lock) is held while writing and removed on every way out.
!>
!> Every run that ends normally also gets `<name>.xdmf` (driver_results_xdmf), written beside
!> the open results file and renamed into place once the HDF5 file has its final name.
!>
!> Checkpoints (driver_checkpoint): the time loops of every kind of run (beam, particles,
!> beam-particle coupled, continuum, continuum-particle coupled) write
!> '<results folder>/checkpoint.h5' as the deck's [output] checkpoint_interval /
!> checkpoint_seconds say, at a stop signal and at the end; `--restart` continues a run from
!> one (same deck, same code version), into the same results file, with the option of a new
!> end time (`--end`).
module driver_run
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_input_error
    use core_strings, only: string_t, to_str, num => sci_text
    use io_lock, only: lock_t, lock_acquire, lock_release
    use io_memory, only: available_memory
    use io_progress, only: progress_t
    use core_signals, only: caught_signal, signal_name, install_signal_handlers
    use core_threads, only: thread_setting
    use io_deck_schema, only: multicor_schema
    use io_deck, only: deck_t, deck_entry_t, read_deck
    use io_paths, only: stem, basename, mkdir_p, remove_empty_folders, file_exists, remove_file, rename_file
    use driver_results, only: results_writer_t
    use driver_results_xdmf, only: write_results_xdmf
    use driver_guards, only: model_size_t, model_memory_bytes, check_memory
    use fem_mesh_generator, only: rectangle_size, check_rectangle_size
    use fem_element_registry, only: element_slot_t, new_element, kind_of_name
    use driver_simulation, only: simulation_t, report_iface
    use driver_simulations, only: select_simulation
    use driver_config, only: steps_to_end, max_steps
    use driver_run_dem, only: fclib_after_end_warning
    use driver_checkpoint, only: checkpoint_run_t, checkpoint_name, checkpoint_open, checkpoint_owner, deck_hash
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
        !> Checkpoint to continue from (unallocated: start at t = 0).
        character(len=:), allocatable :: restart
        !> End time replacing the deck's [time] end [s] (negative: the deck's).
        real(wp) :: end_time = -1.0_wp
    end type run_options_t

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
        class(simulation_t), allocatable :: sim
        type(results_writer_t) :: out
        type(lock_t) :: lock
        type(checkpoint_run_t) :: ck
        character(len=:), allocatable :: dir, created, path, warning, kind, run_id
        character(len=32) :: tbuf
        ! Wall time of a static or modal analysis, from the model's build (`init`: assembly,
        ! factorisations, and for some kinds the solve) to its results written.
        type(progress_t) :: clock

        if (present(stopped_by)) stopped_by = 0
        call read_deck(opts%deck_path, multicor_schema(), deck, error)
        if (allocated(error)) return
        call select_simulation(deck, sim, error)
        if (allocated(error)) return
        call check_model_size(deck, error)
        if (allocated(error)) return
        call clock%start(0_i8, 0.0_wp, 0.0_wp)
        call sim%init(deck, report, error)
        if (allocated(error)) return
        kind = sim%checkpoint_kind()
        call apply_end_time(error)
        if (allocated(error)) return
        call warn_keywords_without_effect()
        call warn_aliased_functions()
        call warn_end_off_the_steps()
        if (opts%check_only) then
            ! (the run itself warns when its loop starts)
            call warn_fclib_after_end()
            call report(opts%deck_path//': deck is valid ('//sim%describe()//')')
            return
        end if

        dir = 'results/'//stem(opts%deck_path)
        if (allocated(opts%output_dir)) dir = opts%output_dir
        call mkdir_p(dir, error, created)
        if (allocated(error)) return
        call write_into_folder(error)
        ! A failed run leaves no folder of its own making behind empty (what it holds stays).
        if (allocated(error)) call remove_empty_folders(dir, created)

    contains

        !> Lock the results folder `dir` (it exists), run and write the results, report them.
        subroutine write_into_folder(error)
            type(error_t), allocatable, intent(out) :: error
            path = dir//'/'//stem(opts%deck_path)//'.h5'
            call lock_acquire(lock, dir, warning, error)
            if (allocated(error)) return
            if (len(warning) > 0) call report(warning)
            ck%path = dir//'/'//checkpoint_name
            ! The deck and the files it reads (a mesh): a restart must find them unchanged.
            ck%deck_text = deck%text//sim%inputs_text()
            ck%schedule%every = sim%settings%checkpoint_interval
            ck%schedule%seconds = sim%settings%checkpoint_seconds
            ck%results = basename(path)
            if (allocated(opts%restart)) then
                call open_checkpoint(error)
            else
                call guard_other_run(error)
            end if
            ! Until here a signal kills the program at once (nothing is written yet).
            if (.not. allocated(error)) call install_signal_handlers(error)
            if (.not. allocated(error)) call write_results(error)
            call lock_release(lock)
            if (allocated(error)) return
            call report('results written to '//path)
            if (ck%last_step >= 0) call report('checkpoint: '//to_str(ck%last_step)//' steps, t = '// &
                                               num(ck%last_time)//' s, in '//ck%path//' (to go on to a later '// &
                                               'end time: '//continue_command(.false.)//' --end T)')
        end subroutine write_into_folder

        !> Run the analysis into '<path>.partial', renamed to `path` on success (the caller
        !> holds the folder's lock). A failed run leaves the folder's results, partial file and
        !> checkpoint as it found them (a resumed partial file keeps the outputs after its
        !> checkpoint, which the next restart cuts); a run that ends or is stopped by a signal
        !> leaves its own.
        subroutine write_results(error)
            type(error_t), allocatable, intent(out) :: error
            logical :: kept
            call run_and_close(error, kept)
            if (kept) then
                call ck%settle()
            else
                call ck%revert()
            end if
        end subroutine write_results

        !> Open or resume the results file, run, and close the file (finished or stopped; the
        !> writer cleans up after its own failures).
        subroutine run_and_close(error, kept)
            type(error_t), allocatable, intent(out) :: error
            !> Whether the run ended or was stopped cleanly: its files are the folder's now.
            logical, intent(out) :: kept
            type(error_t), allocatable :: ignored, xdmf_error
            character(len=:), allocatable :: xdmf
            kept = .false.
            xdmf = path(1:len(path) - 3)//'.xdmf'
            if (ck%restart) then
                call out%resume(path, run_id, error)
                if (allocated(error)) call ck%source%close(ignored)
            else
                call out%open(path, opts%deck_path, deck%text, sim_title(), sim_analysis(), error)
            end if
            if (allocated(error)) return
            call sim%run(out, opts%quiet, report, ck, error)
            ! A time loop writes /summary itself; a static or modal analysis has no steps,
            ! and its wall time is that of `clock`.
            if (.not. allocated(error) .and. .not. sim%has_time_loop()) call out%write_summary(0, clock, error)
            if (allocated(error)) then
                call out%abort()
                error%message = deck%file//': '//error%message
                return
            end if
            if (out%stopped()) then
                call out%close_unfinished(error)
                if (allocated(error)) return
                kept = .true.
                if (present(stopped_by)) stopped_by = caught_signal()
                write (tbuf, '(es16.8e3)') out%stop_time
                call report('stopped: '//out%stop_reason)
                call report('saved: every output up to t = '//trim(adjustl(tbuf))//' s (the last one '// &
                            'at the stop) in '//out%partial_path//' (/summary finished = 0)')
                if (file_exists(path)) call report('the earlier result '//path//' is left as it was')
                if (ck%last_step >= 0) then
                    call report('checkpoint: '//to_str(ck%last_step)//' steps, t = '//num(ck%last_time)// &
                                ' s, in '//ck%path)
                    call report('to continue: '//continue_command(.true.))
                else
                    call report('to continue: run the deck again (no checkpoint was written)')
                end if
                call make_error(error, deck%file//': run stopped by '//signal_name(caught_signal())// &
                                '; results so far in '//out%partial_path)
                return
            end if
            ! The XDMF file of the complete run, written beside the partial file and renamed
            ! once the results file has its final name: a failed run leaves an earlier result's
            ! XDMF file as it was, and a stopped run writes none (the earlier one still
            ! describes the earlier result, which is left as it was).
            ! ParaView's XDMF 2 reader splits a reference 'file.h5:/dataset' at the first colon
            if (index(basename(path), ':') > 0) call report('warning: the name '//basename(path)// &
                                                            ' contains a colon, which ParaView''s XDMF reader '// &
                                                            'cannot open; rename the deck to view '// &
                                                            basename(xdmf)//' in ParaView')
            call write_results_xdmf(out%file, xdmf//'.partial', basename(path), error)
            if (allocated(error)) then
                call out%abort()
                call remove_file(xdmf//'.partial')
                error%message = deck%file//': '//error%message
                return
            end if
            call out%close(error)
            kept = .not. allocated(error)
            if (.not. kept) then
                call remove_file(xdmf//'.partial')
                return
            end if
            call rename_file(xdmf//'.partial', xdmf, xdmf_error)
            if (allocated(xdmf_error)) call report('warning: '//xdmf_error%message)
        end subroutine run_and_close

        !> The command that continues this run from its checkpoint; with `same_end`, to the end
        !> time this run was given: `--end T` again when the run had one (17 significant
        !> digits: read back as the same double, the same step count), else the deck's end.
        function continue_command(same_end) result(command)
            !> Whether to repeat this run's `--end` (else the caller appends its own).
            logical, intent(in) :: same_end
            character(len=:), allocatable :: command
            character(len=32) :: end_text
            command = 'multicor '//shell_word(opts%deck_path)
            if (allocated(opts%output_dir)) command = command//' --output '//shell_word(opts%output_dir)
            command = command//' --restart '//shell_word(ck%path)
            if (same_end .and. opts%end_time >= 0.0_wp) then
                write (end_text, '(es25.17e3)') opts%end_time
                command = command//' --end '//trim(adjustl(end_text))
            end if
        end function continue_command

        !> A path as one word of a POSIX shell command, so that the printed command can be
        !> pasted: as it is when it holds only safe characters, else in single quotes (a quote
        !> inside written '\'').
        function shell_word(path) result(word)
            character(len=*), intent(in) :: path
            character(len=:), allocatable :: word
            character(len=*), parameter :: safe = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789'// &
                                           '_-./+=:,@%'
            integer :: i
            if (len(path) > 0 .and. verify(path, safe) == 0) then
                word = path
                return
            end if
            word = "'"
            do i = 1, len(path)
                if (path(i:i) == "'") then
                    word = word//"'\''"
                else
                    word = word//path(i:i)
                end if
            end do
            word = word//"'"
        end function shell_word

        !> Settings given in the deck that another setting or the kind of run turns off (the
        !> deck is valid: a tuning value left in place while it is off).
        subroutine warn_keywords_without_effect()
            type(string_t), allocatable :: warnings(:)
            integer :: i
            warnings = [deck%ineffective(), sim%deck_warnings(deck)]
            do i = 1, size(warnings)
                call report(warnings(i)%s)
            end do
        end subroutine warn_keywords_without_effect

        !> Warn about a harmonic function faster than half the sampling rate of the time step:
        !> the run sees it at fewer than two steps per period, i.e. an alias of another
        !> frequency. Allowed (the deck may mean it), said once per function.
        subroutine warn_aliased_functions()
            type(deck_entry_t), allocatable :: list(:)
            real(wp) :: nyquist
            integer :: i
            if (sim%settings%analysis /= 'dynamic' .or. .not. sim%settings%h > 0.0_wp) return
            nyquist = 0.5_wp/sim%settings%h
            allocate (list, source=deck%records('functions', 'function'))
            do i = 1, size(list)
                if (list(i)%word('kind') /= 'harmonic') cycle
                if (.not. list(i)%real('freq') > nyquist) cycle
                call report('warning: '//deck%file//':'//to_str(list(i)%line)//': harmonic function '// &
                            to_str(list(i)%int('id'))//' at '//to_str(list(i)%real('freq'))// &
                            ' Hz is above 1/(2 h) = '//to_str(nyquist)//' Hz of [time] step: the run '// &
                            'samples it below two steps per period and sees an alias; lower the step')
            end do
        end subroutine warn_aliased_functions

        !> Warn when the end time (the deck's, or --end) is not a whole number of time steps: the
        !> run goes on to the next step, past the end asked for.
        subroutine warn_end_off_the_steps()
            real(wp) :: t_last
            character(len=24) :: buf
            if (sim%settings%analysis /= 'dynamic' .or. .not. sim%settings%h > 0.0_wp) return
            associate (run => sim%settings)
                t_last = real(run%n_steps, wp)*run%h
                ! a whole number of steps up to the rounding of end / step (steps_to_end)
                if (abs(t_last - run%t_end) <= 1.0e-9_wp*run%t_end) return
                if (opts%end_time >= 0.0_wp) then
                    write (buf, '(es17.10e3)') run%t_end
                    call report('warning: --end '//trim(adjustl(buf))//' s is not a whole number of time '// &
                                'steps of '//num(run%h)//' s: the run ends after '//to_str(run%n_steps)// &
                                ' steps, at t = '//num(t_last)//' s')
                else
                    call report('warning: '//deck%file//':'//to_str(deck%line('time', 'end'))//': [time] end = '// &
                                deck%get_word('time', 'end')//' s is not a whole number of time steps of '// &
                                deck%get_word('time', 'step')//' s: the run ends after '//to_str(run%n_steps)// &
                                ' steps, at t = '//num(t_last)//' s')
                end if
            end associate
        end subroutine warn_end_off_the_steps

        !> Warn of `[solver] fclib_step` after the last step (end / step, or --end) at --check,
        !> as the run does when it starts.
        subroutine warn_fclib_after_end()
            integer :: step
            if (sim%settings%analysis /= 'dynamic' .or. .not. deck%has('solver', 'fclib_step')) return
            step = deck%get_int('solver', 'fclib_step')
            if (step > sim%settings%n_steps) call report(fclib_after_end_warning(step, sim%settings%n_steps))
        end subroutine warn_fclib_after_end

        !> Option `--end`: a new end time (the models built by `init` do not depend on it, the step
        !> count does).
        subroutine apply_end_time(error)
            type(error_t), allocatable, intent(out) :: error
            real(wp) :: steps
            if (opts%end_time < 0.0_wp) return
            if (.not. sim%has_time_loop()) then
                call make_error(error, '--end: '//deck%file//' is not a dynamic analysis (static and modal '// &
                                'analyses have no time steps to continue)')
                return
            end if
            associate (run => sim%settings)
                if (.not. (opts%end_time >= run%h)) then
                    call make_error(error, '--end '//num(opts%end_time)//' s: shorter than the time step '// &
                                    num(run%h)//' s')
                    return
                end if
                steps = steps_to_end(opts%end_time, run%h)
                if (steps > real(max_steps, wp)) then
                    call make_error(error, '--end '//num(opts%end_time)//' s with step '//num(run%h)// &
                                    ' s needs more time steps than a run can count ('//to_str(max_steps)//')')
                    return
                end if
                run%t_end = opts%end_time
                run%n_steps = max(int(steps, i8), 1_i8)
            end associate
        end subroutine apply_end_time

        !> A fresh run replaces the folder's checkpoint (at its first commit). When that
        !> checkpoint is another deck's and its run is interrupted (its results file still
        !> '.partial'), the interrupted run could no longer be continued by the command it
        !> printed: refused. Another deck's finished run only loses the checkpoint that would
        !> extend it (`--restart --end`): a warning.
        subroutine guard_other_run(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: hash, results
            logical :: found
            call checkpoint_owner(ck%path, found, hash, results)
            if (.not. found) return
            if (hash == deck_hash(ck%deck_text) .or. results == basename(path)) return
            if (len(results) > 0) then
                if (file_exists(dir//'/'//results//'.partial')) then
                    call make_error(error, deck%file//': the folder '//dir//' holds the checkpoint of an '// &
                                    'interrupted run of another deck (its results '//dir//'/'//results// &
                                    '.partial): this run would replace it, and that run could no longer be '// &
                                    'continued; continue it first, or give this run another --output')
                    return
                end if
            end if
            if (len(results) > 0) results = ' ('//results//')'
            call report('warning: this run replaces '//ck%path//', the checkpoint of another deck''s run'// &
                        results//', which can then no longer be extended with --restart --end')
        end subroutine guard_other_run

        !> Option `--restart`: open the checkpoint and check it belongs to this deck, this code and this
        !> kind of run, and that it leaves steps to do.
        subroutine open_checkpoint(error)
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: ignored
            if (.not. sim%has_time_loop()) then
                call make_error(error, '--restart: '//deck%file//' is not a dynamic analysis (only time '// &
                                'integrations have checkpoints)')
                return
            end if
            call checkpoint_open(ck%source, opts%restart, deck%file, ck%deck_text, kind, ck%start, run_id, error)
            if (allocated(error)) return
            if (ck%start%step >= sim%settings%n_steps) then
                call ck%source%close(ignored)
                call make_error(error, "--restart: checkpoint '"//opts%restart//"' is at step "// &
                                to_str(ck%start%step)//', the end time '//num(sim%settings%t_end)// &
                                ' s is step '//to_str(sim%settings%n_steps)//': nothing to do (give a later '// &
                                'end time: --end T)')
                return
            end if
            ck%restart = .true.
            call report('restart from '//opts%restart//' at step '//to_str(ck%start%step))
            if (len(ck%start%threads) > 0 .and. ck%start%threads /= thread_setting()) &
                call report('warning: the checkpoint was written with '//ck%start%threads//'; this run has '// &
                            thread_setting()//': the results go on correctly, but bit for bit they are '// &
                            'those of neither uninterrupted run (the split sweeps from 4 000 contacts, and '// &
                            'OpenBLAS in the sparse factorisations, depend on the threads); set the same '// &
                            'values to reproduce the run exactly')
            if (.not. ck%start%wall_recorded) call report('note: the checkpoint, written by an earlier '// &
                                                          'MULTICOR build, does not record the wall time of the '// &
                                                          'runs before it: /summary wall_seconds counts from this '// &
                                                          'restart')
        end subroutine open_checkpoint

        !> Title of the run ([run] title).
        function sim_title() result(text)
            character(len=:), allocatable :: text
            text = deck%get_text('run', 'title')
        end function sim_title

        !> Kind of analysis ([run] analysis).
        function sim_analysis() result(text)
            character(len=:), allocatable :: text
            text = deck%get_word('run', 'analysis')
        end function sim_analysis
    end subroutine run_deck

    !> Refuse a model whose memory estimate exceeds the available memory, from the numbers of
    !> disks, nodes and elements the deck asks for (before allocating them), and a rectangle
    !> mesh with more nodes or elements than a mesh can number. The memory error names the
    !> generator record (lattice, row, deposit, beam line, continuum mesh) that asks for the
    !> most memory; the counts are summed without overflow (saturating at huge(0_i8), where
    !> the estimate is refused anyway).
    subroutine check_model_size(deck, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Set when the model is too large.
        type(error_t), allocatable, intent(out) :: error
        type(model_size_t) :: total, part
        type(element_slot_t) :: element
        integer(i8) :: n_nodes, n_elements, largest
        integer :: k, line
        character(len=:), allocatable :: keyword, message
        largest = -1
        line = 0
        keyword = ''
        total%disks = deck%count('particles', 'disk')
        total%beam_nodes = deck%count('beam', 'node')
        total%beam_elements = deck%count('beam', 'element')
        do k = 1, size(deck%entries)
            associate (e => deck%entries(k))
                part = model_size_t()
                select case (e%section//' '//e%keyword)
                case ('particles row', 'particles deposit')
                    part%disks = e%int('n')
                case ('particles square_lattice', 'particles hex_lattice')
                    part%disks = int(e%int('nx'), i8)*int(e%int('ny'), i8)
                case ('beam line', 'beam polar_line')
                    part%beam_nodes = int(e%int('elements'), i8) + 1
                    part%beam_elements = e%int('elements')
                case ('continuum mesh')
                    if (e%word('kind') /= 'rectangle') cycle
                    ! The schema admits only the names of registered element kinds.
                    call new_element(kind_of_name(e%word('element')), element)
                    call check_rectangle_size(e%int('nx'), e%int('ny'), element%element, error)
                    if (allocated(error)) then
                        message = error%message
                        call make_input_error(error, deck%file, e%line, e%keyword, message)
                        return
                    end if
                    call rectangle_size(e%int('nx'), e%int('ny'), element%element, n_nodes, n_elements)
                    if (e%word('element') == 't3') then
                        part%t3 = n_elements
                    else
                        part%q4 = n_elements
                    end if
                case default
                    cycle
                end select
                total%disks = add(total%disks, part%disks)
                total%beam_nodes = add(total%beam_nodes, part%beam_nodes)
                total%beam_elements = add(total%beam_elements, part%beam_elements)
                total%q4 = add(total%q4, part%q4)
                total%t3 = add(total%t3, part%t3)
                if (model_memory_bytes(part) > largest) then
                    largest = model_memory_bytes(part)
                    line = e%line
                    keyword = e%keyword
                end if
            end associate
        end do
        if (total%disks > huge(0)) then
            call make_error(error, deck%file//': the deck asks for '//to_str(total%disks)// &
                            ' disks, more than a run can number ('//to_str(huge(0))//')')
            return
        end if
        call check_memory(total, available_memory(), error)
        if (allocated(error)) then
            message = error%message
            call make_input_error(error, deck%file, line, keyword, message)
        end if

    contains

        !> a + b for counts >= 0, huge(0_i8) when that overflows.
        pure integer(i8) function add(a, b)
            integer(i8), intent(in) :: a, b
            if (a > huge(0_i8) - b) then
                add = huge(0_i8)
            else
                add = a + b
            end if
        end function add
    end subroutine check_model_size
end module driver_run
