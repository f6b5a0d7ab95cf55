!> Linear isotropic elasticity in two dimensions, plane strain or plane stress, with thickness.
!>
!> Voigt order (xx, yy, xy) with engineering shear strain gamma_xy = 2 eps_xy, so that
!> sigma = D eps and the strain energy density is eps^T D eps / 2. Plane stress:
!> D = E/(1 - nu^2) [1 nu 0; nu 1 0; 0 0 (1 - nu)/2]. Plane strain:
!> D = E/((1 + nu)(1 - 2 nu)) [1-nu nu 0; nu 1-nu 0; 0 0 (1 - 2 nu)/2].
!>
!> The out-of-plane stress follows from the hypothesis: sigma_zz = 0 in plane stress,
!> sigma_zz = nu (sigma_xx + sigma_yy) in plane strain (eps_zz = 0); the von Mises stress of
!> the full state (xx, yy, zz, xy; xz = yz = 0) is
!> sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2)/2 + 3 sxy^2).
module fem_elastic2d
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    implicit none
    private
    public :: elastic2d_t, make_elastic2d, max_plane_strain_poisson

    !> Largest Poisson's ratio in plane strain: lambda/mu = 2 nu/(1 - 2 nu) = 5e5 there. The
    !> stiffness is then the shear part (mu) plus a volumetric part 5e5 times larger: the
    !> factorisation keeps about 16 - 6 = 10 digits of the shear response before the mesh's
    !> own condition number (1e4 to 1e8 for usual meshes) is taken off, the last that still
    !> leaves digits. Closer to 1/2 (a ratio of 1e14 at nu = 0.5 - 1e-14) the factorisation
    !> fails or returns displacements without a correct digit, and the failure looked like
    !> missing supports. The Q4 and T3 displacement elements lock long before (their volumetric
    !> constraints stiffen them visibly from nu = 0.49): the limit refuses only what double
    !> precision cannot compute, not what the elements compute badly. Plane stress has no such
    !> limit (D stays bounded as nu tends to 1/2).
    real(wp), parameter :: max_plane_strain_poisson = 0.499999_wp

    !> An isotropic linear-elastic material of a 2D continuum (SI units).
    type :: elastic2d_t
        !> Young's modulus E (Pa).
        real(wp) :: young = 0.0_wp
        !> Poisson's ratio nu.
        real(wp) :: poisson = 0.0_wp
        !> Mass density rho (kg/m^3).
        real(wp) :: density = 0.0_wp
        !> Out-of-plane thickness t (m); every integral over the area is multiplied by t.
        real(wp) :: thickness = 1.0_wp
        !> True: plane strain (eps_zz = 0); false: plane stress (sigma_zz = 0).
        logical :: plane_strain = .false.
    contains
        !> Elasticity matrix D (3 x 3, Voigt order xx, yy, xy).
        procedure :: d_matrix => elastic2d_d_matrix
        !> Out-of-plane stress sigma_zz of an in-plane stress (xx, yy, xy).
        procedure :: sigma_zz => elastic2d_sigma_zz
        !> Von Mises (equivalent) stress of an in-plane stress (xx, yy, xy) with its sigma_zz.
        procedure :: von_mises => elastic2d_von_mises
    end type elastic2d_t

contains

    !> Build a material, checking E > 0, rho >= 0, t > 0 and -1 < nu < 1/2 (nu < 1 is
    !> enough in plane stress, but 1/2 bounds both cases and excludes incompressibility), and
    !> nu <= max_plane_strain_poisson in plane strain.
    subroutine make_elastic2d(young, poisson, density, thickness, plane_strain, material, error)
        !> Young's modulus E (Pa, > 0).
        real(wp), intent(in) :: young
        !> Poisson's ratio (-1 < nu < 0.5).
        real(wp), intent(in) :: poisson
        !> Mass density (kg/m^3, >= 0).
        real(wp), intent(in) :: density
        !> Thickness (m, > 0).
        real(wp), intent(in) :: thickness
        !> Plane strain (true) or plane stress (false).
        logical, intent(in) :: plane_strain
        !> The material.
        type(elastic2d_t), intent(out) :: material
        !> Set when a value is out of range.
        type(error_t), allocatable, intent(out) :: error
        if (.not. young > 0.0_wp) then
            call make_error(error, 'elastic material: Young''s modulus must be > 0')
        else if (.not. (poisson > -1.0_wp .and. poisson < 0.5_wp)) then
            call make_error(error, 'elastic material: Poisson''s ratio must lie in (-1, 0.5)')
        else if (plane_strain .and. poisson > max_plane_strain_poisson) then
            call make_error(error, 'elastic material: Poisson''s ratio 1/2 - '//to_str(0.5_wp - poisson)// &
                            ' is nearly incompressible in plane strain (lambda/mu = 2 nu/(1 - 2 nu) = '// &
                            to_str(2*poisson/(1 - 2*poisson))//'); above nu = 0.499999 (lambda/mu = 5e5) the '// &
                            'stiffness cannot be factored reliably in double precision, and the displacement '// &
                            'elements Q4 and T3 lock long before (already at nu = 0.49): give nu <= 0.49, a '// &
                            'compressible approximation')
        else if (.not. density >= 0.0_wp) then
            call make_error(error, 'elastic material: density must be >= 0')
        else if (.not. thickness > 0.0_wp) then
            call make_error(error, 'elastic material: thickness must be > 0')
        end if
        if (allocated(error)) return
        material = elastic2d_t(young=young, poisson=poisson, density=density, thickness=thickness, &
                               plane_strain=plane_strain)
    end subroutine make_elastic2d

    !> Elasticity matrix D (Voigt xx, yy, xy with engineering shear strain).
    pure function elastic2d_d_matrix(self) result(d)
        !> The material.
        class(elastic2d_t), intent(in) :: self
        !> D (3 x 3).
        real(wp) :: d(3, 3)
        real(wp) :: e, nu, c
        e = self%young
        nu = self%poisson
        d = 0.0_wp
        if (self%plane_strain) then
            c = e/((1.0_wp + nu)*(1.0_wp - 2.0_wp*nu))
            d(1, 1) = c*(1.0_wp - nu)
            d(2, 2) = c*(1.0_wp - nu)
            d(1, 2) = c*nu
            d(3, 3) = c*(1.0_wp - 2.0_wp*nu)/2.0_wp
        else
            c = e/(1.0_wp - nu*nu)
            d(1, 1) = c
            d(2, 2) = c
            d(1, 2) = c*nu
            d(3, 3) = c*(1.0_wp - nu)/2.0_wp
        end if
        d(2, 1) = d(1, 2)
    end function elastic2d_d_matrix

    !> Out-of-plane stress: nu (sigma_xx + sigma_yy) in plane strain, 0 in plane stress.
    pure function elastic2d_sigma_zz(self, sigma) result(szz)
        !> The material.
        class(elastic2d_t), intent(in) :: self
        !> In-plane stress (xx, yy, xy) [Pa].
        real(wp), intent(in) :: sigma(3)
        !> sigma_zz [Pa].
        real(wp) :: szz
        szz = 0.0_wp
        if (self%plane_strain) szz = self%poisson*(sigma(1) + sigma(2))
    end function elastic2d_sigma_zz

    !> Von Mises stress sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2)/2 + 3 sxy^2),
    !> with szz the material's sigma_zz (`sigma_zz`).
    pure function elastic2d_von_mises(self, sigma) result(vm)
        !> The material.
        class(elastic2d_t), intent(in) :: self
        !> In-plane stress (xx, yy, xy) [Pa].
        real(wp), intent(in) :: sigma(3)
        !> Von Mises stress [Pa] (>= 0).
        real(wp) :: vm
        real(wp) :: szz
        szz = self%sigma_zz(sigma)
        vm = sqrt(0.5_wp*((sigma(1) - sigma(2))**2 + (sigma(2) - szz)**2 + (szz - sigma(1))**2) + &
                  3.0_wp*sigma(3)**2)
    end function elastic2d_von_mises
end module fem_elastic2d
