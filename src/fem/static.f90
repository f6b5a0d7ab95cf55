!> Linear static analysis: K u = F(t) by band Cholesky.
module fem_static
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_linalg, only: band_spd_t
    use fem_beam_model, only: beam_model_t
    implicit none
    private
    public :: solve_static, factor_stiffness

contains

    !> Solve K u = F(t) for the free-DOF displacements.
    subroutine solve_static(model, t, u, error)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Time at which the loads are evaluated [s].
        real(wp), intent(in) :: t
        !> Displacements on the free DOFs (n_free) [m, rad].
        real(wp), allocatable, intent(out) :: u(:)
        !> Set when K is singular (model not supported) or on LAPACK failure.
        type(error_t), allocatable, intent(out) :: error
        type(band_spd_t) :: kf
        call factor_stiffness(model, kf, error)
        if (allocated(error)) return
        allocate (u(model%n_free))
        call model%external_force(t, u)
        call kf%solve(u, error)
    end subroutine solve_static

    !> Factor a copy of the stiffness matrix. Parts of the frame without enough supports are
    !> found from the geometry first (exact); a K still numerically singular gives a message
    !> that names the DOF where the factorisation broke down.
    subroutine factor_stiffness(model, kf, error)
        !> The model.
        type(beam_model_t), intent(in) :: model
        !> Factored copy of K.
        type(band_spd_t), intent(out) :: kf
        !> Set when K is not positive definite.
        type(error_t), allocatable, intent(out) :: error
        call model%check_supports(error)
        if (allocated(error)) return
        kf = model%k
        call kf%factor(error)
        if (.not. allocated(error) .or. kf%failed_equation == 0) return
        call make_error(error, 'stiffness matrix is singular (detected at '// &
                        model%equation_label(kf%failed_equation)//'): the structure can move '// &
                        'as a rigid body or a part of it is not connected; fix more DOFs '// &
                        '(supports) so that every part is held in u, w and rotation')
    end subroutine factor_stiffness
end module fem_static
