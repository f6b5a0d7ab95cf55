!> Modal analysis: lowest natural frequencies and mass-normalised mode shapes of
!> K phi = omega^2 M phi (band generalized eigensolver), and the kind of each mode from its
!> shape: the share of its strain energy in axial deformation, computed element by element in
!> the element's axes, where the axial and bending parts of the stiffness do not couple.
module fem_modal
    use core_kinds, only: wp
    use core_constants, only: relative_roundoff
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use core_linalg, only: band_generalized_eigen
    use fem_beam_model, only: beam_model_t
    use fem_beam_element, only: element_stiffness, rotation_matrix
    implicit none
    private
    public :: solve_modal, mode_axial_fraction, mode_kind, dominant_fraction

    !> A mode is `axial` when at least this share of its strain energy is axial, `bending`
    !> when at least this share is in bending, `mixed` otherwise.
    real(wp), parameter :: dominant_fraction = 0.9_wp

contains

    !> Lowest n_modes circular frequencies (ascending) and mode shapes with phi^T M phi = 1.
    !> Rigid-body modes of an unsupported model come out with omega = 0.
    subroutine solve_modal(model, n_modes, omega, shapes, error)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Number of modes wanted (1..n_free).
        integer, intent(in) :: n_modes
        !> Circular frequencies (n_modes) [rad/s], ascending.
        real(wp), allocatable, intent(out) :: omega(:)
        !> Mode shapes on the free DOFs (n_free, n_modes), mass-normalised.
        real(wp), allocatable, intent(out) :: shapes(:, :)
        !> Set when n_modes is out of range or on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: lambda(:)
        character(len=160) :: buf
        if (n_modes < 1 .or. n_modes > model%n_free) then
            write (buf, '(a,i0,a,i0,a)') 'modal analysis: ', n_modes, ' modes asked but the '// &
                'model has ', model%n_free, ' free DOFs; ask for 1 to that many modes'
            call make_error(error, trim(buf))
            return
        end if
        call band_generalized_eigen(model%k, model%m, 1, n_modes, lambda, error, shapes)
        if (allocated(error)) return
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
        ! Rigid-body eigenvalues are zero up to rounding and may come out slightly negative.
        omega = sqrt(max(lambda, 0.0_wp))
    end subroutine solve_modal

    !> Share of the strain energy of a mode shape in axial deformation: U_axial/(U_axial +
    !> U_bending), with U = sum over elements of 1/2 d.k d in the element's axes (u along the
    !> axis for U_axial; w and theta across it for U_bending). -1 for a rigid-body shape (no
    !> strain energy beyond rounding), which is neither.
    function mode_axial_fraction(model, shape) result(fraction)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Mode shape on the free DOFs (n_free).
        real(wp), intent(in) :: shape(:)
        real(wp) :: fraction
        real(wp) :: d(3, model%n_nodes), dl(6), kl(6, 6), u_axial, u_bending, scale
        integer :: e
        integer, parameter :: ax(2) = [1, 4], tr(4) = [2, 3, 5, 6]
        call model%expand(shape, d)
        u_axial = 0.0_wp
        u_bending = 0.0_wp
        scale = 0.0_wp
        do e = 1, model%n_elements
            dl = matmul(rotation_matrix(model%cosine(e), model%sine(e)), &
                        [d(:, model%conn(1, e)), d(:, model%conn(2, e))])
            kl = element_stiffness(model%ea(e), model%ei(e), model%length(e))
            u_axial = u_axial + 0.5_wp*dot_product(dl(ax), matmul(kl(ax, ax), dl(ax)))
            u_bending = u_bending + 0.5_wp*dot_product(dl(tr), matmul(kl(tr, tr), dl(tr)))
            ! Energy the element would hold if its DOFs deformed it independently.
            scale = scale + maxval(abs(kl))*dot_product(dl, dl)
        end do
        fraction = -1.0_wp
        if (u_axial + u_bending > relative_roundoff*scale) fraction = u_axial/(u_axial + u_bending)
    end function mode_axial_fraction

    !> Kind of a mode from its axial strain-energy share (see `mode_axial_fraction`): 'axial',
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
