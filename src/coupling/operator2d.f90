!> Coupling operator C of the 2D Arlequin coupling and its mediator space (doc/continuum.md,
!> "Arlequin coupling in 2D"; doc/theory.md section 6.9).
!>
!> C interpolates the continuum's displacement at each coupled disk centre with the shape
!> functions of the element holding it (found by coupling_locate2d's cell grid):
!>   u_x(x_p) = sum_a N_a(x_p) u_ax,  u_y(x_p) = sum_a N_a(x_p) u_ay,
!> and optionally the rotation row omega(x_p) = 1/2 (du_y/dx - du_x/dy) (the continuum's
!> infinitesimal rotation, 1/2 curl u), glued to the disk's rotation. Rows are ordered point
!> by point, (x, y[, omega]). Each row keeps up to 8 (dof, value) pairs: the global dof
!> (2a - 1 for x, 2a for y) and its free column (equation number of the model; 0 for a
!> prescribed dof, left out of `apply`, kept by `apply_all`). The entries on dofs prescribed
!> in time (u_p = value f(t)) give C_p u_p(t) and C_p v_p(t) (`add_prescribed`, with a copy of
!> the model's time functions); constant prescribed dofs add nothing to the constraint
!> q - q_0 = C (u - u_0) and its rate.
!>
!> Mediator space (`build_mediator2d`): one multiplier per component on every FE node whose
!> shape function is non-zero at some coupled point (values below 1e-9 count as 0), with
!> the discrete L2 pairing Pi_L2(k, p) = N_k(x_p): the constraint sum_p N_k(x_p) e_p = 0
!> tests the residual e (disk minus interpolated FE displacement) against every mediator
!> shape function, the coupled points acting as quadrature points. H1 pairing (Bauman, Ben
!> Dhia et al. 2008): with e_h = M^-1 Pi_L2 e the L2 representative of the point residual in
!> the mediator space (M, K the scalar mass and Laplacian matrices of the mediator shape
!> functions over the elements holding coupled points), the pairing is
!> mu^T (M + l^2 K) e_h, i.e. Pi_H1 = (M + l^2 K) M^-1 Pi_L2. Pi_H1 = T Pi_L2 with T
!> invertible: both impose the same constraint and give the same row forces and motion; the
!> multipliers differ (lambda_H1 = T^-T lambda_L2, smoother) and so does the conditioning
!> of A_m.
module coupling_operator2d
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_linalg, only: dense_spd_t
    use core_timefunc, only: time_function_slot_t
    use fem_continuum_model, only: continuum_model_t
    use coupling_map, only: coupling_map_t
    use coupling_locate2d, only: element_grid_t
    use coupling_multiplier_space, only: mediator_space_t, make_mediator_space
    implicit none
    private
    public :: continuum_operator_t, build_continuum_operator, build_mediator2d
    public :: pairing_l2, pairing_h1

    !> Mediator pairing: discrete L2.
    integer, parameter :: pairing_l2 = 1
    !> Mediator pairing: H1 (L2 plus l^2 times the gradients).
    integer, parameter :: pairing_h1 = 2
    !> Entries per row (Q4 rotation row: 4 nodes, 2 dofs).
    integer, parameter :: width = 8

    !> C of a continuum at coupled points (see the module description).
    type, extends(coupling_map_t) :: continuum_operator_t
        !> Element holding each point (n_points).
        integer, allocatable :: element(:)
        !> Natural coordinates of each point in its element (2, n_points).
        real(wp), allocatable :: xi(:, :)
        !> Global dof of each entry (width, n_rows); 0 for padding.
        integer, allocatable :: dof(:, :)
        !> Free column of each entry (width, n_rows); 0 for a prescribed dof or padding.
        integer, allocatable :: col(:, :)
        !> Value of each entry (width, n_rows).
        real(wp), allocatable :: val(:, :)
        !> Value times the prescribed amplitude of each entry on a dof prescribed in time
        !> (width, n_rows) [m]; 0 elsewhere.
        real(wp), allocatable :: timed(:, :)
        !> Time function of each entry on a dof prescribed in time (width, n_rows); 0 elsewhere.
        integer, allocatable :: timed_function(:, :)
        !> The model's time functions.
        type(time_function_slot_t), allocatable :: functions(:)
    contains
        !> y = C u (u over the free dofs).
        procedure :: apply => op2d_apply
        !> f = C^T lambda (over the free dofs).
        procedure :: apply_transpose => op2d_apply_transpose
        !> Dense C over the free dofs.
        procedure :: to_dense => op2d_to_dense
        !> y = C u with u over all dofs (prescribed ones included).
        procedure :: apply_all => op2d_apply_all
        !> f = C^T lambda over all dofs (prescribed ones included).
        procedure :: transpose_all => op2d_transpose_all
        !> y += C_p u_p(t) or C_p v_p(t) over the dofs prescribed in time.
        procedure :: add_prescribed => op2d_add_prescribed
    end type continuum_operator_t

contains

    !> Locate the points and build C.
    subroutine build_continuum_operator(model, grid, x, y, op, error, with_rotation)
        !> The continuum model (its equation numbering gives the columns).
        type(continuum_model_t), intent(in) :: model
        !> The cell grid of the model's mesh.
        type(element_grid_t), intent(in) :: grid
        !> Coordinates of the coupled points [m] (n_points each).
        real(wp), intent(in) :: x(:), y(:)
        !> The operator.
        type(continuum_operator_t), intent(out) :: op
        !> Set when sizes differ or a point lies in no element.
        type(error_t), allocatable, intent(out) :: error
        !> Add the rotation row 1/2 curl u per point (default: no).
        logical, intent(in), optional :: with_rotation
        integer, allocatable :: eq(:), nodes(:)
        real(wp), allocatable :: n(:), dndx(:, :)
        real(wp) :: detj
        integer :: p, e, a, nn, r
        character(len=240) :: buf
        if (size(x) /= size(y)) then
            call make_error(error, 'continuum coupling operator: x and y of the coupled points differ in size')
            return
        end if
        op%n_points = size(x)
        op%rows_per_point = 2
        if (present(with_rotation)) then
            if (with_rotation) op%rows_per_point = 3
        end if
        op%n_rows = op%n_points*op%rows_per_point
        call model%equations(eq, op%n_free)
        allocate (op%element(op%n_points), op%xi(2, op%n_points))
        allocate (op%dof(width, op%n_rows), op%col(width, op%n_rows), source=0)
        allocate (op%val(width, op%n_rows), source=0.0_wp)
        do p = 1, op%n_points
            call grid%locate(model%mesh, x(p), y(p), e, op%xi(:, p))
            if (e == 0) then
                write (buf, '(a,i0,a,es13.5e3,a,es13.5e3,a)') 'continuum coupling operator: coupled point ', p, &
                    ' at (', x(p), ', ', y(p), ') m lies in no element of the mesh; move it or extend the mesh'
                call make_error(error, trim(buf))
                return
            end if
            op%element(p) = e
            nodes = model%mesh%element_nodes(e)
            nn = size(nodes)
            allocate (n(nn), dndx(nn, 2))
            associate (el => model%family(model%mesh%kind(e))%element)
                call el%geometry(model%mesh%element_coordinates(e), op%xi(:, p), n, dndx, detj)
            end associate
            r = op%row_of(p, 1)
            op%dof(1:nn, r) = 2*nodes - 1
            op%val(1:nn, r) = n
            r = op%row_of(p, 2)
            op%dof(1:nn, r) = 2*nodes
            op%val(1:nn, r) = n
            if (op%rows_per_point == 3) then
                r = op%row_of(p, 3)
                do a = 1, nn
                    op%dof(2*a - 1:2*a, r) = [2*nodes(a) - 1, 2*nodes(a)]
                    op%val(2*a - 1:2*a, r) = 0.5_wp*[-dndx(a, 2), dndx(a, 1)]
                end do
            end if
            deallocate (n, dndx)
        end do
        allocate (op%timed(width, op%n_rows), source=0.0_wp)
        allocate (op%timed_function(width, op%n_rows), source=0)
        op%functions = model%functions
        do r = 1, op%n_rows
            do a = 1, width
                if (op%dof(a, r) == 0) cycle
                op%col(a, r) = eq(op%dof(a, r))
                if (.not. model%prescribed(op%dof(a, r))) cycle
                op%timed_function(a, r) = model%prescribed_function(op%dof(a, r))
                if (op%timed_function(a, r) > 0) op%timed(a, r) = op%val(a, r)*model%prescribed_value(op%dof(a, r))
            end do
        end do
    end subroutine build_continuum_operator

    !> y = C u over the free dofs.
    pure subroutine op2d_apply(self, u, cu)
        class(continuum_operator_t), intent(in) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: cu(:)
        integer :: r, k
        do r = 1, self%n_rows
            cu(r) = 0.0_wp
            do k = 1, width
                if (self%col(k, r) > 0) cu(r) = cu(r) + self%val(k, r)*u(self%col(k, r))
            end do
        end do
    end subroutine op2d_apply

    !> f = C^T lambda over the free dofs.
    pure subroutine op2d_apply_transpose(self, u, cu)
        class(continuum_operator_t), intent(in) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: cu(:)
        integer :: r, k
        cu = 0.0_wp
        do r = 1, self%n_rows
            do k = 1, width
                if (self%col(k, r) > 0) cu(self%col(k, r)) = cu(self%col(k, r)) + self%val(k, r)*u(r)
            end do
        end do
    end subroutine op2d_apply_transpose

    !> Dense C (n_rows, n_free).
    pure function op2d_to_dense(self) result(c)
        class(continuum_operator_t), intent(in) :: self
        real(wp) :: c(self%n_rows, self%n_free)
        integer :: r, k
        c = 0.0_wp
        do r = 1, self%n_rows
            do k = 1, width
                if (self%col(k, r) > 0) c(r, self%col(k, r)) = c(r, self%col(k, r)) + self%val(k, r)
            end do
        end do
    end function op2d_to_dense

    !> y = C u with u over all dofs (2 per node).
    pure subroutine op2d_apply_all(self, u, cu)
        !> The operator.
        class(continuum_operator_t), intent(in) :: self
        !> Displacements over all dofs.
        real(wp), intent(in) :: u(:)
        !> Values at the coupled points (n_rows).
        real(wp), intent(out) :: cu(:)
        integer :: r, k
        do r = 1, self%n_rows
            cu(r) = 0.0_wp
            do k = 1, width
                if (self%dof(k, r) > 0) cu(r) = cu(r) + self%val(k, r)*u(self%dof(k, r))
            end do
        end do
    end subroutine op2d_apply_all

    !> f = C^T lambda over all dofs (2 per node): on the prescribed ones, the share of the
    !> multipliers' force the supports take.
    pure subroutine op2d_transpose_all(self, lambda, f)
        !> The operator.
        class(continuum_operator_t), intent(in) :: self
        !> Values at the coupled rows (n_rows).
        real(wp), intent(in) :: lambda(:)
        !> Over all dofs (2 per node of the model).
        real(wp), intent(out) :: f(:)
        integer :: r, k
        f = 0.0_wp
        do r = 1, self%n_rows
            do k = 1, width
                if (self%dof(k, r) > 0) f(self%dof(k, r)) = f(self%dof(k, r)) + self%val(k, r)*lambda(r)
            end do
        end do
    end subroutine op2d_transpose_all

    !> y += sum over the entries on dofs prescribed in time of value amplitude f(t) (derivative
    !> 0) or value amplitude f'(t) (derivative 1).
    pure subroutine op2d_add_prescribed(self, t, derivative, y)
        !> The operator.
        class(continuum_operator_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> 0: displacement, 1: velocity.
        integer, intent(in) :: derivative
        !> Values at the coupled rows (n_rows), updated.
        real(wp), intent(inout) :: y(:)
        integer :: r, k
        if (.not. allocated(self%timed_function)) return
        do r = 1, self%n_rows
            do k = 1, width
                if (self%timed_function(k, r) == 0) cycle
                associate (fn => self%functions(self%timed_function(k, r))%fn)
                    if (derivative == 0) y(r) = y(r) + self%timed(k, r)*fn%value(t)
                    if (derivative /= 0) y(r) = y(r) + self%timed(k, r)*fn%rate(t)
                end associate
            end do
        end do
    end subroutine op2d_add_prescribed

    !> The mediator space on the FE nodes carrying coupled points (see the module
    !> description), multipliers ordered node by node, (x, y[, omega]) per node.
    subroutine build_mediator2d(model, op, pairing, length, space, nodes, error)
        !> The continuum model.
        type(continuum_model_t), intent(in) :: model
        !> The coupling operator (points located).
        type(continuum_operator_t), intent(in) :: op
        !> pairing_l2 or pairing_h1.
        integer, intent(in) :: pairing
        !> Length l of the H1 pairing [m] (unused for L2).
        real(wp), intent(in) :: length
        !> The mediator space.
        type(mediator_space_t), intent(out) :: space
        !> Mesh node of each mediator node, increasing.
        integer, allocatable, intent(out) :: nodes(:)
        !> Set when a mediator node is not resolved by the points or M is singular.
        type(error_t), allocatable, intent(out) :: error
        ! Shape values below this are a point on an edge or node up to rounding.
        real(wp), parameter :: snap = 1.0e-9_wp
        ! A row keeping less than this fraction of its norm once projected out of the
        ! previous rows is a combination of them.
        real(wp), parameter :: independent = 1.0e-6_wp
        real(wp), allocatable :: hat(:, :), basis(:, :), pi(:, :), n(:), dndx(:, :), t(:, :)
        integer, allocatable :: slot(:), enodes(:), comp(:)
        logical, allocatable :: carries(:)
        real(wp) :: detj, r0
        integer :: p, a, k, j, c, rpp, nmed
        character(len=400) :: buf
        rpp = op%rows_per_point
        allocate (carries(model%mesh%node_count()), source=.false.)
        do p = 1, op%n_points
            call point_shape(model, op%element(p), op%xi(:, p), n, dndx, detj)
            enodes = model%mesh%element_nodes(op%element(p))
            carries(pack(enodes, n >= snap)) = .true.
        end do
        nodes = pack([(k, k=1, size(carries))], carries)
        nmed = size(nodes)
        allocate (slot(size(carries)), source=0)
        slot(nodes) = [(k, k=1, nmed)]
        allocate (hat(nmed, op%n_points), source=0.0_wp)
        do p = 1, op%n_points
            call point_shape(model, op%element(p), op%xi(:, p), n, dndx, detj)
            enodes = model%mesh%element_nodes(op%element(p))
            do a = 1, size(enodes)
                if (n(a) >= snap) hat(slot(enodes(a)), p) = n(a)
            end do
        end do
        ! Independence of the nodes' rows, by modified Gram-Schmidt in node order.
        basis = transpose(hat)
        do k = 1, nmed
            r0 = norm2(basis(:, k))
            do j = 1, k - 1
                basis(:, k) = basis(:, k) - dot_product(basis(:, j), basis(:, k))*basis(:, j)
            end do
            if (norm2(basis(:, k)) < independent*r0) then
                write (buf, '(a,i0,a)') 'coupling: mediator space: FE node ', nodes(k), ' is not resolved '// &
                    'by the coupled points (its shape functions at the points are a combination of '// &
                    'those of the other mediator nodes): couple more disks around it, or use '// &
                    'multipliers on the disks'
                call make_error(error, trim(buf))
                return
            end if
            basis(:, k) = basis(:, k)/norm2(basis(:, k))
        end do
        if (pairing == pairing_h1) then
            call h1_transform(model, op, slot, nmed, length, t, error)
            if (allocated(error)) return
            hat = matmul(t, hat)
        end if
        allocate (pi(nmed*rpp, op%n_rows), source=0.0_wp)
        allocate (comp(nmed*rpp))
        do k = 1, nmed
            do c = 1, rpp
                comp((k - 1)*rpp + c) = c
                do p = 1, op%n_points
                    pi((k - 1)*rpp + c, op%row_of(p, c)) = hat(k, p)
                end do
            end do
        end do
        call make_mediator_space(pi, comp, space, error)
    end subroutine build_mediator2d

    !> T = (M + l^2 K) M^-1 over the mediator nodes (scalar matrices integrated over the
    !> elements holding coupled points with their own quadrature).
    subroutine h1_transform(model, op, slot, nmed, length, t, error)
        type(continuum_model_t), intent(in) :: model
        type(continuum_operator_t), intent(in) :: op
        integer, intent(in) :: slot(:), nmed
        real(wp), intent(in) :: length
        real(wp), allocatable, intent(out) :: t(:, :)
        type(error_t), allocatable, intent(out) :: error
        type(dense_spd_t) :: mm
        real(wp), allocatable :: kk(:, :), pts(:, :), w(:), n(:), dndx(:, :), g(:, :)
        integer, allocatable :: elems(:), enodes(:)
        real(wp) :: detj
        integer :: i, e, q, a, b, sa, sb
        call mm%init(nmed)
        mm%a = 0.0_wp
        allocate (kk(nmed, nmed), source=0.0_wp)
        elems = op%element
        do i = 1, size(elems)
            e = elems(i)
            if (any(elems(:i - 1) == e)) cycle
            enodes = model%mesh%element_nodes(e)
            associate (el => model%family(model%mesh%kind(e))%element)
                call el%quadrature(pts, w)
                allocate (n(size(enodes)), dndx(size(enodes), 2))
                do q = 1, size(w)
                    call el%geometry(model%mesh%element_coordinates(e), pts(:, q), n, dndx, detj)
                    do a = 1, size(enodes)
                        sa = slot(enodes(a))
                        if (sa == 0) cycle
                        do b = 1, size(enodes)
                            sb = slot(enodes(b))
                            if (sb == 0) cycle
                            mm%a(sa, sb) = mm%a(sa, sb) + w(q)*detj*n(a)*n(b)
                            kk(sa, sb) = kk(sa, sb) + w(q)*detj*dot_product(dndx(a, :), dndx(b, :))
                        end do
                    end do
                end do
                deallocate (n, dndx)
            end associate
        end do
        g = mm%a + length**2*kk
        call mm%factor(error)
        if (allocated(error)) then
            error%message = 'coupling: mediator space: the mass matrix of the mediator nodes is singular; '// &
                            error%message
            return
        end if
        ! T = G M^-1 = (M^-1 G)^T (M and G symmetric).
        call mm%solve(g, error)
        if (allocated(error)) return
        t = transpose(g)
    end subroutine h1_transform

    !> Shape functions and Cartesian derivatives of element e at natural point xi.
    subroutine point_shape(model, e, xi, n, dndx, detj)
        type(continuum_model_t), intent(in) :: model
        integer, intent(in) :: e
        real(wp), intent(in) :: xi(2)
        real(wp), allocatable, intent(out) :: n(:), dndx(:, :)
        real(wp), intent(out) :: detj
        integer :: nn
        nn = size(model%mesh%element_nodes(e))
        allocate (n(nn), dndx(nn, 2))
        associate (el => model%family(model%mesh%kind(e))%element)
            call el%geometry(model%mesh%element_coordinates(e), xi, n, dndx, detj)
        end associate
    end subroutine point_shape
end module coupling_operator2d
