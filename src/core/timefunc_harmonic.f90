!> The harmonic f(t) = sin(2 pi freq t + phase) (`kind = harmonic` in [functions]).
module core_timefunc_harmonic
    use core_kinds, only: wp
    use core_constants, only: two_pi
    use core_timefunc, only: time_function_t
    implicit none
    private
    public :: harmonic_function_t

    !> f(t) = sin(2 pi freq t + phase).
    type, extends(time_function_t) :: harmonic_function_t
        !> Frequency [Hz] (> 0 in a deck; 0 makes the constant sin(phase)).
        real(wp) :: freq = 1.0_wp
        !> Phase [rad].
        real(wp) :: phase = 0.0_wp
    contains
        !> sin(2 pi freq t + phase).
        procedure :: value => harmonic_value
        !> 2 pi freq cos(2 pi freq t + phase).
        procedure :: rate => harmonic_rate
        !> -(2 pi freq)^2 sin(2 pi freq t + phase).
        procedure :: acceleration => harmonic_acceleration
        !> Whether f = 0 on the interval: only at a zero of an interval of length 0.
        procedure :: zero_on => harmonic_zero_on
    end type harmonic_function_t

contains

    !> f(t) = sin(2 pi freq t + phase).
    pure real(wp) function harmonic_value(self, t) result(f)
        !> The function.
        class(harmonic_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        f = sin(two_pi*self%freq*t + self%phase)
    end function harmonic_value

    !> df/dt = 2 pi freq cos(2 pi freq t + phase) [1/s].
    pure real(wp) function harmonic_rate(self, t) result(df)
        !> The function.
        class(harmonic_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        df = two_pi*self%freq*cos(two_pi*self%freq*t + self%phase)
    end function harmonic_rate

    !> d2f/dt2 = -(2 pi freq)^2 sin(2 pi freq t + phase) [1/s^2].
    pure real(wp) function harmonic_acceleration(self, t) result(d2f)
        !> The function.
        class(harmonic_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        d2f = -(two_pi*self%freq)**2*sin(two_pi*self%freq*t + self%phase)
    end function harmonic_acceleration

    !> Whether f = 0 on [t0, t1]: f(t0) = 0 when t0 = t1, never on a longer interval (freq > 0
    !> in a deck; freq = 0 is the constant sin(phase)); true for an empty interval (t1 < t0).
    pure logical function harmonic_zero_on(self, t0, t1) result(zero)
        !> The function.
        class(harmonic_function_t), intent(in) :: self
        !> Start and end of the interval [s].
        real(wp), intent(in) :: t0, t1
        zero = .true.
        if (t1 < t0) return
        if (t1 > t0 .and. self%freq /= 0.0_wp) then
            zero = .false.
        else
            zero = self%value(t0) == 0.0_wp
        end if
    end function harmonic_zero_on
end module core_timefunc_harmonic
