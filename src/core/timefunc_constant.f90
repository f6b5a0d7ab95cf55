!> The constant time function f(t) = c (`kind = constant` in [functions]).
module core_timefunc_constant
    use core_kinds, only: wp
    use core_timefunc, only: time_function_t
    implicit none
    private
    public :: constant_function_t

    !> f(t) = c.
    type, extends(time_function_t) :: constant_function_t
        !> The value c.
        real(wp) :: c = 1.0_wp
    contains
        !> c.
        procedure :: value => constant_value
        !> 0.
        procedure :: rate => constant_rate
        !> 0.
        procedure :: acceleration => constant_acceleration
        !> Whether c = 0 (or the interval is empty).
        procedure :: zero_on => constant_zero_on
    end type constant_function_t

contains

    !> f(t) = c.
    pure real(wp) function constant_value(self, t) result(f)
        !> The function.
        class(constant_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        f = self%c
    end function constant_value

    !> df/dt = 0 [1/s].
    pure real(wp) function constant_rate(self, t) result(df)
        !> The function.
        class(constant_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        df = 0.0_wp
    end function constant_rate

    !> d2f/dt2 = 0 [1/s^2].
    pure real(wp) function constant_acceleration(self, t) result(d2f)
        !> The function.
        class(constant_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        d2f = 0.0_wp
    end function constant_acceleration

    !> Whether f = 0 on [t0, t1]: c = 0, or an empty interval (t1 < t0).
    pure logical function constant_zero_on(self, t0, t1) result(zero)
        !> The function.
        class(constant_function_t), intent(in) :: self
        !> Start and end of the interval [s].
        real(wp), intent(in) :: t0, t1
        zero = t1 < t0 .or. self%c == 0.0_wp
    end function constant_zero_on
end module core_timefunc_constant
