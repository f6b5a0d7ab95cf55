!> Planar Euler-Bernoulli frame element (doc/theory.md, sections 5.1-5.2): local stiffness, consistent
!> and HRZ-lumped mass, rotation to global axes, shape functions.
!>
!> Local DOFs of an element from node 1 to node 2: [u1, w1, theta1, u2, w2, theta2], u along
!> the element axis, w across it, theta = dw/dx (counter-clockwise). With c, s the direction
!> cosines of the axis, d_local = T d_global and k_global = T^T k_local T.
module fem_beam_element
    use core_kinds, only: wp
    implicit none
    private
    public :: element_stiffness, element_mass_consistent, element_mass_lumped
    public :: rotation_matrix, to_global, axial_shape, hermite_shape, hermite_slope
    public :: element_interpolation

contains

    !> Local stiffness matrix (6, 6): axial EA/L and Euler-Bernoulli bending EI/L^3.
    pure function element_stiffness(ea, ei, length) result(k)
        !> Axial rigidity E*A [N].
        real(wp), intent(in) :: ea
        !> Bending rigidity E*I [N.m^2].
        real(wp), intent(in) :: ei
        !> Element length [m].
        real(wp), intent(in) :: length
        real(wp) :: k(6, 6)
        real(wp) :: a, b, l
        l = length
        k = 0.0_wp
        a = ea/l
        k(1, 1) = a
        k(4, 4) = a
        k(1, 4) = -a
        k(4, 1) = -a
        b = ei/l**3
        k([2, 3, 5, 6], [2, 3, 5, 6]) = b*reshape([ &
                                                  12.0_wp, 6*l, -12.0_wp, 6*l, &
                                                  6*l, 4*l**2, -6*l, 2*l**2, &
                                                  -12.0_wp, -6*l, 12.0_wp, -6*l, &
                                                  6*l, 2*l**2, -6*l, 4*l**2], [4, 4])
    end function element_stiffness

    !> Local consistent mass matrix (6, 6): linear axial, cubic Hermite transverse.
    pure function element_mass_consistent(rho_a, length) result(m)
        !> Mass per unit length rho*A [kg/m].
        real(wp), intent(in) :: rho_a
        !> Element length [m].
        real(wp), intent(in) :: length
        real(wp) :: m(6, 6)
        real(wp) :: a, b, l
        l = length
        m = 0.0_wp
        a = rho_a*l/6
        m(1, 1) = 2*a
        m(4, 4) = 2*a
        m(1, 4) = a
        m(4, 1) = a
        b = rho_a*l/420
        m([2, 3, 5, 6], [2, 3, 5, 6]) = b*reshape([ &
                                                  156.0_wp, 22*l, 54.0_wp, -13*l, &
                                                  22*l, 4*l**2, 13*l, -3*l**2, &
                                                  54.0_wp, 13*l, 156.0_wp, -22*l, &
                                                  -13*l, -3*l**2, -22*l, 4*l**2], [4, 4])
    end function element_mass_consistent

    !> HRZ-lumped mass, diagonal (6): rho*A*L/2 on each translation, rho*A*L^3/78 on each
    !> rotation (the consistent diagonal scaled so the translational total is rho*A*L).
    !> The same in local and global axes (equal translational masses).
    pure function element_mass_lumped(rho_a, length) result(m)
        !> Mass per unit length rho*A [kg/m].
        real(wp), intent(in) :: rho_a
        !> Element length [m].
        real(wp), intent(in) :: length
        real(wp) :: m(6)
        real(wp) :: t, r
        t = rho_a*length/2
        r = rho_a*length**3/78
        m = [t, t, r, t, t, r]
    end function element_mass_lumped

    !> Rotation T (6, 6) = blockdiag(R, R), R = [c s 0; -s c 0; 0 0 1]: d_local = T d_global.
    pure function rotation_matrix(c, s) result(t)
        !> Cosine of the angle of the element axis with x.
        real(wp), intent(in) :: c
        !> Sine of that angle.
        real(wp), intent(in) :: s
        real(wp) :: t(6, 6)
        t = 0.0_wp
        t(1, 1) = c
        t(1, 2) = s
        t(2, 1) = -s
        t(2, 2) = c
        t(3, 3) = 1.0_wp
        t(4:6, 4:6) = t(1:3, 1:3)
    end function rotation_matrix

    !> Global matrix T^T a T of a local element matrix a (stiffness or consistent mass).
    pure function to_global(a, c, s) result(g)
        !> Local matrix (6, 6).
        real(wp), intent(in) :: a(6, 6)
        !> Direction cosines of the element axis.
        real(wp), intent(in) :: c, s
        real(wp) :: g(6, 6)
        real(wp) :: t(6, 6)
        t = rotation_matrix(c, s)
        g = matmul(transpose(t), matmul(a, t))
    end function to_global

    !> Linear axial shape functions [1 - xi, xi] at xi = x/L in [0, 1].
    pure function axial_shape(xi) result(n)
        !> Reduced coordinate x/L.
        real(wp), intent(in) :: xi
        real(wp) :: n(2)
        n = [1.0_wp - xi, xi]
    end function axial_shape

    !> Hermite shape functions [N1, N2, N3, N4] of w for DOFs [w1, theta1, w2, theta2]:
    !> N1 = 1-3xi^2+2xi^3, N2 = L xi (1-xi)^2, N3 = 3xi^2-2xi^3, N4 = L xi^2 (xi-1).
    pure function hermite_shape(xi, length) result(n)
        !> Reduced coordinate x/L.
        real(wp), intent(in) :: xi
        !> Element length [m].
        real(wp), intent(in) :: length
        real(wp) :: n(4)
        n(1) = 1.0_wp - 3*xi**2 + 2*xi**3
        n(2) = length*xi*(1.0_wp - xi)**2
        n(3) = 3*xi**2 - 2*xi**3
        n(4) = length*xi**2*(xi - 1.0_wp)
    end function hermite_shape

    !> Slopes dN/dx of the Hermite functions (theta = dw/dx) at xi = x/L.
    pure function hermite_slope(xi, length) result(dn)
        !> Reduced coordinate x/L.
        real(wp), intent(in) :: xi
        !> Element length [m].
        real(wp), intent(in) :: length
        real(wp) :: dn(4)
        dn(1) = (-6*xi + 6*xi**2)/length
        dn(2) = 1.0_wp - 4*xi + 3*xi**2
        dn(3) = (6*xi - 6*xi**2)/length
        dn(4) = 3*xi**2 - 2*xi
    end function hermite_slope

    !> Interpolation matrix (3, 6): [u; w; theta](xi) = n * d_local, with d_local the six
    !> local DOFs; multiply by `rotation_matrix(c, s)` on the right to act on global DOFs.
    pure function element_interpolation(xi, length) result(n)
        !> Reduced coordinate x/L.
        real(wp), intent(in) :: xi
        !> Element length [m].
        real(wp), intent(in) :: length
        real(wp) :: n(3, 6)
        real(wp) :: na(2)
        n = 0.0_wp
        na = axial_shape(xi)
        n(1, [1, 4]) = na
        n(2, [2, 3, 5, 6]) = hermite_shape(xi, length)
        n(3, [2, 3, 5, 6]) = hermite_slope(xi, length)
    end function element_interpolation
end module fem_beam_element
