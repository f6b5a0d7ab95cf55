!> The loop's side of a checkpoint (driver_checkpoint): the counters of a time loop that the
!> results depend on (written as /loop), when checkpoints are due, and what the end of a step
!> calls for, in the one order that makes a restart bitwise.
module driver_checkpoint_loop
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use core_signals, only: caught_signal
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint_values, only: require_finite, require_range, damaged, real_text
    implicit none
    private
    public :: loop_state_t, checkpoint_schedule_t, step_end_t, end_of_step, rest_of_last_step, save_loop, load_loop

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
        !> Converged steps so far whose contacts created energy (driver_guards::step_creates_energy;
        !> the first one warned about, the count in the summary). A checkpoint of an earlier build
        !> does not record it: read as 0.
        integer(i8) :: creating = 0
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

    !> At a restart from the checkpoint of the last step (a run killed after its final
    !> checkpoint, before its results file was closed): what `end_of_step` does after the
    !> regular output of that step, which is in the records the checkpoint counts. The
    !> checkpoint, written again from the state it holds (the one the restart read becomes
    !> '.prev', deleted when the run ends), and the extra last output when the last step is not
    !> an output step: the results are then those of the run that was not killed.
    pure function rest_of_last_step(n_steps, output_interval) result(act)
        !> Steps of the run (those of the checkpoint).
        integer(i8), intent(in) :: n_steps
        !> Steps between regular outputs.
        integer, intent(in) :: output_interval
        !> The actions due: `checkpoint` and perhaps `store_last`.
        type(step_end_t) :: act
        act%checkpoint = .true.
        act%store_last = mod(n_steps, int(output_interval, i8)) /= 0
    end function rest_of_last_step

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
        ! (at most the steps done)
        call file%write_attribute('/loop', 'creating', int(loop%creating), error)
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
        call read_creating(error)
        if (.not. allocated(error)) call read_flag('speed_warned', loop%speed_warned, error)
        if (.not. allocated(error)) call read_flag('blocked_warned', loop%blocked_warned, error)
        if (.not. allocated(error)) call read_flag('rotation_warned', loop%rotation_warned, error)
        if (.not. allocated(error)) call read_wall_time(error)
    contains
        !> Converged steps whose contacts created energy; absent in a checkpoint of an earlier
        !> build (its loop counted them from the restart only): 0.
        subroutine read_creating(error)
            !> Set on a damaged value.
            type(error_t), allocatable, intent(out) :: error
            type(error_t), allocatable :: absent
            integer :: n
            loop%creating = 0
            call file%read_attribute('/loop', 'creating', n, absent)
            if (allocated(absent)) return
            call require_range([n], 0, k, '/loop@creating (at most the steps done)', error)
            if (.not. allocated(error)) loop%creating = int(n, i8)
        end subroutine read_creating

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
end module driver_checkpoint_loop
