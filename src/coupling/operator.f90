!> Coupling operator C of the Arlequin method (doc/theory.md sections 6.3, 6.6): the beam's displacement
!> field interpolated at the coupled points (particle centres).
!>
!> Each point (x_p, y_p) is projected on the beam axis (fem_beam_projection, the projection
!> that also gives the disks their weight alpha): element e, reduced coordinate xi in [0, 1]
!> of its nearest point and the rigid arm (a, d) from there to the point in the element's
!> local axes (t along the element, n = (-sin, cos) across; a = 0 unless the point lies
!> beyond a joint, in the outer corner of a bend). The point moves with the section at xi
!> through that arm:
!>   u_t = (1 - xi) u1 + xi u2 - d theta(xi),  u_n = w(xi) (Hermite) + a theta(xi),
!>   phi = theta(xi),
!> rotated to global x, y; the rotation row (phi) is optional. Every row involves the six
!> DOFs of one element: C is stored as 6 (column, value) pairs per row, in the model's
!> free-DOF numbering (column 0 = a fixed DOF, value 0, skipped). Rows are ordered point by
!> point: (x, y) or (x, y, phi) for point 1, then point 2, ...
!>
!> Mediator space (`build_mediator`, [coupling] multipliers = nodes): the multipliers live on
!> the beam nodes that carry coupled points, one per node and row component (x, y and, with
!> rotation rows, phi), and the constraint is the projection Pi (q - C u) = 0 of the
!> per-point residual. Pi(k, p) is the linear hat function of node k at point p (1 - xi and
!> xi on the element holding p), the same for every component: the coarsest interpolation
!> the beam's nodes carry, the same for axial and transverse displacements, and a partition
!> of unity (a uniform residual is seen fully). Pi (n_mult, n_rows) is dense (small).
module coupling_operator
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    use core_weight, only: weight_function_t
    use fem_beam_model, only: beam_model_t
    use fem_beam_element, only: element_interpolation, rotation_matrix
    use fem_beam_projection, only: beam_point_t, project_on_beam
    use coupling_map, only: coupling_map_t
    implicit none
    private
    public :: coupling_operator_t, build_coupling_operator, row_x, row_y, row_phi
    public :: mediator_t, build_mediator

    !> Component of a point's rows: x displacement.
    integer, parameter :: row_x = 1
    !> Component of a point's rows: y displacement.
    integer, parameter :: row_y = 2
    !> Component of a point's rows: rotation (only with rotation rows).
    integer, parameter :: row_phi = 3

    !> Sparse C (n_rows, n_free) and where each coupled point sits on the beam.
    type, extends(coupling_map_t) :: coupling_operator_t
        !> Element holding each point (n_points).
        integer, allocatable :: element(:)
        !> Reduced coordinate on that element, in [0, 1] (n_points).
        real(wp), allocatable :: xi(:)
        !> Signed distance from the beam axis [m] (n_points): the length of the arm, with the
        !> sign of its component across the element (fem_beam_projection's offset).
        real(wp), allocatable :: offset(:)
        !> Components of the arm along and across the element [m] (2, n_points).
        real(wp), allocatable :: arm(:, :)
        !> Curvilinear abscissa of the projection [m] (n_points), for the weight alpha.
        real(wp), allocatable :: abscissa(:)
        !> Free-DOF column of each non-zero (6, n_rows); 0 for a fixed DOF.
        integer, allocatable :: col(:, :)
        !> Value of each non-zero (6, n_rows); 0 where col = 0.
        real(wp), allocatable :: val(:, :)
    contains
        !> y = C u.
        procedure :: apply
        !> f = C^T lambda.
        procedure :: apply_transpose
        !> C as a dense (n_rows, n_free) matrix (tests, small systems).
        procedure :: to_dense
        !> Weight alpha at each coupled point; error if one is outside the overlap.
        procedure :: point_weights
        !> See `coupling_map_t%rigid_distance`: the difference of the offsets.
        procedure :: rigid_distance
    end type coupling_operator_t

    !> Mediator space of the multipliers on the beam nodes (see the module description).
    type :: mediator_t
        !> Number of mediator nodes.
        integer :: n_nodes = 0
        !> Multipliers per node (= rows per point: 2 or 3).
        integer :: per_node = 2
        !> Number of multipliers n_nodes*per_node.
        integer :: n_mult = 0
        !> Beam node (model numbering) of each mediator node (n_nodes), increasing.
        integer, allocatable :: node(:)
        !> Component (row_x, row_y, row_phi) of each multiplier (n_mult).
        integer, allocatable :: comp(:)
        !> Pi (n_mult, n_rows): hat function of the multiplier's node at the row's point,
        !> for rows of the same component, else 0.
        real(wp), allocatable :: pi(:, :)
    end type mediator_t

contains

    !> Pi of the mediator space for the coupled points of op: the mediator nodes are the beam
    !> nodes with a non-zero hat function at some coupled point (shape values below 1e-9, a
    !> point on a node up to rounding, count as 0). Multipliers are ordered node by node,
    !> (x, y[, phi]) per node. Error when a node's row of Pi is (numerically) a combination
    !> of the rows of other nodes, which makes Pi A Pi^T singular: too few coupled points
    !> around that node (e.g. a single point inside an element whose nodes carry no other).
    subroutine build_mediator(model, op, med, error)
        !> The beam model.
        type(beam_model_t), intent(in) :: model
        !> The coupling operator (points projected on the beam).
        type(coupling_operator_t), intent(in) :: op
        !> The mediator space built.
        type(mediator_t), intent(out) :: med
        !> Set when Pi has dependent rows.
        type(error_t), allocatable, intent(out) :: error
        ! Hat values below this are a point on the other node (rounding of the projection).
        real(wp), parameter :: snap = 1.0e-9_wp
        ! A row keeping less than this fraction of its norm once projected out of the
        ! previous rows is a combination of them.
        real(wp), parameter :: independent = 1.0e-6_wp
        real(wp), allocatable :: hat(:, :), basis(:, :)
        integer, allocatable :: slot(:)
        real(wp) :: nk(2), r0
        integer :: p, j, k, c, m, rpp
        character(len=400) :: buf
        rpp = op%rows_per_point
        ! Hat functions of every node at every point, then the nodes that carry points.
        allocate (hat(model%n_nodes, op%n_points), source=0.0_wp)
        do p = 1, op%n_points
            nk = [1 - op%xi(p), op%xi(p)]
            do j = 1, 2
                if (nk(j) >= snap) hat(model%conn(j, op%element(p)), p) = nk(j)
            end do
        end do
        med%node = pack([(k, k=1, model%n_nodes)], any(hat > 0, dim=2))
        med%n_nodes = size(med%node)
        med%per_node = rpp
        med%n_mult = med%n_nodes*rpp
        allocate (slot(model%n_nodes), source=0)
        slot(med%node) = [(k, k=1, med%n_nodes)]
        allocate (med%pi(med%n_mult, op%n_rows), source=0.0_wp)
        allocate (med%comp(med%n_mult))
        do k = 1, med%n_nodes
            do c = 1, rpp
                m = (k - 1)*rpp + c
                med%comp(m) = c
                do p = 1, op%n_points
                    med%pi(m, op%row_of(p, c)) = hat(med%node(k), p)
                end do
            end do
        end do
        ! Independence of the nodes' rows (one component suffices: the same hats), by
        ! modified Gram-Schmidt in node order.
        allocate (basis(op%n_points, med%n_nodes), source=0.0_wp)
        do k = 1, med%n_nodes
            basis(:, k) = hat(med%node(k), :)
            r0 = norm2(basis(:, k))
            do j = 1, k - 1
                basis(:, k) = basis(:, k) - dot_product(basis(:, j), basis(:, k))*basis(:, j)
            end do
            if (norm2(basis(:, k)) < independent*r0) then
                write (buf, '(a,i0,a)') 'coupling: multipliers = nodes: beam node ', &
                    model%node_id(med%node(k)), ' of the mediator space is not resolved by '// &
                    'the coupled points (its hat functions at the points are a combination '// &
                    'of those of the other mediator nodes, e.g. a single coupled point inside '// &
                    'an element whose nodes carry no other point): couple more disks around '// &
                    'it, or use multipliers = particles'
                call make_error(error, trim(buf))
                return
            end if
            basis(:, k) = basis(:, k)/norm2(basis(:, k))
        end do
    end subroutine build_mediator

    !> Project the points on the beam (fem_beam_projection) and build C.
    subroutine build_coupling_operator(model, x, y, op, error, with_rotation, max_offset)
        !> The beam model.
        type(beam_model_t), intent(in) :: model
        !> Coordinates of the coupled points [m] (n_points each).
        real(wp), intent(in) :: x(:), y(:)
        !> The operator built.
        type(coupling_operator_t), intent(out) :: op
        !> Set when a point's nearest point on the axis lies past an end of the beam, or the
        !> point is too far from the axis.
        type(error_t), allocatable, intent(out) :: error
        !> Add a rotation row phi = theta(xi) per point (default: no).
        logical, intent(in), optional :: with_rotation
        !> Largest accepted |offset| [m] (default: any).
        real(wp), intent(in), optional :: max_offset
        integer :: p, e, k, r
        type(beam_point_t) :: at
        real(wp) :: rows(3, 6)
        character(len=240) :: buf
        if (size(x) /= size(y)) then
            call make_internal_error(error, 'coupling operator', 'x and y of the coupled points '// &
                                     'differ in size')
            return
        end if
        op%n_points = size(x)
        op%rows_per_point = 2
        if (present(with_rotation)) then
            if (with_rotation) op%rows_per_point = 3
        end if
        op%n_rows = op%n_points*op%rows_per_point
        op%n_free = model%n_free
        allocate (op%element(op%n_points), op%xi(op%n_points), op%offset(op%n_points))
        allocate (op%arm(2, op%n_points))
        allocate (op%abscissa(op%n_points), op%col(6, op%n_rows), op%val(6, op%n_rows))
        do p = 1, op%n_points
            at = project_on_beam(model, x(p), y(p))
            if (at%element == 0 .or. at%past_end()) then
                write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a)') 'coupling operator: coupled point ', &
                    p, ' at (', x(p), ', ', y(p), ') m is not over the beam (its nearest point '// &
                    'on the axis lies past an end of the beam); move it or extend the beam'
                call make_error(error, trim(buf))
                return
            end if
            if (present(max_offset)) then
                if (abs(at%offset()) > max_offset) then
                    write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a,es11.3e3,a,es11.3e3,a)') &
                        'coupling operator: coupled point ', p, ' at (', x(p), ', ', y(p), &
                        ') m is ', abs(at%offset()), ' m from the beam axis, more than the ', &
                        max_offset, ' m allowed'
                    call make_error(error, trim(buf))
                    return
                end if
            end if
            e = at%element
            op%element(p) = e
            op%xi(p) = at%xi
            op%offset(p) = at%offset()
            op%arm(:, p) = [at%along, at%across]
            op%abscissa(p) = at%abscissa
            rows = point_rows(model, e, at%xi, at%along, at%across)
            do k = 1, op%rows_per_point
                r = (p - 1)*op%rows_per_point + k
                op%col(1:3, r) = model%eq(:, model%conn(1, e))
                op%col(4:6, r) = model%eq(:, model%conn(2, e))
                op%val(:, r) = merge(rows(k, :), 0.0_wp, op%col(:, r) > 0)
            end do
        end do
    end subroutine build_coupling_operator

    !> Rows (x, y, phi) acting on the six global DOFs of element e for a point at xi with the
    !> arm (along, across): local rows (u_t - across theta, w + along theta, theta) rotated by
    !> R^T and applied to T.
    pure function point_rows(model, e, xi, along, across) result(rows)
        type(beam_model_t), intent(in) :: model
        integer, intent(in) :: e
        real(wp), intent(in) :: xi, along, across
        real(wp) :: rows(3, 6)
        real(wp) :: n(3, 6), t(6, 6), rt(6), rn(6)
        associate (c => model%cosine(e), s => model%sine(e))
            n = element_interpolation(xi, model%length(e))
            t = rotation_matrix(c, s)
            rt = matmul(n(1, :) - across*n(3, :), t)
            rn = matmul(n(2, :) + along*n(3, :), t)
            rows(1, :) = c*rt - s*rn
            rows(2, :) = s*rt + c*rn
            rows(3, :) = matmul(n(3, :), t)
        end associate
    end function point_rows

    !> y = C u.
    pure subroutine apply(self, u, cu)
        !> The operator.
        class(coupling_operator_t), intent(in) :: self
        !> Field on the free DOFs (n_free).
        real(wp), intent(in) :: u(:)
        !> Values at the coupled points (n_rows).
        real(wp), intent(out) :: cu(:)
        integer :: r, k
        do r = 1, self%n_rows
            cu(r) = 0.0_wp
            do k = 1, 6
                if (self%col(k, r) > 0) cu(r) = cu(r) + self%val(k, r)*u(self%col(k, r))
            end do
        end do
    end subroutine apply

    !> f = C^T lambda.
    pure subroutine apply_transpose(self, u, cu)
        !> The operator.
        class(coupling_operator_t), intent(in) :: self
        !> One value per row (n_rows).
        real(wp), intent(in) :: u(:)
        !> Result on the free DOFs (n_free).
        real(wp), intent(out) :: cu(:)
        integer :: r, k
        cu = 0.0_wp
        do r = 1, self%n_rows
            do k = 1, 6
                if (self%col(k, r) > 0) cu(self%col(k, r)) = cu(self%col(k, r)) + &
                                                             self%val(k, r)*u(r)
            end do
        end do
    end subroutine apply_transpose

    !> |d_p - d_q|: plane sections stay plane and keep their depth, so the beam holds the
    !> distance of two points across its axis rigid (to first order); along the axis it strains.
    pure real(wp) function rigid_distance(self, p, q) result(d)
        !> The operator.
        class(coupling_operator_t), intent(in) :: self
        !> Two points (1..n_points).
        integer, intent(in) :: p, q
        d = abs(self%offset(p) - self%offset(q))
    end function rigid_distance

    !> Dense copy of C (n_rows, n_free).
    pure function to_dense(self) result(c)
        !> The operator.
        class(coupling_operator_t), intent(in) :: self
        real(wp) :: c(self%n_rows, self%n_free)
        integer :: r, k
        c = 0.0_wp
        do r = 1, self%n_rows
            do k = 1, 6
                if (self%col(k, r) > 0) c(r, self%col(k, r)) = c(r, self%col(k, r)) + &
                                                               self%val(k, r)
            end do
        end do
    end function to_dense

    !> Weight alpha at each coupled point (from its abscissa). A point where alpha is 0 or 1
    !> (outside the overlap) has no mass on one side and would make the multiplier matrix
    !> singular: that is an error naming the point.
    subroutine point_weights(self, weight, alpha, error)
        !> The operator.
        class(coupling_operator_t), intent(in) :: self
        !> The Arlequin weight.
        class(weight_function_t), intent(in) :: weight
        !> alpha at each point (n_points), in (0, 1).
        real(wp), allocatable, intent(out) :: alpha(:)
        !> Set when a point lies where alpha = 0 or 1.
        type(error_t), allocatable, intent(out) :: error
        integer :: p
        character(len=240) :: buf
        allocate (alpha(self%n_points))
        do p = 1, self%n_points
            alpha(p) = weight%value(self%abscissa(p))
            if (alpha(p) > 0 .and. alpha(p) < 1) cycle
            write (buf, '(a,i0,a,es13.5e3,a,f5.3,a)') 'coupling: coupled point ', p, &
                ' (abscissa ', self%abscissa(p), ' m) has weight alpha = ', alpha(p), &
                ', outside the overlap: only points inside the overlap can be coupled'
            call make_error(error, trim(buf))
            return
        end do
    end subroutine point_weights
end module coupling_operator
