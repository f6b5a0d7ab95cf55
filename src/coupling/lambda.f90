!> Lagrange multipliers of the Arlequin coupling at velocity level (doc/theory.md section 6.4).
!>
!> Conventions: on the particle side the multiplier lambda acts as a force +lambda on the
!> coupled DOF ((1 - alpha) m qdd = F + (1 - alpha) m g + lambda: the disk's loads in full),
!> on the FE side as -C^T lambda (M_alpha udd = F_alpha - C^T lambda). In a step of length h, the particle velocities
!> respond by h W lambda (W = ((1 - alpha) m)^-1 for independent particles, or the mobility
!> of rigid clusters), the FE velocities by -gamma h S^-1 C^T lambda (Newmark, S = M +
!> gamma h C + beta h^2 K). With the free velocity residual g = v_d,free - C v_c,free (plus
!> a drift term (q - C u)/h if wanted), the constraint v_d - C v_c = 0 at t_{n+1} reads
!>   A lambda = -g,   A = h [ W + gamma C S^-1 C^T ],
!> symmetric positive definite when every coupled DOF has a positive weighted mass on both
!> sides and C has full row rank. A is factored once (dense Cholesky) and reused while the
!> coupled set, h and the weights do not change.
module coupling_lambda
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_linalg, only: dense_spd_t, symmetrize
    use fem_newmark, only: newmark_t
    use coupling_map, only: coupling_map_t
    implicit none
    private
    public :: coupling_system_t, fe_coupling_force

    !> Columns of C^T solved at once when A is assembled: bounds the work arrays to
    !> 2 n_free response_block reals (about 50 MB at 10^5 free DOFs) whatever n_rows is.
    integer, parameter :: response_block = 32

    !> The factored multiplier matrix A of one coupled set.
    type :: coupling_system_t
        !> Number of multipliers (rows of C).
        integer :: n = 0
        !> Time step the matrix was built for [s].
        real(wp) :: h = 0.0_wp
        !> A = h (W + gamma C S^-1 C^T) and its Cholesky factor.
        type(dense_spd_t) :: a
    contains
        !> Build and factor A for a beam integrator (Newmark).
        procedure :: assemble
        !> Build and factor A from the FE response S^-1 C^T of any FE model.
        procedure :: assemble_response
        !> lambda = -A^-1 g.
        procedure :: solve
    end type coupling_system_t

contains

    !> Build A = h (W + gamma C S^-1 C^T) and factor it, with the beam integrator's factored S.
    !> W is diag(inverse_mass), plus `mobility` if given (at least one of the two is needed).
    subroutine assemble(self, op, integ, error, inverse_mass, mobility)
        !> The multiplier system.
        class(coupling_system_t), intent(inout) :: self
        !> The coupling operator.
        class(coupling_map_t), intent(in) :: op
        !> The FE time integrator, initialised (its factored S, h and gamma are used; the solves
        !> with S update a sparse factor's workspace).
        type(newmark_t), intent(inout) :: integ
        !> Set on inconsistent sizes, a negative inverse mass or a singular A.
        type(error_t), allocatable, intent(out) :: error
        !> Particle side, independent DOFs: 1/((1 - alpha) m) per row (translations) or
        !> 1/((1 - alpha) I) (rotations) [1/kg, 1/(kg m^2)], size n_rows.
        real(wp), intent(in), optional :: inverse_mass(:)
        !> Particle side, coupled DOFs: velocity response of the coupled DOFs to unit
        !> multipliers (G M^-1 G^T of a rigid cluster), symmetric (n_rows, n_rows).
        real(wp), intent(in), optional :: mobility(:, :)
        real(wp), allocatable :: b(:, :), x(:, :), e(:), cx(:, :)
        integer :: j0, j, k
        call check_particle_side(op%n_rows, error, inverse_mass, mobility)
        if (allocated(error)) return
        if (size(integ%u) /= op%n_free) then
            call make_error(error, 'coupling multipliers: C and the FE integrator have '// &
                            'different numbers of free DOFs')
            return
        end if
        ! C S^-1 C^T, a block of columns of C^T at a time: only the n_rows x n_rows product is
        ! kept, never C^T or S^-1 C^T in full (n_free x n_rows, dense, would not fit for a
        ! large mesh).
        k = min(response_block, op%n_rows)
        allocate (b(op%n_free, k), x(op%n_free, k), e(op%n_rows), cx(op%n_rows, op%n_rows))
        do j0 = 1, op%n_rows, response_block
            k = min(response_block, op%n_rows - j0 + 1)
            do j = 1, k
                e = 0.0_wp
                e(j0 + j - 1) = 1.0_wp
                call op%apply_transpose(e, b(:, j))
            end do
            call integ%solve_effective(b(:, 1:k), x(:, 1:k), error)
            if (allocated(error)) return
            do j = 1, k
                call op%apply(x(:, j), cx(:, j0 + j - 1))
            end do
        end do
        call finish(self, cx, integ%h, integ%gamma, error, inverse_mass, mobility)
    end subroutine assemble

    !> Build A = h (W + gamma C X) and factor it, X = S^-1 C^T the response of the FE model's
    !> effective matrix S (any FE model: beam, 2D continuum) to the columns of C^T.
    subroutine assemble_response(self, op, x, h, gamma, error, inverse_mass, mobility)
        !> The multiplier system.
        class(coupling_system_t), intent(inout) :: self
        !> The coupling operator.
        class(coupling_map_t), intent(in) :: op
        !> S^-1 C^T (n_free, n_rows).
        real(wp), intent(in) :: x(:, :)
        !> Time step [s] and Newmark gamma.
        real(wp), intent(in) :: h, gamma
        !> Set on inconsistent sizes, a negative inverse mass or a singular A.
        type(error_t), allocatable, intent(out) :: error
        !> Particle side, independent DOFs (see `assemble`).
        real(wp), intent(in), optional :: inverse_mass(:)
        !> Particle side, coupled DOFs (see `assemble`).
        real(wp), intent(in), optional :: mobility(:, :)
        real(wp), allocatable :: cx(:, :)
        integer :: j
        call check_particle_side(op%n_rows, error, inverse_mass, mobility)
        if (allocated(error)) return
        if (any(shape(x) /= [op%n_free, op%n_rows])) then
            call make_error(error, 'coupling multipliers: the FE response S^-1 C^T must be (n_free, n_rows)')
            return
        end if
        allocate (cx(op%n_rows, op%n_rows))
        do j = 1, op%n_rows
            call op%apply(x(:, j), cx(:, j))
        end do
        call finish(self, cx, h, gamma, error, inverse_mass, mobility)
    end subroutine assemble_response

    !> A = h (W + gamma C S^-1 C^T) from the product C S^-1 C^T, factored.
    subroutine finish(self, cx, h, gamma, error, inverse_mass, mobility)
        class(coupling_system_t), intent(inout) :: self
        !> C S^-1 C^T (n_rows, n_rows).
        real(wp), intent(in) :: cx(:, :)
        real(wp), intent(in) :: h, gamma
        type(error_t), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: inverse_mass(:)
        real(wp), intent(in), optional :: mobility(:, :)
        integer :: n, j
        n = size(cx, 1)
        self%n = n
        self%h = h
        call self%a%init(n)
        self%a%a = gamma*cx
        if (present(mobility)) self%a%a = self%a%a + mobility
        if (present(inverse_mass)) then
            do j = 1, n
                self%a%a(j, j) = self%a%a(j, j) + inverse_mass(j)
            end do
        end if
        ! Symmetric up to the rounding of the solves; keep it exactly symmetric.
        call symmetrize(self%a%a, self%h)
        call self%a%factor(error)
        if (allocated(error)) then
            error%message = 'coupling multipliers: A = h (W + gamma C S^-1 C^T) is singular: '// &
                            'a coupled DOF without weighted mass on the particle side (alpha = 1), '// &
                            'or more multipliers than the FE can resolve (too many coupled points '// &
                            'per element: couple fewer or use the mediator space); '//error%message
        end if
    end subroutine finish

    !> Checks of the particle side of A (sizes, signs, finiteness).
    subroutine check_particle_side(n, error, inverse_mass, mobility)
        integer, intent(in) :: n
        type(error_t), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: inverse_mass(:)
        real(wp), intent(in), optional :: mobility(:, :)
        character(len=200) :: buf
        if (.not. (present(inverse_mass) .or. present(mobility))) then
            call make_error(error, 'coupling multipliers: the particle side is missing (give '// &
                            'inverse_mass or mobility)')
            return
        end if
        if (present(inverse_mass)) then
            if (size(inverse_mass) /= n) then
                call make_error(error, 'coupling multipliers: inverse_mass needs one value per '// &
                                'row of C')
                return
            end if
            if (any(.not. (inverse_mass >= 0 .and. ieee_is_finite(inverse_mass)))) then
                write (buf, '(a,i0,a)') 'coupling multipliers: inverse mass of row ', &
                    findloc(inverse_mass >= 0 .and. ieee_is_finite(inverse_mass), .false., &
                            dim=1), ' is negative or not finite (alpha = 1 at a coupled '// &
                    'point leaves it no particle-side mass)'
                call make_error(error, trim(buf))
                return
            end if
        end if
        if (present(mobility)) then
            if (any(shape(mobility) /= [n, n])) then
                call make_internal_error(error, 'coupling multipliers', 'mobility must be (n_rows, n_rows)')
                return
            end if
            if (.not. all(ieee_is_finite(mobility))) then
                call make_error(error, 'coupling multipliers: mobility is not finite')
                return
            end if
        end if
    end subroutine check_particle_side

    !> lambda = -A^-1 g: the multipliers that cancel the free velocity residual
    !> g = v_d,free - C v_c,free (see the module description).
    subroutine solve(self, g, lambda, error)
        !> The multiplier system, assembled.
        class(coupling_system_t), intent(in) :: self
        !> Free velocity residual (n) [m/s, rad/s].
        real(wp), intent(in) :: g(:)
        !> Multipliers (n) [N, N.m].
        real(wp), contiguous, intent(out) :: lambda(:)
        !> Set when A is not assembled or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        if (size(g) /= self%n .or. size(lambda) /= self%n) then
            call make_error(error, 'coupling multipliers: g and lambda need one value per '// &
                            'multiplier')
            return
        end if
        lambda = -g
        call self%a%solve(lambda, error)
    end subroutine solve

    !> FE coupling force f = -C^T lambda (n_free), to pass to `newmark_t%correct`.
    pure subroutine fe_coupling_force(op, lambda, f)
        !> The coupling operator.
        class(coupling_map_t), intent(in) :: op
        !> Multipliers (n_rows).
        real(wp), intent(in) :: lambda(:)
        !> Force on the free DOFs (n_free).
        real(wp), intent(out) :: f(:)
        call op%apply_transpose(lambda, f)
        f = -f
    end subroutine fe_coupling_force
end module coupling_lambda
