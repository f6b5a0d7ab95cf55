!> Checkpoints of a time loop and restart from them (doc/output.md, "Checkpoints and restart").
!>
!> A checkpoint is an HDF5 file holding everything a time loop needs to go on as if it had
!> never stopped: the mutable state of the models (Newmark state of a beam or a 2D continuum;
!> Moreau-Jean state of the disks and walls, the contact list with its reactions and statuses
!> for the warm start, bond states and the rupture log; multipliers and constraint state of a
!> coupling, with a beam or a continuum),
!> the counters of the results writers and the record count of every dataset of the results
!> file, the loop's own counters (with the wall time of the analysis up to the checkpoint and
!> its number of runs, which a restart continues), and a header: code version, a hash of the deck's text, the
!> kind of run, the step. What the deck builds (meshes, matrices, materials, functions) is
!> built again from the deck at restart and not stored. There is no random state in a time
!> loop: the random deposit is generated from the deck's seed when the model is built.
!>
!> Every value read back is checked before the run uses it: reals finite, counts, step
!> numbers, body numbers and codes in their ranges, array sizes those of the deck's model;
!> anything else is refused as 'the checkpoint is damaged', naming the value, before the
!> results file is written to.
!>
!> The file is written as '<path>.tmp' and renamed to `path` (atomic on POSIX): a kill
!> during the write leaves the previous checkpoint intact. Before a run replaces the
!> checkpoint it found (an earlier run's, or the one it restarts from) for the first time,
!> that one gets the second name '<path>.prev' (a hard link): a run that fails puts it back
!> (`checkpoint_run_t%revert`), a run that ends or is stopped by a signal deletes it
!> (`settle`).
module driver_checkpoint
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error, make_internal_error
    use core_version, only: multicor_version
    use core_signals, only: caught_signal
    use core_threads, only: thread_setting
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use io_paths, only: rename_file, remove_file, file_exists, link_or_copy_file
    use fem_newmark, only: time_integrator_t, newmark_t, central_difference_t
    use dem_contacts, only: contacts_list_problem
    use dem_moreau_jean, only: dem_system_t
    use dem_nlgs, only: nlgs_stats_t
    use dem_solve_method, only: sweeps_method_t
    use dem_bonded_block, only: bonded_block_method_t, bonded_block_restore
    use coupling_arlequin, only: coupled_system_t
    use driver_results, only: results_writer_t
    use driver_results_dem, only: dem_writer_t
    use driver_results_coupled, only: coupled_writer_t
    implicit none
    private
    public :: checkpoint_name, deck_hash, loop_state_t, checkpoint_schedule_t
    public :: checkpoint_create, checkpoint_commit, checkpoint_open, checkpoint_discard
    public :: save_integrator, load_integrator, save_dem, load_dem, save_coupled, load_coupled
    public :: save_results, load_results, save_dem_writer, load_dem_writer
    public :: save_coupled_writer, load_coupled_writer, save_loop, load_loop
    public :: checkpoint_run_t, step_end_t, end_of_step, read_finite_attribute, checkpoint_owner

    !> File name of the checkpoint in the results folder.
    character(len=*), parameter :: checkpoint_name = 'checkpoint.h5'
    !> Format tag written in every checkpoint.
    character(len=*), parameter :: format_tag = 'MULTICOR checkpoint 1'
    !> What the attribute 'scalars' of an integrator's group holds (for messages).
    character(len=*), parameter :: integrator_scalars(9) = [character(len=20) :: &
                                                            'time', 'time step', 'start time', 'kinetic energy', &
                                                            'strain energy', 'external work', 'damping dissipation', &
                                                            'initial energy', 'coupling work']
    !> What the attribute 'scalars' of a particle system's group holds (for messages).
    character(len=*), parameter :: dem_scalars(13) = [character(len=20) :: &
                                                      'time', 'detection seconds', 'solver seconds', 'kinetic energy', &
                                                      'potential energy', 'external work', 'drive work', &
                                                      'contact dissipation', 'numerical dissip.', 'initial energy', &
                                                      'coupling work', 'solver error', 'solver residual']
    !> States of `checkpoint_run_t%found`.
    integer, parameter :: found_unknown = 0, found_kept = 1, found_none = 2

    !> Counters of a time loop that the results depend on.
    type :: loop_state_t
        !> Steps done.
        integer(i8) :: step = 0
        !> Unconverged steps so far.
        integer :: unconverged = 0
        !> Warnings given once: disk faster than the alert distance, blocked contacts, bonded
        !> coupled disks rotated beyond the range of the linear coupling.
        logical :: speed_warned = .false., blocked_warned = .false., rotation_warned = .false.
        !> Wall time of the analysis up to this state, every run that led to it [s].
        real(wp) :: wall_seconds = 0.0_wp
        !> Runs that led to this state (1 + the restarts).
        integer :: runs = 1
        !> False for a checkpoint of an earlier build, which recorded neither: the wall time
        !> of the runs before it is unknown (counted as 0, and 1 run).
        logical :: wall_recorded = .true.
        !> Parallel setting of the run that wrote the checkpoint (core_threads; '' when the
        !> checkpoint does not record it). Not written with the loop: read by checkpoint_open.
        character(len=:), allocatable :: threads
    end type loop_state_t

    !> When a time loop writes a checkpoint (besides signals and the end of the run).
    type :: checkpoint_schedule_t
        !> Every this many steps (0: never).
        integer :: every = 0
        !> Every this many seconds of wall time (0: never).
        real(wp) :: seconds = 0.0_wp
        !> Clock count of the last checkpoint (or of the start).
        integer(i8), private :: last = 0
        !> Clock rate.
        integer(i8), private :: rate = 1
    contains
        !> Start the wall-time clock.
        procedure :: start => schedule_start
        !> Whether a checkpoint is due after step k (restarts the clock when it is).
        procedure :: due => schedule_due
    end type checkpoint_schedule_t

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

    !> What the end of a step of a time loop calls for, to be done in this order: the regular
    !> output (`store_first`), the checkpoint, the extra output of the last step or of a stop
    !> (`store_last`; never with `store_first`), then the end of the loop (`stop`).
    type :: step_end_t
        !> Store the regular output of the step.
        logical :: store_first = .false.
        !> Write a checkpoint (last step, stop request, or due by the schedule).
        logical :: checkpoint = .false.
        !> Store the extra output of the last step or of a stop.
        logical :: store_last = .false.
        !> A stop signal came before the last step: the loop ends at this step.
        logical :: stop = .false.
    end type step_end_t

contains

    !> Start the wall-time clock of a schedule.
    subroutine schedule_start(self)
        !> The schedule.
        class(checkpoint_schedule_t), intent(inout) :: self
        call system_clock(self%last, self%rate)
        if (self%rate <= 0) self%rate = 1
    end subroutine schedule_start

    !> Whether a checkpoint is due after step k: every `every` steps or once `seconds` of wall
    !> time have passed since the last one.
    logical function schedule_due(self, k)
        !> The schedule.
        class(checkpoint_schedule_t), intent(inout) :: self
        !> Steps done.
        integer(i8), intent(in) :: k
        integer(i8) :: now
        schedule_due = .false.
        if (self%every > 0) schedule_due = mod(k, int(self%every, i8)) == 0
        if (self%seconds > 0.0_wp .and. .not. schedule_due) then
            call system_clock(now)
            schedule_due = real(now - self%last, wp)/real(self%rate, wp) >= self%seconds
        end if
        if (schedule_due) call system_clock(self%last)
    end function schedule_due

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

    !> Whose checkpoint lies at `path`: the hash of its deck and the name of its results file
    !> ('' when the checkpoint does not record it); `found` is false when there is no
    !> checkpoint there or it cannot be read (a restart from it says why).
    subroutine checkpoint_owner(path, found, hash, results)
        !> Path of the checkpoint.
        character(len=*), intent(in) :: path
        !> A checkpoint could be read there.
        logical, intent(out) :: found
        !> Its 'deck_hash' and 'results' root attributes.
        character(len=:), allocatable, intent(out) :: hash, results
        type(h5_file_t) :: file
        type(error_t), allocatable :: error, ignored
        found = .false.
        hash = ''
        results = ''
        if (.not. file_exists(path)) return
        call file%open(path, error)
        if (allocated(error)) return
        call file%read_attribute('/', 'deck_hash', hash, error)
        found = .not. allocated(error)
        ! (a checkpoint of an older version has no 'results')
        if (found) call file%read_attribute('/', 'results', results, ignored)
        if (allocated(ignored)) results = ''
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
    !> `path`, the one it found there is deleted.
    subroutine checkpoint_run_settle(self)
        !> The run's checkpoints.
        class(checkpoint_run_t), intent(inout) :: self
        if (self%found == found_kept) call remove_file(self%path//'.prev')
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
            call refuse("'"//path//"' is not a MULTICOR checkpoint")
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

    ! ---------------------------------------------------------------------------------------
    ! Loop counters
    ! ---------------------------------------------------------------------------------------

    !> Write the loop counters (attributes of /loop).
    subroutine save_loop(file, loop, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The counters.
        type(loop_state_t), intent(in) :: loop
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group('/loop', error)
        if (allocated(error)) return
        ! n_steps <= max_steps = huge(0) (driver_config)
        call file%write_attribute('/loop', 'step', int(loop%step), error)
        if (allocated(error)) return
        call file%write_attribute('/loop', 'unconverged', loop%unconverged, error)
        if (allocated(error)) return
        call file%write_attribute('/loop', 'speed_warned', merge(1, 0, loop%speed_warned), error)
        if (allocated(error)) return
        call file%write_attribute('/loop', 'blocked_warned', merge(1, 0, loop%blocked_warned), error)
        if (allocated(error)) return
        call file%write_attribute('/loop', 'rotation_warned', merge(1, 0, loop%rotation_warned), error)
        if (allocated(error)) return
        call file%write_attribute('/loop', 'wall_seconds', loop%wall_seconds, error)
        if (allocated(error)) return
        call file%write_attribute('/loop', 'runs', loop%runs, error)
    end subroutine save_loop

    !> Read the loop counters.
    subroutine load_loop(file, loop, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The counters.
        type(loop_state_t), intent(out) :: loop
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        call file%read_attribute('/loop', 'step', k, error)
        if (allocated(error)) return
        call require_range([k], 0, huge(0), '/loop@step', error)
        if (allocated(error)) return
        loop%step = int(k, i8)
        call file%read_attribute('/loop', 'unconverged', loop%unconverged, error)
        if (allocated(error)) return
        call require_range([loop%unconverged], 0, k, '/loop@unconverged (at most the steps done)', error)
        if (allocated(error)) return
        call read_flag('speed_warned', loop%speed_warned, error)
        if (.not. allocated(error)) call read_flag('blocked_warned', loop%blocked_warned, error)
        if (.not. allocated(error)) call read_flag('rotation_warned', loop%rotation_warned, error)
        if (.not. allocated(error)) call read_wall_time(error)
    contains
        !> Wall time and runs up to the checkpoint; both absent in a checkpoint of an earlier
        !> build (`wall_recorded` false, counted as 0 s and 1 run).
        subroutine read_wall_time(error)
            !> Set on a damaged value, or when only one of the two is there.
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: no_wall, no_runs
            real(wp) :: w
            call file%read_attribute('/loop', 'wall_seconds', w, no_wall)
            if (.not. allocated(no_wall)) call require_finite([w], '/loop@wall_seconds', no_wall)
            call file%read_attribute('/loop', 'runs', loop%runs, no_runs)
            if (allocated(no_wall) .and. allocated(no_runs)) then
                loop%wall_seconds = 0.0_wp
                loop%runs = 1
                loop%wall_recorded = .false.
                return
            end if
            if (allocated(no_wall)) then
                call move_alloc(no_wall, error)
                return
            end if
            if (allocated(no_runs)) then
                call move_alloc(no_runs, error)
                return
            end if
            if (w < 0.0_wp) then
                call damaged(error, '/loop@wall_seconds: '//real_text(w)//' s is negative')
                return
            end if
            loop%wall_seconds = w
            call require_range([loop%runs], 1, huge(0), '/loop@runs', error)
        end subroutine read_wall_time

        subroutine read_flag(name, flag, error)
            character(len=*), intent(in) :: name
            logical, intent(out) :: flag
            type(error_t), allocatable, intent(out) :: error
            integer :: v
            flag = .false.
            call file%read_attribute('/loop', name, v, error)
            if (allocated(error)) return
            call require_range([v], 0, 1, '/loop@'//name, error)
            flag = v /= 0
        end subroutine read_flag
    end subroutine load_loop

    ! ---------------------------------------------------------------------------------------
    ! Beam: Newmark state
    ! ---------------------------------------------------------------------------------------

    !> Write the state of a time integrator under `group`.
    subroutine save_integrator(file, group, integ, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/fe'.
        character(len=*), intent(in) :: group
        !> The integrator.
        class(time_integrator_t), intent(in) :: integ
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group(group, error)
        if (allocated(error)) return
        call file%write_attribute(group, 'scalars', [integ%t, integ%h, integ%t0, integ%kinetic, &
                                                     integ%strain, integ%external_work, integ%damping_dissipation, &
                                                     integ%initial_energy, integ%coupling_work], error)
        if (allocated(error)) return
        call file%write_attribute(group, 'step_count', integ%step_count, error)
        if (allocated(error)) return
        call put_r1(file, group//'/u', integ%u, error)
        if (allocated(error)) return
        call put_r1(file, group//'/v', integ%v, error)
        if (allocated(error)) return
        call put_r1(file, group//'/a', integ%a, error)
        if (allocated(error)) return
        call put_r1(file, group//'/u_old', integ%u_old, error)
        if (allocated(error)) return
        call put_r1(file, group//'/v_old', integ%v_old, error)
        if (allocated(error)) return
        call put_r1(file, group//'/f_old', integ%f_old, error)
        if (allocated(error)) return
        call put_r1(file, group//'/f_new', integ%f_new, error)
        if (allocated(error)) return
        select type (integ)
        type is (newmark_t)
            call file%write_attribute(group, 'predicted', merge(1, 0, integ%predicted), error)
            if (allocated(error)) return
            call put_r1(file, group//'/fc_old', integ%fc_old, error)
        type is (central_difference_t)
            ! no state beyond the common one (init builds the rest from the deck)
        class default
            call make_internal_error(error, 'save_integrator', 'no checkpoint for the state of this time integrator')
        end select
    end subroutine save_integrator

    !> Read the state of a time integrator (built from the deck) from `group`.
    subroutine load_integrator(file, group, integ, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/fe'.
        character(len=*), intent(in) :: group
        !> The integrator (init done).
        class(time_integrator_t), intent(inout) :: integ
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure, a size mismatch or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: s(:)
        integer :: k
        call read_finite_attribute(file, group, 'scalars', s, 9, error, names=integrator_scalars)
        if (allocated(error)) return
        call file%read_attribute(group, 'step_count', k, error)
        if (allocated(error)) return
        call require_range([k], int(step), int(step), group//'@step_count (the steps of /loop@step)', error)
        if (allocated(error)) return
        ! the deck (same hash) gives the step; the time is t0 + steps * h exactly (fem_newmark)
        if (s(2) /= integ%h .or. s(1) /= s(3) + k*s(2)) then
            call damaged(error, group//'@scalars: time step '//real_text(s(2))//' s (the deck''s: '// &
                         real_text(integ%h)//' s) and time '//real_text(s(1))//' s do not match the '// &
                         to_str(k)//' steps from '//real_text(s(3))//' s')
            return
        end if
        integ%t = s(1)
        integ%h = s(2)
        integ%t0 = s(3)
        integ%kinetic = s(4)
        integ%strain = s(5)
        integ%external_work = s(6)
        integ%damping_dissipation = s(7)
        integ%initial_energy = s(8)
        integ%coupling_work = s(9)
        integ%step_count = k
        call get_r1(file, group//'/u', integ%u, error)
        if (allocated(error)) return
        call get_r1(file, group//'/v', integ%v, error)
        if (allocated(error)) return
        call get_r1(file, group//'/a', integ%a, error)
        if (allocated(error)) return
        call get_r1(file, group//'/u_old', integ%u_old, error)
        if (allocated(error)) return
        call get_r1(file, group//'/v_old', integ%v_old, error)
        if (allocated(error)) return
        call get_r1(file, group//'/f_old', integ%f_old, error)
        if (allocated(error)) return
        call get_r1(file, group//'/f_new', integ%f_new, error)
        if (allocated(error)) return
        select type (integ)
        type is (newmark_t)
            call file%read_attribute(group, 'predicted', k, error)
            if (allocated(error)) return
            call require_range([k], 0, 1, group//'@predicted', error)
            if (allocated(error)) return
            integ%predicted = k /= 0
            call get_r1(file, group//'/fc_old', integ%fc_old, error)
        type is (central_difference_t)
            ! no state beyond the common one (init builds the rest from the deck)
        class default
            call make_internal_error(error, 'load_integrator', 'no checkpoint for the state of this time integrator')
        end select
    end subroutine load_integrator

    ! ---------------------------------------------------------------------------------------
    ! Particles: Moreau-Jean state, contacts, bonds
    ! ---------------------------------------------------------------------------------------

    !> Write the mutable state of a particle system under `group`.
    subroutine save_dem(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        call file%create_group(group, error)
        if (allocated(error)) return
        associate (e => sys%energies, st => sys%stats)
            call file%write_attribute(group, 'scalars', [sys%time, sys%time_detection, sys%time_solver, &
                                                         e%kinetic, e%potential, e%external_work, e%drive_work, &
                                                         e%contact_dissipation, e%numerical_dissipation, e%initial, &
                                                         e%coupling_work, st%error, st%residual], error)
            if (allocated(error)) return
            call file%write_attribute(group, 'integers', real([sys%step, merge(1, 0, sys%bonds_pending), &
                                                               st%sweeps, st%n_contacts, st%n_active, st%n_blocked, &
                                                               merge(1, 0, st%converged), sys%particles%n, sys%walls%n], wp), error)
            if (allocated(error)) return
            call file%write_attribute(group, 'counts_i8', real([st%local_iterations, st%updates], wp), error)
            if (allocated(error)) return
        end associate
        associate (p => sys%particles, w => sys%walls)
            n = p%n
            call put_part(file, group//'/x', p%x(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/y', p%y(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/rot', p%rot(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/vx', p%vx(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/vy', p%vy(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/w', p%w(1:n), error)
            if (allocated(error)) return
            n = w%n
            if (n > 0) then
                call put_part(file, group//'/walls/x1', w%x1(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/y1', w%y1(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/x2', w%x2(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/y2', w%y2(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/vx', w%vx(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/vy', w%vy(1:n), error)
                if (allocated(error)) return
            end if
        end associate
        call save_contacts(error)
        if (allocated(error)) return
        call save_ruptures(error)
        if (allocated(error)) return
        call save_block(error)
    contains
        !> The factor of the bonded block in use (solver method = block): its bond graph and
        !> values, factored again at the restart (dem_bonded_block::bonded_block_restore).
        subroutine save_block(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: g
            if (.not. allocated(sys%method)) return
            select type (m => sys%method)
            type is (bonded_block_method_t)
                associate (b => m%block)
                    if (.not. (b%factored .and. allocated(b%values_factored))) return
                    if (size(b%key_i1) == 0) return
                    g = group//'/block'
                    call file%write_dataset(g//'/key_i1', b%key_i1, error)
                    if (.not. allocated(error)) call file%write_dataset(g//'/key_i2', b%key_i2, error)
                    if (.not. allocated(error)) call file%write_dataset(g//'/key_rows', b%key_rows, error)
                    if (.not. allocated(error)) call file%write_dataset(g//'/values', b%values_factored, error)
                    if (.not. allocated(error)) call file%write_dataset(g//'/scale', b%scale_factored, error)
                    ! slots whose bonds left the block: identity rows, some deleted from the factor
                    ! after its factorisation (replayed in order at the restart)
                    if (.not. any(b%dead)) return
                    if (.not. allocated(error)) call file%write_dataset(g//'/dead', merge(1, 0, b%dead), error)
                    if (.not. allocated(error) .and. b%n_deleted > 0) &
                        call file%write_dataset(g//'/deleted', b%deleted(1:b%n_deleted), error)
                end associate
            type is (sweeps_method_t)
                ! no state between steps
            class default
                call make_internal_error(error, 'save_dem', 'no checkpoint for the state of this solve method')
            end select
        end subroutine save_block

        subroutine save_contacts(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: g
            integer :: m
            g = group//'/contacts'
            associate (cs => sys%contacts)
                m = cs%n
                call file%create_group(g, error)
                if (allocated(error)) return
                call file%write_attribute(g, 'n', m, error)
                if (allocated(error) .or. m == 0) return
                call file%write_dataset(g//'/i1', cs%i1(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/i2', cs%i2(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/nrm', cs%nrm(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/gap', cs%gap(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/lever', cs%lever(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/w', cs%w(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/shift', cs%shift(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/r', cs%r(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/u', cs%u(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/y', cs%y(:, 1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/mu', cs%mu(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/erol', cs%erol(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/amoy', cs%amoy(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/coh', cs%coh(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/pcase', cs%pcase(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/break_mode', cs%break_mode(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/status', cs%status(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/active', &
                                                                    merge(1, 0, cs%active(1:m)), error)
            end associate
        end subroutine save_contacts

        subroutine save_ruptures(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: g
            integer :: m
            g = group//'/ruptures'
            associate (rl => sys%ruptures)
                m = rl%n
                call file%create_group(g, error)
                if (allocated(error)) return
                call file%write_attribute(g, 'n', m, error)
                if (allocated(error) .or. m == 0) return
                call file%write_dataset(g//'/i1', rl%i1(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/i2', rl%i2(1:m), error)
                ! steps <= max_steps = huge(0) (driver_config)
                if (.not. allocated(error)) call file%write_dataset(g//'/step', int(rl%step(1:m)), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/time', rl%time(1:m), error)
                if (.not. allocated(error)) call file%write_dataset(g//'/mode', rl%mode(1:m), error)
            end associate
        end subroutine save_ruptures
    end subroutine save_dem

    !> Read the mutable state of a particle system (built from the deck, mj_init done).
    subroutine load_dem(file, group, sys, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(inout) :: sys
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure, when the numbers of disks or walls differ, or on a damaged value.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: s(:), c(:)
        integer, allocatable :: iv(:)
        integer :: n
        call read_finite_attribute(file, group, 'scalars', s, 13, error, names=dem_scalars)
        if (allocated(error)) return
        call read_int_attr_1d(file, group, 'integers', iv, error)
        if (allocated(error)) return
        call read_finite_attribute(file, group, 'counts_i8', c, 2, error)
        if (allocated(error)) return
        if (size(iv) /= 9) then
            call make_error(error, 'checkpoint: '//group//': wrong number of values')
            return
        end if
        if (iv(8) /= sys%particles%n .or. iv(9) /= sys%walls%n) then
            call make_error(error, 'checkpoint: '//group//': numbers of disks or walls differ from the deck')
            return
        end if
        ! step (that of /loop), bonds pending, sweeps, contacts, active, blocked, converged
        call require_range(iv(1:1), int(step), int(step), group//'@integers value 1 (the steps of /loop@step)', error)
        if (.not. allocated(error)) call require_range(iv(2:2), 0, 1, group//'@integers value 2 (bonds pending)', error)
        if (.not. allocated(error)) call require_range(iv(3:6), 0, huge(0), group//'@integers (counts '// &
                                                       'of sweeps and contacts)', error, first=3)
        if (.not. allocated(error)) call require_range(iv(7:7), 0, 1, group//'@integers value 7 (converged)', error)
        if (allocated(error)) return
        if (any(c < 0.0_wp) .or. any(c > 2.0_wp**62) .or. any(c /= aint(c))) then
            call damaged(error, group//'@counts_i8: '//real_text(c(1))//', '//real_text(c(2))// &
                         ' are not counts')
            return
        end if
        sys%time = s(1)
        sys%time_detection = s(2)
        sys%time_solver = s(3)
        associate (e => sys%energies, st => sys%stats)
            e%kinetic = s(4)
            e%potential = s(5)
            e%external_work = s(6)
            e%drive_work = s(7)
            e%contact_dissipation = s(8)
            e%numerical_dissipation = s(9)
            e%initial = s(10)
            e%coupling_work = s(11)
            st%error = s(12)
            st%residual = s(13)
            sys%step = iv(1)
            sys%bonds_pending = iv(2) /= 0
            st%sweeps = iv(3)
            st%n_contacts = iv(4)
            st%n_active = iv(5)
            st%n_blocked = iv(6)
            st%converged = iv(7) /= 0
            st%local_iterations = int(c(1), i8)
            st%updates = int(c(2), i8)
        end associate
        associate (p => sys%particles, w => sys%walls)
            n = p%n
            call get_part(group//'/x', p%x, error)
            if (.not. allocated(error)) call get_part(group//'/y', p%y, error)
            if (.not. allocated(error)) call get_part(group//'/rot', p%rot, error)
            if (.not. allocated(error)) call get_part(group//'/vx', p%vx, error)
            if (.not. allocated(error)) call get_part(group//'/vy', p%vy, error)
            if (.not. allocated(error)) call get_part(group//'/w', p%w, error)
            if (allocated(error)) return
            n = w%n
            if (n > 0) then
                call get_part(group//'/walls/x1', w%x1, error)
                if (.not. allocated(error)) call get_part(group//'/walls/y1', w%y1, error)
                if (.not. allocated(error)) call get_part(group//'/walls/x2', w%x2, error)
                if (.not. allocated(error)) call get_part(group//'/walls/y2', w%y2, error)
                if (.not. allocated(error)) call get_part(group//'/walls/vx', w%vx, error)
                if (.not. allocated(error)) call get_part(group//'/walls/vy', w%vy, error)
                if (allocated(error)) return
            end if
        end associate
        call load_contacts(error)
        if (allocated(error)) return
        call load_ruptures(error)
        if (allocated(error)) return
        call load_block(error)
    contains
        subroutine load_block(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: g
            integer, allocatable :: k1(:), k2(:), kr(:), dead(:), deleted(:)
            real(wp), allocatable :: v(:), scale(:)
            g = group//'/block'
            if (.not. file%exists(g//'/values')) return
            ! a checkpoint of the block before its scaling (no 'scale'): its values are those of
            ! W_BB + eps I, not of S W_BB S + eps I; the restart then factors the current values
            ! (the run goes on within the solver's tolerance, not bitwise)
            if (.not. file%exists(g//'/scale')) return
            call file%read_dataset(g//'/scale', scale, error)
            if (allocated(error)) return
            call file%read_dataset(g//'/key_i1', k1, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/key_i2', k2, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/key_rows', kr, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/values', v, error)
            if (allocated(error)) return
            if (size(k2) /= size(k1) .or. size(kr) /= size(k1)) then
                call damaged(error, g//': key_i1, key_i2 and key_rows differ in size')
                return
            end if
            allocate (dead(size(k1)), deleted(0))
            dead = 0
            if (file%exists(g//'/dead')) call file%read_dataset(g//'/dead', dead, error)
            if (allocated(error)) return
            if (file%exists(g//'/deleted')) call file%read_dataset(g//'/deleted', deleted, error)
            if (allocated(error)) return
            if (size(dead) /= size(k1)) then
                call damaged(error, g//': dead and key_i1 differ in size')
                return
            end if
            call require_range(dead, 0, 1, g//'/dead', error)
            if (.not. allocated(error)) call require_range(deleted, 1, size(k1), g//'/deleted', error)
            if (allocated(error)) return
            if (size(deleted) > 0) then
                if (any(dead(deleted) == 0)) then
                    call damaged(error, g//': a slot of deleted is not dead')
                    return
                end if
            end if
            call require_range(k1, -sys%walls%n, sys%particles%n, g//'/key_i1', error)
            if (.not. allocated(error)) call require_range(k2, 1, sys%particles%n, g//'/key_i2', error)
            if (.not. allocated(error)) call require_finite(v, g//'/values', error)
            if (.not. allocated(error)) call require_finite(scale, g//'/scale', error)
            if (allocated(error)) return
            if (size(scale) /= sum(popcnt(kr))) then
                call damaged(error, g//': scale has not one value per unknown of key_rows')
                return
            end if
            ! the deck (whose hash the checkpoint matches) chose the strategy: only the
            ! bonded block has a factor to restore
            if (.not. allocated(sys%method)) then
                call damaged(error, g//': the deck solves no bonded block ([solver] method)')
                return
            end if
            select type (m => sys%method)
            type is (bonded_block_method_t)
                call bonded_block_restore(m%block, k1, k2, kr, v, scale, dead == 1, deleted)
            class default
                call damaged(error, g//': the deck solves no bonded block ([solver] method)')
            end select
        end subroutine load_block

        !> Read the first n values of a per-body array (the array keeps its size).
        subroutine get_part(path, x, error)
            character(len=*), intent(in) :: path
            real(wp), intent(inout) :: x(:)
            type(error_t), allocatable, intent(out) :: error
            real(wp), allocatable :: v(:)
            if (n == 0) return
            call file%read_dataset(path, v, error)
            if (allocated(error)) return
            if (size(v) /= n .or. size(x) < n) then
                call make_error(error, 'checkpoint: '//path//': size differs from the deck')
                return
            end if
            call require_finite(v, path, error)
            if (allocated(error)) return
            x(1:n) = v
        end subroutine get_part

        subroutine load_contacts(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: g, problem
            integer, allocatable :: active(:)
            integer :: m
            g = group//'/contacts'
            associate (cs => sys%contacts)
                call file%read_attribute(g, 'n', m, error)
                if (allocated(error)) return
                call require_range([m], 0, huge(0), g//'@n', error)
                if (allocated(error)) return
                if (allocated(cs%i1)) deallocate (cs%i1, cs%i2, cs%nrm, cs%gap, cs%lever, cs%w, cs%shift, &
                                                  cs%r, cs%u, cs%mu, cs%erol, cs%amoy, cs%coh, cs%pcase, &
                                                  cs%break_mode, cs%status, cs%active)
                if (allocated(cs%y)) deallocate (cs%y)
                if (allocated(cs%y_prev)) deallocate (cs%y_prev)
                cs%n = m
                cs%capacity = m
                cs%n_prev = 0
                cs%merge_pos = 1
                if (m == 0) then
                    allocate (cs%i1(0), cs%i2(0), cs%nrm(2, 0), cs%gap(0), cs%lever(2, 0), cs%w(6, 0), &
                              cs%shift(2, 0), cs%r(3, 0), cs%u(3, 0), cs%mu(0), cs%erol(0), cs%amoy(0), &
                              cs%coh(0), cs%pcase(0), cs%break_mode(0), cs%status(0), cs%active(0), &
                              cs%y(2, 0), cs%y_prev(2, 0))
                    return
                end if
                call file%read_dataset(g//'/i1', cs%i1, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/i2', cs%i2, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/nrm', cs%nrm, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/gap', cs%gap, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/lever', cs%lever, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/w', cs%w, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/shift', cs%shift, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/r', cs%r, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/u', cs%u, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/y', cs%y, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/mu', cs%mu, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/erol', cs%erol, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/amoy', cs%amoy, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/coh', cs%coh, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/pcase', cs%pcase, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/break_mode', cs%break_mode, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/status', cs%status, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/active', active, error)
                if (allocated(error)) return
                call check_sizes(g, m, active, error)
                if (allocated(error)) return
                call require_finite([cs%nrm], g//'/nrm', error)
                if (.not. allocated(error)) call require_finite(cs%gap, g//'/gap', error)
                if (.not. allocated(error)) call require_finite([cs%lever], g//'/lever', error)
                if (.not. allocated(error)) call require_finite([cs%w], g//'/w', error)
                if (.not. allocated(error)) call require_finite([cs%shift], g//'/shift', error)
                if (.not. allocated(error)) call require_finite([cs%r], g//'/r', error)
                if (.not. allocated(error)) call require_finite([cs%u], g//'/u', error)
                if (.not. allocated(error)) call require_finite([cs%y], g//'/y', error)
                if (.not. allocated(error)) call require_finite(cs%mu, g//'/mu', error)
                if (.not. allocated(error)) call require_finite(cs%erol, g//'/erol', error)
                if (.not. allocated(error)) call require_finite(cs%amoy, g//'/amoy', error)
                if (.not. allocated(error)) call require_finite(cs%coh, g//'/coh', error)
                ! codes: dem_contacts status_*, dem_bipotential case_* (0 before a solve),
                ! dem_bonds break_*
                if (.not. allocated(error)) call require_range(cs%status, 0, 4, g//'/status', error)
                if (.not. allocated(error)) call require_range(cs%pcase, 0, 5, g//'/pcase', error)
                if (.not. allocated(error)) call require_range(cs%break_mode, 0, 4, g//'/break_mode', error)
                if (.not. allocated(error)) call require_range(active, 0, 1, g//'/active', error)
                if (allocated(error)) return
                cs%active = active /= 0
                ! the outputs of the previous step are not needed after the step's laws
                allocate (cs%y_prev(2, m), source=0.0_wp)
                problem = contacts_list_problem(cs, sys%particles%n, sys%walls%n)
                if (len(problem) > 0) then
                    call make_error(error, 'checkpoint: '//problem//': the checkpoint is damaged')
                    return
                end if
            end associate
        end subroutine load_contacts

        !> Every per-contact dataset holds the n contacts of the list.
        subroutine check_sizes(g, m, active, error)
            character(len=*), intent(in) :: g
            integer, intent(in) :: m, active(:)
            type(error_t), allocatable, intent(out) :: error
            associate (cs => sys%contacts)
                if (size(cs%i1) /= m .or. size(cs%i2) /= m .or. size(cs%gap) /= m .or. size(cs%mu) /= m .or. &
                    size(cs%erol) /= m .or. size(cs%amoy) /= m .or. size(cs%coh) /= m .or. &
                    size(cs%pcase) /= m .or. size(cs%break_mode) /= m .or. size(cs%status) /= m .or. &
                    size(active) /= m .or. any(shape(cs%nrm) /= [2, m]) .or. any(shape(cs%lever) /= [2, m]) .or. &
                    any(shape(cs%w) /= [6, m]) .or. any(shape(cs%shift) /= [2, m]) .or. &
                    any(shape(cs%r) /= [3, m]) .or. any(shape(cs%u) /= [3, m]) .or. any(shape(cs%y) /= [2, m])) &
                    call damaged(error, g//': a dataset does not hold the '//to_str(m)//' contacts of '//g//'@n')
            end associate
        end subroutine check_sizes

        subroutine load_ruptures(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: g
            integer, allocatable :: rupture_step(:)
            integer :: m
            g = group//'/ruptures'
            associate (rl => sys%ruptures)
                call file%read_attribute(g, 'n', m, error)
                if (allocated(error)) return
                call require_range([m], 0, huge(0), g//'@n', error)
                if (allocated(error)) return
                rl%n = m
                if (allocated(rl%i1)) deallocate (rl%i1, rl%i2, rl%step, rl%time, rl%mode)
                if (m == 0) return
                call file%read_dataset(g//'/i1', rl%i1, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/i2', rl%i2, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/step', rupture_step, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/time', rl%time, error)
                if (.not. allocated(error)) call file%read_dataset(g//'/mode', rl%mode, error)
                if (allocated(error)) return
                if (size(rl%i1) /= m .or. size(rl%i2) /= m .or. size(rupture_step) /= m .or. &
                    size(rl%time) /= m .or. size(rl%mode) /= m) then
                    call damaged(error, g//': a dataset does not hold the '//to_str(m)//' ruptures of '//g//'@n')
                    return
                end if
                call require_range(rl%i1, -sys%walls%n, sys%particles%n, g//'/i1', error)
                if (.not. allocated(error)) call require_range(rl%i2, 1, sys%particles%n, g//'/i2', error)
                if (.not. allocated(error)) call require_range(rupture_step, 1, int(step), g//'/step', error)
                if (.not. allocated(error)) call require_finite(rl%time, g//'/time', error)
                ! dem_bonds break_tension .. break_shear_moment
                if (.not. allocated(error)) call require_range(rl%mode, 1, 4, g//'/mode', error)
                if (allocated(error)) return
                rl%step = int(rupture_step, i8)
            end associate
        end subroutine load_ruptures
    end subroutine load_dem

    ! ---------------------------------------------------------------------------------------
    ! Coupling: multipliers and constraint state
    ! ---------------------------------------------------------------------------------------

    !> Write the state of a coupled system: beam, particles and coupling.
    subroutine save_coupled(file, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system.
        type(coupled_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call save_integrator(file, '/fe', sys%fe, error)
        if (allocated(error)) return
        call save_dem(file, '/dem', sys%dem, error)
        if (allocated(error)) return
        call file%create_group('/coupling', error)
        if (allocated(error)) return
        associate (st => sys%stats)
            call file%write_attribute('/coupling', 'integers', &
                                      real([sys%step, st%sweeps, st%corrections, st%n_contacts, st%n_active, &
                                            merge(1, 0, st%converged)], wp), error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'scalars', [st%nlgs_error, st%free_residual, &
                                                               st%velocity_residual, st%position_residual, st%particle_residual, &
                                                               st%rotation_residual, st%lambda_norm], error)
            if (allocated(error)) return
        end associate
        call put_r1(file, '/coupling/lambda', sys%lambda, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/lambda_old', sys%lambda_old, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/g', sys%g, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/q', sys%q, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/cu0', sys%cu0, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/drift', sys%drift, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/start', sys%start, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/multiplier', sys%multiplier, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/cv', sys%cv, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/gv', sys%gv, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/fc', sys%fc, error)
    end subroutine save_coupled

    !> Read the state of a coupled system (built from the deck).
    subroutine load_coupled(file, sys, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system.
        type(coupled_system_t), intent(inout) :: sys
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: iv(:)
        real(wp), allocatable :: s(:)
        call load_integrator(file, '/fe', sys%fe, step, error)
        if (allocated(error)) return
        call load_dem(file, '/dem', sys%dem, step, error)
        if (allocated(error)) return
        call read_int_attr_1d(file, '/coupling', 'integers', iv, error)
        if (allocated(error)) return
        call read_finite_attribute(file, '/coupling', 'scalars', s, 7, error)
        if (allocated(error)) return
        if (size(iv) /= 6) then
            call make_error(error, 'checkpoint: /coupling: wrong number of values')
            return
        end if
        ! step (that of /loop), sweeps, corrections, contacts, active, converged
        call require_range(iv(1:1), int(step), int(step), '/coupling@integers value 1 (the steps of /loop@step)', error)
        if (.not. allocated(error)) call require_range(iv(2:5), 0, huge(0), '/coupling@integers (counts)', &
                                                       error, first=2)
        if (.not. allocated(error)) call require_range(iv(6:6), 0, 1, '/coupling@integers value 6 (converged)', error)
        if (allocated(error)) return
        associate (st => sys%stats)
            sys%step = iv(1)
            st%sweeps = iv(2)
            st%corrections = iv(3)
            st%n_contacts = iv(4)
            st%n_active = iv(5)
            st%converged = iv(6) /= 0
            st%nlgs_error = s(1)
            st%free_residual = s(2)
            st%velocity_residual = s(3)
            st%position_residual = s(4)
            st%particle_residual = s(5)
            st%rotation_residual = s(6)
            st%lambda_norm = s(7)
        end associate
        call get_r1(file, '/coupling/lambda', sys%lambda, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/lambda_old', sys%lambda_old, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/g', sys%g, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/q', sys%q, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/cu0', sys%cu0, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/drift', sys%drift, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/start', sys%start, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/multiplier', sys%multiplier, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/cv', sys%cv, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/gv', sys%gv, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/fc', sys%fc, error)
    end subroutine load_coupled

    ! ---------------------------------------------------------------------------------------
    ! Results writers and the results file
    ! ---------------------------------------------------------------------------------------

    !> Write the results writer's counters and the record count of every dataset of the
    !> results file (flushed before).
    subroutine save_results(file, out, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The results writer (open).
        type(results_writer_t), intent(in) :: out
        !> Set on a read or write failure.
        type(error_t), allocatable, intent(out) :: error
        character(len=256), allocatable :: paths(:)
        integer, allocatable :: counts(:)
        character(len=:), allocatable :: joined
        integer :: k
        call out%file%list_datasets(paths, counts, error)
        if (allocated(error)) return
        call file%create_group('/results', error)
        if (allocated(error)) return
        call file%write_attribute('/results', 'writer', real([out%n_nodes, merge(1, 0, out%have_state), &
                                                              merge(1, 0, out%have_energy)], wp), error)
        if (allocated(error)) return
        call file%write_attribute('/results', 'energy0', out%energy0, error)
        if (allocated(error)) return
        joined = ''
        do k = 1, size(paths)
            joined = joined//trim(paths(k))//new_line('a')
        end do
        call file%write_attribute('/results', 'datasets', joined, error)
        if (allocated(error) .or. size(paths) == 0) return
        call file%write_dataset('/results/records', counts, error)
    end subroutine save_results

    !> Restore the results writer's counters, and bring its (open) results file back to the
    !> checkpoint: datasets written after it are deleted, series cut to their record counts.
    !> The first write to the results file of a restart: everything read before it (the state)
    !> and in it is checked first.
    subroutine load_results(file, out, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The results writer, its file open for writing.
        type(results_writer_t), intent(inout) :: out
        !> Set on a read or write failure, or when a dataset of the checkpoint is missing.
        type(error_t), allocatable, intent(out) :: error
        character(len=256), allocatable :: paths(:)
        integer, allocatable :: counts(:), saved(:), w(:)
        character(len=:), allocatable :: joined
        integer :: k, j, start, n_saved
        real(wp) :: energy0
        call read_int_attr_1d(file, '/results', 'writer', w, error)
        if (allocated(error)) return
        if (size(w) /= 3) then
            call damaged(error, '/results@writer: '//to_str(size(w))//' values, not 3')
            return
        end if
        ! nodes, state series written, energy series written
        call require_range(w(1:1), 0, huge(0), '/results@writer value 1 (nodes)', error)
        if (.not. allocated(error)) call require_range(w(2:3), 0, 1, '/results@writer (flags)', error, first=2)
        if (.not. allocated(error)) call file%read_attribute('/results', 'energy0', energy0, error)
        if (.not. allocated(error)) call require_finite([energy0], '/results@energy0', error)
        if (allocated(error)) return
        out%n_nodes = w(1)
        out%have_state = w(2) /= 0
        out%have_energy = w(3) /= 0
        out%energy0 = energy0
        call file%read_attribute('/results', 'datasets', joined, error)
        if (allocated(error)) return
        ! the results' own dataset paths, one per line: other bytes are damage (not quoted)
        if (any([(.not. (joined(k:k) == new_line('a') .or. (iachar(joined(k:k)) >= 32 .and. &
                                                            iachar(joined(k:k)) <= 126)), k=1, len(joined))])) then
            call make_error(error, "checkpoint: '/results@datasets' holds bytes that are not a dataset path: the "// &
                            'checkpoint is damaged')
            return
        end if
        n_saved = count([(joined(k:k) == new_line('a'), k=1, len(joined))])
        allocate (saved(0))
        if (n_saved > 0) call file%read_dataset('/results/records', saved, error)
        if (allocated(error)) return
        if (size(saved) /= n_saved) then
            call make_error(error, 'checkpoint: '//to_str(size(saved))//' record counts for '// &
                            to_str(n_saved)//' datasets: the checkpoint is damaged')
            return
        end if
        call out%file%list_datasets(paths, counts, error)
        if (allocated(error)) return
        ! The results file holds at least the records of the checkpoint: a count beyond it
        ! (a damaged checkpoint) would extend the series instead of cutting it.
        do k = 1, size(paths)
            j = find(trim(paths(k)))
            if (j == 0) cycle
            if (saved(j) >= 0 .and. saved(j) <= counts(k)) cycle
            call make_error(error, "checkpoint: it counts "//to_str(saved(j))//" records of '"// &
                            trim(paths(k))//"', the results file '"//out%file%path//"' holds "// &
                            to_str(counts(k))//': the checkpoint is damaged or not of these results')
            return
        end do
        ! Every dataset of the checkpoint must be there.
        start = 1
        do k = 1, len(joined)
            if (joined(k:k) /= new_line('a')) cycle
            if (.not. any(paths == joined(start:k - 1))) then
                call make_error(error, "checkpoint: the results file '"//out%file%path// &
                                "' has no dataset '"//joined(start:k - 1)//"'")
                return
            end if
            start = k + 1
        end do
        call out%mark_running(error)
        if (allocated(error)) return
        ! Every dataset of the file: kept (series cut to the checkpoint) or deleted.
        do k = 1, size(paths)
            j = find(trim(paths(k)))
            if (j == 0) then
                call out%file%delete(trim(paths(k)), error)
            else if (counts(k) /= saved(j)) then
                call out%file%resize_series(trim(paths(k)), saved(j), error)
            end if
            if (allocated(error)) return
        end do
    contains
        !> Index of `path` in the checkpoint's list (0: not there).
        integer function find(path)
            character(len=*), intent(in) :: path
            integer :: i, s0, idx
            find = 0
            s0 = 1
            idx = 0
            do i = 1, len(joined)
                if (joined(i:i) /= new_line('a')) cycle
                idx = idx + 1
                if (joined(s0:i - 1) == path) then
                    find = idx
                    return
                end if
                s0 = i + 1
            end do
        end function find
    end subroutine load_results

    !> Write the counters of the particle writer (its buffered statistics written before).
    subroutine save_dem_writer(file, writer, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The writer, nothing buffered.
        type(dem_writer_t), intent(in) :: writer
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group('/writers', error)
        if (allocated(error)) return
        call file%write_attribute('/writers', 'dem', real([writer%n_out, writer%n_contacts_stored, &
                                                           writer%n_steps, writer%n_buffered, writer%n_ruptures], wp), error)
    end subroutine save_dem_writer

    !> Read the counters of the particle writer (begun again: its buffers exist).
    subroutine load_dem_writer(file, writer, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The writer.
        type(dem_writer_t), intent(inout) :: writer
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: c(:)
        call read_int_attr_1d(file, '/writers', 'dem', c, error)
        if (allocated(error)) return
        if (size(c) /= 5) then
            call make_error(error, 'checkpoint: /writers: wrong number of particle writer counters')
            return
        end if
        call require_range(c, 0, huge(0), '/writers@dem', error)
        if (allocated(error)) return
        if (c(4) /= 0) then
            call make_error(error, 'checkpoint: the particle writer had unwritten statistics')
            return
        end if
        writer%n_out = c(1)
        writer%n_contacts_stored = c(2)
        writer%n_steps = c(3)
        writer%n_buffered = 0
        writer%n_ruptures = c(5)
    end subroutine load_dem_writer

    !> Write the counters and running maxima of the coupling writer (nothing buffered).
    subroutine save_coupled_writer(file, writer, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The writer, nothing buffered.
        type(coupled_writer_t), intent(in) :: writer
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group('/writers', error)
        if (allocated(error)) return
        call file%write_attribute('/writers', 'coupled', real([writer%n_out, writer%n_steps, &
                                                               writer%n_buffered], wp), error)
        if (allocated(error)) return
        call file%write_attribute('/writers', 'coupled_max', [writer%max_position, writer%max_velocity, &
                                                              writer%max_coordinate, writer%max_balance], error)
    end subroutine save_coupled_writer

    !> Read the counters and running maxima of the coupling writer (begun again).
    subroutine load_coupled_writer(file, writer, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The writer.
        type(coupled_writer_t), intent(inout) :: writer
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: c(:)
        real(wp), allocatable :: m(:)
        call read_int_attr_1d(file, '/writers', 'coupled', c, error)
        if (allocated(error)) return
        if (size(c) /= 3) then
            call make_error(error, 'checkpoint: /writers: wrong number of coupling writer counters')
            return
        end if
        call require_range(c, 0, huge(0), '/writers@coupled', error)
        if (.not. allocated(error)) call read_finite_attribute(file, '/writers', 'coupled_max', m, 4, error)
        if (allocated(error)) return
        if (c(3) /= 0) then
            call make_error(error, 'checkpoint: the coupling writer had unwritten statistics')
            return
        end if
        writer%n_out = c(1)
        writer%n_steps = c(2)
        writer%n_buffered = 0
        writer%max_position = m(1)
        writer%max_velocity = m(2)
        writer%max_coordinate = m(3)
        writer%max_balance = m(4)
    end subroutine load_coupled_writer

    ! ---------------------------------------------------------------------------------------
    ! Helpers
    ! ---------------------------------------------------------------------------------------

    !> Write a real array if it is allocated and not empty.
    subroutine put_r1(file, path, x, error)
        type(h5_file_t), intent(inout) :: file
        character(len=*), intent(in) :: path
        real(wp), allocatable, intent(in) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        if (.not. allocated(x)) return
        if (size(x) == 0) return
        call file%write_dataset(path, x, error)
    end subroutine put_r1

    !> Write a real array if it is not empty.
    subroutine put_part(file, path, x, error)
        type(h5_file_t), intent(inout) :: file
        character(len=*), intent(in) :: path
        real(wp), intent(in) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        if (size(x) == 0) return
        call file%write_dataset(path, x, error)
    end subroutine put_part

    !> Read a real array written by put_r1 (left as it is when absent; it must then be
    !> unallocated or empty).
    subroutine get_r1(file, path, x, error)
        type(h5_file_t), intent(inout) :: file
        character(len=*), intent(in) :: path
        real(wp), allocatable, intent(inout) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: v(:)
        if (.not. file%exists(path)) then
            if (allocated(x)) then
                if (size(x) > 0) call make_error(error, 'checkpoint: no dataset '//path)
            end if
            return
        end if
        call file%read_dataset(path, v, error)
        if (allocated(error)) return
        if (allocated(x)) then
            if (size(x) /= size(v)) then
                call make_error(error, 'checkpoint: '//path//': size differs from the deck''s model')
                return
            end if
        end if
        call require_finite(v, path, error)
        if (allocated(error)) return
        call move_alloc(v, x)
    end subroutine get_r1

    !> Read an integer attribute array (the file API has 1-D attributes of reals only: the
    !> integers are written as reals, exact below 2**53).
    subroutine read_int_attr_1d(file, object, name, values, error)
        type(h5_file_t), intent(inout) :: file
        character(len=*), intent(in) :: object, name
        integer, allocatable, intent(out) :: values(:)
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: r(:)
        integer :: k
        call file%read_attribute(object, name, r, error)
        if (allocated(error)) return
        do k = 1, size(r)
            if (ieee_is_finite(r(k))) then
                if (r(k) == aint(r(k)) .and. abs(r(k)) <= real(huge(0), wp)) cycle
            end if
            call damaged(error, object//'@'//name//' value '//to_str(k)//' is '//real_text(r(k))// &
                         ', not a 32-bit integer')
            return
        end do
        values = nint(r)
    end subroutine read_int_attr_1d

    !> Read a real attribute array of n values, all finite (else the checkpoint is damaged).
    subroutine read_finite_attribute(file, object, name, values, n, error, names)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group or dataset, and name of the attribute.
        character(len=*), intent(in) :: object, name
        !> The values.
        real(wp), allocatable, intent(out) :: values(:)
        !> Number of values expected.
        integer, intent(in) :: n
        !> Set on a read failure, another number of values, or a value not finite.
        type(error_t), allocatable, intent(out) :: error
        !> What each value is (for the message).
        character(len=*), intent(in), optional :: names(:)
        call file%read_attribute(object, name, values, error)
        if (allocated(error)) return
        if (size(values) /= n) then
            call damaged(error, object//'@'//name//': '//to_str(size(values))//' values, not '//to_str(n))
            return
        end if
        call require_finite(values, object//'@'//name, error, names)
    end subroutine read_finite_attribute

    !> Refuse a value read from a checkpoint that is not finite, naming it.
    subroutine require_finite(values, what, error, names)
        !> The values.
        real(wp), intent(in) :: values(:)
        !> Where they come from ('/fe@scalars', '/dem/x').
        character(len=*), intent(in) :: what
        !> Set on the first value that is NaN or infinite.
        type(error_t), allocatable, intent(out) :: error
        !> What each value is (for the message).
        character(len=*), intent(in), optional :: names(:)
        integer :: k
        do k = 1, size(values)
            if (ieee_is_finite(values(k))) cycle
            if (present(names)) then
                call damaged(error, what//' value '//to_str(k)//' ('//trim(names(k))//') is '// &
                             real_text(values(k)))
            else if (size(values) == 1) then
                call damaged(error, what//' is '//real_text(values(k)))
            else
                call damaged(error, what//' value '//to_str(k)//' is '//real_text(values(k)))
            end if
            return
        end do
    end subroutine require_finite

    !> Refuse integers read from a checkpoint outside [lo, hi], naming the first.
    subroutine require_range(values, lo, hi, what, error, first)
        !> The values.
        integer, intent(in) :: values(:)
        !> Allowed range.
        integer, intent(in) :: lo, hi
        !> Where they come from ('/dem/contacts/status').
        character(len=*), intent(in) :: what
        !> Set on the first value out of range.
        type(error_t), allocatable, intent(out) :: error
        !> Index of values(1) in the message (default 1).
        integer, intent(in), optional :: first
        integer :: k, k0
        k0 = 0
        if (present(first)) k0 = first - 1
        do k = 1, size(values)
            if (values(k) >= lo .and. values(k) <= hi) cycle
            if (size(values) == 1 .and. .not. present(first)) then
                call damaged(error, what//' is '//to_str(values(k))//', outside '//to_str(lo)//'..'//to_str(hi))
            else
                call damaged(error, what//' value '//to_str(k + k0)//' is '//to_str(values(k))//', outside '// &
                             to_str(lo)//'..'//to_str(hi))
            end if
            return
        end do
    end subroutine require_range

    !> The error for a damaged checkpoint: 'checkpoint: <problem>: the checkpoint is damaged'.
    subroutine damaged(error, problem)
        !> Set.
        type(error_t), allocatable, intent(out) :: error
        !> What is wrong, naming the value.
        character(len=*), intent(in) :: problem
        call make_error(error, 'checkpoint: '//problem//': the checkpoint is damaged')
    end subroutine damaged

    !> A real for messages: 'NaN', 'Infinity', '-Infinity' or 4 significant digits.
    function real_text(x) result(text)
        !> The value.
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=24) :: buf
        if (ieee_is_nan(x)) then
            text = 'NaN'
        else if (.not. ieee_is_finite(x)) then
            text = merge('Infinity ', '-Infinity', x > 0.0_wp)
            text = trim(text)
        else
            write (buf, '(es11.3e3)') x
            text = trim(adjustl(buf))
        end if
    end function real_text

    !> Outputs, checkpoint and stop test after step k of a time loop, in the one order that
    !> makes a restart bitwise: the regular output of step k, then the checkpoint (last step,
    !> stop request, or due by the schedule), then the extra output of the last step or of a
    !> stop. The checkpoint thus holds the regular outputs up to step k and not the extra one
    !> (a restart with a later end time cuts it). The caller does the actions (its own
    !> procedures, called directly: passing them here would need trampolines, an executable
    !> stack).
    function end_of_step(k, n_steps, output_interval, schedule) result(act)
        !> Steps done, and steps of the run.
        integer(i8), intent(in) :: k, n_steps
        !> Steps between regular outputs.
        integer, intent(in) :: output_interval
        !> When checkpoints are due.
        type(checkpoint_schedule_t), intent(inout) :: schedule
        !> The actions due, in the order of their components.
        type(step_end_t) :: act
        act%store_first = mod(k, int(output_interval, i8)) == 0
        ! each impure call on its own: in an .and./.or. expression gfortran may skip it
        act%stop = .false.
        if (k < n_steps) act%stop = caught_signal() /= 0
        act%checkpoint = k == n_steps .or. act%stop
        if (.not. act%checkpoint) act%checkpoint = schedule%due(k)
        act%store_last = (k == n_steps .or. act%stop) .and. .not. act%store_first
    end function end_of_step
end module driver_checkpoint
