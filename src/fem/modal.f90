!> Modal analysis: lowest natural frequencies and mass-normalised mode shapes of
!> K phi = omega^2 M phi (shift-invert subspace iteration, `core_band_eigen`: the lowest
!> frequencies keep their relative accuracy however fine the mesh), and the kind of each mode
!> from its shape: rigid when it is a rigid-body motion that the supports allow, otherwise by
!> the share of its strain energy in axial deformation, computed element by element in the
!> element's axes, where the axial and bending parts of the stiffness do not couple.
module fem_modal
    use core_kinds, only: wp
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_error, only: error_t, make_error, make_internal_error
    use core_linalg, only: dense_spd_t
    use core_strings, only: to_str
    use core_band_eigen, only: lowest_band_eigen
    use fem_beam_model, only: beam_model_t
    use fem_beam_element, only: rotation_matrix
    implicit none
    private
    public :: solve_modal, axial_fractions, mode_kind, dominant_fraction, rigid_shares, strain_energies

    !> A mode is `axial` when at least this share of its strain energy is axial, `bending`
    !> when at least this share is in bending, `mixed` otherwise.
    real(wp), parameter :: dominant_fraction = 0.9_wp

contains

    !> Lowest n_modes circular frequencies (ascending) and mode shapes with phi^T M phi = 1.
    !>
    !> The shapes come from the shift-invert subspace iteration (`lowest_band_eigen`); each
    !> omega^2 is then the Rayleigh quotient 2 U(phi)/(phi^T M phi), the strain energy U summed
    !> over the elements from their deformations (`strain_energies`). The eigenvalues of the
    !> iteration itself carry the backward error of the Cholesky factor of K, eps |U^T| |U|,
    !> which is not a perturbation of the elements: measured, about 2e3 eps n_el^2 relative on
    !> the first mode of a cantilever (1.5e-7 with 512 elements). The Rayleigh quotient's error
    !> is the square of the shape's (1e-13 at 512 elements, the discretisation error), plus the
    !> rounding of the element deformations, at most about eps n_el^2 relative. Rigid-body
    !> modes of an unsupported model come out with omega = 0 up to rounding.
    subroutine solve_modal(model, n_modes, omega, shapes, error)
        !> The model (not weighted: K and M are those of its elements).
        type(beam_model_t), intent(in) :: model
        !> Number of modes wanted (1..n_free).
        integer, intent(in) :: n_modes
        !> Circular frequencies (n_modes) [rad/s], ascending.
        real(wp), allocatable, intent(out) :: omega(:)
        !> Mode shapes on the free DOFs (n_free, n_modes), mass-normalised.
        real(wp), allocatable, intent(out) :: shapes(:, :)
        !> Set when n_modes is out of range or on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: lambda(:), mv(:)
        real(wp) :: u_axial, u_bending
        character(len=160) :: buf
        integer :: k
        if (n_modes < 1 .or. n_modes > model%n_free) then
            write (buf, '(a,i0,a,i0,a)') 'modal analysis: ', n_modes, ' modes asked but the '// &
                'model has ', model%n_free, ' free DOFs; ask for 1 to that many modes'
            call make_error(error, trim(buf))
            return
        end if
        if (model%weighted) then
            call make_internal_error(error, 'modal analysis', 'the beam model is weighted (Arlequin)')
            return
        end if
        call lowest_band_eigen(model%k, model%m, n_modes, lambda, shapes, error)
        if (allocated(error)) return
        if (size(lambda) == n_modes .and. all(ieee_is_finite(lambda))) then
            allocate (mv(model%n_free))
            do k = 1, n_modes
                call strain_energies(model, shapes(:, k), u_axial, u_bending)
                call model%mass_times(shapes(:, k), mv)
                lambda(k) = 2*(u_axial + u_bending)/dot_product(shapes(:, k), mv)
            end do
            call sort_modes(lambda, shapes)
        end if
        ! The solver scales K and M to entries of order 1; what fails after that are magnitudes
        ! that real(wp) cannot hold: omega^2 beyond 1.8e308, or K and M assembled from values
        ! at the ends of the range (overflowed or subnormal entries), an input problem.
        if (size(lambda) /= n_modes .or. .not. all(ieee_is_finite(lambda))) then
            call make_error(error, 'modal analysis: the eigenvalue problem K phi = omega^2 M phi is '// &
                            'beyond the range of double precision (stiffness entries up to '// &
                            to_str(maxval(abs(model%k%ab)))//', mass entries up to '// &
                            to_str(maxval(abs(model%m%ab)))//'): check the magnitudes of young, density, '// &
                            'area and inertia in [beam] section')
            return
        end if
        omega = sqrt(lambda)
    end subroutine solve_modal

    !> Sort eigenvalues ascending with their shapes (insertion sort: few modes; the Rayleigh
    !> quotients may swap two modes whose eigenvalues agree to rounding).
    pure subroutine sort_modes(lambda, shapes)
        real(wp), intent(inout) :: lambda(:), shapes(:, :)
        real(wp) :: key
        real(wp), allocatable :: column(:)
        integer :: i, j
        do i = 2, size(lambda)
            key = lambda(i)
            column = shapes(:, i)
            j = i - 1
            do while (j >= 1)
                if (.not. lambda(j) > key) exit
                lambda(j + 1) = lambda(j)
                shapes(:, j + 1) = shapes(:, j)
                j = j - 1
            end do
            lambda(j + 1) = key
            shapes(:, j + 1) = column
        end do
    end subroutine sort_modes

    !> Strain energy of a shape, axial and bending parts, summed over the elements from their
    !> deformations in the element's axes: the stretch u2 - u1, and the rotations of the end
    !> sections relative to the chord, b_i = theta_i - (w2 - w1)/L, with
    !> U = EA/(2L) (u2 - u1)^2 + 2 EI/L (b1^2 + b1 b2 + b2^2), the same quadratic form as the
    !> element stiffness but without its cancellation: d.k d subtracts terms of about
    !> max|k| |d|^2, n_el^4 times the energy of a smooth mode, where the deformations lose
    !> about eps n_el^2 (w2 - w1 and theta - chord), and a rigid motion has none.
    pure subroutine strain_energies(model, shape, u_axial, u_bending)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Displacements on the free DOFs (n_free).
        real(wp), intent(in) :: shape(:)
        !> Axial and bending strain energies [J for a shape in m and rad].
        real(wp), intent(out) :: u_axial, u_bending
        real(wp) :: d(3, model%n_nodes), dl(6), chord, b1, b2
        integer :: e
        call model%expand(shape, d)
        u_axial = 0.0_wp
        u_bending = 0.0_wp
        do e = 1, model%n_elements
            dl = matmul(rotation_matrix(model%cosine(e), model%sine(e)), &
                        [d(:, model%conn(1, e)), d(:, model%conn(2, e))])
            chord = (dl(5) - dl(2))/model%length(e)
            b1 = dl(3) - chord
            b2 = dl(6) - chord
            u_axial = u_axial + 0.5_wp*model%ea(e)/model%length(e)*(dl(4) - dl(1))**2
            u_bending = u_bending + 2*model%ei(e)/model%length(e)*(b1**2 + b1*b2 + b2**2)
        end do
    end subroutine strain_energies

    !> Share of each shape, in the mass norm, that is a rigid-body motion the supports allow:
    !> |P phi|_M^2/|phi|_M^2, P the M-orthogonal projector on those motions (each connected
    !> part's, `part_rigid_motions`; parts share no element, so their motions are
    !> M-orthogonal and project one part at a time). These motions are the null space of K, so
    !> an exact mode with omega = 0 lies in it (share 1) and every other mode is M-orthogonal
    !> to it (share 0); a computed mode departs from 0 or 1 by the square of its error. The
    !> share is a ratio of two M-norms of the same shape: it does not depend on the units, the
    !> mesh or the frequency.
    subroutine rigid_shares(model, shapes, share, error)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Shapes on the free DOFs (n_free, n_shapes), none zero.
        real(wp), contiguous, intent(in) :: shapes(:, :)
        !> The share of each shape, in [0, 1] (n_shapes).
        real(wp), allocatable, intent(out) :: share(:)
        !> Set on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: g(:, :), mg(:, :), b(:, :), c(:, :)
        real(wp) :: mv(model%n_free)
        type(dense_spd_t) :: gram
        integer :: comp(model%n_nodes), root, i, j
        allocate (share(size(shapes, 2)), source=0.0_wp)
        comp = model%part_roots()
        do root = 1, model%n_nodes
            if (comp(root) /= root) cycle
            g = model%part_rigid_motions(comp, root, error)
            if (allocated(error)) return
            if (size(g, 2) == 0) cycle
            allocate (mg, mold=g)
            do j = 1, size(g, 2)
                call model%mass_times(g(:, j), mg(:, j))
            end do
            call gram%init(size(g, 2))
            do j = 1, size(g, 2)
                do i = 1, j
                    call gram%add(i, j, dot_product(g(:, i), mg(:, j)))
                end do
            end do
            call gram%factor(error)
            if (allocated(error)) return
            ! Coefficients c = (G^T M G)^-1 G^T M phi of each shape; |P phi|_M^2 = (G^T M phi).c.
            b = matmul(transpose(mg), shapes)
            c = b
            call gram%solve(c, error)
            if (allocated(error)) return
            share = share + sum(b*c, dim=1)
            deallocate (mg)
        end do
        do j = 1, size(shapes, 2)
            call model%mass_times(shapes(:, j), mv)
            share(j) = share(j)/dot_product(shapes(:, j), mv)
        end do
    end subroutine rigid_shares

    !> Share of the strain energy of each mode shape in axial deformation: U_axial/(U_axial +
    !> U_bending) (`strain_energies`). -1 for a rigid-body shape (`rigid_shares` above 1/2:
    !> closer to the rigid motions than to their M-orthogonal complement), which is neither.
    subroutine axial_fractions(model, shapes, fraction, error)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Mode shapes on the free DOFs (n_free, n_modes).
        real(wp), contiguous, intent(in) :: shapes(:, :)
        !> Axial share of each mode (n_modes), or -1.
        real(wp), allocatable, intent(out) :: fraction(:)
        !> Set on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: share(:)
        real(wp) :: u_axial, u_bending
        integer :: k
        call rigid_shares(model, shapes, share, error)
        if (allocated(error)) return
        allocate (fraction(size(shapes, 2)), source=-1.0_wp)
        do k = 1, size(shapes, 2)
            if (share(k) > 0.5_wp) cycle
            call strain_energies(model, shapes(:, k), u_axial, u_bending)
            if (u_axial + u_bending > 0) fraction(k) = u_axial/(u_axial + u_bending)
        end do
    end subroutine axial_fractions

    !> Kind of a mode from its axial strain-energy share (see `axial_fractions`): 'axial',
    !> 'bending', 'mixed', or 'rigid' for a negative share.
    pure function mode_kind(fraction) result(kind)
        !> Axial share of the strain energy (-1 for a rigid-body mode).
        real(wp), intent(in) :: fraction
        character(len=:), allocatable :: kind
        if (fraction < 0.0_wp) then
            kind = 'rigid'
        else if (fraction >= dominant_fraction) then
            kind = 'axial'
        else if (1.0_wp - fraction >= dominant_fraction) then
            kind = 'bending'
        else
            kind = 'mixed'
        end if
    end function mode_kind
end module fem_modal
