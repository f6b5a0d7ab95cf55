!> The checkpoint file (driver_checkpoint): its header (format, code version, hash of the
!> deck, kind of run, time, run id, threads, loop counters), the checks a restart makes on the
!> checkpoint it opens (this deck, this code version, this kind of run), and the checkpoints
!> of one run (`checkpoint_run_t`).
!>
!> The file is written as '<path>.tmp' and renamed to `path` (atomic on POSIX): a kill
!> during the write leaves the previous checkpoint intact. Before a run replaces the
!> checkpoint it found (an earlier run's, or the one it restarts from) for the first time,
!> that one gets the second name '<path>.prev' (a hard link): a run that fails puts it back
!> (`checkpoint_run_t%revert`), a run that ends or is stopped by a signal deletes it
!> (`settle`), with a '<path>.tmp' that a run killed during a write left.
module driver_checkpoint_file
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_version, only: multicor_version
    use core_threads, only: thread_setting
    use io_hdf5_file, only: h5_file_t
    use io_paths, only: rename_file, remove_file, file_exists, link_or_copy_file
    use driver_checkpoint_loop, only: loop_state_t, checkpoint_schedule_t, save_loop, load_loop
    implicit none
    private
    public :: checkpoint_name, deck_hash, checkpoint_run_t
    public :: checkpoint_create, checkpoint_commit, checkpoint_open, checkpoint_discard, checkpoint_owner

    !> File name of the checkpoint in the results folder.
    character(len=*), parameter :: checkpoint_name = 'checkpoint.h5'
    !> Format tag written in every checkpoint: its layout number goes up when the layout
    !> changes within a code version (2: the particle writer's count of steps whose bonded
    !> block was given up; 3: and of those given up unconverged at its cap; 4: and of the
    !> steps whose give-up at the cap was taken back), so that a checkpoint of an earlier
    !> build is refused by name.
    character(len=*), parameter :: format_stem = 'MULTICOR checkpoint '
    character(len=*), parameter :: format_tag = format_stem//'4'
    !> States of `checkpoint_run_t%found`.
    integer, parameter :: found_unknown = 0, found_kept = 1, found_none = 2
    !> Checkpoints of one run: where and when to write them, and the checkpoint a restart
    !> starts from.
    type :: checkpoint_run_t
        !> Where checkpoints are written ('<results folder>/checkpoint.h5').
        character(len=:), allocatable :: path
        !> The deck's text followed by what stands for the files it reads (a mesh's hash), hashed
        !> into every checkpoint.
        character(len=:), allocatable :: deck_text
        !> Name of the run's results file in the folder ('deck.h5'), recorded in every
        !> checkpoint (root attribute 'results'; `checkpoint_owner`).
        character(len=:), allocatable :: results
        !> When to write them besides signals and the end.
        type(checkpoint_schedule_t) :: schedule
        !> Whether the run continues from `source`.
        logical :: restart = .false.
        !> The checkpoint a restart reads (open while the loop loads it).
        type(h5_file_t) :: source
        !> Loop counters at the checkpoint of a restart.
        type(loop_state_t) :: start
        !> Step and time of the last checkpoint written by this run (-1: none yet).
        integer(i8) :: last_step = -1
        !> Time of the state in the last checkpoint written [s].
        real(wp) :: last_time = 0.0_wp
        !> The checkpoint this run found at `path`: not looked at yet (before the run's first
        !> commit), kept as '<path>.prev', or none.
        integer, private :: found = found_unknown
    contains
        !> End the checkpoint being written: committed, or discarded after a failed write.
        procedure :: finish => checkpoint_run_finish
        !> After a failed run: the checkpoint it found at `path` back in place (or none).
        procedure :: revert => checkpoint_run_revert
        !> After a run that ended or was stopped: its own checkpoint stays, the one it found
        !> is deleted.
        procedure :: settle => checkpoint_run_settle
    end type checkpoint_run_t
contains

    !> Hash of a deck's text: 16 hexadecimal digits (two polynomial hashes modulo primes below
    !> 2**31, and the length); it tells decks apart, it is not a cryptographic digest.
    pure function deck_hash(text) result(hex)
        !> The deck's text.
        character(len=*), intent(in) :: text
        character(len=16) :: hex
        integer(i8), parameter :: p1 = 2147483647_i8, p2 = 2147483629_i8
        integer(i8) :: h1, h2
        integer :: i
        h1 = int(len(text), i8)
        h2 = 7_i8
        do i = 1, len(text)
            h1 = mod(h1*257_i8 + int(ichar(text(i:i)), i8), p1)
            h2 = mod(h2*263_i8 + int(ichar(text(i:i)), i8) + 1_i8, p2)
        end do
        write (hex, '(z8.8,z8.8)') h1, h2
    end function deck_hash

    !> Create '<path>.tmp' and write the header.
    subroutine checkpoint_create(file, path, deck_text, kind, loop, time, run_id, error)
        !> The checkpoint file (closed on entry).
        type(h5_file_t), intent(inout) :: file
        !> Final name of the checkpoint.
        character(len=*), intent(in) :: path
        !> The deck's text.
        character(len=*), intent(in) :: deck_text
        !> Kind of run: 'beam', 'particles', 'coupled', 'continuum' or 'coupled2d'.
        character(len=*), intent(in) :: kind
        !> The loop's counters.
        type(loop_state_t), intent(in) :: loop
        !> Time of the state [s].
        real(wp), intent(in) :: time
        !> Root attribute 'run_id' of the results file (identifies the run).
        character(len=*), intent(in) :: run_id
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create(path//'.tmp', error, checksums=.true.)
        if (allocated(error)) return
        call file%write_attribute('/', 'format', format_tag, error)
        if (allocated(error)) return
        call file%write_attribute('/', 'code_version', multicor_version, error)
        if (allocated(error)) return
        call file%write_attribute('/', 'deck_hash', deck_hash(deck_text), error)
        if (allocated(error)) return
        call file%write_attribute('/', 'kind', kind, error)
        if (allocated(error)) return
        call file%write_attribute('/', 'time', time, error)
        if (allocated(error)) return
        call file%write_attribute('/', 'run_id', run_id, error)
        if (allocated(error)) return
        call file%write_attribute('/', 'threads', thread_setting(), error)
        if (allocated(error)) return
        call save_loop(file, loop, error)
    end subroutine checkpoint_create

    !> Close '<path>.tmp' and rename it to `path` (replacing the previous checkpoint).
    subroutine checkpoint_commit(file, path, error)
        !> The checkpoint file being written; closed on return.
        type(h5_file_t), intent(inout) :: file
        !> Final name of the checkpoint.
        character(len=*), intent(in) :: path
        !> Set when the file cannot be closed or renamed.
        type(error_t), allocatable, intent(out) :: error
        call file%close(error)
        if (allocated(error)) then
            call remove_file(path//'.tmp')
            return
        end if
        call rename_file(path//'.tmp', path, error)
    end subroutine checkpoint_commit

    !> Close and delete '<path>.tmp' after a failed write (the previous checkpoint stays).
    subroutine checkpoint_discard(file, path)
        !> The checkpoint file being written; closed on return.
        type(h5_file_t), intent(inout) :: file
        !> Final name of the checkpoint.
        character(len=*), intent(in) :: path
        type(error_t), allocatable :: ignored
        call file%close(ignored)
        call remove_file(path//'.tmp')
    end subroutine checkpoint_discard

    !> End the checkpoint `file` being written for step k (time t): after a failure while
    !> writing it (`error` set on entry) the partial file is discarded and the error kept, the
    !> previous checkpoint staying; otherwise it is committed and becomes the run's last one.
    subroutine checkpoint_run_finish(self, file, k, t, error)
        !> The run's checkpoints.
        class(checkpoint_run_t), intent(inout) :: self
        !> The checkpoint being written (from checkpoint_create); closed on return.
        type(h5_file_t), intent(inout) :: file
        !> Step of the state written.
        integer(i8), intent(in) :: k
        !> Time of the state written [s].
        real(wp), intent(in) :: t
        !> The error of the writes (kept), or set when the commit fails.
        type(error_t), allocatable, intent(inout) :: error
        if (.not. allocated(error) .and. allocated(self%results)) &
            call file%write_attribute('/', 'results', self%results, error)
        if (allocated(error)) then
            call checkpoint_discard(file, self%path)
            return
        end if
        if (self%found == found_unknown) then
            self%found = found_none
            if (file_exists(self%path)) then
                call link_or_copy_file(self%path, self%path//'.prev', error)
                if (allocated(error)) then
                    call checkpoint_discard(file, self%path)
                    error%message = 'checkpoint: '//error%message//' (the checkpoint found in the folder, '// &
                                    'kept until this run ends)'
                    return
                end if
                self%found = found_kept
            end if
        end if
        call checkpoint_commit(file, self%path, error)
        if (allocated(error)) return
        self%last_step = k
        self%last_time = t
    end subroutine checkpoint_run_finish

    !> Whose checkpoint lies at `path`: the hash of its deck, the name of its results file
    !> ('' when the checkpoint does not record it), the run id of its results, and the step
    !> and time it holds; `found` is false when there is no checkpoint there or it cannot be
    !> read (a restart from it says why).
    subroutine checkpoint_owner(path, found, hash, results, run_id, step, time, this_build)
        !> Path of the checkpoint.
        character(len=*), intent(in) :: path
        !> A checkpoint could be read there.
        logical, intent(out) :: found
        !> Its 'deck_hash' and 'results' root attributes.
        character(len=:), allocatable, intent(out) :: hash, results
        !> Its 'run_id' root attribute, that of its results file ('' when not found).
        character(len=:), allocatable, intent(out) :: run_id
        !> Its step (/loop@step; -1 when it cannot be read).
        integer, intent(out), optional :: step
        !> Its time (root attribute 'time') [s] (0 when it cannot be read).
        real(wp), intent(out), optional :: time
        !> Whether this build can continue it: its layout ('format') and code version are this
        !> build's (a restart refuses another's).
        logical, intent(out), optional :: this_build
        character(len=:), allocatable :: text
        type(h5_file_t) :: file
        type(error_t), allocatable :: error, ignored
        found = .false.
        hash = ''
        results = ''
        run_id = ''
        if (present(step)) step = -1
        if (present(time)) time = 0.0_wp
        if (present(this_build)) this_build = .false.
        if (.not. file_exists(path)) return
        call file%open(path, error)
        if (allocated(error)) return
        call file%read_attribute('/', 'deck_hash', hash, error)
        found = .not. allocated(error)
        ! (a checkpoint of an older version has no 'results')
        if (found) call file%read_attribute('/', 'results', results, ignored)
        if (allocated(ignored)) results = ''
        if (found) call file%read_attribute('/', 'run_id', run_id, ignored)
        if (allocated(ignored)) run_id = ''
        if (found .and. present(step)) then
            call file%read_attribute('/loop', 'step', step, ignored)
            if (allocated(ignored)) step = -1
        end if
        if (found .and. present(time)) then
            call file%read_attribute('/', 'time', time, ignored)
            if (allocated(ignored)) time = 0.0_wp
        end if
        if (found .and. present(this_build)) then
            call file%read_attribute('/', 'format', text, ignored)
            this_build = .not. allocated(ignored)
            if (this_build) this_build = text == format_tag
            if (this_build) call file%read_attribute('/', 'code_version', text, ignored)
            if (this_build) this_build = .not. allocated(ignored)
            if (this_build) this_build = text == multicor_version
        end if
        call file%close(ignored)
    end subroutine checkpoint_owner

    !> After a failed run: the checkpoint found at `path` before the run's first commit is
    !> put back, or, when there was none, the run's own is deleted (it belongs to results
    !> the failure deleted, or to a restart that leaves the state it started from).
    subroutine checkpoint_run_revert(self)
        !> The run's checkpoints.
        class(checkpoint_run_t), intent(inout) :: self
        type(error_t), allocatable :: ignored
        select case (self%found)
        case (found_kept)
            call rename_file(self%path//'.prev', self%path, ignored)
            ! still there when both names were one file (the commit never replaced it)
            call remove_file(self%path//'.prev')
        case (found_none)
            call remove_file(self%path)
        end select
        self%found = found_unknown
        self%last_step = -1
    end subroutine checkpoint_run_revert

    !> After a run that ended or was stopped by a signal: its own last checkpoint stays at
    !> `path`, the one it found there is deleted, and so is a '<path>.tmp' left by a run
    !> killed while it wrote a checkpoint (kill -9, a crash): nothing reads it, and the run's
    !> own '.tmp' files were each renamed or deleted (one run at a time writes a folder).
    subroutine checkpoint_run_settle(self)
        !> The run's checkpoints.
        class(checkpoint_run_t), intent(inout) :: self
        if (self%found == found_kept) call remove_file(self%path//'.prev')
        if (allocated(self%path)) call remove_file(self%path//'.tmp')
        self%found = found_unknown
    end subroutine checkpoint_run_settle

    !> Open a checkpoint for reading and check it belongs to this deck, this code version and
    !> this kind of run.
    subroutine checkpoint_open(file, path, deck_file, deck_text, kind, loop, run_id, error)
        !> The checkpoint file (closed on entry; open on success).
        type(h5_file_t), intent(inout) :: file
        !> Path of the checkpoint.
        character(len=*), intent(in) :: path
        !> Deck path (for messages).
        character(len=*), intent(in) :: deck_file
        !> The deck's text.
        character(len=*), intent(in) :: deck_text
        !> Kind of run of the deck: 'beam', 'particles', 'coupled', 'continuum' or 'coupled2d'.
        character(len=*), intent(in) :: kind
        !> The loop's counters at the checkpoint.
        type(loop_state_t), intent(out) :: loop
        !> Root attribute 'run_id' of the results file of the run.
        character(len=:), allocatable, intent(out) :: run_id
        !> Set when the file is not a checkpoint of this deck and code.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: tag, version, hash, ckind
        type(error_t), allocatable :: ignored
        if (.not. file_exists(path)) then
            call make_error(error, "--restart: no checkpoint '"//path//"'")
            return
        end if
        call file%open(path, error)
        if (allocated(error)) then
            call make_error(error, "--restart: '"//path//"' is not an HDF5 file")
            return
        end if
        call file%read_attribute('/', 'format', tag, error)
        if (allocated(error)) tag = ''
        if (tag /= format_tag) then
            if (index(tag, format_stem) == 1) then
                call refuse("checkpoint '"//path//"' has the layout of an earlier build ('"//trim(tag)// &
                            "', this build reads '"//format_tag//"'): continue the run with the build that "// &
                            'wrote it, or run the deck from the start')
            else
                call refuse("'"//path//"' is not a MULTICOR checkpoint")
            end if
            return
        end if
        call file%read_attribute('/', 'code_version', version, error)
        if (.not. allocated(error)) call file%read_attribute('/', 'deck_hash', hash, error)
        if (.not. allocated(error)) call file%read_attribute('/', 'kind', ckind, error)
        if (.not. allocated(error)) call file%read_attribute('/', 'run_id', run_id, error)
        if (allocated(error)) then
            call refuse("'"//path//"' is an incomplete checkpoint")
            return
        end if
        if (version /= multicor_version) then
            call refuse("checkpoint '"//path//"' was written by MULTICOR "//version// &
                        ', this is MULTICOR '//multicor_version//': a restart needs the same code '// &
                        'version (run the deck from the start, or use that version)')
        else if (hash /= deck_hash(deck_text)) then
            call refuse("checkpoint '"//path//"' was written for another deck (deck hash "// &
                        hash//", '"//deck_file//"' has "//deck_hash(deck_text)//'; the hash covers '// &
                        'the deck and the mesh file it reads): restart with the deck of that run and '// &
                        'its mesh, unchanged (a new end time goes on the command line: --end)')
        else if (ckind /= kind) then
            call refuse("checkpoint '"//path//"' holds a "//ckind//' run, the deck is a '//kind//' run')
        else
            call load_loop(file, loop, error)
            if (allocated(error)) then
                call file%close(ignored)
                error%message = "--restart: '"//path//"': "//error%message
                return
            end if
            ! absent from the checkpoints of an earlier build
            call file%read_attribute('/', 'threads', loop%threads, ignored)
            if (allocated(ignored)) loop%threads = ''
        end if
    contains
        subroutine refuse(message)
            character(len=*), intent(in) :: message
            call file%close(ignored)
            call make_error(error, '--restart: '//message)
        end subroutine refuse
    end subroutine checkpoint_open
end module driver_checkpoint_file
