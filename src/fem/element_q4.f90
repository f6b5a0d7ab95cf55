!> Bilinear quadrilateral Q4: nodes counter-clockwise at natural (-1,-1), (1,-1), (1,1),
!> (-1,1); N_a = (1 + xi xi_a)(1 + eta eta_a)/4; 2 x 2 Gauss quadrature (exact stiffness for
!> parallelograms, exact consistent mass for any quadrilateral). Inverse map by the family's
!> Newton; rules of higher order are n x n Gauss. Deck name 'q4', XDMF 'Quadrilateral' (code
!> 5), Gmsh type 3; one per grid cell.
module fem_element_q4
    use core_kinds, only: wp
    use fem_element2d, only: element2d_t, gauss_legendre
    implicit none
    private
    public :: element_q4_t

    real(wp), parameter :: corners(2, 4) = reshape([-1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, &
                                                    1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], [2, 4])

    !> The Q4 element type.
    type, extends(element2d_t) :: element_q4_t
        !> Natural coordinates of the corners (2, 4).
        real(wp) :: corner(2, 4) = corners
        !> Gauss points (2, 4): the corners scaled by 1/sqrt(3).
        real(wp) :: gauss(2, 4) = corners/sqrt(3.0_wp)
        !> Gauss weights.
        real(wp) :: weights(4) = 1.0_wp
    contains
        !> 4 nodes.
        procedure :: node_count => q4_node_count
        !> Corners of the square [-1, 1]^2.
        procedure :: natural_nodes => q4_natural_nodes
        !> Bilinear shape functions.
        procedure :: shape => q4_shape
        !> 2 x 2 Gauss.
        procedure :: quadrature => q4_quadrature
        !> 'q4'.
        procedure :: name => q4_name
        !> |xi|, |eta| <= 1, up to the tolerance.
        procedure :: inside => q4_inside
        !> n x n Gauss.
        procedure :: gauss_rule => q4_gauss_rule
        !> 'Quadrilateral'.
        procedure :: xdmf_topology => q4_xdmf_topology
        !> 5.
        procedure :: xdmf_code => q4_xdmf_code
        !> 3.
        procedure :: gmsh_type => q4_gmsh_type
        !> One quadrilateral per cell.
        procedure :: grid_cell => q4_grid_cell
    end type element_q4_t

contains

    !> Number of nodes (4).
    pure integer function q4_node_count(self)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        q4_node_count = size(self%corner, 2)
    end function q4_node_count

    !> Natural coordinates of the corners.
    pure function q4_natural_nodes(self) result(xi)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> (2, 4).
        real(wp), allocatable :: xi(:, :)
        xi = self%corner
    end function q4_natural_nodes

    !> N_a = (1 + xi xi_a)(1 + eta eta_a)/4 and its natural derivatives.
    pure subroutine q4_shape(self, xi, n, dn)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> Natural point (xi, eta).
        real(wp), intent(in) :: xi(2)
        !> Shape functions (4).
        real(wp), intent(out) :: n(:)
        !> dN/dxi (4, 2).
        real(wp), intent(out) :: dn(:, :)
        integer :: a
        do a = 1, 4
            associate (c => self%corner(:, a))
                n(a) = 0.25_wp*(1.0_wp + xi(1)*c(1))*(1.0_wp + xi(2)*c(2))
                dn(a, 1) = 0.25_wp*c(1)*(1.0_wp + xi(2)*c(2))
                dn(a, 2) = 0.25_wp*c(2)*(1.0_wp + xi(1)*c(1))
            end associate
        end do
    end subroutine q4_shape

    !> 2 x 2 Gauss points +-1/sqrt(3), weights 1.
    pure subroutine q4_quadrature(self, points, weights)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> Points (2, 4).
        real(wp), allocatable, intent(out) :: points(:, :)
        !> Weights (4), summing to 4.
        real(wp), allocatable, intent(out) :: weights(:)
        points = self%gauss
        weights = self%weights
    end subroutine q4_quadrature

    !> Deck name of the kind.
    pure function q4_name(self) result(name)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> 'q4'.
        character(len=:), allocatable :: name
        name = 'q4'
    end function q4_name

    !> True when |xi| <= 1 + tol and |eta| <= 1 + tol.
    pure logical function q4_inside(self, xi, tol)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> Natural point (xi, eta).
        real(wp), intent(in) :: xi(2)
        !> Tolerance in natural coordinates.
        real(wp), intent(in) :: tol
        q4_inside = maxval(abs(xi)) <= 1 + tol
    end function q4_inside

    !> The n x n Gauss-Legendre tensor rule on [-1, 1]^2; xi runs fastest.
    pure subroutine q4_gauss_rule(self, n, points, weights)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> Gauss points per direction (>= 1).
        integer, intent(in) :: n
        !> Points (2, n^2).
        real(wp), allocatable, intent(out) :: points(:, :)
        !> Weights (n^2), summing to 4.
        real(wp), allocatable, intent(out) :: weights(:)
        real(wp) :: t(n), wt(n)
        integer :: i, j, q
        call gauss_legendre(n, t, wt)
        allocate (points(2, n*n), weights(n*n))
        q = 0
        do j = 1, n
            do i = 1, n
                q = q + 1
                points(:, q) = [t(i), t(j)]
                weights(q) = wt(i)*wt(j)
            end do
        end do
    end subroutine q4_gauss_rule

    !> XDMF topology of a quadrilateral mesh.
    pure function q4_xdmf_topology(self) result(topology)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> 'Quadrilateral'.
        character(len=:), allocatable :: topology
        topology = 'Quadrilateral'
    end function q4_xdmf_topology

    !> XDMF code of a quadrilateral in a mixed topology (5).
    pure integer function q4_xdmf_code(self)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        q4_xdmf_code = 5
    end function q4_xdmf_code

    !> Gmsh type of the 4-node quadrangle (3).
    pure integer function q4_gmsh_type(self)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        q4_gmsh_type = 3
    end function q4_gmsh_type

    !> The cell itself: corners (1, 2, 3, 4).
    pure function q4_grid_cell(self) result(cell)
        !> The element type.
        class(element_q4_t), intent(in) :: self
        !> Corner numbers (4, 1).
        integer, allocatable :: cell(:, :)
        cell = reshape([1, 2, 3, 4], [4, 1])
    end function q4_grid_cell
end module fem_element_q4
