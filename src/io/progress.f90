!> Progress lines for long runs: step n/N, simulated time, % done, wall time, the cost per
!> step since the previous line and the ETA from it.
!>
!> Nothing is printed here: the driver asks `due()` and prints `line(step, t)`. Wall time comes
!> from `system_clock`; the text itself is built by pure helpers that take the elapsed time as
!> an argument (`format_progress_line`, `format_summary_line`, `format_hms`), so the
!> formatting and the ETA are testable without a clock.
!>
!> The ETA comes from the cost per step since the previous progress line (since the start for
!> the first): a run whose steps grow dearer (a settling deposit gains contacts) would
!> otherwise be told the average of its cheap first steps (an audit's 100 000-disk deposit:
!> 'ETA 00:00:18' at 22 %, with 6 min 45 s left).
!>
!> A run that continues an analysis from a checkpoint (`resume`) knows the steps and the wall
!> time of the earlier runs: its ETA and its cost per step are those of its own steps, and
!> `analysis_seconds` adds its wall time to theirs.
module io_progress
    use core_kinds, only: wp, i8
    use core_strings, only: counted
    implicit none
    private
    public :: progress_t, format_progress_line, format_summary_line, format_hms, eta_seconds

    !> Progress of a time-stepping run.
    type :: progress_t
        !> Number of steps of the run.
        integer(i8) :: total_steps = 0
        !> End time of the run [s].
        real(wp) :: t_end = 0.0_wp
        !> Minimum wall time between two progress lines [s].
        real(wp) :: interval = 0.0_wp
        !> Clock count at `start`.
        integer(i8) :: start_count = 0
        !> Clock count when `due` last returned true.
        integer(i8) :: last_count = 0
        !> Clock counts per second.
        integer(i8) :: rate = 1
        !> Steps done before this run (a restart's checkpoint step; 0 for a run from the start).
        integer(i8) :: first_step = 0
        !> Wall time of the earlier runs of the analysis up to that step [s].
        real(wp) :: earlier_seconds = 0.0_wp
        !> Runs of the analysis, this one included (1 + the restarts).
        integer :: runs = 1
        !> Step of the previous progress line (`first_step` before the first).
        integer(i8) :: line_step = 0
        !> Wall time of this run at the previous progress line [s] (0 before the first).
        real(wp) :: line_seconds = 0.0_wp
    contains
        !> Start the clock for a run of n steps to t_end, reporting every interval seconds.
        procedure :: start => progress_start
        !> True when a progress line is due (interval elapsed since the last one).
        procedure :: due => progress_due
        !> This run continues an analysis: steps done, wall time and runs before it.
        procedure :: resume => progress_resume
        !> Wall-clock seconds since `start`.
        procedure :: elapsed => progress_elapsed
        !> Wall-clock seconds of the analysis: the earlier runs' and this run's.
        procedure :: analysis_seconds => progress_analysis_seconds
        !> Progress line at a step: step, time, fraction done, elapsed time, cost per step
        !> since the previous line and remaining time (the line is recorded for the next).
        procedure :: line => progress_line
        !> Closing line: steps done, wall time, time per step.
        procedure :: summary_line => progress_summary_line
    end type progress_t

contains

    !> Start timing a run.
    subroutine progress_start(self, total_steps, t_end, interval_seconds)
        !> The progress object.
        class(progress_t), intent(out) :: self
        !> Number of steps of the run.
        integer(i8), intent(in) :: total_steps
        !> End time of the run [s].
        real(wp), intent(in) :: t_end
        !> Minimum wall time between two progress lines [s] (0: never).
        real(wp), intent(in) :: interval_seconds
        self%total_steps = total_steps
        self%t_end = t_end
        self%interval = interval_seconds
        call system_clock(self%start_count, self%rate)
        if (self%rate <= 0) self%rate = 1
        self%last_count = self%start_count
    end subroutine progress_start

    !> Record that this run continues an analysis from step `first_step`, which its earlier
    !> runs reached in `earlier_seconds` of wall time (call after `start`; the clock goes on).
    subroutine progress_resume(self, first_step, earlier_seconds, earlier_runs)
        !> The progress object (started).
        class(progress_t), intent(inout) :: self
        !> Steps done before this run.
        integer(i8), intent(in) :: first_step
        !> Wall time of the earlier runs [s].
        real(wp), intent(in) :: earlier_seconds
        !> Number of earlier runs.
        integer, intent(in) :: earlier_runs
        self%first_step = first_step
        self%line_step = first_step
        self%earlier_seconds = earlier_seconds
        self%runs = earlier_runs + 1
    end subroutine progress_resume

    !> True when at least `interval_seconds` of wall time have passed since `start` or since
    !> the last time `due` returned true (the interval then restarts).
    impure logical function progress_due(self)
        !> The progress object (its interval restarts when the result is true).
        class(progress_t), intent(inout) :: self
        integer(i8) :: now
        call system_clock(now)
        ! An interval of 0 means no progress lines at all ([output] progress = 0).
        progress_due = self%interval > 0.0_wp .and. &
                       real(now - self%last_count, wp)/real(self%rate, wp) >= self%interval
        if (progress_due) self%last_count = now
    end function progress_due

    !> Wall time since `start` [s].
    impure real(wp) function progress_elapsed(self)
        !> The progress object.
        class(progress_t), intent(in) :: self
        integer(i8) :: now
        call system_clock(now)
        progress_elapsed = real(now - self%start_count, wp)/real(self%rate, wp)
    end function progress_elapsed

    !> Wall time of the analysis [s]: that of the earlier runs (`resume`) plus this run's.
    impure real(wp) function progress_analysis_seconds(self)
        !> The progress object.
        class(progress_t), intent(in) :: self
        progress_analysis_seconds = self%earlier_seconds + self%elapsed()
    end function progress_analysis_seconds

    !> Progress line for the current step, e.g.
    !> `step 1200/5000 (24.0%)  t = 1.2000E-03 s  wall 00:00:12  9.500 ms/step  ETA 00:00:36`,
    !> the cost per step and the ETA from the steps since the previous line.
    impure function progress_line(self, step, t) result(text)
        !> The progress object (the line's step and time recorded for the next).
        class(progress_t), intent(inout) :: self
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Simulated time reached [s].
        real(wp), intent(in) :: t
        !> The line (no trailing newline).
        character(len=:), allocatable :: text
        real(wp) :: now
        now = self%elapsed()
        text = format_progress_line(step, self%total_steps, t, self%t_end, now, self%first_step, &
                                    step - self%line_step, now - self%line_seconds)
        self%line_step = step
        self%line_seconds = now
    end function progress_line

    !> Closing line of a run, e.g. `done: 5000 steps, t = 5.0000E-03 s, wall 00:01:40
    !> (20.000 ms/step)`, or `stopped after 2400 steps, ...` for a run stopped early; a
    !> restarted run gives the wall time and cost per step of its own steps, then the wall
    !> time of the analysis (see `format_summary_line`).
    impure function progress_summary_line(self, steps, t, stopped) result(text)
        !> The progress object.
        class(progress_t), intent(in) :: self
        !> Steps done.
        integer(i8), intent(in) :: steps
        !> Simulated time reached [s] (not shown when absent).
        real(wp), intent(in), optional :: t
        !> Whether the run was stopped before its end (default: it ran to its end).
        logical, intent(in), optional :: stopped
        !> The line.
        character(len=:), allocatable :: text
        if (self%runs > 1) then
            text = format_summary_line(steps, self%elapsed(), t, stopped, self%first_step, &
                                       self%earlier_seconds + self%elapsed(), self%runs)
        else
            text = format_summary_line(steps, self%elapsed(), t, stopped)
        end if
    end function progress_summary_line

    !> Estimated remaining wall time [s] after `step` of `total_steps` steps took `elapsed`
    !> seconds, assuming a constant cost per step; negative when unknown (no step done yet).
    pure real(wp) function eta_seconds(step, total_steps, elapsed)
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Number of steps of the run.
        integer(i8), intent(in) :: total_steps
        !> Wall time spent so far [s].
        real(wp), intent(in) :: elapsed
        if (step <= 0) then
            eta_seconds = -1.0_wp
        else
            eta_seconds = elapsed*real(max(total_steps - step, 0_i8), wp)/real(step, wp)
        end if
    end function eta_seconds

    !> Progress line built from explicit values (see `progress_t%line`).
    pure function format_progress_line(step, total_steps, t, t_end, elapsed, first_step, recent_steps, &
                                       recent_seconds) result(text)
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Number of steps of the run.
        integer(i8), intent(in) :: total_steps
        !> Simulated time reached [s].
        real(wp), intent(in) :: t
        !> End time of the run [s] (not shown when <= 0).
        real(wp), intent(in) :: t_end
        !> Wall time spent so far [s] (by this run).
        real(wp), intent(in) :: elapsed
        !> Steps done before this run, which `elapsed` does not cover (a restart; default 0).
        integer(i8), intent(in), optional :: first_step
        !> Steps since the previous line: with `recent_seconds`, the line gives their cost per
        !> step and the ETA from it (else the ETA from the run's average, no cost).
        integer(i8), intent(in), optional :: recent_steps
        !> Wall time of those steps [s].
        real(wp), intent(in), optional :: recent_seconds
        !> The line.
        character(len=:), allocatable :: text
        character(len=64) :: buf
        real(wp) :: percent
        integer(i8) :: k0
        k0 = 0
        if (present(first_step)) k0 = first_step
        write (buf, '(i0,a,i0)') step, '/', total_steps
        text = 'step '//trim(buf)
        if (total_steps > 0) then
            percent = 100.0_wp*real(step, wp)/real(total_steps, wp)
            text = text//' ('//fixed(percent, '(f0.1)')//'%)'
        end if
        write (buf, '(es12.4e3)') t
        text = text//'  t = '//trim(adjustl(buf))
        if (t_end > 0.0_wp) then
            write (buf, '(es12.4e3)') t_end
            text = text//' / '//trim(adjustl(buf))
        end if
        text = text//' s  wall '//format_hms(elapsed)
        if (present(recent_steps) .and. present(recent_seconds)) then
            if (recent_steps > 0) then
                text = text//'  '//fixed(1000.0_wp*recent_seconds/real(recent_steps, wp), '(f0.3)')// &
                       ' ms/step  ETA '//format_hms(eta_seconds(recent_steps, recent_steps + total_steps - step, &
                                                                recent_seconds))
                return
            end if
        end if
        text = text//'  ETA '//format_hms(eta_seconds(step - k0, total_steps - k0, elapsed))
    end function format_progress_line

    !> Summary line built from explicit values (see `progress_t%summary_line`).
    pure function format_summary_line(steps, elapsed, t, stopped, first_step, analysis_seconds, runs) result(text)
        !> Steps done (by the analysis, earlier runs included).
        integer(i8), intent(in) :: steps
        !> Wall time of this run [s].
        real(wp), intent(in) :: elapsed
        !> Simulated time reached [s] (not shown when absent).
        real(wp), intent(in), optional :: t
        !> Whether the run was stopped before its end: 'stopped after N steps' instead of
        !> 'done: N steps' (default .false.).
        logical, intent(in), optional :: stopped
        !> Steps done before this run (a restart): the line then says how many steps this
        !> run did, and the cost per step is `elapsed` over those (default 0).
        integer(i8), intent(in), optional :: first_step
        !> Wall time of the analysis, earlier runs included [s] (shown with `runs`).
        real(wp), intent(in), optional :: analysis_seconds
        !> Runs of the analysis, this one included (shown with `analysis_seconds`).
        integer, intent(in), optional :: runs
        !> The line.
        character(len=:), allocatable :: text
        character(len=64) :: buf
        logical :: early
        integer(i8) :: k0, own
        early = .false.
        if (present(stopped)) early = stopped
        k0 = 0
        if (present(first_step)) k0 = first_step
        own = steps - k0
        if (early) then
            text = 'stopped after '//counted(steps, 'step')
        else
            text = 'done: '//counted(steps, 'step')
        end if
        if (k0 > 0) then
            write (buf, '(i0)') own
            text = text//' ('//trim(buf)//' in this run)'
        end if
        if (present(t)) then
            write (buf, '(es12.4e3)') t
            text = text//', t = '//trim(adjustl(buf))//' s'
        end if
        text = text//', wall '//format_hms(elapsed)
        if (own > 0) then
            text = text//' ('//fixed(1000.0_wp*elapsed/real(own, wp), '(f0.3)')//' ms/step)'
        end if
        if (present(analysis_seconds) .and. present(runs)) then
            text = text//'; analysis '//format_hms(analysis_seconds)//' in '//counted(runs, 'run')
        end if
    end function format_summary_line

    !> Wall time as hh:mm:ss (rounded to the nearest second; hours grow past 99 as needed);
    !> '--:--:--' for a negative (unknown) time.
    pure function format_hms(seconds) result(text)
        !> Time [s].
        real(wp), intent(in) :: seconds
        !> The text.
        character(len=:), allocatable :: text
        character(len=32) :: buf
        integer(i8) :: s
        if (seconds < 0.0_wp .or. seconds /= seconds) then
            text = '--:--:--'
            return
        end if
        s = nint(min(seconds, 3.6e12_wp), i8)
        write (buf, '(i0.2,a,i2.2,a,i2.2)') s/3600, ':', mod(s/60, 60_i8), ':', mod(s, 60_i8)
        text = trim(buf)
    end function format_hms

    !> A real in the fixed-point format `fmt` (e.g. '(f0.1)'), with a leading zero ('0.5').
    pure function fixed(x, fmt) result(text)
        !> Value.
        real(wp), intent(in) :: x
        !> Edit descriptor in parentheses.
        character(len=*), intent(in) :: fmt
        !> The text.
        character(len=:), allocatable :: text
        character(len=64) :: buf
        write (buf, fmt) x
        text = trim(adjustl(buf))
        if (text(1:1) == '.') then
            text = '0'//text
        else if (len(text) >= 2) then
            if (text(1:2) == '-.') text = '-0'//text(2:)
        end if
    end function fixed
end module io_progress
