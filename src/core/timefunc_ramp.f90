!> The ramp f(t) = min(t/t1, 1) for t >= 0, 0 before (`kind = ramp` in [functions]).
module core_timefunc_ramp
    use core_kinds, only: wp
    use core_timefunc, only: time_function_t
    implicit none
    private
    public :: ramp_function_t

    !> f(t) = min(max(t, 0)/t1, 1): 0 up to t = 0, linear up to 1 at t1, then 1.
    type, extends(time_function_t) :: ramp_function_t
        !> Rise time t1 [s] (> 0).
        real(wp) :: t1 = 1.0_wp
    contains
        !> min(max(t, 0)/t1, 1).
        procedure :: value => ramp_value
        !> 1/t1 on [0, t1), 0 elsewhere.
        procedure :: rate => ramp_rate
        !> 0.
        procedure :: acceleration => ramp_acceleration
        !> Whether f(t1 of the interval) = 0.
        procedure :: zero_on => ramp_zero_on
    end type ramp_function_t

contains

    !> f(t) = min(max(t, 0)/t1, 1).
    pure real(wp) function ramp_value(self, t) result(f)
        !> The function.
        class(ramp_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        f = min(max(t, 0.0_wp)/self%t1, 1.0_wp)
    end function ramp_value

    !> df/dt [1/s]: 1/t1 on [0, t1) (the right derivative at the kinks 0 and t1), 0 elsewhere.
    pure real(wp) function ramp_rate(self, t) result(df)
        !> The function.
        class(ramp_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        df = merge(1.0_wp/self%t1, 0.0_wp, t >= 0 .and. t < self%t1)
    end function ramp_rate

    !> d2f/dt2 = 0 [1/s^2] on the linear pieces (the impulses at the kinks are not represented).
    pure real(wp) function ramp_acceleration(self, t) result(d2f)
        !> The function.
        class(ramp_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        d2f = 0.0_wp
    end function ramp_acceleration

    !> Whether f = 0 on [t0, t1]: f is non-decreasing from 0, so f(t1) = 0; true for an empty
    !> interval (t1 < t0).
    pure logical function ramp_zero_on(self, t0, t1) result(zero)
        !> The function.
        class(ramp_function_t), intent(in) :: self
        !> Start and end of the interval [s].
        real(wp), intent(in) :: t0, t1
        zero = .true.
        if (t1 < t0) return
        zero = self%value(t1) == 0.0_wp
    end function ramp_zero_on
end module core_timefunc_ramp
