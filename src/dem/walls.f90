!> Straight walls (segments), fixed or driven in translation (velocity = value * f(t)).
!>
!> A wall is an obstacle of infinite mass and zero thickness; a disk touches it on either side.
!> The contact normal goes from the closest point of the segment into the disk. Time functions
!> are referenced by index into `walls_t%functions` (0 = constant 1).
module dem_walls
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_timefunc, only: time_function_slot_t
    implicit none
    private
    public :: walls_t, walls_add, walls_velocity, walls_advance, segment_closest_point

    !> The walls (structure of arrays).
    type :: walls_t
        !> Number of walls.
        integer :: n = 0
        !> First end point [m].
        real(wp), allocatable :: x1(:), y1(:)
        !> Second end point [m].
        real(wp), allocatable :: x2(:), y2(:)
        !> Velocity amplitude [m/s] (0 for a fixed wall).
        real(wp), allocatable :: vx(:), vy(:)
        !> Time function index of the velocity (0 = constant 1).
        integer, allocatable :: func(:)
        !> Material index.
        integer, allocatable :: mat(:)
        !> Time functions referenced by `func`.
        type(time_function_slot_t), allocatable :: functions(:)
    end type walls_t

contains

    !> Append a wall from (x1, y1) to (x2, y2); optionally driven at (vx, vy) * f(t).
    subroutine walls_add(w, x1, y1, x2, y2, error, mat, vx, vy, func)
        !> Walls.
        type(walls_t), intent(inout) :: w
        !> End points [m] (distinct).
        real(wp), intent(in) :: x1, y1, x2, y2
        !> Error if the segment has zero length or the time function does not exist.
        type(error_t), allocatable, intent(out) :: error
        !> Material index (default 1).
        integer, intent(in), optional :: mat
        !> Velocity amplitude [m/s] (default 0).
        real(wp), intent(in), optional :: vx, vy
        !> Time function index (default 0 = constant 1).
        integer, intent(in), optional :: func
        integer :: f, nf
        if (x1 == x2 .and. y1 == y2) then
            call make_error(error, 'walls_add: the two end points of a wall coincide')
            return
        end if
        f = 0
        if (present(func)) f = func
        nf = 0
        if (allocated(w%functions)) nf = size(w%functions)
        if (f < 0 .or. f > nf) then
            call make_error(error, 'walls_add: time function index out of range')
            return
        end if
        if (.not. allocated(w%x1)) then
            allocate (w%x1(0), w%y1(0), w%x2(0), w%y2(0), w%vx(0), w%vy(0), w%func(0), w%mat(0))
        end if
        w%x1 = [w%x1, x1]
        w%y1 = [w%y1, y1]
        w%x2 = [w%x2, x2]
        w%y2 = [w%y2, y2]
        w%vx = [w%vx, opt(vx)]
        w%vy = [w%vy, opt(vy)]
        w%func = [w%func, f]
        w%mat = [w%mat, 1]
        if (present(mat)) w%mat(w%n + 1) = mat
        w%n = w%n + 1
    contains
        pure real(wp) function opt(v)
            real(wp), intent(in), optional :: v
            opt = 0.0_wp
            if (present(v)) opt = v
        end function opt
    end subroutine walls_add

    !> Velocity of wall k at time t.
    pure function walls_velocity(w, k, t) result(v)
        !> Walls.
        type(walls_t), intent(in) :: w
        !> Wall index.
        integer, intent(in) :: k
        !> Time [s].
        real(wp), intent(in) :: t
        !> (vx, vy) [m/s].
        real(wp) :: v(2)
        real(wp) :: f
        f = 1.0_wp
        if (w%func(k) > 0) f = w%functions(w%func(k))%fn%value(t)
        v = [w%vx(k), w%vy(k)]*f
    end function walls_velocity

    !> Move every wall over [t, t + h] with the theta rule:
    !> x += h [(1 - theta) v(t) + theta v(t + h)].
    pure subroutine walls_advance(w, t, h, theta)
        !> Walls.
        type(walls_t), intent(inout) :: w
        !> Time at the start of the step [s].
        real(wp), intent(in) :: t
        !> Time step [s].
        real(wp), intent(in) :: h
        !> Theta of the scheme.
        real(wp), intent(in) :: theta
        real(wp) :: d(2)
        integer :: k
        do k = 1, w%n
            d = h*((1.0_wp - theta)*walls_velocity(w, k, t) + theta*walls_velocity(w, k, t + h))
            w%x1(k) = w%x1(k) + d(1)
            w%x2(k) = w%x2(k) + d(1)
            w%y1(k) = w%y1(k) + d(2)
            w%y2(k) = w%y2(k) + d(2)
        end do
    end subroutine walls_advance

    !> Closest point (cx, cy) of segment (x1, y1)-(x2, y2) to point (px, py).
    pure elemental subroutine segment_closest_point(x1, y1, x2, y2, px, py, cx, cy)
        !> Segment end points.
        real(wp), intent(in) :: x1, y1, x2, y2
        !> Point.
        real(wp), intent(in) :: px, py
        !> Closest point on the segment.
        real(wp), intent(out) :: cx, cy
        real(wp) :: ex, ey, s
        ex = x2 - x1
        ey = y2 - y1
        s = ((px - x1)*ex + (py - y1)*ey)/(ex*ex + ey*ey)
        s = min(max(s, 0.0_wp), 1.0_wp)
        cx = x1 + s*ex
        cy = y1 + s*ey
    end subroutine segment_closest_point
end module dem_walls
