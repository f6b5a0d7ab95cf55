!> Contact law parameters per pair of materials: Coulomb friction mu, Newton restitution e and
!> cohesion stress sigma_cohe (r_cohe = sigma_cohe * mean radius of the pair, per unit
!> thickness). Disks and walls carry a material index into this symmetric table.
module dem_materials
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    implicit none
    private
    public :: materials_t, materials_init, materials_set_pair

    !> Symmetric tables (n_mat, n_mat) of the contact law parameters.
    type :: materials_t
        !> Number of materials.
        integer :: n = 0
        !> Friction coefficient [-].
        real(wp), allocatable :: mu(:, :)
        !> Restitution coefficient [-], in [0, 1].
        real(wp), allocatable :: restitution(:, :)
        !> Cohesion stress [Pa] (force per unit thickness = sigma_cohe * mean radius).
        real(wp), allocatable :: cohesion(:, :)
    end type materials_t

contains

    !> n materials; every pair frictionless, perfectly plastic (e = 0) and without cohesion.
    subroutine materials_init(m, n, error)
        !> Table to build.
        type(materials_t), intent(out) :: m
        !> Number of materials (>= 1).
        integer, intent(in) :: n
        !> Error if n < 1.
        type(error_t), allocatable, intent(out) :: error
        if (n < 1) then
            call make_error(error, 'materials_init: the number of materials must be >= 1')
            return
        end if
        m%n = n
        allocate (m%mu(n, n), m%restitution(n, n), m%cohesion(n, n))
        m%mu = 0.0_wp
        m%restitution = 0.0_wp
        m%cohesion = 0.0_wp
    end subroutine materials_init

    !> Set the law of the pair (a, b) (and (b, a)).
    subroutine materials_set_pair(m, a, b, mu, restitution, cohesion, error)
        !> Table.
        type(materials_t), intent(inout) :: m
        !> Material indices.
        integer, intent(in) :: a, b
        !> Friction coefficient (>= 0).
        real(wp), intent(in) :: mu
        !> Restitution coefficient in [0, 1].
        real(wp), intent(in) :: restitution
        !> Cohesion stress [Pa] (>= 0).
        real(wp), intent(in) :: cohesion
        !> Error on an unknown material or a value out of range.
        type(error_t), allocatable, intent(out) :: error
        if (a < 1 .or. a > m%n .or. b < 1 .or. b > m%n) then
            call make_error(error, 'materials_set_pair: material index out of range')
        else if (mu < 0.0_wp .or. cohesion < 0.0_wp) then
            call make_error(error, 'materials_set_pair: friction and cohesion must be >= 0')
        else if (restitution < 0.0_wp .or. restitution > 1.0_wp) then
            call make_error(error, 'materials_set_pair: restitution must be in [0, 1]')
        else
            m%mu(a, b) = mu
            m%mu(b, a) = mu
            m%restitution(a, b) = restitution
            m%restitution(b, a) = restitution
            m%cohesion(a, b) = cohesion
            m%cohesion(b, a) = cohesion
        end if
    end subroutine materials_set_pair
end module dem_materials
