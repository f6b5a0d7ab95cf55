!> Results file of a run (HDF5, layout in doc/output.md).
!>
!> The file is written as '<final_path>.partial' and renamed to `final_path` by `close` only
!> when the run succeeded: an earlier result stays intact until then, and `abort` deletes the
!> partial file. The partial file of an earlier run (interrupted, perhaps resumable) is set
!> aside as '<final_path>.partial.prev' while this run writes its own: `abort` puts it back;
!> after `close` or `close_unfinished`, `settle_earlier` deletes it, or one a killed run set
!> aside, unless it holds the results the folder's checkpoint continues (this run wrote no
!> checkpoint: a static or modal analysis), which it gives back their name. A '.prev' file
!> holding those results (the checkpoint's run id and at least its records: driver_results_mark)
!> is never replaced: a partial file found beside it that does not hold them (a killed run's, or
!> an earlier state of the checkpoint's run, so no restart continues it) is deleted instead; a
!> restart continues the '.prev' file itself (`resume`). Files written
!> beside the results (an FCLIB export, `companion`) follow the results file: written as
!> '<path>.partial', renamed by `close` and `close_unfinished`, deleted by `abort`, so that a
!> failed run leaves an earlier run's export as it was. /summary is written at creation with
!> finished = 0 and set to 1 by `close`;
!> the run loops `flush` after every output, so the partial file of a killed run opens and
!> holds every output up to the last one. A run stopped by a signal (`stop_at`) is closed by
!> `close_unfinished`: it stays '.partial' with finished = 0 and the reason in /summary. A run
!> that ended but cannot complete its end after its final checkpoint (its XDMF file cannot be
!> written: `close_partial`; the final rename fails: `close`) keeps its file whole as '.partial'
!> (`kept_partial`), the state a kill there leaves, which a restart from that checkpoint finishes.
!> A time loop that fails in a step (`fail_at`: a guard, the step's solver, not a write) after
!> storing outputs beyond those it began with (`begin_loop`) is closed by `close_failed`: its
!> records are kept as '<final_path>.failed' with the failure in /summary status, the folder's
!> other files settled as by `abort`.
!> The beam's datasets are written by the writer's part `beam` (driver_results_beam), those of
!> the other models by their own writers (driver_results_continuum, driver_results_dem,
!> driver_results_coupled) into `file`.
module driver_results
    use, intrinsic :: iso_fortran_env, only: int64
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    use core_version, only: multicor_version, multicor_name
    use core_threads, only: thread_setting
    use core_strings, only: string_t, shell_word
    use io_hdf5_file, only: h5_file_t
    use io_progress, only: progress_t
    use io_paths, only: rename_file, remove_file, copy_file, file_exists
    use driver_results_mark, only: results_mark_t, results_file_damage
    use driver_results_beam, only: beam_writer_t
    implicit none
    private
    public :: results_writer_t

    !> Writes the results of one run into one HDF5 file.
    type :: results_writer_t
        !> The HDF5 file ('.partial' while writing).
        type(h5_file_t) :: file
        !> Name the file gets on success.
        character(len=:), allocatable :: final_path
        !> Name of the file while writing.
        character(len=:), allocatable :: partial_path
        !> The beam's datasets (driver_results_beam), written into `file`.
        type(beam_writer_t) :: beam
        !> Why the run stopped before its end ('' while it runs; set by `stop_at`).
        character(len=:), allocatable :: stop_reason
        !> Time of the last output stored before a stop [s] (set by `stop_at`).
        real(wp) :: stop_time = 0.0_wp
        !> Root attribute 'run_id' of the file: start date-time and clock count of the run,
        !> kept by its restarts.
        character(len=:), allocatable :: run_id
        !> Whether the file is the partial file of an earlier run, continued (`resume`): the
        !> only copy of its outputs, which a failed run then keeps (not a copy of the finished file).
        logical :: resumed = .false.
        !> Whether an earlier partial file was set aside as '<partial_path>.prev' (`abort`
        !> puts it back).
        logical :: set_aside = .false.
        !> Whether `resume` continues the checkpoint's results from '<partial_path>.prev', where a
        !> run that was then killed had set them aside (given their name back).
        logical :: from_set_aside = .false.
        !> Final paths of the files written beside the results by this run (`companion`), and
        !> of those an interrupted run wrote before its checkpoint (`adopt`).
        type(string_t), allocatable :: companions(:)
        !> For each companion, whether this run wrote it (`abort` deletes only those).
        logical, allocatable :: own(:)
        !> Stored outputs flushed whole so far (/summary@outputs).
        integer :: outputs = 0
        !> Whether the file of a run that ended was closed whole but keeps its partial name
        !> (`close_partial`, or `close` whose rename failed); the earlier partial file set aside and
        !> the files beside the results are then settled as for a stopped run.
        logical :: kept_partial = .false.
        !> Outputs counted when the time loop began its first step (`begin_loop`): those of the
        !> checkpoint at a restart, the initial state's in a fresh run.
        integer :: loop_outputs = huge(0)
        !> Step in which the time loop failed, its results file sound (`fail_at`; 0: none).
        integer(int64) :: failed_step = 0
        !> Time that step reaches [s].
        real(wp) :: failed_time = 0.0_wp
    contains
        !> Create the results file (written as .partial until `close`).
        procedure :: open => writer_open
        !> Reopen the results file of a checkpointed run to continue it (restart).
        procedure :: resume => writer_resume
        !> Mark a resumed file unfinished again (after the checkpoint is read).
        procedure :: mark_running => writer_mark_running
        !> Write the run statistics as attributes of /summary.
        procedure :: write_summary => writer_write_summary
        !> Flush the file so that a killed run leaves every stored output readable.
        procedure :: flush => writer_flush
        !> Flush a stored output, then count it in /summary@outputs (flushed again).
        procedure :: flush_output => writer_flush_output
        !> Record why and when the run stops before its end (a signal).
        procedure :: stop_at => writer_stop_at
        !> True when `stop_at` was called.
        procedure :: stopped => writer_stopped
        !> Close the file and give it its final name (finished = 1).
        procedure :: close => writer_close
        !> Close a stopped run: the file stays .partial with the reason in /summary.
        procedure :: close_unfinished => writer_close_unfinished
        !> Close the file of a run that ended, with no more writes, as '.partial' (its end could
        !> not be completed: the XDMF file cannot be written).
        procedure :: close_partial => writer_close_partial
        !> Close and delete the partial file after an error.
        procedure :: abort => writer_abort
        !> Count the outputs stored before the time loop's first step.
        procedure :: begin_loop => writer_begin_loop
        !> Record that the time loop failed in a step (the step or a guard, not a write).
        procedure :: fail_at => writer_fail_at
        !> Whether a failed run keeps its records (`close_failed`).
        procedure :: keeps_failure => writer_keeps_failure
        !> Close the file of a failed time loop and keep it as '<final_path>.failed'.
        procedure :: close_failed => writer_close_failed
        !> True while the file is open.
        procedure :: is_open => writer_is_open
        !> Path to write a file beside the results under, which follows the results file.
        procedure :: companion => writer_companion
        !> Take over a file beside the results that a killed run left as '<path>.partial'.
        procedure :: adopt => writer_adopt
        !> After the run ended or was stopped: delete the earlier partial file set aside, or put back
        !> the results of the folder's checkpoint.
        procedure :: settle_earlier => writer_settle_earlier
    end type results_writer_t

contains

    !> Create '<final_path>.partial' and write the root attributes (code, deck, title, date).
    subroutine writer_open(self, final_path, deck_file, deck_text, title, analysis, keep, error)
        !> The writer; must not be open.
        class(results_writer_t), intent(inout) :: self
        !> Name of the results file on success (its folder must exist).
        character(len=*), intent(in) :: final_path
        !> Deck file name (as given on the command line).
        character(len=*), intent(in) :: deck_file
        !> The whole deck text.
        character(len=*), intent(in) :: deck_text
        !> Title of the run.
        character(len=*), intent(in) :: title
        !> Analysis type ('static', 'modal', 'dynamic').
        character(len=*), intent(in) :: analysis
        !> The results of the folder's checkpoint (run id '': none), which are kept when set aside.
        type(results_mark_t), intent(in) :: keep
        !> Set when the file cannot be created or written.
        type(error_t), allocatable, intent(out) :: error
        if (self%is_open()) then
            call make_error(error, "results: cannot open '"//final_path//"': '" &
                            //self%final_path//"' is still open")
            return
        end if
        self%final_path = final_path
        self%partial_path = final_path//'.partial'
        self%beam = beam_writer_t()
        self%stop_reason = ''
        self%stop_time = 0.0_wp
        self%run_id = new_run_id()
        self%resumed = .false.
        self%companions = [string_t ::]
        self%own = [logical ::]
        call set_aside_partial(self, keep, error)
        if (allocated(error)) return
        call self%file%create(self%partial_path, error)
        if (allocated(error)) return
        call root_attributes(error)
        if (.not. allocated(error)) call self%file%create_group('/summary', error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'finished', 0, error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'status', &
                                                                   'running (or killed)', error)
        self%outputs = 0
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'outputs', 0, error)
        if (.not. allocated(error)) call summary_placeholders(error)
        if (.not. allocated(error)) call self%flush(error)
        if (allocated(error)) call self%abort()
    contains
        !> The attributes `write_summary` sets at the end, created now with their types (steps
        !> and runs 0, times 0, strings empty) so that the end of the run, or of a restart,
        !> overwrites them in place: a kill while the file is closed leaves it readable
        !> (doc/output.md, restart).
        subroutine summary_placeholders(error)
            type(error_t), allocatable, intent(out) :: error
            call self%file%write_attribute('/summary', 'steps', 0, error)
            if (allocated(error)) return
            call self%file%write_attribute('/summary', 'wall_seconds', 0.0_wp, error)
            if (allocated(error)) return
            call self%file%write_attribute('/summary', 'wall_seconds_last_run', 0.0_wp, error)
            if (allocated(error)) return
            call self%file%write_attribute('/summary', 'runs', 0, error)
            if (allocated(error)) return
            call self%file%write_attribute('/summary', 'ended', '', error)
            if (allocated(error)) return
            call self%file%write_attribute('/summary', 'threads', '', error)
        end subroutine summary_placeholders

        subroutine root_attributes(error)
            type(error_t), allocatable, intent(out) :: error
            call self%file%write_attribute('/', 'code_name', multicor_name, error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'code_version', multicor_version, error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'deck_file', deck_file, error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'deck_text', deck_text, error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'title', title, error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'analysis', analysis, error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'created', iso_date_time(), error)
            if (allocated(error)) return
            call self%file%write_attribute('/', 'run_id', self%run_id, error)
        end subroutine root_attributes
    end subroutine writer_open

    !> Open the results file of a run to continue it (restart). The file continued is the
    !> first of these that holds the checkpoint's results (its run id and at least the records
    !> of the checkpoint, `results_mark_t`): '<final_path>.partial', continued in place;
    !> '<final_path>.partial.prev', where a run started afresh and then killed set it aside,
    !> given its name back and continued in place (the partial file of that killed run, or an
    !> earlier copy of the run's results, is deleted first: no restart continues it); a copy of
    !> `final_path` made as the partial file (the finished file stays as it is until the
    !> continued run ends normally). Failing that, the partial file or the finished file of the
    !> run (its run id, fewer records), which the reading of the checkpoint then refuses with the
    !> counts. Nothing is written to it until the checkpoint is read (`mark_running`).
    subroutine writer_resume(self, final_path, mark, error)
        !> The writer; must not be open.
        class(results_writer_t), intent(inout) :: self
        !> Name of the results file on success.
        character(len=*), intent(in) :: final_path
        !> The checkpoint's results: run id and record counts.
        type(results_mark_t), intent(in) :: mark
        !> Set when no file belongs to the run, or it cannot be opened for writing.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: prev, source
        type(results_mark_t) :: same_run
        logical :: copy
        if (self%is_open()) then
            call make_error(error, "results: cannot resume '"//final_path//"': '" &
                            //self%final_path//"' is still open")
            return
        end if
        self%final_path = final_path
        self%partial_path = final_path//'.partial'
        self%stop_reason = ''
        self%stop_time = 0.0_wp
        self%run_id = mark%run_id
        self%resumed = .true.
        self%set_aside = .false.
        self%from_set_aside = .false.
        self%companions = [string_t ::]
        self%own = [logical ::]
        prev = self%partial_path//'.prev'
        ! a file of the checkpoint's run whatever its records (finished or partial, any state)
        same_run%run_id = mark%run_id
        if (mark%held_by(self%partial_path)) then
            copy = .false.
        else if (mark%held_by(prev)) then
            copy = .false.
            call take_back_set_aside(error)
            if (allocated(error)) return
        else if (mark%held_by(final_path)) then
            copy = .true.
        else if (same_run%held_by(self%partial_path)) then
            copy = .false.
        else if (same_run%held_by(final_path)) then
            copy = .true.
        else
            ! a file there that HDF5 cannot read is damaged, not another run's
            call refuse_damaged(self%partial_path, error)
            if (.not. allocated(error)) call refuse_damaged(final_path, error)
            if (.not. allocated(error)) &
                call make_error(error, "results: neither '"//self%partial_path//"' nor '"// &
                                final_path//"' is the results file of the checkpoint's run (run_id "// &
                                mark%run_id//'): '//moved())
            return
        end if
        ! read whole before it is copied or written: a damaged file (truncated, overwritten in
        ! part) is named as such, not as a copy that a failed run deletes
        source = self%partial_path
        if (copy) source = final_path
        call refuse_damaged(source, error)
        if (allocated(error)) return
        if (copy) then
            ! a copy: the finished file keeps the outputs, a failure removes the copy (and puts
            ! back the partial file of another run it set aside)
            self%resumed = .false.
            call set_aside_partial(self, mark, error)
            if (allocated(error)) return
            call copy_file(final_path, self%partial_path, error)
            if (allocated(error)) then
                call self%abort()
                error%message = 'results: '//error%message
                return
            end if
        end if
        call self%file%open(self%partial_path, error, writable=.true.)
        if (allocated(error)) then
            call self%abort()
            error%message = 'results: '//error%message
            return
        end if
    contains
        !> An error when the file `path` exists and HDF5 cannot read it whole.
        subroutine refuse_damaged(path, error)
            character(len=*), intent(in) :: path
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: reason
            if (.not. file_exists(path)) return
            reason = results_file_damage(path)
            if (len(reason) == 0) return
            call make_error(error, "results: the results file '"//path//"' of the checkpoint's run is "// &
                            'damaged, truncated or overwritten in part ('//reason//'): a restart cannot '// &
                            'continue it; put back a good copy of it, or run the deck again without '// &
                            '--restart (h5dump -H '//shell_word(path)//' shows what can still be read)')
        end subroutine refuse_damaged

        !> Give '<partial_path>.prev' its name back, deleting the partial file found under it.
        subroutine take_back_set_aside(error)
            type(error_t), allocatable, intent(out) :: error
            if (file_exists(self%partial_path)) then
                call remove_file(self%partial_path)
                if (file_exists(self%partial_path)) then
                    call make_error(error, "results: cannot delete '"//self%partial_path//"', the partial file "// &
                                    "of a killed run, to continue the checkpoint's results set aside as '"//prev//"'")
                    return
                end if
            end if
            call rename_file(prev, self%partial_path, error)
            if (allocated(error)) then
                error%message = 'results: '//error%message//" (the checkpoint's results, set aside by a run "// &
                                'that was killed)'
                return
            end if
            self%from_set_aside = .true.
        end subroutine take_back_set_aside

        !> Where the results went: an earlier state of the run set aside as '.prev', or unknown.
        function moved() result(text)
            character(len=:), allocatable :: text
            if (same_run%held_by(prev)) then
                text = "'"//prev//"' is that run's but holds fewer records than the checkpoint (an earlier "// &
                       'state of the run, from which the checkpoint cannot be continued)'
            else
                text = 'it was moved, deleted or replaced by another run'
            end if
        end function moved
    end subroutine writer_resume

    !> Mark a resumed file as the file of a running run again (/summary finished = 0), once
    !> the checkpoint it continues from has been read and checked.
    subroutine writer_mark_running(self, error)
        !> An open writer.
        class(results_writer_t), intent(inout) :: self
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call require_open(self, 'mark_running', error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'finished', 0, error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'status', &
                                                                   'running (or killed)', error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'outputs', self%outputs, error)
        if (allocated(error)) error%message = 'results: '//error%message
    end subroutine writer_mark_running

    !> Write run statistics as attributes of /summary: `steps`, `wall_seconds` (the analysis,
    !> every run of it: a restarted run adds its own time to that of the runs before its
    !> checkpoint), `wall_seconds_last_run` (this run alone), `runs` (1 + the restarts),
    !> `ended` and `threads` (this run's parallel setting, core_threads).
    subroutine writer_write_summary(self, steps, clock, error)
        !> An open writer.
        class(results_writer_t), intent(inout) :: self
        !> Number of time steps done (0 for a static or modal analysis).
        integer, intent(in) :: steps
        !> The run's clock (started at the start of this run's analysis; resumed at a restart).
        type(progress_t), intent(in) :: clock
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: last_run
        call require_open(self, 'write_summary', error)
        if (allocated(error)) return
        last_run = clock%elapsed()
        call self%file%write_attribute('/summary', 'steps', steps, error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'wall_seconds', clock%earlier_seconds + last_run, error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'wall_seconds_last_run', last_run, error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'runs', clock%runs, error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'ended', iso_date_time(), error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'threads', thread_setting(), error)
    end subroutine writer_write_summary

    !> Write what HDF5 buffers to the file: called after every output, so that a killed run
    !> leaves a readable file with every output up to this one.
    subroutine writer_flush(self, error)
        !> An open writer.
        class(results_writer_t), intent(inout) :: self
        !> Set when the data cannot be written (disk full, quota, file size limit).
        type(error_t), allocatable, intent(out) :: error
        call require_open(self, 'flush', error)
        if (allocated(error)) return
        call self%file%flush(error)
        if (allocated(error)) error%message = 'results: '//error%message
    end subroutine writer_flush

    !> Flush the output just stored, then count it: /summary@outputs, overwritten in place
    !> and flushed again. A kill inside the first flush can leave that output incomplete
    !> (HDF5 writes the flush's metadata and values in its own order: a series may count the
    !> record before its values are written); the count then still names the outputs before
    !> it, which the first flush of each had written whole. The second flush writes that
    !> attribute's header alone.
    subroutine writer_flush_output(self, error)
        !> An open writer.
        class(results_writer_t), intent(inout) :: self
        !> Set when the data cannot be written (disk full, quota, file size limit).
        type(error_t), allocatable, intent(out) :: error
        call self%flush(error)
        if (allocated(error)) return
        self%outputs = self%outputs + 1
        call self%file%write_attribute('/summary', 'outputs', self%outputs, error)
        if (allocated(error)) then
            error%message = 'results: '//error%message
            return
        end if
        call self%flush(error)
    end subroutine writer_flush_output

    !> Record that the run stops early (a signal) after storing its state at time `t`.
    subroutine writer_stop_at(self, signal, step, t)
        !> An open writer.
        class(results_writer_t), intent(inout) :: self
        !> Name of the signal ('SIGTERM', ...).
        character(len=*), intent(in) :: signal
        !> Last time step done.
        integer(int64), intent(in) :: step
        !> Time of that step, stored as the last output [s].
        real(wp), intent(in) :: t
        character(len=40) :: sbuf, tbuf
        write (sbuf, '(i0)') step
        write (tbuf, '(es16.8e3)') t
        self%stop_reason = 'signal '//signal//' at step '//trim(sbuf)//', t = '// &
                           trim(adjustl(tbuf))//' s'
        self%stop_time = t
    end subroutine writer_stop_at

    !> Whether `stop_at` was called.
    pure logical function writer_stopped(self)
        !> The writer.
        class(results_writer_t), intent(in) :: self
        writer_stopped = .false.
        if (allocated(self%stop_reason)) writer_stopped = len(self%stop_reason) > 0
    end function writer_stopped

    !> Close the file and rename '<final_path>.partial' to `final_path` (replacing an earlier
    !> file). If the rename fails, the results stay whole in the partial file (`kept_partial`),
    !> settled as by `close_partial`, and the earlier file is left as it was.
    subroutine writer_close(self, error)
        !> An open writer; closed on return.
        class(results_writer_t), intent(inout) :: self
        !> Set when the file cannot be closed or renamed.
        type(error_t), allocatable, intent(out) :: error
        call require_open(self, 'close', error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'finished', 1, error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'status', 'finished', error)
        if (allocated(error)) then
            call self%abort()
            error%message = 'results: '//error%message
            return
        end if
        call self%file%close(error)
        if (allocated(error)) then
            ! An HDF5 file that failed to close is not trustworthy.
            if (.not. self%resumed) call remove_file(self%partial_path)
            call put_back_partial(self)
            error%message = 'results: '//error%message
            return
        end if
        call rename_file(self%partial_path, self%final_path, error)
        if (allocated(error)) then
            error%message = 'results: '//error%message
            call keep_as_partial(self)
            return
        end if
        ! the earlier partial file set aside is settled by `settle_earlier`
        self%set_aside = .false.
        call keep_companions(self, error)
    end subroutine writer_close

    !> Close the file of a run stopped early (`stop_at`) and keep it as '<final_path>.partial'
    !> with /summary finished = 0 and status = the reason: an earlier finished result is left
    !> as it was.
    subroutine writer_close_unfinished(self, error)
        !> An open writer; closed on return.
        class(results_writer_t), intent(inout) :: self
        !> Set when the file cannot be written or closed.
        type(error_t), allocatable, intent(out) :: error
        call require_open(self, 'close', error)
        if (allocated(error)) return
        call self%file%write_attribute('/summary', 'status', self%stop_reason, error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'ended', &
                                                                   iso_date_time(), error)
        if (allocated(error)) then
            call self%abort()
            error%message = 'results: '//error%message
            return
        end if
        call self%file%close(error)
        if (allocated(error)) then
            error%message = 'results: '//error%message
            return
        end if
        ! the earlier partial file set aside is settled by `settle_earlier`
        self%set_aside = .false.
        call keep_companions(self, error)
    end subroutine writer_close_unfinished

    !> Close the file of a run that ended, whose end after its final checkpoint cannot be
    !> completed (its XDMF file cannot be written), with no more writes to it: it keeps the name
    !> '<final_path>.partial' and /summary finished = 0, whole, as a run killed there leaves it
    !> (`kept_partial`). As after `close_unfinished`, the earlier partial file set aside is left
    !> to `settle_earlier` and the files beside the results get their final names. When the file
    !> cannot be closed (HDF5 writes its last metadata then), it is not trusted: as `abort`.
    subroutine writer_close_partial(self, error)
        !> An open writer; closed on return.
        class(results_writer_t), intent(inout) :: self
        !> Set when the file cannot be closed (then deleted, but a resumed one).
        type(error_t), allocatable, intent(out) :: error
        call require_open(self, 'close_partial', error)
        if (allocated(error)) return
        call self%file%close(error)
        if (allocated(error)) then
            if (.not. self%resumed) call remove_file(self%partial_path)
            call put_back_partial(self)
            call drop_companions(self)
            error%message = 'results: '//error%message
            return
        end if
        call keep_as_partial(self)
    end subroutine writer_close_partial

    !> The file of a run that ended is closed whole as '<final_path>.partial': the earlier
    !> partial file set aside is left to `settle_earlier`, the files beside the results get their
    !> final names (one whose rename fails stays '.partial', which a restart takes over: `adopt`).
    subroutine keep_as_partial(self)
        !> The writer, closed.
        class(results_writer_t), intent(inout) :: self
        type(error_t), allocatable :: ignored
        self%kept_partial = .true.
        self%set_aside = .false.
        call keep_companions(self, ignored)
    end subroutine keep_as_partial

    !> Close and delete the partial file after a failed run (an earlier result is untouched)
    !> and put back the earlier partial file set aside for it. A resumed partial file is
    !> kept: it holds the outputs of the earlier part of the run, and a restart from the
    !> checkpoint cuts what came after it; a copy of the finished file made to continue it is
    !> removed.
    subroutine writer_abort(self)
        !> The writer; closed on return.
        class(results_writer_t), intent(inout) :: self
        type(error_t), allocatable :: ignored
        if (self%file%is_open()) then
            call self%file%close(ignored)
            if (.not. self%resumed) call remove_file(self%partial_path)
        end if
        call put_back_partial(self)
        call drop_companions(self)
    end subroutine writer_abort

    !> Count the outputs stored before the time loop's first step (the initial state's in a
    !> fresh run, the checkpoint's at a restart): a failure keeps the records of a run that
    !> stored outputs after them (`keeps_failure`).
    subroutine writer_begin_loop(self)
        !> The open writer.
        class(results_writer_t), intent(inout) :: self
        self%loop_outputs = self%outputs
    end subroutine writer_begin_loop

    !> Record that the time loop failed in step `step` (a failure of the step, such as its
    !> solver, or of a guard after it; an internal error there too), the results file
    !> untouched since its last output: not for a failed write, after which the file may be
    !> unsound.
    subroutine writer_fail_at(self, step, t)
        !> The open writer.
        class(results_writer_t), intent(inout) :: self
        !> The step that failed.
        integer(int64), intent(in) :: step
        !> The time that step reaches [s].
        real(wp), intent(in) :: t
        self%failed_step = step
        self%failed_time = t
    end subroutine writer_fail_at

    !> Whether the run, which failed, keeps its records as '<final_path>.failed'
    !> (`close_failed`): its time loop failed in a step (`fail_at`) after it stored outputs
    !> beyond those it began with (a run that fails at its first step, or before its first
    !> output, has nothing to show but its deck: it leaves nothing).
    logical function writer_keeps_failure(self)
        !> The writer.
        class(results_writer_t), intent(in) :: self
        writer_keeps_failure = self%is_open() .and. self%failed_step > 0 .and. self%outputs > self%loop_outputs
    end function writer_keeps_failure

    !> Close the file of a time loop that failed (`keeps_failure`) and keep what it holds as
    !> '<final_path>.failed' (replacing an earlier one), with /summary finished = 0, status
    !> 'failed at step N, t = T s: <the first line of `reason`>', steps N - 1 and the outputs it
    !> stored whole, as a stopped run's. The folder's other files are left as a failed run
    !> leaves them (`abort`): the earlier partial file set aside is put back, the files beside
    !> the results are deleted; a partial file continued in place (a restart) is kept as it is
    !> (the next restart cuts what came after its checkpoint) and copied to the '.failed' name.
    !> When the file cannot be written, closed, or given that name, nothing is kept: `error`
    !> says why and the file is settled as by `abort`.
    subroutine writer_close_failed(self, reason, error)
        !> An open writer; closed on return.
        class(results_writer_t), intent(inout) :: self
        !> The error of the run (its first line goes into /summary status).
        character(len=*), intent(in) :: reason
        !> Set when the records cannot be kept.
        type(error_t), allocatable, intent(out) :: error
        character(len=40) :: sbuf, tbuf
        character(len=:), allocatable :: failed
        integer :: eol
        call require_open(self, 'close_failed', error)
        if (allocated(error)) return
        failed = self%final_path//'.failed'
        write (sbuf, '(i0)') self%failed_step
        write (tbuf, '(es16.8e3)') self%failed_time
        eol = index(reason, new_line('a'))
        if (eol == 0) eol = len(reason) + 1
        call self%file%write_attribute('/summary', 'status', 'failed at step '//trim(sbuf)//', t = '// &
                                       trim(adjustl(tbuf))//' s: '//reason(:eol - 1), error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'steps', &
                                                                   int(self%failed_step - 1), error)
        if (.not. allocated(error)) call self%file%write_attribute('/summary', 'ended', iso_date_time(), error)
        if (allocated(error)) then
            call self%abort()
            error%message = 'results: '//error%message
            return
        end if
        call self%file%close(error)
        if (.not. allocated(error)) then
            if (self%resumed) then
                call copy_file(self%partial_path, failed, error)
            else
                call rename_file(self%partial_path, failed, error)
            end if
        end if
        if (allocated(error)) then
            if (.not. self%resumed) call remove_file(self%partial_path)
            error%message = 'results: '//error%message
        end if
        call put_back_partial(self)
        call drop_companions(self)
    end subroutine writer_close_failed

    !> Before this run creates '<partial_path>': rename the partial file of an earlier run,
    !> if any, to '<partial_path>.prev' (`abort` puts it back). When '<partial_path>.prev'
    !> already holds the results `keep` (those of the folder's checkpoint, set aside by a run
    !> that was then killed) and the partial file does not, the partial file is deleted
    !> instead: it is a killed run's, or an earlier state of the checkpoint's run with fewer
    !> records than the checkpoint (a copy of its finished file that a restart killed before it
    !> ended left), which no restart continues; the rename would replace the only copy of the
    !> results the checkpoint continues.
    subroutine set_aside_partial(self, keep, error)
        !> The writer, partial_path set, not open.
        class(results_writer_t), intent(inout) :: self
        !> The results whose file set aside is kept (run id '': none).
        type(results_mark_t), intent(in) :: keep
        !> Set if the rename fails.
        type(error_t), allocatable, intent(out) :: error
        self%set_aside = .false.
        if (.not. file_exists(self%partial_path)) return
        if (keep%held_by(self%partial_path//'.prev')) then
            if (.not. keep%held_by(self%partial_path)) then
                call remove_file(self%partial_path)
                if (file_exists(self%partial_path)) &
                    call make_error(error, "results: cannot delete '"//self%partial_path//"', the partial file of a killed run")
                return
            end if
        end if
        call rename_file(self%partial_path, self%partial_path//'.prev', error)
        if (allocated(error)) then
            error%message = 'results: '//error%message//' (the partial file of an earlier run, kept '// &
                            'until this run ends)'
            return
        end if
        self%set_aside = .true.
    end subroutine set_aside_partial

    !> Give the earlier partial file set aside its name back (after this run failed).
    subroutine put_back_partial(self)
        !> The writer, closed.
        class(results_writer_t), intent(inout) :: self
        type(error_t), allocatable :: ignored
        if (.not. self%set_aside) return
        call rename_file(self%partial_path//'.prev', self%partial_path, ignored)
        self%set_aside = .false.
    end subroutine put_back_partial

    !> After the run ended or was stopped (`close`, `close_unfinished`): settle
    !> '<partial_path>.prev', the partial file of an earlier run that this run set aside, or that
    !> a run started afresh set aside and, killed, never put back. It is deleted, unless it holds
    !> the results `keep` (those of the folder's checkpoint, when this run wrote none: a static or
    !> modal analysis), which a restart from that checkpoint continues: it gets its name
    !> '<partial_path>' back (this run's file was renamed to its final name), so that the command
    !> the interrupted run printed still continues it.
    subroutine writer_settle_earlier(self, keep)
        !> The writer, closed.
        class(results_writer_t), intent(inout) :: self
        !> The results whose file is kept (run id '': none).
        type(results_mark_t), intent(in) :: keep
        type(error_t), allocatable :: ignored
        if (.not. allocated(self%partial_path)) return
        if (keep%held_by(self%partial_path//'.prev')) then
            ! (not this run's own results: a run that ends holds the results of its own
            ! checkpoint under the final name, and a '.prev' of the same run is an earlier copy of
            ! it; given its name back it was continued by the next restart instead of the
            ! finished file)
            if (keep%run_id /= self%run_id) then
                ! kept as '.prev' if the name is taken or the rename fails: a restart continues it
                if (.not. file_exists(self%partial_path)) &
                    call rename_file(self%partial_path//'.prev', self%partial_path, ignored)
                return
            end if
        end if
        call remove_file(self%partial_path//'.prev')
    end subroutine writer_settle_earlier

    !> Register `path`, a file this run writes beside the results, and return the name to
    !> write it under, '<path>.partial': `close` and `close_unfinished` rename it to `path`,
    !> `abort` deletes it.
    subroutine writer_companion(self, path, partial)
        !> The writer.
        class(results_writer_t), intent(inout) :: self
        !> Final path of the file.
        character(len=*), intent(in) :: path
        !> Path to write it under while the run goes on.
        character(len=:), allocatable, intent(out) :: partial
        if (.not. allocated(self%companions)) self%companions = [string_t ::]
        if (.not. allocated(self%own)) self%own = [logical ::]
        self%companions = [self%companions, string_t(path)]
        self%own = [self%own, .true.]
        partial = path//'.partial'
    end subroutine writer_companion

    !> A restart takes over '<path>.partial', a file beside the results that the interrupted
    !> run wrote and closed before its checkpoint but did not rename (killed by SIGKILL, a node
    !> failure): `close` and `close_unfinished` give it its name, `abort` leaves it (the
    !> interrupted run's, as the folder was). Nothing when there is no such file.
    subroutine writer_adopt(self, path)
        !> The writer.
        class(results_writer_t), intent(inout) :: self
        !> Final path of the file.
        character(len=*), intent(in) :: path
        if (.not. file_exists(path//'.partial')) return
        if (.not. allocated(self%companions)) self%companions = [string_t ::]
        if (.not. allocated(self%own)) self%own = [logical ::]
        self%companions = [self%companions, string_t(path)]
        self%own = [self%own, .false.]
    end subroutine writer_adopt

    !> Give the files written beside the results their final names (the run ended or was
    !> stopped: its files are the folder's now).
    subroutine keep_companions(self, error)
        !> The writer.
        class(results_writer_t), intent(inout) :: self
        !> Set if a rename fails (the file stays '.partial'; the error names it).
        type(error_t), allocatable, intent(out) :: error
        integer :: i
        if (.not. allocated(self%companions)) return
        do i = 1, size(self%companions)
            associate (path => self%companions(i)%s)
                if (.not. file_exists(path//'.partial')) cycle
                call rename_file(path//'.partial', path, error)
                if (allocated(error)) then
                    error%message = 'results: '//error%message//" (the file is kept as '"//path//".partial')"
                    return
                end if
            end associate
        end do
        self%companions = [string_t ::]
        self%own = [logical ::]
    end subroutine keep_companions

    !> Delete the files this run wrote beside the results (it failed).
    subroutine drop_companions(self)
        !> The writer.
        class(results_writer_t), intent(inout) :: self
        integer :: i
        if (.not. allocated(self%companions)) return
        do i = 1, size(self%companions)
            if (self%own(i)) call remove_file(self%companions(i)%s//'.partial')
        end do
        self%companions = [string_t ::]
        self%own = [logical ::]
    end subroutine drop_companions

    !> Whether a results file is being written.
    pure logical function writer_is_open(self)
        !> The writer.
        class(results_writer_t), intent(in) :: self
        writer_is_open = self%file%is_open()
    end function writer_is_open

    !> Error unless the writer is open.
    subroutine require_open(self, what, error)
        !> The writer.
        type(results_writer_t), intent(in) :: self
        !> Name of the operation.
        character(len=*), intent(in) :: what
        !> Set when the writer is not open.
        type(error_t), allocatable, intent(out) :: error
        if (.not. self%is_open()) then
            call make_internal_error(error, 'results: '//what, 'no results file is open')
        end if
    end subroutine require_open

    !> Identifier of a new run: local date-time and the processor clock count.
    function new_run_id() result(text)
        character(len=:), allocatable :: text
        character(len=24) :: buf
        integer(int64) :: count
        call system_clock(count)
        write (buf, '(i0)') count
        text = iso_date_time()//' '//trim(buf)
    end function new_run_id

    !> Local date and time as ISO 8601, e.g. '2025-01-31T14:05:09+01:00'.
    function iso_date_time() result(text)
        !> The date-time.
        character(len=:), allocatable :: text
        character(len=8) :: date
        character(len=10) :: time
        character(len=5) :: zone
        call date_and_time(date, time, zone)
        text = date(1:4)//'-'//date(5:6)//'-'//date(7:8)//'T'//time(1:2)//':'//time(3:4)//':' &
               //time(5:6)//zone(1:3)//':'//zone(4:5)
    end function iso_date_time
end module driver_results
