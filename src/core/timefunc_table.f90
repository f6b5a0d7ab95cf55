!> The piecewise-linear table f(t) through points (t_i, f_i) (`kind = table` in [functions]).
module core_timefunc_table
    use core_kinds, only: wp
    use core_timefunc, only: time_function_t
    implicit none
    private
    public :: table_function_t

    !> f(t): linear interpolation in the points (t_i, f_i), constant beyond the first and the
    !> last point.
    type, extends(time_function_t) :: table_function_t
        !> Times t_i [s], strictly increasing (at least one; the deck gives two or more).
        real(wp), allocatable :: t(:)
        !> Values f_i at those times (as many).
        real(wp), allocatable :: f(:)
    contains
        !> Linear interpolation in the points, constant beyond the ends.
        procedure :: value => table_value
        !> Slope of the piece that starts at t; 0 beyond the ends.
        procedure :: rate => table_rate
        !> 0.
        procedure :: acceleration => table_acceleration
        !> Whether f = 0 at both ends of the interval and at every point between.
        procedure :: zero_on => table_zero_on
    end type table_function_t

contains

    !> f(t): f_1 up to t_1, f_n from t_n on, linear between consecutive points.
    pure real(wp) function table_value(self, t) result(f)
        !> The function.
        class(table_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        integer :: i, n
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
    end function table_value

    !> df/dt [1/s]: the slope of the piece [t_(i-1), t_i) that holds t (at a point t_i, the
    !> right derivative); 0 before t_1 and from t_n on.
    pure real(wp) function table_rate(self, t) result(df)
        !> The function.
        class(table_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        integer :: i, n
        n = size(self%t)
        df = 0.0_wp
        if (t < self%t(1) .or. t >= self%t(n)) return
        do i = 2, n
            if (t < self%t(i)) exit
        end do
        df = (self%f(i) - self%f(i - 1))/(self%t(i) - self%t(i - 1))
    end function table_rate

    !> d2f/dt2 = 0 [1/s^2] on the linear pieces (the impulses at the points are not
    !> represented).
    pure real(wp) function table_acceleration(self, t) result(d2f)
        !> The function.
        class(table_function_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        d2f = 0.0_wp
    end function table_acceleration

    !> Whether f = 0 on [t0, t1]: f is linear between its points, so f = 0 at t0, at t1 and
    !> at every point t_i between them; true for an empty interval (t1 < t0).
    pure logical function table_zero_on(self, t0, t1) result(zero)
        !> The function.
        class(table_function_t), intent(in) :: self
        !> Start and end of the interval [s].
        real(wp), intent(in) :: t0, t1
        zero = .true.
        if (t1 < t0) return
        zero = self%value(t0) == 0.0_wp .and. self%value(t1) == 0.0_wp .and. &
               all(self%f == 0.0_wp .or. self%t <= t0 .or. self%t >= t1)
    end function table_zero_on
end module core_timefunc_table
