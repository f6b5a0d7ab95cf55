!> The abstract coupling operator C of the Arlequin method (doc/theory.md section 6.3): a
!> linear map from the FE free DOFs (n_free) to the coupled rows (n_rows, rows_per_point per
!> coupled point: x, y and optionally the rotation). The beam (coupling_operator) and the 2D
!> continuum (coupling_operator2d) extend it; the multiplier assembly (coupling_lambda) and
!> the multiplier spaces only use this interface. `prescribed` adds the part of C u that comes
!> from FE dofs prescribed in time, C_p u_p(t) (none by default).
module coupling_map
    use core_kinds, only: wp
    implicit none
    private
    public :: coupling_map_t

    !> C (n_rows, n_free), applied without being stored densely.
    type, abstract :: coupling_map_t
        !> Number of coupled points.
        integer :: n_points = 0
        !> Rows per point: 2 (x, y) or 3 (x, y, rotation).
        integer :: rows_per_point = 2
        !> Number of rows n_points*rows_per_point.
        integer :: n_rows = 0
        !> Number of columns (free DOFs of the FE model).
        integer :: n_free = 0
    contains
        !> y = C u.
        procedure(map_apply_iface), deferred :: apply
        !> f = C^T lambda.
        procedure(map_apply_iface), deferred :: apply_transpose
        !> C as a dense (n_rows, n_free) matrix.
        procedure(map_dense_iface), deferred :: to_dense
        !> Row index of a component (1 = x, 2 = y, 3 = rotation) of a point.
        procedure :: row_of => map_row_of
        !> y += C_p u_p(t) (or its rate) over the FE dofs prescribed in time; none by default.
        procedure :: add_prescribed => map_add_prescribed
        !> Distance between two coupled points across which the FE kinematics has no strain;
        !> 0 by default (a continuum strains between any two points).
        procedure :: rigid_distance => map_rigid_distance
    end type coupling_map_t

    abstract interface
        !> A product with C or C^T.
        pure subroutine map_apply_iface(self, u, cu)
            import :: coupling_map_t, wp
            !> The operator.
            class(coupling_map_t), intent(in) :: self
            !> Input (n_free for C, n_rows for C^T).
            real(wp), intent(in) :: u(:)
            !> Output (n_rows for C, n_free for C^T).
            real(wp), intent(out) :: cu(:)
        end subroutine map_apply_iface

        !> Dense copy of C.
        pure function map_dense_iface(self) result(c)
            import :: coupling_map_t, wp
            !> The operator.
            class(coupling_map_t), intent(in) :: self
            !> C (n_rows, n_free).
            real(wp) :: c(self%n_rows, self%n_free)
        end function map_dense_iface
    end interface

contains

    !> Rows are ordered point by point: row (p - 1) rows_per_point + comp.
    pure integer function map_row_of(self, p, comp)
        !> The operator.
        class(coupling_map_t), intent(in) :: self
        !> Point (1..n_points).
        integer, intent(in) :: p
        !> Component.
        integer, intent(in) :: comp
        map_row_of = (p - 1)*self%rows_per_point + comp
    end function map_row_of

    !> y += C_p u_p(t), derivative 0, or C_p v_p(t), derivative 1: the coupled rows' share of
    !> FE dofs prescribed in time. The default has none (y unchanged).
    pure subroutine map_add_prescribed(self, t, derivative, y)
        !> The operator.
        class(coupling_map_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> 0: displacement, 1: velocity.
        integer, intent(in) :: derivative
        !> Values at the coupled rows (n_rows), updated.
        real(wp), intent(inout) :: y(:)
        ! No prescribed dof in C: nothing to add.
    end subroutine map_add_prescribed

    !> No rigid part: a continuum strains between any two points.
    pure real(wp) function map_rigid_distance(self, p, q) result(d)
        !> The operator.
        class(coupling_map_t), intent(in) :: self
        !> Two points (1..n_points).
        integer, intent(in) :: p, q
        d = 0.0_wp
    end function map_rigid_distance
end module coupling_map
