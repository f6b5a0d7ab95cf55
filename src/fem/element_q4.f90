!> Bilinear quadrilateral Q4: nodes counter-clockwise at natural (-1,-1), (1,-1), (1,1),
!> (-1,1); N_a = (1 + xi xi_a)(1 + eta eta_a)/4; 2 x 2 Gauss quadrature (exact stiffness for
!> parallelograms, exact consistent mass for any quadrilateral).
module fem_element_q4
    use core_kinds, only: wp
    use fem_element2d, only: element2d_t
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
end module fem_element_q4
