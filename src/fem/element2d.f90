!> The family of isoparametric 2D continuum elements (two displacement dofs per node).
!>
!> An extension gives its number of nodes, the natural coordinates of its nodes, its shape
!> functions and their natural derivatives at a point, its quadrature rule, and what the code
!> outside the family asks of an element kind: its deck name, its reference element (which
!> natural points it holds), a quadrature rule of a chosen order, its XDMF topology and Gmsh
!> type, and how it fills a cell of a structured grid (fem_element_registry maps kind ids,
!> deck names and Gmsh types to elements). Everything else is common and lives here: geometry
!> (x = sum N_a x_a, J = dx/dxi), strain-displacement matrix B, stiffness K = int B^T D B t dA,
!> consistent mass M = int rho t N^T N dA, row-sum lumped mass, body force f = int rho t N^T g
!> dA, the stress D B u at a point, and the inverse map of a physical point (Newton from the
!> centre, which an element may replace by a closed form).
!> Local dofs are ordered (u_1x, u_1y, u_2x, u_2y, ...).
module fem_element2d
    use core_kinds, only: wp
    use core_constants, only: pi
    use fem_elastic2d, only: elastic2d_t
    implicit none
    private
    public :: element2d_t, gauss_legendre

    !> An isoparametric 2D continuum element type (stateless: one instance serves every element
    !> of that type; the nodal coordinates are passed in).
    type, abstract :: element2d_t
    contains
        !> Number of nodes.
        procedure(node_count_iface), deferred :: node_count
        !> Natural coordinates of the nodes (2, node_count).
        procedure(natural_nodes_iface), deferred :: natural_nodes
        !> Shape functions and their derivatives with respect to the natural coordinates.
        procedure(shape_iface), deferred :: shape
        !> Quadrature points (natural coordinates) and weights on the reference element.
        procedure(quadrature_iface), deferred :: quadrature
        !> Name of the element kind in the deck (lower case, e.g. 'q4').
        procedure(name_iface), deferred :: name
        !> Whether a natural point lies in the reference element, up to a tolerance.
        procedure(inside_iface), deferred :: inside
        !> Quadrature rule of n Gauss-Legendre points per direction on the reference element.
        procedure(gauss_rule_iface), deferred :: gauss_rule
        !> XDMF topology type of a mesh of this kind alone (e.g. 'Quadrilateral').
        procedure(xdmf_topology_iface), deferred :: xdmf_topology
        !> XDMF cell type code in a 'Mixed' topology.
        procedure(integer_iface), deferred :: xdmf_code
        !> Gmsh element type number (MSH 4.1).
        procedure(integer_iface), deferred :: gmsh_type
        !> Elements of this kind filling one cell of a structured grid, by the cell's corners.
        procedure(grid_cell_iface), deferred :: grid_cell
        !> Natural coordinates of a physical point (Newton from the centre by default).
        procedure :: inverse_map => element_inverse_map
        !> Shape functions, Cartesian derivatives and det J at a natural point.
        procedure :: geometry => element_geometry
        !> Smallest det J over the nodes and quadrature points (> 0 for a valid element).
        procedure :: min_jacobian => element_min_jacobian
        !> Strain-displacement matrix B (3, 2 n) at a natural point.
        procedure :: b_matrix => element_b_matrix
        !> Area of the element.
        procedure :: area => element_area
        !> Stiffness matrix (2 n, 2 n).
        procedure :: stiffness => element_stiffness
        !> Consistent mass matrix (2 n, 2 n).
        procedure :: mass_consistent => element_mass_consistent
        !> Row-sum lumped mass (diagonal, 2 n).
        procedure :: mass_lumped => element_mass_lumped
        !> Equivalent nodal forces of a uniform body acceleration g (weight rho t g per area).
        procedure :: body_force => element_body_force
        !> Stress (xx, yy, xy) at a natural point for element displacements u.
        procedure :: stress_at => element_stress_at
        !> Stress at the element centre (mean of the natural node coordinates).
        procedure :: stress_centre => element_stress_centre
        !> Physical coordinates of the element centre.
        procedure :: centre => element_centre
    end type element2d_t

    abstract interface
        !> Number of nodes of the element type.
        pure integer function node_count_iface(self)
            import :: element2d_t
            !> The element type.
            class(element2d_t), intent(in) :: self
        end function node_count_iface

        !> Natural coordinates of the nodes.
        pure function natural_nodes_iface(self) result(xi)
            import :: element2d_t, wp
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> Natural coordinates (2, node_count).
            real(wp), allocatable :: xi(:, :)
        end function natural_nodes_iface

        !> Shape functions N and natural derivatives dN/dxi at the natural point xi.
        pure subroutine shape_iface(self, xi, n, dn)
            import :: element2d_t, wp
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> Natural coordinates of the point.
            real(wp), intent(in) :: xi(2)
            !> Shape functions (node_count).
            real(wp), intent(out) :: n(:)
            !> Derivatives dN_a/dxi_k (node_count, 2).
            real(wp), intent(out) :: dn(:, :)
        end subroutine shape_iface

        !> Quadrature rule on the reference element.
        pure subroutine quadrature_iface(self, points, weights)
            import :: element2d_t, wp
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> Natural coordinates of the points (2, npoints).
            real(wp), allocatable, intent(out) :: points(:, :)
            !> Weights (npoints), summing to the reference area.
            real(wp), allocatable, intent(out) :: weights(:)
        end subroutine quadrature_iface

        !> Name of the element kind in the deck.
        pure function name_iface(self) result(name)
            import :: element2d_t
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> The name, lower case.
            character(len=:), allocatable :: name
        end function name_iface

        !> True when the natural point xi lies in the reference element enlarged by tol.
        pure logical function inside_iface(self, xi, tol)
            import :: element2d_t, wp
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> Natural coordinates of the point.
            real(wp), intent(in) :: xi(2)
            !> How far (in natural coordinates) outside the reference element still counts.
            real(wp), intent(in) :: tol
        end function inside_iface

        !> A rule of n Gauss-Legendre points per direction on the reference element (the
        !> tensor rule on a square, its collapsed form on a triangle): n^2 points.
        pure subroutine gauss_rule_iface(self, n, points, weights)
            import :: element2d_t, wp
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> Gauss-Legendre points per direction (>= 1).
            integer, intent(in) :: n
            !> Natural coordinates of the points (2, n^2).
            real(wp), allocatable, intent(out) :: points(:, :)
            !> Weights (n^2), summing to the reference area.
            real(wp), allocatable, intent(out) :: weights(:)
        end subroutine gauss_rule_iface

        !> XDMF topology type of a mesh of elements of this kind only.
        pure function xdmf_topology_iface(self) result(topology)
            import :: element2d_t
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> The XDMF TopologyType.
            character(len=:), allocatable :: topology
        end function xdmf_topology_iface

        !> An integer property of the element kind.
        pure integer function integer_iface(self)
            import :: element2d_t
            !> The element type.
            class(element2d_t), intent(in) :: self
        end function integer_iface

        !> The elements of this kind covering one cell of a structured grid: the cell's corner
        !> nodes are numbered 1 (lower left), 2 (lower right), 3 (upper right), 4 (upper left);
        !> column k gives the corners that are the nodes of the cell's element k, in element
        !> node order (counter-clockwise).
        pure function grid_cell_iface(self) result(cell)
            import :: element2d_t
            !> The element type.
            class(element2d_t), intent(in) :: self
            !> Corner numbers (node_count, elements per cell).
            integer, allocatable :: cell(:, :)
        end function grid_cell_iface
    end interface

contains

    !> Shape functions, Cartesian derivatives dN/dx (n, 2) and det J at natural point xi.
    pure subroutine element_geometry(self, x, xi, n, dndx, detj)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Natural coordinates of the point.
        real(wp), intent(in) :: xi(2)
        !> Shape functions (node_count).
        real(wp), intent(out) :: n(:)
        !> Cartesian derivatives dN_a/dx_k (node_count, 2); zero when det J = 0.
        real(wp), intent(out) :: dndx(:, :)
        !> Jacobian determinant det(dx/dxi).
        real(wp), intent(out) :: detj
        real(wp) :: dn(size(n), 2), jac(2, 2), inv(2, 2)
        call self%shape(xi, n, dn)
        jac = matmul(x, dn) ! jac(i, k) = dx_i/dxi_k
        detj = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
        if (detj == 0.0_wp) then
            dndx = 0.0_wp
            return
        end if
        ! inv(k, i) = dxi_k/dx_i
        inv(1, 1) = jac(2, 2)/detj
        inv(1, 2) = -jac(1, 2)/detj
        inv(2, 1) = -jac(2, 1)/detj
        inv(2, 2) = jac(1, 1)/detj
        dndx = matmul(dn, inv)
    end subroutine element_geometry

    !> Smallest det J over the nodes and quadrature points; an element with a value <= 0 is
    !> inverted or degenerate (for Q4: not convex, or nodes clockwise).
    pure real(wp) function element_min_jacobian(self, x) result(jmin)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        real(wp), allocatable :: pts(:, :), w(:), xin(:, :)
        real(wp) :: n(self%node_count()), dndx(self%node_count(), 2), detj
        integer :: p
        call self%quadrature(pts, w)
        xin = self%natural_nodes()
        jmin = huge(1.0_wp)
        do p = 1, size(w)
            call self%geometry(x, pts(:, p), n, dndx, detj)
            jmin = min(jmin, detj)
        end do
        do p = 1, size(xin, 2)
            call self%geometry(x, xin(:, p), n, dndx, detj)
            jmin = min(jmin, detj)
        end do
    end function element_min_jacobian

    !> Strain-displacement matrix: eps = B u with rows (xx, yy, xy = du_x/dy + du_y/dx).
    pure function element_b_matrix(self, x, xi) result(b)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Natural coordinates of the point.
        real(wp), intent(in) :: xi(2)
        !> B (3, 2 node_count).
        real(wp) :: b(3, 2*self%node_count())
        real(wp) :: n(self%node_count()), dndx(self%node_count(), 2), detj
        call self%geometry(x, xi, n, dndx, detj)
        b = b_from_derivatives(dndx)
    end function element_b_matrix

    !> B from the Cartesian derivatives of the shape functions.
    pure function b_from_derivatives(dndx) result(b)
        real(wp), intent(in) :: dndx(:, :)
        real(wp) :: b(3, 2*size(dndx, 1))
        integer :: a
        b = 0.0_wp
        do a = 1, size(dndx, 1)
            b(1, 2*a - 1) = dndx(a, 1)
            b(2, 2*a) = dndx(a, 2)
            b(3, 2*a - 1) = dndx(a, 2)
            b(3, 2*a) = dndx(a, 1)
        end do
    end function b_from_derivatives

    !> Area int dA by the element's quadrature.
    pure real(wp) function element_area(self, x) result(area)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        real(wp), allocatable :: pts(:, :), w(:)
        real(wp) :: n(self%node_count()), dndx(self%node_count(), 2), detj
        integer :: p
        call self%quadrature(pts, w)
        area = 0.0_wp
        do p = 1, size(w)
            call self%geometry(x, pts(:, p), n, dndx, detj)
            area = area + w(p)*detj
        end do
    end function element_area

    !> Stiffness K = sum_p w_p det J_p t B_p^T D B_p.
    pure function element_stiffness(self, x, material) result(k)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Material (D matrix and thickness).
        type(elastic2d_t), intent(in) :: material
        !> K (2 n, 2 n).
        real(wp) :: k(2*self%node_count(), 2*self%node_count())
        real(wp), allocatable :: pts(:, :), w(:)
        real(wp) :: n(self%node_count()), dndx(self%node_count(), 2), detj
        real(wp) :: b(3, 2*self%node_count()), d(3, 3)
        integer :: p
        call self%quadrature(pts, w)
        d = material%d_matrix()
        k = 0.0_wp
        do p = 1, size(w)
            call self%geometry(x, pts(:, p), n, dndx, detj)
            b = b_from_derivatives(dndx)
            k = k + (w(p)*detj*material%thickness)*matmul(transpose(b), matmul(d, b))
        end do
    end function element_stiffness

    !> Consistent mass M_(2a-1+i, 2b-1+i) = int rho t N_a N_b dA (i = 0, 1).
    pure function element_mass_consistent(self, x, material) result(m)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Material (density and thickness).
        type(elastic2d_t), intent(in) :: material
        !> M (2 n, 2 n).
        real(wp) :: m(2*self%node_count(), 2*self%node_count())
        real(wp), allocatable :: pts(:, :), w(:)
        real(wp) :: n(self%node_count()), dndx(self%node_count(), 2), detj, c
        integer :: p, a, bb
        call self%quadrature(pts, w)
        m = 0.0_wp
        do p = 1, size(w)
            call self%geometry(x, pts(:, p), n, dndx, detj)
            c = w(p)*detj*material%density*material%thickness
            do bb = 1, size(n)
                do a = 1, size(n)
                    m(2*a - 1, 2*bb - 1) = m(2*a - 1, 2*bb - 1) + c*n(a)*n(bb)
                    m(2*a, 2*bb) = m(2*a, 2*bb) + c*n(a)*n(bb)
                end do
            end do
        end do
    end function element_mass_consistent

    !> Row-sum lumped mass: the diagonal entry of a dof is the sum of its row of the consistent
    !> mass, i.e. int rho t N_a dA (positive for Q4 and T3, whose shape functions are >= 0).
    pure function element_mass_lumped(self, x, material) result(m)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Material (density and thickness).
        type(elastic2d_t), intent(in) :: material
        !> Diagonal of the lumped mass (2 n).
        real(wp) :: m(2*self%node_count())
        m = sum(self%mass_consistent(x, material), dim=2)
    end function element_mass_lumped

    !> Equivalent nodal forces of the weight: f_(2a-1+i) = int rho t N_a g_i dA.
    pure function element_body_force(self, x, material, g) result(f)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Material (density and thickness).
        type(elastic2d_t), intent(in) :: material
        !> Acceleration of gravity (m/s^2), e.g. (0, -9.81).
        real(wp), intent(in) :: g(2)
        !> Nodal forces (2 n).
        real(wp) :: f(2*self%node_count())
        real(wp), allocatable :: pts(:, :), w(:)
        real(wp) :: n(self%node_count()), dndx(self%node_count(), 2), detj, c
        integer :: p, a
        call self%quadrature(pts, w)
        f = 0.0_wp
        do p = 1, size(w)
            call self%geometry(x, pts(:, p), n, dndx, detj)
            c = w(p)*detj*material%density*material%thickness
            do a = 1, size(n)
                f(2*a - 1:2*a) = f(2*a - 1:2*a) + c*n(a)*g
            end do
        end do
    end function element_body_force

    !> Stress sigma = D B(xi) u (xx, yy, xy) at a natural point.
    pure function element_stress_at(self, x, material, u, xi) result(sigma)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Material.
        type(elastic2d_t), intent(in) :: material
        !> Element displacements (2 n).
        real(wp), intent(in) :: u(:)
        !> Natural coordinates of the point.
        real(wp), intent(in) :: xi(2)
        !> Stress (xx, yy, xy) (Pa).
        real(wp) :: sigma(3)
        sigma = matmul(material%d_matrix(), matmul(self%b_matrix(x, xi), u))
    end function element_stress_at

    !> Stress at the element centre.
    pure function element_stress_centre(self, x, material, u) result(sigma)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Material.
        type(elastic2d_t), intent(in) :: material
        !> Element displacements (2 n).
        real(wp), intent(in) :: u(:)
        !> Stress (xx, yy, xy) (Pa).
        real(wp) :: sigma(3)
        real(wp), allocatable :: xin(:, :)
        xin = self%natural_nodes()
        sigma = self%stress_at(x, material, u, sum(xin, dim=2)/size(xin, 2))
    end function element_stress_centre

    !> Physical coordinates of the centre (image of the mean natural node position).
    pure function element_centre(self, x) result(c)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> Centre (2).
        real(wp) :: c(2)
        real(wp), allocatable :: xin(:, :)
        real(wp) :: n(self%node_count()), dn(self%node_count(), 2)
        xin = self%natural_nodes()
        call self%shape(sum(xin, dim=2)/size(xin, 2), n, dn)
        c = matmul(x, n)
    end function element_centre

    !> Natural coordinates xi of the physical point p by Newton's method on x(xi) = p from the
    !> centre (the mean natural node position): stopped when |xi| exceeds 10 (the point is far
    !> outside, where Newton may wander), when det J = 0, or after 30 iterations; converged when
    !> the step falls below max(1e-14, 64 eps max|x| / sqrt|det J|). The step bound is the
    !> rounding of xi: the residual carries the rounding of the coordinates (eps |x|), which the
    !> step divides by the element size, so small elements far from the origin need more than
    !> 1e-14.
    pure subroutine element_inverse_map(self, x, p, xi, converged)
        !> The element type.
        class(element2d_t), intent(in) :: self
        !> Nodal coordinates (2, node_count).
        real(wp), intent(in) :: x(:, :)
        !> The physical point.
        real(wp), intent(in) :: p(2)
        !> Natural coordinates of the point (the last iterate when not converged).
        real(wp), intent(out) :: xi(2)
        !> Whether the map was inverted (always, for a closed form).
        logical, intent(out) :: converged
        real(wp), allocatable :: xin(:, :)
        real(wp) :: jac(2, 2), det, r(2), dxi(2), n(self%node_count()), dn(self%node_count(), 2)
        integer :: it
        xin = self%natural_nodes()
        xi = sum(xin, dim=2)/size(xin, 2)
        converged = .false.
        do it = 1, 30
            call self%shape(xi, n, dn)
            r = p - matmul(x, n)
            jac = matmul(x, dn)
            det = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
            if (.not. abs(det) > 0) exit
            dxi(1) = (jac(2, 2)*r(1) - jac(1, 2)*r(2))/det
            dxi(2) = (-jac(2, 1)*r(1) + jac(1, 1)*r(2))/det
            xi = xi + dxi
            if (maxval(abs(xi)) > 10) exit
            if (maxval(abs(dxi)) < max(1.0e-14_wp, 64*epsilon(1.0_wp)*maxval(abs(x))/sqrt(abs(det)))) then
                converged = .true.
                exit
            end if
        end do
    end subroutine element_inverse_map

    !> Gauss-Legendre points and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses).
    pure subroutine gauss_legendre(n, t, w)
        !> Number of points.
        integer, intent(in) :: n
        !> Points (n), increasing.
        real(wp), intent(out) :: t(n)
        !> Weights (n), summing to 2.
        real(wp), intent(out) :: w(n)
        real(wp) :: x, p0, p1, p2, dp, dx
        integer :: i, k, it
        do i = 1, n
            x = -cos(pi*(i - 0.25_wp)/(n + 0.5_wp))
            do it = 1, 100
                p0 = 1.0_wp
                p1 = x
                do k = 2, n
                    p2 = ((2*k - 1)*x*p1 - (k - 1)*p0)/k
                    p0 = p1
                    p1 = p2
                end do
                ! p1 = P_n(x), p0 = P_{n-1}(x).
                dp = n*(x*p1 - p0)/(x*x - 1)
                dx = p1/dp
                x = x - dx
                if (abs(dx) < 1.0e-16_wp) exit
            end do
            t(i) = x
            w(i) = 2/((1 - x*x)*dp*dp)
        end do
    end subroutine gauss_legendre
end module fem_element2d
