!> Checks and warnings of a deck before its run (driver_run): the model's size against the
!> memory, before anything is built; option `--end` applied to the model built; the settings
!> the deck gives without effect, harmonic functions the time step aliases, time functions
!> that are zero over the whole run, and an end time that is not a whole number of steps.
module driver_run_checks
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: string_t, to_str, num => sci_text
    use io_memory, only: available_memory
    use io_deck, only: deck_t, deck_entry_t
    use driver_model_size, only: size_estimate_t, check_size_estimate
    use driver_simulation, only: simulation_t, report_iface
    use driver_config, only: steps_to_end, max_steps
    use driver_config_timefunc, only: build_time_functions
    use core_timefunc, only: time_function_slot_t
    use driver_run_dem, only: fclib_after_end_warning
    implicit none
    private
    public :: check_model_size, apply_end_time, warn_about_deck, warn_fclib_after_end

contains

    !> The deck's warnings, in this order: its text (comments that are not UTF-8), settings
    !> without effect, harmonic functions the
    !> time step aliases, time functions zero over the whole run, an end time that is not a
    !> whole number of steps.
    subroutine warn_about_deck(end_time, deck, sim, report)
        !> Option `--end`: the end time replacing the deck's [s] (negative: none).
        real(wp), intent(in) :: end_time
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation (model built, `--end` applied).
        class(simulation_t), intent(in) :: sim
        !> Where the warnings go.
        procedure(report_iface) :: report
        integer :: i
        do i = 1, size(deck%warnings)
            call report(deck%warnings(i)%s)
        end do
        call warn_keywords_without_effect(deck, sim, report)
        call warn_aliased_functions(deck, sim, report)
        call warn_idle_functions(deck, sim, report)
        call warn_end_off_the_steps(end_time, deck, sim, report)
    end subroutine warn_about_deck

    !> `--check` only (a run warns when its loop starts): an FCLIB export asked for a step after
    !> the last one.
    subroutine warn_fclib_after_end(deck, sim, report)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation (model built, `--end` applied).
        class(simulation_t), intent(in) :: sim
        !> Where the warning goes.
        procedure(report_iface) :: report
        integer :: step
        if (.not. sim%has_time_loop() .or. .not. deck%has('solver', 'fclib_step')) return
        step = deck%get_int('solver', 'fclib_step')
        if (step > sim%settings%n_steps) call report(fclib_after_end_warning(step, sim%settings%n_steps))
    end subroutine warn_fclib_after_end

    !> Settings given in the deck that another setting or the kind of run turns off (the
    !> deck is valid: a tuning value left in place while it is off).
    subroutine warn_keywords_without_effect(deck, sim, report)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation.
        class(simulation_t), intent(in) :: sim
        !> Where the warnings go.
        procedure(report_iface) :: report
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
    subroutine warn_aliased_functions(deck, sim, report)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation (run settings built).
        class(simulation_t), intent(in) :: sim
        !> Where the warnings go.
        procedure(report_iface) :: report
        type(deck_entry_t), allocatable :: list(:)
        real(wp) :: nyquist
        integer :: i
        if (.not. sim%has_time_loop() .or. .not. sim%settings%h > 0.0_wp) return
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

    !> Warn about each time function that records of the deck use (loads, tractions, imposed
    !> displacements and velocities, driven walls) and that is zero at every time of a dynamic
    !> run, from t = 0 to its last step (`time_function_t%zero_on`): nothing it multiplies is
    !> applied before the end. Allowed (the deck may be the first part of a longer run), said
    !> once per function with the lines of the records that use it.
    subroutine warn_idle_functions(deck, sim, report)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation (run settings built, `--end` applied).
        class(simulation_t), intent(in) :: sim
        !> Where the warnings go.
        procedure(report_iface) :: report
        !> Records named in full in a warning; the others are counted.
        integer, parameter :: listed = 3
        type(time_function_slot_t), allocatable :: functions(:)
        type(deck_entry_t), allocatable :: list(:)
        type(error_t), allocatable :: error
        integer, allocatable :: ids(:)
        character(len=:), allocatable :: users
        real(wp) :: t_last
        integer :: i, k, n_users
        if (.not. sim%has_time_loop() .or. .not. sim%settings%h > 0.0_wp) return
        ! the model's build has read the same functions without error
        call build_time_functions(deck, functions, ids, error)
        if (allocated(error)) return
        allocate (list, source=deck%records('functions', 'function'))
        ! the last step's loads are those at n h, at or just past the end asked for
        t_last = max(sim%settings%t_end, real(sim%settings%n_steps, wp)*sim%settings%h)
        do i = 1, size(functions)
            if (.not. functions(i)%fn%zero_on(0.0_wp, t_last)) cycle
            users = ''
            n_users = 0
            do k = 1, size(deck%entries)
                associate (e => deck%entries(k))
                    if (index(' '//e%names//' ', ' function ') == 0) cycle
                    if (.not. e%has('function')) cycle
                    if (e%int('function') /= ids(i)) cycle
                    n_users = n_users + 1
                    if (n_users > listed) cycle
                    if (n_users > 1) users = users//', '
                    users = users//'['//e%section//'] '//e%keyword//' on line '//to_str(e%line)
                end associate
            end do
            if (n_users == 0) cycle
            if (n_users > listed) users = users//' and '//to_str(n_users - listed)//' more'
            call report('warning: '//deck%file//':'//to_str(list(i)%line)//': time function '//to_str(ids(i))// &
                        ' is zero at every time of the run, from t = 0 to its end at '//num(t_last)// &
                        ' s: nothing it multiplies ('//users//') is applied before the end; make it non-zero '// &
                        'before the end, or raise the end time')
        end do
    end subroutine warn_idle_functions

    !> Warn when the end time (the deck's, or --end) is not a whole number of time steps: the
    !> run goes on to the next step, past the end asked for.
    subroutine warn_end_off_the_steps(end_time, deck, sim, report)
        !> Option `--end`: the end time replacing the deck's [s] (negative: none).
        real(wp), intent(in) :: end_time
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation (run settings built, `--end` applied).
        class(simulation_t), intent(in) :: sim
        !> Where the warning goes.
        procedure(report_iface) :: report
        real(wp) :: t_last
        character(len=24) :: buf
        if (.not. sim%has_time_loop() .or. .not. sim%settings%h > 0.0_wp) return
        associate (run => sim%settings)
            t_last = real(run%n_steps, wp)*run%h
            ! a whole number of steps up to the rounding of end / step (steps_to_end)
            if (abs(t_last - run%t_end) <= 1.0e-9_wp*run%t_end) return
            if (end_time >= 0.0_wp) then
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

    !> Option `--end`: a new end time (the models built by `init` do not depend on it, the step
    !> count does).
    subroutine apply_end_time(end_time, deck, sim, error)
        !> Option `--end`: the end time replacing the deck's [s] (negative: none).
        real(wp), intent(in) :: end_time
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation: end time and step count replaced.
        class(simulation_t), intent(inout) :: sim
        !> Set when the deck has no time steps, or the end time is too short or too long.
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: steps
        if (end_time < 0.0_wp) return
        if (.not. sim%has_time_loop()) then
            call make_error(error, '--end: '//deck%file//' is not a dynamic analysis (static and modal '// &
                            'analyses have no time steps to continue)')
            return
        end if
        associate (run => sim%settings)
            if (.not. (end_time >= run%h)) then
                call make_error(error, '--end '//num(end_time)//' s: shorter than the time step '// &
                                num(run%h)//' s')
                return
            end if
            steps = steps_to_end(end_time, run%h)
            if (steps > real(max_steps, wp)) then
                call make_error(error, '--end '//num(end_time)//' s with step '//num(run%h)// &
                                ' s needs more time steps than a run can count ('//to_str(max_steps)//')')
                return
            end if
            run%t_end = end_time
            run%n_steps = max(int(steps, i8), 1_i8)
        end associate
    end subroutine apply_end_time

    !> Refuse a model whose memory estimate exceeds the available memory, from the numbers of
    !> disks, nodes and elements the deck asks for (before allocating them: each kind of run
    !> adds its parts, `simulation_t%size_estimate`), and a model with more disks or beam nodes, or a
    !> rectangle mesh with more nodes or elements than a run can number. The memory error
    !> names the generator record (lattice, row, deposit, beam line, continuum mesh) that asks
    !> for the most memory (driver_model_size).
    subroutine check_model_size(deck, sim, error)
        !> The deck.
        type(deck_t), intent(in) :: deck
        !> Its simulation (not yet initialised).
        class(simulation_t), intent(in) :: sim
        !> Set when the model is too large.
        type(error_t), allocatable, intent(out) :: error
        type(size_estimate_t) :: estimate
        call sim%size_estimate(deck, estimate, error)
        if (allocated(error)) return
        call check_size_estimate(deck, estimate, available_memory(), error)
    end subroutine check_model_size
end module driver_run_checks
