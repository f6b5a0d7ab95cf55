!> Modal analysis: lowest natural frequencies and mass-normalised mode shapes of
!> K phi = omega^2 M phi (band generalized eigensolver).
module fem_modal
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_linalg, only: band_generalized_eigen
    use fem_beam_model, only: beam_model_t
    implicit none
    private
    public :: solve_modal

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
        if (size(lambda) /= n_modes) then
            call make_error(error, 'modal analysis: the eigensolver returned fewer modes '// &
                            'than asked')
            return
        end if
        ! Rigid-body eigenvalues are zero up to rounding and may come out slightly negative.
        omega = sqrt(max(lambda, 0.0_wp))
    end subroutine solve_modal
end module fem_modal
