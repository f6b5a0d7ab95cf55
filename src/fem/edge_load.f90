!> Surface tractions on 2-node boundary edges (the sides of Q4 and T3 elements).
!>
!> An edge a -> b has the unit tangent s = (x_b - x_a)/L and the normal n = (s_y, -s_x), which
!> points out of the body when the boundary is traversed counter-clockwise (the body on the
!> left). A traction given as (normal, tangential) components is t = t_n n + t_s s: t_n > 0
!> pulls, a pressure p is t_n = -p. Equivalent nodal forces f_a = int N_a t thickness ds with
!> the linear edge shape functions N_a = 1 - s/L, N_b = s/L.
module fem_edge_load
    use core_kinds, only: wp
    implicit none
    private
    public :: edge_normal, edge_traction_linear, edge_traction_normal_tangential, &
              edge_traction_function, traction_field_t, parabolic_traction_t

    !> A traction field t(x) (Pa) over the boundary: a family of load distributions.
    type, abstract :: traction_field_t
    contains
        !> Traction at a point of the boundary.
        procedure(traction_at_iface), deferred :: at
    end type traction_field_t

    abstract interface
        !> Traction (tx, ty) (Pa) at the point x of the boundary.
        pure function traction_at_iface(self, x) result(t)
            import :: wp, traction_field_t
            !> The field.
            class(traction_field_t), intent(in) :: self
            !> Point on the boundary.
            real(wp), intent(in) :: x(2)
            !> Traction (tx, ty) (Pa).
            real(wp) :: t(2)
        end function traction_at_iface
    end interface

    !> Parabolic traction 1.5 mean (1 - s^2) across [lo, hi] along one axis (s = -1..1): the
    !> profile of a shear across a beam's end, whose resultant over [lo, hi] is that of the
    !> uniform traction `mean`.
    type, extends(traction_field_t) :: parabolic_traction_t
        !> Mean traction (tx, ty) (Pa).
        real(wp) :: mean(2) = 0.0_wp
        !> Axis across which the profile varies (1: x, 2: y).
        integer :: axis = 2
        !> Ends of the profile along that axis (m); the traction is zero there.
        real(wp) :: lo = -1.0_wp, hi = 1.0_wp
    contains
        !> See `traction_field_t%at`.
        procedure :: at => parabolic_at
    end type parabolic_traction_t

contains

    !> Unit normal (s_y, -s_x) of the edge a -> b (outward for a counter-clockwise boundary).
    pure function edge_normal(xa, xb) result(n)
        !> First node.
        real(wp), intent(in) :: xa(2)
        !> Second node.
        real(wp), intent(in) :: xb(2)
        !> Unit normal.
        real(wp) :: n(2)
        real(wp) :: d(2)
        d = xb - xa
        n = [d(2), -d(1)]/norm2(d)
    end function edge_normal

    !> Nodal forces (f_ax, f_ay, f_bx, f_by) of a traction varying linearly from t_a at node a
    !> to t_b at node b (exact: f_a = L thickness (2 t_a + t_b)/6, f_b = L thickness (t_a + 2 t_b)/6).
    pure function edge_traction_linear(xa, xb, ta, tb, thickness) result(f)
        !> First node.
        real(wp), intent(in) :: xa(2)
        !> Second node.
        real(wp), intent(in) :: xb(2)
        !> Traction (tx, ty) at node a (Pa).
        real(wp), intent(in) :: ta(2)
        !> Traction (tx, ty) at node b (Pa).
        real(wp), intent(in) :: tb(2)
        !> Thickness (m).
        real(wp), intent(in) :: thickness
        !> Nodal forces (4) (N).
        real(wp) :: f(4)
        real(wp) :: c
        c = norm2(xb - xa)*thickness/6.0_wp
        f(1:2) = c*(2.0_wp*ta + tb)
        f(3:4) = c*(ta + 2.0_wp*tb)
    end function edge_traction_linear

    !> Nodal forces of a uniform traction given by its normal (t_n, > 0 pulls) and tangential
    !> (t_s, along a -> b) components.
    pure function edge_traction_normal_tangential(xa, xb, tn, ts, thickness) result(f)
        !> First node.
        real(wp), intent(in) :: xa(2)
        !> Second node.
        real(wp), intent(in) :: xb(2)
        !> Normal component (Pa); a pressure p is tn = -p.
        real(wp), intent(in) :: tn
        !> Tangential component along a -> b (Pa).
        real(wp), intent(in) :: ts
        !> Thickness (m).
        real(wp), intent(in) :: thickness
        !> Nodal forces (4) (N).
        real(wp) :: f(4)
        real(wp) :: n(2), s(2), t(2)
        n = edge_normal(xa, xb)
        s = [-n(2), n(1)]
        t = tn*n + ts*s
        f = edge_traction_linear(xa, xb, t, t, thickness)
    end function edge_traction_normal_tangential

    !> Nodal forces of a traction field t(x), integrated with 3-point Gauss-Legendre on the
    !> edge (exact when t is a polynomial of degree <= 4 along the edge).
    pure function edge_traction_function(xa, xb, traction, thickness) result(f)
        !> First node.
        real(wp), intent(in) :: xa(2)
        !> Second node.
        real(wp), intent(in) :: xb(2)
        !> Traction field.
        class(traction_field_t), intent(in) :: traction
        !> Thickness (m).
        real(wp), intent(in) :: thickness
        !> Nodal forces (4) (N).
        real(wp) :: f(4)
        real(wp), parameter :: r = 0.7745966692414833770_wp ! sqrt(3/5)
        real(wp), parameter :: gp(3) = [-r, 0.0_wp, r], gw(3) = [5.0_wp, 8.0_wp, 5.0_wp]/9.0_wp
        real(wp) :: na, nb, t(2), half
        integer :: p
        half = 0.5_wp*norm2(xb - xa)*thickness
        f = 0.0_wp
        do p = 1, 3
            na = 0.5_wp*(1.0_wp - gp(p))
            nb = 0.5_wp*(1.0_wp + gp(p))
            t = traction%at(na*xa + nb*xb)
            f(1:2) = f(1:2) + gw(p)*half*na*t
            f(3:4) = f(3:4) + gw(p)*half*nb*t
        end do
    end function edge_traction_function

    !> See `traction_field_t%at`: 1.5 mean (1 - s^2), s = (2 x(axis) - lo - hi)/(hi - lo).
    pure function parabolic_at(self, x) result(t)
        !> The field.
        class(parabolic_traction_t), intent(in) :: self
        !> Point on the boundary.
        real(wp), intent(in) :: x(2)
        !> Traction (tx, ty) (Pa).
        real(wp) :: t(2)
        real(wp) :: s
        s = (2*x(self%axis) - self%lo - self%hi)/(self%hi - self%lo)
        t = 1.5_wp*(1 - s**2)*self%mean
    end function parabolic_at
end module fem_edge_load
