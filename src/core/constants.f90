!> Numerical constants shared by the packages, each defined once with a name that says what
!> it is for. The three tolerances have the same value 1e-12 but different purposes: well
!> above the rounding of a few double-precision operations (epsilon = 2.2e-16), well below
!> any difference that matters physically.
module core_constants
    use core_kinds, only: wp
    implicit none
    private
    public :: pi, two_pi, deg_to_rad, relative_roundoff, singular_ratio, diagonal_floor

    !> The ratio of a circle's circumference to its diameter.
    real(wp), parameter :: pi = 3.141592653589793238462643383279502884_wp
    !> 2 pi: radians per cycle (angular frequency = two_pi * frequency).
    real(wp), parameter :: two_pi = 2*pi
    !> Radians per degree (deck angles are in degrees).
    real(wp), parameter :: deg_to_rad = pi/180
    !> Relative tolerance under which two computed values of the same scale are taken as equal
    !> (a length as zero relative to the model size, a point as on an end, a ratio as whole):
    !> rounding, not a physical difference.
    real(wp), parameter :: relative_roundoff = 1.0e-12_wp
    !> A normalised determinant (the determinant over the product of the diagonal, 1 for
    !> orthogonal rows) below this means a singular matrix: exact rank deficiency rounds to
    !> ~1e-16, nearly dependent but genuine rows stay far above.
    real(wp), parameter :: singular_ratio = 1.0e-12_wp
    !> Floor of a diagonal entry of a local operator relative to its trace, so that a
    !> direction held by the fixities does not divide by zero (a contact whose normal entry is
    !> below it is blocked).
    real(wp), parameter :: diagonal_floor = 1.0e-12_wp
end module core_constants
