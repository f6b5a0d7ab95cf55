!> Runs one deck: read and validate, build the model, run the analysis, write the results.
!>
!> Dispatch: `driver_simulations` picks the kind of run from the deck's sections (beam,
!> particles, coupled, ...), an extension of `simulation_t` (driver_simulation), which builds
!> the model (`init`), describes it (`describe`) and runs it (`run`).
!>
!> Everything that can fail because of the input is checked before the results folder is
!> touched; the HDF5 file is written as '<name>.h5.partial' and renamed only on success, so
!> earlier results stay intact when a run fails, and a results folder the failed run created
!> is removed again when it is left empty. A time loop that fails in a step (a guard, the
!> step's solver) after it stored outputs keeps them as '<name>.h5.failed' (`keep_failed`), a
!> name no run reads, replacing only an earlier failed run's.
!>
!> Guards (driver_guards): before anything is built, the model's memory estimate is checked
!> against the available memory; disks and walls must lie in the box the detection can
!> represent; after every time step the state must be finite (and, for particles, no disk
!> may tunnel through a wall or another disk). One run at a time writes a results folder: a
!> lock file (io_lock) is held while writing and removed on every way out.
!>
!> Every run that ends normally also gets `<name>.xdmf` (driver_results_xdmf), written beside
!> the open results file and renamed into place once the HDF5 file has its final name. A time
!> loop whose XDMF file cannot be written (a full disk, a quota, a file size limit), or whose
!> results file cannot be renamed, after its final checkpoint and with its results file whole,
!> fails (exit 1) leaving the folder as a run killed there does: its results '<name>.h5.partial'
!> and that checkpoint, which the command the error gives finishes with no step to do.
!>
!> Checkpoints (driver_checkpoint): the time loops of every kind of run (beam, particles,
!> beam-particle coupled, continuum, continuum-particle coupled) write
!> '<results folder>/checkpoint.h5' as the deck's [output] checkpoint_interval /
!> checkpoint_seconds say, at a stop signal and at the end; `--restart` continues a run from
!> one (same deck, same code version), into the same results file, with the option of a new
!> end time (`--end`).
module driver_run
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, counted, num => sci_text, shell_word, to_lower
    use io_lock, only: lock_t, lock_acquire, lock_release
    use io_progress, only: progress_t
    use core_signals, only: caught_signal, signal_name, install_signal_handlers
    use core_threads, only: openmp_part, single_thread_blas, thread_setting
    use io_deck_schema, only: multicor_schema
    use io_deck, only: deck_t, read_deck
    use io_paths, only: stem, basename, dirname, mkdir_p, remove_empty_folders, file_exists, remove_file, rename_file
    use driver_results, only: results_writer_t
    use driver_results_mark, only: results_mark_t, results_deck_file, results_root_text
    use driver_results_xdmf, only: write_results_xdmf
    use driver_simulation, only: simulation_t, report_iface
    use driver_simulations, only: select_simulation
    use driver_run_checks, only: check_model_size, apply_end_time, warn_about_deck, warn_fclib_after_end
    use driver_checkpoint, only: checkpoint_run_t, checkpoint_name, checkpoint_open, checkpoint_owner, deck_hash, &
                                 checkpoint_results_mark
    implicit none
    private
    public :: run_options_t, run_deck, report_iface

    !> Command-line options of one run.
    type :: run_options_t
        !> Path of the deck.
        character(len=:), allocatable :: deck_path
        !> Results folder (unallocated: the folder of the `restart` checkpoint, else
        !> results/<deck name>).
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

    !> One run of a deck, from its model's build to its results: what the steps of `run_deck`
    !> share.
    type :: deck_run_t
        !> The deck read.
        type(deck_t) :: deck
        !> Its kind of run, which builds and runs the model.
        class(simulation_t), allocatable :: sim
        !> Writer of the results file.
        type(results_writer_t) :: out
        !> Lock of the results folder, held while writing.
        type(lock_t) :: lock
        !> The run's checkpoints, and the one a restart continues from.
        type(checkpoint_run_t) :: ck
        !> Results folder, and the outermost folder this run created ('' when it existed).
        character(len=:), allocatable :: dir, created
        !> Path of the results file ('<dir>/<deck name>.h5').
        character(len=:), allocatable :: path
        !> Kind of run named in checkpoints (`simulation_t%checkpoint_kind`).
        character(len=:), allocatable :: kind
        !> Root attribute 'run_id' of the results file a restart continues.
        character(len=:), allocatable :: run_id
        !> The results a restart continues: run id and record counts of its checkpoint.
        type(results_mark_t) :: mark
        !> Wall time of a static or modal analysis, from the model's build (`init`: assembly,
        !> factorisations, and for some kinds the solve) to its results written.
        type(progress_t) :: clock
    end type deck_run_t

contains

    !> Read, check and run a deck; write results unless only checking.
    !>
    !> From the opening of the results file on, SIGTERM, SIGINT, SIGUSR1, SIGUSR2, SIGHUP and SIGXCPU stop a time loop
    !> after the step under way: that step is stored, the file is closed as
    !> '<name>.h5.partial' with /summary finished = 0, and `error` says what was saved
    !> (`stopped_by` is then the signal number). Caught after the model's build and before the
    !> results file is opened, they stop any run before it writes anything, its folder's lock
    !> removed (`stop_before_writing`).
    subroutine run_deck(opts, report, error, stopped_by)
        !> What to run and where to write.
        type(run_options_t), intent(in) :: opts
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> Set on any input or run error, and when a signal stopped the run.
        type(error_t), allocatable, intent(out) :: error
        !> Signal that stopped the run early (0: none).
        integer, intent(out), optional :: stopped_by
        type(deck_run_t) :: run

        if (present(stopped_by)) stopped_by = 0
        ! Before any factorisation: results that do not depend on the threads OpenBLAS is given
        call single_thread_blas()
        call check_deck_name(opts%deck_path, error)
        if (allocated(error)) return
        call build_run(opts, report, run, error)
        if (allocated(error)) return
        if (opts%check_only) then
            call warn_fclib_after_end(run%deck, run%sim, report)
            call report(opts%deck_path//': deck is valid ('//run%sim%describe()//')')
            return
        end if

        call results_folder(opts, run%dir, error)
        if (allocated(error)) return
        ! From here a stop signal is only recorded: the run must not die holding the folder's
        ! lock (stop_before_writing, write_into_folder). Until here (the deck read, the model
        ! built) its default action stops the program at once, with nothing written.
        call install_signal_handlers(error)
        if (allocated(error)) return
        call mkdir_p(run%dir, error, run%created)
        if (allocated(error)) return
        call write_into_folder(opts, report, run, error, stopped_by)
        ! A failed run leaves no folder of its own making behind empty (what it holds stays).
        if (allocated(error)) call remove_empty_folders(run%dir, run%created)
    end subroutine run_deck

    !> Read and check the deck, build its model, apply `--end` and give the deck's warnings.
    subroutine build_run(opts, report, run, error)
        !> What to run.
        type(run_options_t), intent(in) :: opts
        !> Where the warnings go.
        procedure(report_iface) :: report
        !> The run: its deck, simulation (model built), kind and clock set.
        type(deck_run_t), intent(inout) :: run
        !> Set on any input error.
        type(error_t), allocatable, intent(out) :: error
        call read_deck(opts%deck_path, multicor_schema(), run%deck, error)
        if (allocated(error)) return
        call select_simulation(run%deck, run%sim, error)
        if (allocated(error)) return
        call check_model_size(run%deck, run%sim, error)
        if (allocated(error)) return
        call run%clock%start(0_i8, 0.0_wp, 0.0_wp)
        call run%sim%init(run%deck, report, error)
        if (allocated(error)) return
        run%kind = run%sim%checkpoint_kind()
        call apply_end_time(opts%end_time, run%deck, run%sim, error)
        if (allocated(error)) return
        call warn_about_deck(opts%end_time, run%deck, run%sim, report)
    end subroutine build_run

    !> The results folder of a run: `--output`, else the folder of the `--restart` checkpoint
    !> (a restart continues the results next to its checkpoint), else results/<deck name>.
    subroutine results_folder(opts, dir, error)
        !> What to run and where to write.
        type(run_options_t), intent(in) :: opts
        !> The results folder.
        character(len=:), allocatable, intent(out) :: dir
        !> Set when `--restart` names a folder or no file (checked before a folder is made
        !> from its name).
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: folder
        if (allocated(opts%output_dir)) then
            dir = opts%output_dir
        else if (allocated(opts%restart)) then
            if (file_exists(opts%restart//'/.')) then
                folder = opts%restart
                do while (len(folder) > 1 .and. folder(len(folder):) == '/')
                    folder = folder(:len(folder) - 1)
                end do
                call make_error(error, "--restart: '"//opts%restart//"' is a folder: give the checkpoint "// &
                                "file in it ('"//folder//'/'//checkpoint_name//"')")
            else if (.not. file_exists(opts%restart)) then
                call make_error(error, "--restart: no checkpoint '"//opts%restart//"'")
            else
                dir = dirname(opts%restart)
            end if
        else
            dir = 'results/'//stem(opts%deck_path)
        end if
    end subroutine results_folder

    !> Lock the results folder `run%dir` (it exists), run and write the results, report them.
    subroutine write_into_folder(opts, report, run, error, stopped_by)
        !> What to run and where to write.
        type(run_options_t), intent(in) :: opts
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> The run, its model built.
        type(deck_run_t), intent(inout) :: run
        !> Set on any run error, and when a signal stopped the run.
        type(error_t), allocatable, intent(out) :: error
        !> Signal that stopped the run early (unchanged when none).
        integer, intent(inout), optional :: stopped_by
        character(len=:), allocatable :: warning
        run%path = run%dir//'/'//stem(opts%deck_path)//'.h5'
        call lock_acquire(run%lock, run%dir, warning, error)
        if (allocated(error)) then
            ! a restart continues the results in the checkpoint's folder: no other folder can take it
            if (.not. allocated(opts%restart)) error%message = error%message//'; or give this run another '// &
                                                               '--output folder'
            return
        end if
        if (len(warning) > 0) call report(warning)
        call start_checkpoints(opts, report, run, error)
        if (.not. allocated(error)) call stop_before_writing(opts, report, run, error, stopped_by)
        if (.not. allocated(error)) call write_results(opts, report, run, error, stopped_by)
        call lock_release(run%lock)
        if (allocated(error)) return
        call report('results written to '//run%path)
        if (run%ck%last_step >= 0) call report('checkpoint: '//to_str(run%ck%last_step)//' steps, t = '// &
                                               num(run%ck%last_time)//' s, in '//run%ck%path//' (to go on to a later '// &
                                               'end time: '//continue_command(opts, run%ck%path, .false.)//' --end T)')
    end subroutine write_into_folder

    !> A stop signal (SIGTERM, SIGINT, SIGUSR1, SIGUSR2, SIGHUP, SIGXCPU) caught from the handlers' installation
    !> (before the results folder is made) to the opening of the results file ends the run
    !> there, before it writes anything: the checkpoint a restart read is closed as it was, and
    !> `error` says the run stopped (`stopped_by` is the signal; the caller releases the lock
    !> and removes a folder the run made). Before, the handlers were installed only after the
    !> checkpoint was read, and a signal after the lock was taken (a restart reads its
    !> checkpoint meanwhile: 5 ms for a 2 500-disk deposit) killed the program and left the
    !> lock, which refused every later start on another host.
    subroutine stop_before_writing(opts, report, run, error, stopped_by)
        !> What to run.
        type(run_options_t), intent(in) :: opts
        !> Where the lines go.
        procedure(report_iface) :: report
        !> The run, its folder locked and its checkpoints started.
        type(deck_run_t), intent(inout) :: run
        !> Set when a stop signal was caught.
        type(error_t), allocatable, intent(out) :: error
        !> Signal that stopped the run (unchanged when none).
        integer, intent(inout), optional :: stopped_by
        type(error_t), allocatable :: ignored
        if (caught_signal() == 0) return
        if (run%ck%restart) call run%ck%source%close(ignored)
        if (present(stopped_by)) stopped_by = caught_signal()
        call report('stopped: '//signal_name(caught_signal())//' before the run wrote anything (the folder is '// &
                    'as it was)')
        if (allocated(opts%restart)) then
            call report('to continue: '//continue_command(opts, opts%restart, .true.))
        else
            call report('to continue: run the deck again (nothing was written)')
        end if
        call make_error(error, run%deck%file//': run stopped by '//signal_name(caught_signal())// &
                        ' before it wrote anything')
    end subroutine stop_before_writing

    !> The run's checkpoints: where and when they are written; with `--restart`, the
    !> checkpoint the run continues from, else, for a run that writes checkpoints (a time
    !> loop), the guard of another deck's checkpoint in the folder (a static or modal analysis
    !> writes none: it leaves the folder's checkpoint as it is).
    subroutine start_checkpoints(opts, report, run, error)
        !> What to run and where to write.
        type(run_options_t), intent(in) :: opts
        !> Where the notes and warnings go.
        procedure(report_iface) :: report
        !> The run, its results path set.
        type(deck_run_t), intent(inout) :: run
        !> Set when the checkpoint cannot be continued, or the folder's may not be replaced.
        type(error_t), allocatable, intent(out) :: error
        run%ck%path = run%dir//'/'//checkpoint_name
        ! The deck and the files it reads (a mesh): a restart must find them unchanged. The
        ! deck's bytes as read (the results store a comment that is not UTF-8 otherwise).
        run%ck%deck_text = run%deck%source_text//run%sim%inputs_text()
        run%ck%schedule%every = run%sim%settings%checkpoint_interval
        run%ck%schedule%seconds = run%sim%settings%checkpoint_seconds
        run%ck%results = basename(run%path)
        if (allocated(opts%restart)) then
            call open_checkpoint(opts, report, run, error)
        else if (run%sim%has_time_loop()) then
            call guard_other_run(opts, report, run, error)
        else
            call guard_other_results(report, run)
        end if
    end subroutine start_checkpoints

    !> A static or modal run replaces the folder's results '<deck name>.h5' when it ends. When
    !> they are another deck's of the same file name (the deck they record differs:
    !> `case1/beam.dat` and `case2/beam.dat` into the default folder), a warning says so, as for
    !> a run with a time loop (`guard_other_run`, whose checkpoint identifies the deck); the
    !> same deck again reproduces them silently.
    subroutine guard_other_results(report, run)
        !> Where the warning goes.
        procedure(report_iface) :: report
        !> The run, its results path set.
        type(deck_run_t), intent(in) :: run
        character(len=:), allocatable :: deck_file
        if (.not. file_exists(run%path)) return
        if (results_root_text(run%path, 'deck_text') == run%deck%text) return
        deck_file = results_deck_file(run%path)
        if (len(deck_file) > 0) deck_file = ' ('//deck_file//')'
        call report('warning: the folder '//run%dir//' holds the results of another deck of the same file name'// &
                    deck_file//': this run replaces them, '//run%path//', when it ends (to keep both, give each deck '// &
                    'its own --output)')
    end subroutine guard_other_results

    !> Run the analysis into '<path>.partial', renamed to `path` on success (the caller
    !> holds the folder's lock). A failed run leaves the folder's results, partial file and
    !> checkpoint as it found them (a resumed partial file keeps the outputs after its
    !> checkpoint, which the next restart cuts), but for the partial file of a killed run that
    !> it deleted because the '.prev' beside it holds the folder's checkpoint's results (no
    !> restart can continue it: results.f90, set_aside_partial); a run that ends or is stopped by a signal
    !> leaves its own, and deletes the '.prev' files it or killed runs set aside, but gives the
    !> results the folder's checkpoint continues their name back (a static or modal analysis
    !> writes no checkpoint).
    subroutine write_results(opts, report, run, error, stopped_by)
        !> What to run.
        type(run_options_t), intent(in) :: opts
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> The run, its folder locked.
        type(deck_run_t), intent(inout) :: run
        !> Set on any run error, and when a signal stopped the run.
        type(error_t), allocatable, intent(out) :: error
        !> Signal that stopped the run early (unchanged when none).
        integer, intent(inout), optional :: stopped_by
        logical :: kept
        call run_and_close(opts, report, run, error, kept, stopped_by)
        if (kept) then
            call run%ck%settle()
            call run%out%settle_earlier(checkpoint_results_mark(run%ck%path))
        else
            call run%ck%revert()
        end if
    end subroutine write_results

    !> Open or resume the results file, run, and close the file (finished or stopped; the
    !> writer cleans up after its own failures).
    subroutine run_and_close(opts, report, run, error, kept, stopped_by)
        !> What to run.
        type(run_options_t), intent(in) :: opts
        !> Where progress and summary lines go.
        procedure(report_iface) :: report
        !> The run, its folder locked.
        type(deck_run_t), intent(inout) :: run
        !> Set on any run error, and when a signal stopped the run.
        type(error_t), allocatable, intent(out) :: error
        !> Whether the run ended or was stopped cleanly: its files are the folder's now.
        logical, intent(out) :: kept
        !> Signal that stopped the run early (unchanged when none).
        integer, intent(inout), optional :: stopped_by
        type(error_t), allocatable :: ignored
        kept = .false.
        if (run%ck%restart) then
            call run%out%resume(run%path, run%mark, error)
            if (allocated(error)) call run%ck%source%close(ignored)
            if (run%out%from_set_aside) call report("note: the results of the checkpoint's run were in "// &
                                                    run%out%partial_path//'.prev, set aside by a run that was '// &
                                                    'killed: they are continued under their name '// &
                                                    run%out%partial_path)
        else
            ! the folder's checkpoint (this run has written none yet): its results are kept
            call run%out%open(run%path, opts%deck_path, run%deck%text, run%deck%get_text('run', 'title'), &
                              run%deck%get_word('run', 'analysis'), checkpoint_results_mark(run%ck%path), error)
        end if
        if (allocated(error)) return
        call run%sim%run(run%out, opts%quiet, report, run%ck, error)
        ! A time loop writes /summary itself; a static or modal analysis has no steps,
        ! and its wall time is that of `clock`.
        if (.not. allocated(error) .and. .not. run%sim%has_time_loop()) call run%out%write_summary(0, run%clock, error)
        if (allocated(error)) then
            if (run%out%keeps_failure()) then
                call keep_failed(run, error)
            else
                call run%out%abort()
                error%message = run%deck%file//': '//error%message
            end if
            return
        end if
        if (run%out%stopped()) then
            call close_stopped(opts, report, run, error, kept, stopped_by)
        else
            call close_finished(opts, report, run, error, kept)
        end if
    end subroutine run_and_close

    !> A time loop that failed in a step after it stored outputs (driver_results,
    !> `keeps_failure`: a guard, the step's solver, an internal error there; not a failed write)
    !> keeps its records as '<path>.failed', with its /summary status naming the failure, so
    !> that what led to it can be read; the message ends with where they are. The folder is
    !> otherwise left as any failed run leaves it (`write_results`): its checkpoints are
    !> dropped and the earlier ones put back, for a restart from one of its checkpoints with the
    !> same deck would fail again, and one with the deck changed is refused (its hash differs).
    subroutine keep_failed(run, error)
        !> The run, its results file open.
        type(deck_run_t), intent(inout) :: run
        !> The run's error, its message completed.
        type(error_t), intent(inout) :: error
        type(error_t), allocatable :: keep_error
        call run%out%close_failed(error%message, keep_error)
        error%message = run%deck%file//': '//error%message
        if (allocated(keep_error)) then
            error%message = error%message//' (its records could not be kept: '//keep_error%message//')'
        else
            error%message = error%message//'; the records up to the failure ('//counted(run%out%outputs, 'output')// &
                            ") are kept in '"//run%out%final_path//".failed' (/summary status: what failed)"
        end if
    end subroutine keep_failed

    !> Close the results file of a run a signal stopped as '<path>.partial' and say what was
    !> saved and how to continue; `error` says the run stopped.
    subroutine close_stopped(opts, report, run, error, kept, stopped_by)
        !> What was run.
        type(run_options_t), intent(in) :: opts
        !> Where the lines go.
        procedure(report_iface) :: report
        !> The run, stopped.
        type(deck_run_t), intent(inout) :: run
        !> Set: the run stopped (or the file could not be closed).
        type(error_t), allocatable, intent(out) :: error
        !> Whether the partial file was closed: its files are the folder's now.
        logical, intent(out) :: kept
        !> Signal that stopped the run.
        integer, intent(inout), optional :: stopped_by
        character(len=32) :: tbuf
        kept = .false.
        call run%out%close_unfinished(error)
        if (allocated(error)) return
        kept = .true.
        if (present(stopped_by)) stopped_by = caught_signal()
        write (tbuf, '(es16.8e3)') run%out%stop_time
        call report('stopped: '//run%out%stop_reason)
        call report('saved: every output up to t = '//trim(adjustl(tbuf))//' s (the last one '// &
                    'at the stop) in '//run%out%partial_path//' (/summary finished = 0)')
        if (file_exists(run%path)) call report('the earlier result '//run%path//' is left as it was')
        if (run%ck%last_step >= 0) then
            call report('checkpoint: '//to_str(run%ck%last_step)//' steps, t = '//num(run%ck%last_time)// &
                        ' s, in '//run%ck%path)
            call report('to continue: '//continue_command(opts, run%ck%path, .true.))
        else
            call report('to continue: run the deck again (no checkpoint was written)')
        end if
        call make_error(error, run%deck%file//': run stopped by '//signal_name(caught_signal())// &
                        '; results so far in '//run%out%partial_path)
    end subroutine close_stopped

    !> Write the XDMF file of a run that ended, close its results file with its final name and
    !> rename the XDMF file into place.
    !>
    !> The XDMF file is written beside the partial file and renamed once the results file has
    !> its final name: a failed run leaves an earlier result's XDMF file as it was, and a
    !> stopped run writes none (the earlier one still describes the earlier result, which is
    !> left as it was). A time loop that fails here after its final checkpoint with its results
    !> whole (the XDMF file cannot be written, the results read whole; or the final rename
    !> fails) keeps them, as '.partial', and that checkpoint: the state a kill there leaves,
    !> which a restart finishes (`error` gives its command; `kept`).
    subroutine close_finished(opts, report, run, error, kept)
        !> What was run.
        type(run_options_t), intent(in) :: opts
        !> Where warnings go.
        procedure(report_iface) :: report
        !> The run, ended.
        type(deck_run_t), intent(inout) :: run
        !> Set when the XDMF file cannot be written or the results file closed.
        type(error_t), allocatable, intent(out) :: error
        !> Whether the results file got its final name, or was kept whole as a run killed after its
        !> final checkpoint leaves it: its files are the folder's now.
        logical, intent(out) :: kept
        type(error_t), allocatable :: xdmf_error, close_error
        character(len=:), allocatable :: xdmf
        logical :: results_read
        kept = .false.
        xdmf = run%path(1:len(run%path) - 3)//'.xdmf'
        ! ParaView's XDMF 2 reader splits a reference 'file.h5:/dataset' at the first colon
        if (index(basename(run%path), ':') > 0) call report('warning: the name '//basename(run%path)// &
                                                            ' contains a colon, which ParaView''s XDMF reader '// &
                                                            'cannot open; rename the deck to view '// &
                                                            basename(xdmf)//' in ParaView')
        ! the results written out first: a disk that the XDMF file fills leaves the close of a
        ! whole results file nothing to write
        call run%out%flush(error)
        if (allocated(error)) then
            call run%out%abort()
            error%message = run%deck%file//': '//error%message
            return
        end if
        call write_results_xdmf(run%out%file, xdmf//'.partial', basename(run%path), error, results_read)
        if (allocated(error)) then
            ! first: the space it took is free again for the close of the results file
            call remove_file(xdmf//'.partial')
            error%message = run%deck%file//': '//error%message
            if (results_read .and. after_last_checkpoint(run)) then
                ! no more writes to it but its close: whole, as a run killed here leaves it
                call run%out%close_partial(close_error)
                kept = .not. allocated(close_error)
                if (kept) then
                    call say_how_to_finish(opts, run, 'the XDMF file can be written (space freed)', error)
                    return
                end if
                error%message = error%message//'; '//close_error%message
            end if
            call run%out%abort()
            return
        end if
        call run%out%close(error)
        kept = .not. allocated(error)
        if (.not. kept) then
            call remove_file(xdmf//'.partial')
            if (.not. run%out%kept_partial) return
            ! closed whole, its rename failed
            if (after_last_checkpoint(run)) then
                kept = .true.
                error%message = run%deck%file//': '//error%message
                call say_how_to_finish(opts, run, 'the results file can be renamed', error)
            else
                error%message = error%message//" (the results are kept in '"//run%out%partial_path//"')"
            end if
            return
        end if
        call rename_file(xdmf//'.partial', xdmf, xdmf_error)
        if (allocated(xdmf_error)) call report('warning: '//xdmf_error%message)
    end subroutine close_finished

    !> Whether the run has a time loop whose final checkpoint is written: what its end writes
    !> after that checkpoint, a restart from it writes again (no step to do).
    logical function after_last_checkpoint(run)
        !> The run, ended.
        type(deck_run_t), intent(in) :: run
        after_last_checkpoint = run%sim%has_time_loop() .and. run%ck%last_step == run%sim%settings%n_steps
    end function after_last_checkpoint

    !> Add to the error of a run that ended and kept its results whole as '.partial' with its
    !> final checkpoint what the folder holds and the command that finishes the run.
    subroutine say_how_to_finish(opts, run, when, error)
        !> What was run.
        type(run_options_t), intent(in) :: opts
        !> The run, its results file closed as '.partial'.
        type(deck_run_t), intent(in) :: run
        !> When the command can finish it ('the XDMF file can be written (space freed)').
        character(len=*), intent(in) :: when
        !> The error of the run's end, its message completed.
        type(error_t), intent(inout) :: error
        error%message = error%message//"; the results are whole, kept as '"//run%out%partial_path// &
                        "' with the checkpoint of the last step '"//run%ck%path//"', as a run killed "// &
                        'after its final checkpoint leaves them; once '//when//', this command finishes '// &
                        'the run, with no step to do: '//continue_command(opts, run%ck%path, .true.)
    end subroutine say_how_to_finish

    !> The command that continues this run from its checkpoint; with `same_end`, to the end
    !> time this run was given: `--end T` again when the run had one (in the fewest digits
    !> that read back as the same double, hence the same step count), else the deck's end.
    function continue_command(opts, checkpoint, same_end) result(command)
        !> The run's options.
        type(run_options_t), intent(in) :: opts
        !> Path of the checkpoint to continue from.
        character(len=*), intent(in) :: checkpoint
        !> Whether to repeat this run's `--end` (else the caller appends its own).
        logical, intent(in) :: same_end
        character(len=:), allocatable :: command
        character(len=32) :: end_text
        real(wp) :: back
        integer :: ios
        command = 'multicor '//shell_word(opts%deck_path)
        if (allocated(opts%output_dir)) command = command//' --output '//shell_word(opts%output_dir)
        command = command//' --restart '//shell_word(checkpoint)
        if (same_end .and. opts%end_time >= 0.0_wp) then
            ! as the user wrote it when its shortest form reads back as the same double
            ! (0.4, not 4.00000000000000022E-001), else all 17 digits
            end_text = to_str(opts%end_time)
            read (end_text, *, iostat=ios) back
            if (ios /= 0 .or. back /= opts%end_time) write (end_text, '(es25.17e3)') opts%end_time
            command = command//' --end '//trim(adjustl(end_text))
        end if
    end function continue_command

    !> A deck whose results file would be the folder's checkpoint: its name without extension is
    !> 'checkpoint' (`checkpoint.dat` writes '<folder>/checkpoint.h5'), in any case of letters
    !> (`Checkpoint.dat` writes the same file where the file system does not tell case apart:
    !> macOS, Windows shares). Refused before anything is read or written. Before, its results
    !> replaced the checkpoint and the checkpoint them, and the printed `--restart` command
    !> failed ('is not a MULTICOR checkpoint'). No other name of a run's files can be another's:
    !> the results' ('<name>.h5', '.h5.partial', '.h5.partial.prev', '<name>.xdmf',
    !> '.xdmf.partial', '<name>_fclib_<step>.h5', '.h5.partial') end in '.h5', '.xdmf', '.partial'
    !> or '.prev'; the checkpoint's are 'checkpoint.h5', '.h5.tmp' and '.h5.prev'; the lock's
    !> ('.multicor.lock', '.multicor.lock.<host>.<pid>', '.multicor.lock.break', ...) end in
    !> neither, and the lock's clean-up removes only names ending in a process id.
    subroutine check_deck_name(deck_path, error)
        !> Path of the deck.
        character(len=*), intent(in) :: deck_path
        !> Set when the deck's name is refused.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: results, case_note
        if (to_lower(stem(deck_path))//'.h5' /= checkpoint_name) return
        results = stem(deck_path)//'.h5'
        case_note = ''
        if (results /= checkpoint_name) case_note = ' where the file system does not tell case apart'
        call make_error(error, deck_path//": a deck named '"//basename(deck_path)//"' writes its results as '"// &
                        results//"', the name of the results folder's checkpoint ('"//checkpoint_name//"'"// &
                        case_note//"): they would overwrite each other; rename the deck (its name without "// &
                        "extension other than '"//stem(checkpoint_name)//"', in any case of letters)")
    end subroutine check_deck_name

    !> A fresh run with a time loop replaces the folder's checkpoint (at its first commit), and
    !> at its end the results file '<deck name>.h5'.
    !>
    !> - When the checkpoint's run can still be continued (its results, which the checkpoint
    !>   records by run id and record counts, are still '.partial', or '.partial.prev' where a
    !>   fresh run set them aside and was killed: a run stopped by a signal, killed after a
    !>   checkpoint), the run is refused, whatever the deck: that run's deck, this deck again,
    !>   another of the same file name. The message gives the step and time of the checkpoint,
    !>   the command that continues it, and what to do to start afresh (remove the checkpoint,
    !>   or another `--output`). Before, only another deck of another file name was refused;
    !>   a fresh run of the same deck, or of another deck of the same file name (`c1/deck.dat`,
    !>   `c2/deck.dat`), replaced the stopped run silently.
    !> - Another deck's finished run only loses the checkpoint that would extend it (`--restart
    !>   --end`), and, when its deck has the same file name, its results: a warning.
    !> - The same deck over its own finished results: nothing to say (a run reproduces it).
    subroutine guard_other_run(opts, report, run, error)
        !> The run's options (for the command that continues the stopped run).
        type(run_options_t), intent(in) :: opts
        !> Where the warning goes.
        procedure(report_iface) :: report
        !> The run, its checkpoint path and deck text set.
        type(deck_run_t), intent(in) :: run
        !> Set when the folder holds the checkpoint of a run that can still be continued.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: hash, results, run_id, held, deck_file
        type(results_mark_t) :: mark
        logical :: found, same_deck, same_name, this_build
        integer :: step
        real(wp) :: time
        call checkpoint_owner(run%ck%path, found, hash, results, run_id, step, time, this_build)
        if (.not. found) return
        same_deck = hash == deck_hash(run%ck%deck_text)
        if (len(results) > 0) then
            mark = checkpoint_results_mark(run%ck%path)
            held = run%dir//'/'//results//'.partial'
            if (.not. mark%held_by(held)) held = held//'.prev'
            if (mark%held_by(held)) then
                call refuse_over_interrupted_run(opts, run, same_deck, results, held, step, time, this_build, &
                                                 error)
                return
            end if
        end if
        if (same_deck) return
        same_name = results == basename(run%path)
        if (same_name) same_name = mark%held_by(run%path)
        if (same_name) then
            deck_file = results_deck_file(run%path)
            if (len(deck_file) > 0) deck_file = ' ('//deck_file//')'
            call report('warning: the folder '//run%dir//' holds the finished results of another deck of the same '// &
                        'file name'//deck_file//': this run replaces its checkpoint '//run%ck%path// &
                        ' and, when it ends, its results '//run%path//' (to keep them, stop this run and give it '// &
                        'another --output)')
            return
        end if
        if (len(results) > 0) results = ' ('//results//')'
        call report('warning: this run replaces '//run%ck%path//', the checkpoint of another deck''s run'// &
                    results//', which can then no longer be extended with --restart --end')
    end subroutine guard_other_run

    !> The refusal of a fresh run into the folder of a run that can still be continued (its
    !> checkpoint `run%ck%path`, its results `held`, still partial): what that run is, the
    !> command that continues it, and how to start afresh.
    subroutine refuse_over_interrupted_run(opts, run, same_deck, results, held, step, time, this_build, error)
        !> The run's options.
        type(run_options_t), intent(in) :: opts
        !> The fresh run.
        type(deck_run_t), intent(in) :: run
        !> Whether the checkpoint is this deck's (same hash).
        logical, intent(in) :: same_deck
        !> Name of the checkpoint's results file in the folder ('deck.h5').
        character(len=*), intent(in) :: results
        !> The checkpoint's results: '<results>.partial' or '<results>.partial.prev'.
        character(len=*), intent(in) :: held
        !> Step of the checkpoint (-1: unknown).
        integer, intent(in) :: step
        !> Time of the checkpoint [s].
        real(wp), intent(in) :: time
        !> Whether this build can continue the checkpoint (else the build that wrote it can).
        logical, intent(in) :: this_build
        !> The refusal.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: who, at, command, replaced, afresh
        if (same_deck) then
            who = 'this deck'
            command = continue_command(opts, run%ck%path, .true.)
            replaced = 'this run would replace them'
            afresh = 'to start afresh instead'
        else
            who = results_deck_file(held)
            if (len(who) > 0) then
                command = 'multicor '//shell_word(who)//' --restart '//shell_word(run%ck%path)//' (its deck as it was)'
                who = 'another deck ('//who//')'
            else
                command = 'multicor DECK --restart '//shell_word(run%ck%path)//' (DECK: that run''s deck as it was)'
                who = 'another deck'
            end if
            if (results == basename(run%path)) then
                who = who//' of the same file name'
                replaced = 'this run would replace them, and that run could no longer be continued'
            else
                replaced = 'this run would replace that checkpoint, and that run could no longer be continued'
            end if
            afresh = 'to run this deck here all the same'
        end if
        at = ''
        if (step >= 0) at = ' at step '//to_str(step)//', t = '//num(time)//' s'
        if (.not. this_build) command = 'with the MULTICOR build that wrote it (another code version or layout '// &
                                        'than this build, which cannot), '//command
        call make_error(error, run%deck%file//': the folder '//run%dir//' holds an interrupted run of '//who// &
                        ', which can still be continued from its checkpoint'//at//' ('//run%ck%path// &
                        '; its results '//held//'): '//replaced//'. To continue it: '//command//'; '//afresh// &
                        ', remove that checkpoint (rm '//shell_word(run%ck%path)//') or give this run '// &
                        'another --output')
    end subroutine refuse_over_interrupted_run

    !> Option `--restart`: open the checkpoint and check it belongs to this deck, this code and this
    !> kind of run, and that it leaves steps to do, or that it is the checkpoint of the last step
    !> of a run whose results file is still '.partial' (killed after its final checkpoint, before
    !> the file was closed): the restart then does what the end of that step did after its
    !> checkpoint, and closes the file.
    subroutine open_checkpoint(opts, report, run, error)
        !> The run's options (`--restart`).
        type(run_options_t), intent(in) :: opts
        !> Where the notes and warnings go.
        procedure(report_iface) :: report
        !> The run: its checkpoints' source opened, start counters and run id read.
        type(deck_run_t), intent(inout) :: run
        !> Set when the checkpoint cannot be continued by this run.
        type(error_t), allocatable, intent(out) :: error
        type(error_t), allocatable :: ignored
        logical :: at_end
        if (.not. run%sim%has_time_loop()) then
            call make_error(error, '--restart: '//run%deck%file//' is not a dynamic analysis (only time '// &
                            'integrations have checkpoints)')
            return
        end if
        ! what the checkpoint records of its results file (read before its checks, not trusted
        ! until the restart reads it again: `load_results`)
        run%mark = checkpoint_results_mark(opts%restart)
        associate (ck => run%ck, sim => run%sim)
            call checkpoint_open(ck%source, opts%restart, run%deck%file, ck%deck_text, run%kind, ck%start, &
                                 run%run_id, error)
            if (allocated(error)) return
            run%mark%run_id = run%run_id
            call check_results_place(opts, run, error)
            if (allocated(error)) then
                call ck%source%close(ignored)
                return
            end if
            at_end = ck%start%step == sim%settings%n_steps
            if (at_end) at_end = interrupted()
            if (ck%start%step >= sim%settings%n_steps .and. .not. at_end) then
                call ck%source%close(ignored)
                call make_error(error, "--restart: checkpoint '"//opts%restart//"' is at step "// &
                                to_str(ck%start%step)//', the end time '//num(sim%settings%t_end)// &
                                ' s is step '//to_str(sim%settings%n_steps)//': nothing to do (give a later '// &
                                'end time: --end T)')
                return
            end if
            ck%restart = .true.
            call report('restart from '//opts%restart//' at step '//to_str(ck%start%step))
            if (at_end) call report('note: the checkpoint is of the last step and the results file of its run '// &
                                    'is still partial (the run was killed, or failed with its results whole, after '// &
                                    'its final checkpoint): no step to do, the results are finished from the '// &
                                    'checkpoint')
            if (len(ck%start%threads) > 0 .and. openmp_part(ck%start%threads) /= openmp_part(thread_setting())) &
                call report('warning: the checkpoint was written with '//ck%start%threads//'; this run has '// &
                            thread_setting()//': the results go on correctly, bit for bit as both '// &
                            'uninterrupted runs while no step sweeps 4 000 contacts or more (2 000 per '// &
                            'thread); from such a step the split sweeps depend on the threads, and the results '// &
                            'are those of neither run: set the same OMP_NUM_THREADS to reproduce the run exactly')
            if (.not. ck%start%wall_recorded) call report('note: the checkpoint, written by an earlier '// &
                                                          'MULTICOR build, does not record the wall time of the '// &
                                                          'runs before it: /summary wall_seconds counts from this '// &
                                                          'restart')
        end associate
    contains
        !> Whether the partial results file (perhaps set aside as '.prev') holds the checkpoint's
        !> results.
        logical function interrupted()
            interrupted = run%mark%held_by(run%path//'.partial')
            if (.not. interrupted) interrupted = run%mark%held_by(run%path//'.partial.prev')
        end function interrupted
    end subroutine open_checkpoint

    !> With `--restart`: the run continues the results file `<results folder>/<deck name>.h5`
    !> (or its '.partial'). When no file of the checkpoint's run is there, but the file the
    !> checkpoint records (its root attribute `results`) is in the checkpoint's folder, the deck
    !> has another name than the checkpoint's run's (a copy of it), or `--output` names another
    !> folder: refused, naming that file and what to change. Before, the restart said that
    !> neither file there was the run's: 'it was moved, deleted or replaced by another run'.
    subroutine check_results_place(opts, run, error)
        !> The run's options.
        type(run_options_t), intent(in) :: opts
        !> The run: its results path and the checkpoint's run id set.
        type(deck_run_t), intent(in) :: run
        !> Set when the checkpoint's results lie elsewhere than this run would continue them.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: hash, results, run_id, folder, held, advice, renamed
        type(results_mark_t) :: same_run
        logical :: found
        call checkpoint_owner(opts%restart, found, hash, results, run_id)
        if (.not. found .or. len(results) == 0) return
        same_run%run_id = run%run_id
        if (len(run_file(run%path)) > 0) return
        folder = dirname(opts%restart)
        held = run_file(folder//'/'//results)
        if (len(held) == 0) return
        advice = ''
        if (results /= basename(run%path)) then
            ! the deck's name with the stem of the checkpoint's results ('.dat' kept)
            renamed = basename(opts%deck_path)
            renamed = dirname(opts%deck_path)//'/'//stem(results)//renamed(len(stem(opts%deck_path)) + 1:)
            advice = "the results file's name follows the deck's file name ("//opts%deck_path//' writes '// &
                     basename(run%path)//'): run the deck as '//shell_word(renamed)//", the name the "// &
                     "checkpoint's run had (copy it to that name)"
        end if
        if (run%dir /= folder) then
            if (len(advice) > 0) advice = advice//', and '
            advice = advice//"the results folder is the checkpoint's ("//folder//') unless --output gives '// &
                     'another: leave out --output, or give --output '//shell_word(folder)
        end if
        call make_error(error, "--restart: this run would continue '"//run%path//"', but the results of the "// &
                        "checkpoint's run are '"//held//"' (the file its attribute 'results' records, beside "// &
                        'it): '//advice)
    contains
        !> The file of the checkpoint's run among '<path>.partial', '<path>.partial.prev' and
        !> `path` ('' when none is).
        function run_file(path) result(name)
            character(len=*), intent(in) :: path
            character(len=:), allocatable :: name
            name = path//'.partial'
            if (same_run%held_by(name)) return
            name = path//'.partial.prev'
            if (same_run%held_by(name)) return
            name = path
            if (same_run%held_by(name)) return
            name = ''
        end function run_file
    end subroutine check_results_place
end module driver_run
