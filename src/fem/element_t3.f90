!> Linear triangle T3 (constant strain): nodes counter-clockwise at natural (0,0), (1,0),
!> (0,1); N = (1 - xi - eta, xi, eta); 3-point quadrature exact for quadratics (interior
!> points (1/6, 1/6), (2/3, 1/6), (1/6, 2/3), weights 1/6), so that the consistent mass
!> int N_a N_b dA is exact; the stiffness is exact with any rule. Inverse map in closed form
!> (the map is affine); rules of higher order collapse the n x n Gauss square onto the triangle
!> (Duffy). Deck name 't3', XDMF 'Triangle' (code 4), Gmsh type 2; two per grid cell, split
!> along the diagonal from the lower-left to the upper-right corner.
module fem_element_t3
    use core_kinds, only: wp
    use fem_element2d, only: element2d_t, gauss_legendre
    implicit none
    private
    public :: element_t3_t

    real(wp), parameter :: a6 = 1.0_wp/6.0_wp, b3 = 2.0_wp/3.0_wp

    !> The T3 element type.
    type, extends(element2d_t) :: element_t3_t
        !> Natural coordinates of the vertices (2, 3).
        real(wp) :: vertex(2, 3) = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 3])
        !> Shape functions at the origin of the natural coordinates: N = n0 + G xi.
        real(wp) :: n0(3) = [1.0_wp, 0.0_wp, 0.0_wp]
        !> Constant natural gradient G = dN/dxi (3, 2).
        real(wp) :: gradient(3, 2) = reshape([-1.0_wp, 1.0_wp, 0.0_wp, -1.0_wp, 0.0_wp, 1.0_wp], [3, 2])
        !> Quadrature points (2, 3).
        real(wp) :: points(2, 3) = reshape([a6, a6, b3, a6, a6, b3], [2, 3])
        !> Quadrature weights (summing to the reference area 1/2).
        real(wp) :: weights(3) = a6
    contains
        !> 3 nodes.
        procedure :: node_count => t3_node_count
        !> Vertices of the reference triangle.
        procedure :: natural_nodes => t3_natural_nodes
        !> Linear shape functions.
        procedure :: shape => t3_shape
        !> 3-point rule of degree 2.
        procedure :: quadrature => t3_quadrature
        !> 't3'.
        procedure :: name => t3_name
        !> xi >= 0, eta >= 0, xi + eta <= 1, up to the tolerance.
        procedure :: inside => t3_inside
        !> Collapsed n x n Gauss rule.
        procedure :: gauss_rule => t3_gauss_rule
        !> 'Triangle'.
        procedure :: xdmf_topology => t3_xdmf_topology
        !> 4.
        procedure :: xdmf_code => t3_xdmf_code
        !> 2.
        procedure :: gmsh_type => t3_gmsh_type
        !> Two triangles per cell.
        procedure :: grid_cell => t3_grid_cell
        !> Closed form (barycentric coordinates).
        procedure :: inverse_map => t3_inverse_map
    end type element_t3_t

contains

    !> Number of nodes (3).
    pure integer function t3_node_count(self)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        t3_node_count = size(self%vertex, 2)
    end function t3_node_count

    !> Natural coordinates of the vertices.
    pure function t3_natural_nodes(self) result(xi)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> (2, 3).
        real(wp), allocatable :: xi(:, :)
        xi = self%vertex
    end function t3_natural_nodes

    !> N = (1 - xi - eta, xi, eta) = n0 + G xi and its (constant) natural derivatives G.
    pure subroutine t3_shape(self, xi, n, dn)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> Natural point (xi, eta).
        real(wp), intent(in) :: xi(2)
        !> Shape functions (3).
        real(wp), intent(out) :: n(:)
        !> dN/dxi (3, 2).
        real(wp), intent(out) :: dn(:, :)
        n = self%n0 + matmul(self%gradient, xi)
        dn = self%gradient
    end subroutine t3_shape

    !> Interior 3-point rule, degree 2.
    pure subroutine t3_quadrature(self, points, weights)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> Points (2, 3).
        real(wp), allocatable, intent(out) :: points(:, :)
        !> Weights (3), summing to 1/2 (the reference area).
        real(wp), allocatable, intent(out) :: weights(:)
        points = self%points
        weights = self%weights
    end subroutine t3_quadrature

    !> Deck name of the kind.
    pure function t3_name(self) result(name)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> 't3'.
        character(len=:), allocatable :: name
        name = 't3'
    end function t3_name

    !> True when xi >= -tol, eta >= -tol and xi + eta <= 1 + tol.
    pure logical function t3_inside(self, xi, tol)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> Natural point (xi, eta).
        real(wp), intent(in) :: xi(2)
        !> Tolerance in natural coordinates.
        real(wp), intent(in) :: tol
        t3_inside = xi(1) >= -tol .and. xi(2) >= -tol .and. xi(1) + xi(2) <= 1 + tol
    end function t3_inside

    !> The n x n Gauss-Legendre rule of the unit square (u, v) mapped onto the triangle by
    !> (xi, eta) = (u, v (1 - u)), Jacobian 1 - u; u runs fastest.
    pure subroutine t3_gauss_rule(self, n, points, weights)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> Gauss points per direction (>= 1).
        integer, intent(in) :: n
        !> Points (2, n^2).
        real(wp), allocatable, intent(out) :: points(:, :)
        !> Weights (n^2), summing to 1/2.
        real(wp), allocatable, intent(out) :: weights(:)
        real(wp) :: t(n), wt(n)
        integer :: i, j, q
        call gauss_legendre(n, t, wt)
        allocate (points(2, n*n), weights(n*n))
        q = 0
        do j = 1, n
            do i = 1, n
                q = q + 1
                associate (u => 0.5_wp*(1 + t(i)), v => 0.5_wp*(1 + t(j)))
                    points(:, q) = [u, v*(1 - u)]
                    weights(q) = 0.25_wp*wt(i)*wt(j)*(1 - u)
                end associate
            end do
        end do
    end subroutine t3_gauss_rule

    !> XDMF topology of a triangle mesh.
    pure function t3_xdmf_topology(self) result(topology)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> 'Triangle'.
        character(len=:), allocatable :: topology
        topology = 'Triangle'
    end function t3_xdmf_topology

    !> XDMF code of a triangle in a mixed topology (4).
    pure integer function t3_xdmf_code(self)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        t3_xdmf_code = 4
    end function t3_xdmf_code

    !> Gmsh type of the 3-node triangle (2).
    pure integer function t3_gmsh_type(self)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        t3_gmsh_type = 2
    end function t3_gmsh_type

    !> Triangles (1, 2, 3) and (1, 3, 4) of a cell: the diagonal from lower left to upper right.
    pure function t3_grid_cell(self) result(cell)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> Corner numbers (3, 2).
        integer, allocatable :: cell(:, :)
        cell = reshape([1, 2, 3, 1, 3, 4], [3, 2])
    end function t3_grid_cell

    !> Natural coordinates of p in closed form: with J = (x_2 - x_1, x_3 - x_1),
    !> xi = J^-1 (p - x_1) by Cramer's rule (non-finite when det J = 0).
    pure subroutine t3_inverse_map(self, x, p, xi, converged)
        !> The element type.
        class(element_t3_t), intent(in) :: self
        !> Nodal coordinates (2, 3).
        real(wp), intent(in) :: x(:, :)
        !> The physical point.
        real(wp), intent(in) :: p(2)
        !> Natural coordinates (xi, eta).
        real(wp), intent(out) :: xi(2)
        !> Always true.
        logical, intent(out) :: converged
        real(wp) :: jac(2, 2), det, r(2)
        jac(:, 1) = x(:, 2) - x(:, 1)
        jac(:, 2) = x(:, 3) - x(:, 1)
        det = jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)
        r = p - x(:, 1)
        xi(1) = (jac(2, 2)*r(1) - jac(1, 2)*r(2))/det
        xi(2) = (-jac(2, 1)*r(1) + jac(1, 1)*r(2))/det
        converged = .true.
    end subroutine t3_inverse_map
end module fem_element_t3
