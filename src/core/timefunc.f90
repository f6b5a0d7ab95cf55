!> Time functions f(t) that multiply loads: constant, ramp, step, piecewise-linear table,
!> harmonic. One concrete type with a kind tag keeps arrays of functions simple; evaluation
!> is not in a hot loop (once per load per step).
module core_timefunc
    use core_kinds, only: wp
    use core_constants, only: two_pi
    implicit none
    private
    public :: time_function_t, tf_constant, tf_ramp, tf_step, tf_table, tf_harmonic

    !> Kinds of time function.
    integer, parameter :: tf_constant = 1, tf_ramp = 2, tf_step = 3, tf_table = 4, tf_harmonic = 5

    !> f(t). constant: f = c; ramp: f = min(t/t1, 1); step: f = 0 for t < t0, 1 after;
    !> table: linear interpolation in (t_i, f_i), constant beyond the ends;
    !> harmonic: f = sin(2 pi freq t + phase).
    type :: time_function_t
        !> One of tf_constant, tf_ramp, tf_step, tf_table, tf_harmonic.
        integer :: kind = tf_constant
        !> Parameters: constant (c), ramp (t1), step (t0), harmonic (freq [Hz], phase [rad]).
        real(wp) :: p(2) = [1.0_wp, 0.0_wp]
        !> Table abscissae [s] (strictly increasing) and values, for tf_table.
        real(wp), allocatable :: t(:), f(:)
    contains
        !> Value at time t.
        procedure :: value => time_function_value
        !> Rate df/dt at time t (right derivative at a kink).
        procedure :: rate => time_function_rate
        !> Second derivative d2f/dt2 at time t (zero on the linear pieces; the impulses at the
        !> kinks of ramp, step and table are not represented).
        procedure :: acceleration => time_function_acceleration
        !> Whether f(t) = 0 at every t of a closed interval [t0, t1].
        procedure :: zero_on => time_function_zero_on
    end type time_function_t

contains

    !> Value of the time function at time t [s].
    pure real(wp) function time_function_value(self, t) result(f)
        !> The function.
        class(time_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        integer :: i, n
        select case (self%kind)
        case (tf_constant)
            f = self%p(1)
        case (tf_ramp)
            f = min(max(t, 0.0_wp)/self%p(1), 1.0_wp)
        case (tf_step)
            f = merge(1.0_wp, 0.0_wp, t >= self%p(1))
        case (tf_table)
            n = size(self%t)
            if (t <= self%t(1)) then
                f = self%f(1)
            else if (t >= self%t(n)) then
                f = self%f(n)
            else
                do i = 2, n
                    if (t <= self%t(i)) exit
                end do
                f = self%f(i - 1) + (self%f(i) - self%f(i - 1))*(t - self%t(i - 1))/(self%t(i) - self%t(i - 1))
            end if
        case (tf_harmonic)
            f = sin(two_pi*self%p(1)*t + self%p(2))
        case default
            f = 0.0_wp
        end select
    end function time_function_value

    !> Rate df/dt [1/s] at time t: the right derivative (the slope of the piece that starts
    !> at t) where f has a kink; 0 for constant and step (whose jump has no finite rate).
    pure real(wp) function time_function_rate(self, t) result(df)
        !> The function.
        class(time_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        integer :: i, n
        select case (self%kind)
        case (tf_ramp)
            df = merge(1.0_wp/self%p(1), 0.0_wp, t >= 0 .and. t < self%p(1))
        case (tf_table)
            n = size(self%t)
            df = 0.0_wp
            if (t < self%t(1) .or. t >= self%t(n)) return
            do i = 2, n
                if (t < self%t(i)) exit
            end do
            df = (self%f(i) - self%f(i - 1))/(self%t(i) - self%t(i - 1))
        case (tf_harmonic)
            df = two_pi*self%p(1)*cos(two_pi*self%p(1)*t + self%p(2))
        case default
            df = 0.0_wp
        end select
    end function time_function_rate

    !> Second derivative d2f/dt2 [1/s^2] at time t: zero on the linear pieces of ramp and
    !> table, -(2 pi freq)^2 f for harmonic.
    pure real(wp) function time_function_acceleration(self, t) result(d2f)
        !> The function.
        class(time_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        select case (self%kind)
        case (tf_harmonic)
            d2f = -(two_pi*self%p(1))**2*sin(two_pi*self%p(1)*t + self%p(2))
        case default
            d2f = 0.0_wp
        end select
    end function time_function_acceleration

    !> Whether f(t) = 0 at every t of [t0, t1] (true for an empty interval, t1 < t0), exact for
    !> f as `value` computes it: constant, c = 0; ramp and step (non-decreasing from 0),
    !> f(t1) = 0; table (linear between its points), f = 0 at t0, at t1 and at every table
    !> time between; harmonic, f(t0) = 0 when t0 = t1 and never on a longer interval (freq > 0
    !> in a deck; freq = 0 is the constant sin(phase)).
    pure logical function time_function_zero_on(self, t0, t1) result(zero)
        !> The function.
        class(time_function_t), intent(in) :: self
        !> Start and end of the interval [s].
        real(wp), intent(in) :: t0, t1
        zero = .true.
        if (t1 < t0) return
        select case (self%kind)
        case (tf_constant)
            zero = self%p(1) == 0.0_wp
        case (tf_ramp, tf_step)
            zero = self%value(t1) == 0.0_wp
        case (tf_table)
            zero = self%value(t0) == 0.0_wp .and. self%value(t1) == 0.0_wp .and. &
                   all(self%f == 0.0_wp .or. self%t <= t0 .or. self%t >= t1)
        case (tf_harmonic)
            if (t1 > t0 .and. self%p(1) /= 0.0_wp) then
                zero = .false.
            else
                zero = self%value(t0) == 0.0_wp
            end if
        case default
            zero = .true.
        end select
    end function time_function_zero_on
end module core_timefunc
