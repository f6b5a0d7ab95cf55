!> Contact law parameters per pair of materials: Coulomb friction mu, Newton restitution e,
!> rolling resistance length e_r and cohesion stress sigma_cohe (r_cohe = sigma_cohe * mean
!> radius of the pair, per unit thickness), and the bounds of the bonds that cohesion makes:
!> shear coefficient mu_b and moment length e_b (doc/theory.md, "Bonded contacts"). Without
!> bond bounds of its own, a bond of a cohesive pair takes the pair's mu and e_r. Disks and
!> walls carry a material index into this symmetric table.
module dem_materials
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    implicit none
    private
    public :: materials_t, materials_init, materials_set_pair, materials_set_bond
    public :: bond_e_default

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
        !> Rolling resistance length e_r [m] of ordinary contacts: |M| <= e_r r_n.
        real(wp), allocatable :: rolling(:, :)
        !> Shear coefficient mu_b of intact bonds [-]: |r_t| <= mu_b (r_n + r_cohe).
        real(wp), allocatable :: bond_mu(:, :)
        !> Moment length e_b of intact bonds [m]: |M| <= e_b (r_n + r_cohe); bond_e_default
        !> means half the mean radius of the pair.
        real(wp), allocatable :: bond_e(:, :)
    end type materials_t

    !> Marks `bond_e` as the default e_b = a_bar/2 (half the mean radius of the pair).
    real(wp), parameter :: bond_e_default = -1.0_wp

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
        allocate (m%mu(n, n), m%restitution(n, n), m%cohesion(n, n), m%rolling(n, n), m%bond_mu(n, n), &
                  m%bond_e(n, n))
        m%mu = 0.0_wp
        m%restitution = 0.0_wp
        m%cohesion = 0.0_wp
        m%rolling = 0.0_wp
        m%bond_mu = 0.0_wp
        m%bond_e = 0.0_wp
    end subroutine materials_init

    !> Set the law of the pair (a, b) (and (b, a)). The bonds of the pair take mu and the
    !> rolling length until `materials_set_bond` gives them bounds of their own.
    subroutine materials_set_pair(m, a, b, mu, restitution, cohesion, error, rolling)
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
        !> Rolling resistance length e_r [m] (>= 0; default 0: none).
        real(wp), intent(in), optional :: rolling
        real(wp) :: er
        er = 0.0_wp
        if (present(rolling)) er = rolling
        if (a < 1 .or. a > m%n .or. b < 1 .or. b > m%n) then
            call make_error(error, 'materials_set_pair: material index out of range')
        else if (mu < 0.0_wp .or. cohesion < 0.0_wp .or. er < 0.0_wp) then
            call make_error(error, 'materials_set_pair: friction, cohesion and rolling length must be >= 0')
        else if (restitution < 0.0_wp .or. restitution > 1.0_wp) then
            call make_error(error, 'materials_set_pair: restitution must be in [0, 1]')
        else
            m%mu(a, b) = mu
            m%mu(b, a) = mu
            m%restitution(a, b) = restitution
            m%restitution(b, a) = restitution
            m%cohesion(a, b) = cohesion
            m%cohesion(b, a) = cohesion
            m%rolling(a, b) = er
            m%rolling(b, a) = er
            m%bond_mu(a, b) = mu
            m%bond_mu(b, a) = mu
            m%bond_e(a, b) = er
            m%bond_e(b, a) = er
        end if
    end subroutine materials_set_pair

    !> Give the bonds of the pair (a, b) their own bounds: shear coefficient mu_b and moment
    !> length e_b (bond_e_default: half the mean radius of each bonded pair). Call after
    !> `materials_set_pair` for the same pair.
    subroutine materials_set_bond(m, a, b, mu_b, e_b, error)
        !> Table.
        type(materials_t), intent(inout) :: m
        !> Material indices.
        integer, intent(in) :: a, b
        !> Shear coefficient of intact bonds (>= 0).
        real(wp), intent(in) :: mu_b
        !> Moment length of intact bonds [m] (>= 0, or bond_e_default).
        real(wp), intent(in) :: e_b
        !> Error on an unknown material or a value out of range.
        type(error_t), allocatable, intent(out) :: error
        if (a < 1 .or. a > m%n .or. b < 1 .or. b > m%n) then
            call make_error(error, 'materials_set_bond: material index out of range')
        else if (mu_b < 0.0_wp .or. (e_b < 0.0_wp .and. e_b /= bond_e_default)) then
            call make_error(error, 'materials_set_bond: mu_b and e_b must be >= 0')
        else
            m%bond_mu(a, b) = mu_b
            m%bond_mu(b, a) = mu_b
            m%bond_e(a, b) = e_b
            m%bond_e(b, a) = e_b
        end if
    end subroutine materials_set_bond
end module dem_materials
