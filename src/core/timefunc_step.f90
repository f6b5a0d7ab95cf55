!> The unit step f(t) = 0 for t < t0, 1 from t0 on (`kind = step` in [functions]).
module core_timefunc_step
    use core_kinds, only: wp
    use core_timefunc, only: time_function_t
    implicit none
    private
    public :: step_function_t

    !> f(t) = 0 for t < t0, 1 for t >= t0.
    type, extends(time_function_t) :: step_function_t
        !> Time of the jump t0 [s].
        real(wp) :: t0 = 0.0_wp
    contains
        !> 0 before t0, 1 from t0 on.
        procedure :: value => step_value
        !> 0 (the jump has no finite rate).
        procedure :: rate => step_rate
        !> 0.
        procedure :: acceleration => step_acceleration
        !> Whether f(t1 of the interval) = 0.
        procedure :: zero_on => step_zero_on
    end type step_function_t

contains

    !> f(t) = 0 for t < t0, 1 for t >= t0.
    pure real(wp) function step_value(self, t) result(f)
        !> The function.
        class(step_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        f = merge(1.0_wp, 0.0_wp, t >= self%t0)
    end function step_value

    !> df/dt = 0 [1/s] (the jump at t0 has no finite rate).
    pure real(wp) function step_rate(self, t) result(df)
        !> The function.
        class(step_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        df = 0.0_wp
    end function step_rate

    !> d2f/dt2 = 0 [1/s^2].
    pure real(wp) function step_acceleration(self, t) result(d2f)
        !> The function.
        class(step_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        d2f = 0.0_wp
    end function step_acceleration

    !> Whether f = 0 on [t0, t1]: f is non-decreasing from 0, so f(t1) = 0; true for an empty
    !> interval (t1 < t0).
    pure logical function step_zero_on(self, t0, t1) result(zero)
        !> The function.
        class(step_function_t), intent(in) :: self
        !> Start and end of the interval [s].
        real(wp), intent(in) :: t0, t1
        zero = .true.
        if (t1 < t0) return
        zero = self%value(t1) == 0.0_wp
    end function step_zero_on
end module core_timefunc_step
