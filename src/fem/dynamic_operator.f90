!> What the time integrators (fem_newmark) need from a structural model, as an abstract type:
!> M a + C v + K u = F(t) on the model's `n_free` equations, with Rayleigh damping
!> C = a0 M + a1 K.
!>
!> A model gives the products K u, M v, C v, the loads F(t), and factors of the symmetric
!> positive-definite combinations c_m M + c_k K (`factor_combination`) as a `spd_factor_t`,
!> which solves in place. The planar frame (fem_beam_model, band storage) and the 2D
!> continuum (fem_continuum_dynamics, sparse storage) extend it, so that one integrator serves
!> both. The storage stays the model's business: band LAPACK for beams, CHOLMOD for the
!> continuum.
module fem_dynamic_operator
    use core_kinds, only: wp
    use core_error, only: error_t
    use fem_mass_scheme, only: mass_scheme_t
    implicit none
    private
    public :: dynamic_operator_t, spd_factor_t

    !> A factored symmetric positive-definite matrix that solves A x = b in place.
    type, abstract :: spd_factor_t
    contains
        !> x <- A^-1 x for one vector.
        procedure(factor_solve_vec), deferred :: solve_vec
        !> X <- A^-1 X for the columns of X.
        procedure(factor_solve_mat), deferred :: solve_mat
        !> Solve in place (one or several right-hand sides).
        generic :: solve => solve_vec, solve_mat
    end type spd_factor_t

    !> A linear structural model M a + C v + K u = F(t) on its free equations.
    type, abstract :: dynamic_operator_t
        !> Number of free DOFs (equations).
        integer :: n_free = 0
        !> How the mass matrix was assembled (consistent or lumped; fem_mass_scheme).
        class(mass_scheme_t), allocatable :: mass_scheme
        !> Rayleigh damping C = a0 M + a1 K: a0 [1/s], a1 [s].
        real(wp) :: rayleigh_a0 = 0.0_wp
        !> See `rayleigh_a0`.
        real(wp) :: rayleigh_a1 = 0.0_wp
    contains
        !> f(n_free) = external forces at time t.
        procedure(operator_force), deferred :: external_force
        !> ku = K u.
        procedure(operator_times), deferred :: stiffness_times
        !> mv = M v.
        procedure(operator_mass_times), deferred :: mass_times
        !> cv = C v.
        procedure(operator_damping_times), deferred :: damping_times
        !> True when C /= 0.
        procedure(operator_flag), deferred :: is_damped
        !> 1/2 u.K u.
        procedure(operator_energy), deferred :: strain_energy
        !> 1/2 v.M v.
        procedure(operator_kinetic_energy), deferred :: kinetic_energy
        !> Factor c_m M + c_k K.
        procedure(operator_factor), deferred :: factor_combination
        !> Diagonal of the mass matrix (lumped mass only).
        procedure(operator_diagonal), deferred :: mass_diagonal
        !> Largest eigenvalue omega_max^2 of K phi = omega^2 M phi (for critical steps).
        procedure(operator_largest), deferred :: largest_eigenvalue
        !> Whether the mass matrix is diagonal (false without a mass scheme).
        procedure, non_overridable :: has_diagonal_mass
    end type dynamic_operator_t

    abstract interface
        !> x <- A^-1 x.
        subroutine factor_solve_vec(self, x, error)
            import :: spd_factor_t, wp, error_t
            !> The factor (a sparse solver updates its workspace).
            class(spd_factor_t), intent(inout) :: self
            !> Right-hand side on entry, solution on exit.
            real(wp), contiguous, intent(inout) :: x(:)
            !> Set on a size mismatch or a failed solve.
            type(error_t), allocatable, intent(out) :: error
        end subroutine factor_solve_vec

        !> X <- A^-1 X.
        subroutine factor_solve_mat(self, x, error)
            import :: spd_factor_t, wp, error_t
            !> The factor (a sparse solver updates its workspace).
            class(spd_factor_t), intent(inout) :: self
            !> Right-hand sides on entry (n, k), solutions on exit.
            real(wp), contiguous, intent(inout) :: x(:, :)
            !> Set on a size mismatch or a failed solve.
            type(error_t), allocatable, intent(out) :: error
        end subroutine factor_solve_mat

        !> External forces at time t.
        subroutine operator_force(self, t, f)
            import :: dynamic_operator_t, wp
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Time [s].
            real(wp), intent(in) :: t
            !> Forces (n_free).
            real(wp), intent(out) :: f(:)
        end subroutine operator_force

        !> ku = K u.
        subroutine operator_times(self, u, ku)
            import :: dynamic_operator_t, wp
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Displacements (n_free).
            real(wp), contiguous, intent(in) :: u(:)
            !> Product (n_free).
            real(wp), contiguous, intent(out) :: ku(:)
        end subroutine operator_times

        !> mv = M v.
        subroutine operator_mass_times(self, v, mv)
            import :: dynamic_operator_t, wp
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Velocities or accelerations (n_free).
            real(wp), contiguous, intent(in) :: v(:)
            !> Product (n_free).
            real(wp), contiguous, intent(out) :: mv(:)
        end subroutine operator_mass_times

        !> cv = C v.
        subroutine operator_damping_times(self, v, cv)
            import :: dynamic_operator_t, wp
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Velocities (n_free).
            real(wp), contiguous, intent(in) :: v(:)
            !> Product (n_free).
            real(wp), contiguous, intent(out) :: cv(:)
        end subroutine operator_damping_times

        !> A property of the model.
        pure logical function operator_flag(self)
            import :: dynamic_operator_t
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
        end function operator_flag

        !> Strain energy 1/2 u.K u [J].
        real(wp) function operator_energy(self, u)
            import :: dynamic_operator_t, wp
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Displacements (n_free).
            real(wp), contiguous, intent(in) :: u(:)
        end function operator_energy

        !> Kinetic energy 1/2 v.M v [J].
        real(wp) function operator_kinetic_energy(self, v)
            import :: dynamic_operator_t, wp
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Velocities (n_free).
            real(wp), contiguous, intent(in) :: v(:)
        end function operator_kinetic_energy

        !> Factor c_m M + c_k K (symmetric positive definite).
        subroutine operator_factor(self, c_m, c_k, factor, error)
            import :: dynamic_operator_t, spd_factor_t, wp, error_t
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Coefficient of M.
            real(wp), intent(in) :: c_m
            !> Coefficient of K.
            real(wp), intent(in) :: c_k
            !> The factor.
            class(spd_factor_t), allocatable, intent(out) :: factor
            !> Set when the matrix is not positive definite.
            type(error_t), allocatable, intent(out) :: error
        end subroutine operator_factor

        !> Diagonal of the lumped mass matrix.
        subroutine operator_diagonal(self, d)
            import :: dynamic_operator_t, wp
            !> The model (lumped mass).
            class(dynamic_operator_t), intent(in) :: self
            !> Diagonal (n_free).
            real(wp), intent(out) :: d(:)
        end subroutine operator_diagonal

        !> Largest eigenvalue of K phi = lambda M phi.
        subroutine operator_largest(self, lambda_max, error)
            import :: dynamic_operator_t, wp, error_t
            !> The model.
            class(dynamic_operator_t), intent(in) :: self
            !> Largest eigenvalue (or an upper bound of it) [1/s^2].
            real(wp), intent(out) :: lambda_max
            !> Set on eigensolver failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine operator_largest
    end interface

contains

    !> Whether the mass matrix is diagonal (lumped); false when no mass scheme is set.
    pure logical function has_diagonal_mass(self)
        !> The model.
        class(dynamic_operator_t), intent(in) :: self
        has_diagonal_mass = .false.
        if (allocated(self%mass_scheme)) has_diagonal_mass = self%mass_scheme%is_diagonal()
    end function has_diagonal_mass
end module fem_dynamic_operator
