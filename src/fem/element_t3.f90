!> Linear triangle T3 (constant strain): nodes counter-clockwise at natural (0,0), (1,0),
!> (0,1); N = (1 - xi - eta, xi, eta); 3-point quadrature exact for quadratics (interior
!> points (1/6, 1/6), (2/3, 1/6), (1/6, 2/3), weights 1/6), so that the consistent mass
!> int N_a N_b dA is exact; the stiffness is exact with any rule.
module fem_element_t3
    use core_kinds, only: wp
    use fem_element2d, only: element2d_t
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
end module fem_element_t3
