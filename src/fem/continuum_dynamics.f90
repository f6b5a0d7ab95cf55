!> The 2D continuum (fem_continuum_model) as a `dynamic_operator_t`: K, M and the loads reduced
!> to the free dofs, in CHOLMOD sparse storage, for the time integrators of fem_newmark and
!> for the static and modal solutions.
!>
!> Prescribed displacements u_p are eliminated (fem_continuum_model `reduce`): the free dofs
!> carry F(t) = f_f - K_fp u_p(t) - C_fp v_p(t) - M_fp a_p(t) + sum_k f_k(t) g_k,f (the model's
!> loads times its time functions, `timed_load`), so that the integrator's energy accounts
!> (on the free dofs) close; the strain energy of the whole body 1/2 u.K u over all dofs is
!> `total_strain_energy`. A prescribed dof is constant, or u_p(t) = value f(t) with one of the
!> model's time functions: its rate and acceleration are value f'(t) and value f''(t), the
!> exact derivatives of the function (not finite differences of u_p: those of the trapezoidal
!> rule, v_n+1 = 2 du/h - v_n, ring with an undamped period-2 oscillation after any kink of
!> u_p). Within a step where u_p is linear in time (ramp and table functions between their
!> kinks, whatever the step) they satisfy the scheme's own relations du_p = h (v_n + v_n+1)/2
!> and dv_p = h (a_n + a_n+1)/2 exactly, which is what makes the energy audit of the whole body
!> (`continuum_audit_t`) close to round-off. At a kink of f (the velocity of the support jumps)
!> the rate is the one after the kink and the impulse of the kink is not represented: the
!> audit's balance then moves once, by about 1/2 dv_p.M dv_p.
!>
!> Energy audit of the whole body (`continuum_audit_t`): kinetic 1/2 v.M v and strain
!> 1/2 u.K u over all dofs, Rayleigh dissipation int du.C v, work of the loads int du.f, work of
!> the reactions on the prescribed dofs int du_p.r with r = (K u + C v + M a - f - f_c)_p, and
!> the work of the coupling force f_c; every integral by the trapezoidal rule of the scheme. In
!> a coupled run f_c = -C^T lambda over all dofs (given to `start`, `advance`, `resume`): the
!> supports then take what the multipliers put on the prescribed dofs, and the coupling work is
!> the integrator's (free dofs) plus the one through the prescribed dofs; uncoupled, f_c = 0.
!>
!> Combinations c_m M + c_k K share the pattern of K (a lumped M is
!> diagonal, inside it) and are factored by CHOLMOD (`sparse_cholesky`). The lowest modes come
!> from a subspace iteration with that factor (`solve_modes`); the critical time step from the
!> largest element eigenvalue (`largest_eigenvalue`).
module fem_continuum_dynamics
    use core_kinds, only: wp, i8
    use core_constants, only: pi
    use core_error, only: error_t, make_error
    use core_sparse, only: sparse_matrix_t, sparse_solver_t
    use core_linalg, only: band_spd_t, band_generalized_eigen
    use fem_dynamic_operator, only: dynamic_operator_t, spd_factor_t
    use core_timefunc, only: time_function_slot_t
    use fem_continuum_model, only: continuum_model_t
    use fem_triplets, only: fem_triplets_t
    use fem_newmark, only: time_integrator_t
    use fem_mass_scheme, only: mass_scheme_t
    implicit none
    private
    public :: continuum_dynamics_t, continuum_audit_t

    !> The continuum on its free dofs.
    type, extends(dynamic_operator_t) :: continuum_dynamics_t
        !> Stiffness K_ff (finalized).
        type(sparse_matrix_t) :: k
        !> Mass M_ff (finalized; with the pattern of K).
        type(sparse_matrix_t) :: m
        !> K_ff and M_ff as triplets.
        type(fem_triplets_t) :: k_triplets, m_triplets
        !> Largest eigenvalue over the elements of K_e phi = lambda M_e phi [1/s^2].
        real(wp) :: element_lambda_max = 0.0_wp
        !> Constant load on the free dofs, f_f - K_fp u_p [N].
        real(wp), allocatable :: load(:)
        !> Loads on the free dofs times a time function: column k times functions(k)(t) [N].
        real(wp), allocatable :: timed_load(:, :)
        !> The model's time functions (one per column of `timed_load`).
        type(time_function_slot_t), allocatable :: functions(:)
        !> Stiffness over all dofs (for the strain energy of the whole body).
        type(fem_triplets_t) :: k_all
        !> Mass over all dofs (for the prescribed motion's inertia and the audit).
        type(fem_triplets_t) :: m_all
        !> Loads over all dofs: constant, and times the functions [N].
        real(wp), allocatable :: load_all(:), timed_all(:, :)
        !> Amplitude of every timed prescribed dof (0 elsewhere) [m].
        real(wp), allocatable :: timed_value(:)
        !> Time function of every prescribed dof (index into `functions`; 0: none).
        integer, allocatable :: timed_function(:)
        !> Equation number of every dof (0: prescribed).
        integer, allocatable :: equation(:)
    contains
        !> Assemble and reduce the model.
        procedure :: build => dynamics_build
        !> Reduce given matrices and loads (e.g. alpha-weighted ones).
        procedure :: build_from => dynamics_build_from
        !> See `dynamic_operator_t`.
        procedure :: external_force => dynamics_force
        !> ku = K u on the free DOFs.
        procedure :: stiffness_times => dynamics_stiffness_times
        !> mv = M v on the free DOFs.
        procedure :: mass_times => dynamics_mass_times
        !> cv = C v (Rayleigh).
        procedure :: damping_times => dynamics_damping_times
        !> True when C /= 0.
        procedure :: is_damped => dynamics_is_damped
        !> 1/2 u.K u.
        procedure :: strain_energy => dynamics_strain_energy
        !> 1/2 v.M v.
        procedure :: kinetic_energy => dynamics_kinetic_energy
        !> Cholesky factor of c_m M + c_k K.
        procedure :: factor_combination => dynamics_factor_combination
        !> Diagonal of the (lumped) mass matrix.
        procedure :: mass_diagonal => dynamics_mass_diagonal
        !> Largest eigenvalue of K x = lambda M x (stable step of explicit schemes).
        procedure :: largest_eigenvalue => dynamics_largest_eigenvalue
        !> Lowest modes of K phi = omega^2 M phi.
        procedure :: solve_modes => dynamics_solve_modes
        !> 1/2 u.K u over all dofs [J].
        procedure :: total_strain_energy => dynamics_total_strain_energy
        !> Loads over all dofs at time t [N].
        procedure :: loads_at => dynamics_loads_at
        !> Static loads at time t on the free dofs: f_f - K_fp u_p(t) (no rate terms).
        procedure :: static_force => dynamics_static_force
        !> Timed prescribed motion over all dofs at t: displacement, rate or acceleration.
        procedure :: timed_motion => dynamics_timed_motion
        !> Nodal reactions r = K u + C v + M a - f(t) over all dofs (meaningful on the
        !> prescribed ones) [N].
        procedure :: reactions => dynamics_reactions
    end type continuum_dynamics_t

    !> Energy audit of the whole body, prescribed dofs included (see the module description).
    type :: continuum_audit_t
        !> Kinetic 1/2 v.M v and strain 1/2 u.K u over all dofs [J].
        real(wp) :: kinetic = 0.0_wp, strain = 0.0_wp
        !> Rayleigh dissipation, work of the loads, of the reactions on the prescribed dofs and
        !> of the coupling forces, since the start [J].
        real(wp) :: damping = 0.0_wp, load_work = 0.0_wp, reaction_work = 0.0_wp, coupling_work = 0.0_wp
        !> Kinetic + strain energy at the start [J].
        real(wp) :: initial = 0.0_wp
        !> Resultant of the reactions on the prescribed dofs, (x, y), at the last time [N].
        real(wp) :: reaction_resultant(2) = 0.0_wp
        !> State over all dofs at the last time; reactions and loads there.
        real(wp), allocatable :: u(:), v(:), r(:), f(:)
    contains
        !> Take the initial state.
        procedure :: start => audit_start
        !> Add one step (the integrator after it).
        procedure :: advance => audit_advance
        !> kinetic + strain + damping - works - initial [J].
        procedure :: balance => audit_balance
        !> The accumulated scalars (initial, damping, load work, reaction work), for checkpoints.
        procedure :: totals => audit_totals
        !> Start from the integrator's state with accumulated scalars of `totals` (restart).
        procedure :: resume => audit_resume
    end type continuum_audit_t

    !> A CHOLMOD factor as a `spd_factor_t` (freed with it: sparse_solver_t's finaliser).
    type, extends(spd_factor_t) :: sparse_factor_t
        !> The factored solver.
        type(sparse_solver_t), allocatable :: solver
    contains
        procedure :: solve_vec => sparse_factor_solve_vec
        procedure :: solve_mat => sparse_factor_solve_mat
    end type sparse_factor_t

contains

    !> Assemble K and M of the model, reduce them and the loads to the free dofs.
    subroutine dynamics_build(self, model, mass, a0, a1, error)
        !> The operator.
        class(continuum_dynamics_t), intent(out) :: self
        !> The continuum (materials, loads and prescribed dofs set).
        type(continuum_model_t), intent(in) :: model
        !> How the element masses enter: consistent or row-sum lumped (fem_mass_scheme).
        class(mass_scheme_t), intent(in) :: mass
        !> Rayleigh coefficients: C = a0 M + a1 K.
        real(wp), intent(in) :: a0, a1
        !> Set when an element has no material or CHOLMOD fails.
        type(error_t), allocatable, intent(out) :: error
        type(fem_triplets_t) :: k_all, m_all
        call model%assemble_stiffness(k_all, error)
        if (allocated(error)) return
        call model%assemble_mass(mass, m_all, error)
        if (allocated(error)) return
        call self%build_from(model, k_all, m_all, model%load, mass, a0, a1, error)
    end subroutine dynamics_build

    !> Reduce given K, M and loads over all dofs to the free dofs of the model (e.g. the
    !> alpha-weighted K_alpha, M_alpha and loads of an Arlequin overlap, coupling_weighted2d).
    !> The element bound of the critical step is that of the model's own element matrices: a
    !> weight constant on an element scales K_e and M_e alike and leaves it unchanged.
    subroutine dynamics_build_from(self, model, k_all, m_all, load, mass, a0, a1, error)
        !> The operator.
        class(continuum_dynamics_t), intent(out) :: self
        !> The continuum (materials and prescribed dofs set).
        type(continuum_model_t), intent(in) :: model
        !> Stiffness over all dofs.
        type(fem_triplets_t), intent(in) :: k_all
        !> Mass over all dofs (assembled under `mass`: diagonal when lumped).
        type(fem_triplets_t), intent(in) :: m_all
        !> Loads over all dofs [N].
        real(wp), intent(in) :: load(:)
        !> The scheme `m_all` was assembled with.
        class(mass_scheme_t), intent(in) :: mass
        !> Rayleigh coefficients: C = a0 M + a1 K.
        real(wp), intent(in) :: a0, a1
        !> Set when CHOLMOD fails or the element bound cannot be computed.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: dummy(:)
        integer, allocatable :: eq(:)
        integer :: p, c, n
        self%k_all = k_all
        self%m_all = m_all
        self%load_all = load
        self%timed_all = model%timed_load
        self%timed_value = merge(model%prescribed_value, 0.0_wp, model%prescribed .and. model%prescribed_function > 0)
        self%timed_function = merge(model%prescribed_function, 0, model%prescribed)
        call model%reduce(self%k_all, load, self%k_triplets, self%load)
        ! Timed loads: their free rows (the prescribed dofs' reactions are constant, in `load`).
        call model%equations(eq, n)
        self%equation = eq
        allocate (self%timed_load(n, size(model%functions)), source=0.0_wp)
        self%functions = model%functions
        do c = 1, size(eq)
            if (eq(c) > 0) self%timed_load(eq(c), :) = model%timed_load(c, :)
        end do
        ! M acts on accelerations: the prescribed dofs do not move, no right-hand side.
        call model%reduce(m_all, 0*load, self%m_triplets, dummy)
        self%n_free = self%k_triplets%n
        allocate (self%mass_scheme, source=mass)
        self%rayleigh_a0 = a0
        self%rayleigh_a1 = a1
        call self%k%init(self%n_free, int(self%k_triplets%nnz, i8))
        call self%m%init(self%n_free, int(self%k_triplets%nnz, i8))
        do p = 1, self%k_triplets%nnz
            associate (i => self%k_triplets%i(p), j => self%k_triplets%j(p))
                if (i >= j) call self%k%add(i, j, self%k_triplets%v(p))
                ! M takes the pattern of K (zeros included) so that c_m M + c_k K adds values.
                if (i >= j) call self%m%add(i, j, 0.0_wp)
            end associate
        end do
        do p = 1, self%m_triplets%nnz
            associate (i => self%m_triplets%i(p), j => self%m_triplets%j(p))
                if (i >= j) call self%m%add(i, j, self%m_triplets%v(p))
            end associate
        end do
        call self%k%finalize(error)
        if (.not. allocated(error)) call self%m%finalize(error)
        if (allocated(error)) return
        call element_bound(error)
        if (allocated(error)) return
        if (self%m%nnz() == self%k%nnz()) then
            if (all(self%m%rowind == self%k%rowind) .and. all(self%m%colptr == self%k%colptr)) return
        end if
        call make_error(error, 'continuum: the mass matrix has entries outside the stiffness pattern')
    contains
        !> Largest element eigenvalue (skipped when a density is zero: no dynamics then).
        subroutine element_bound(error)
            type(error_t), allocatable, intent(out) :: error
            type(band_spd_t) :: ke, me
            real(wp), allocatable :: k_e(:, :), m_e(:, :), lambda(:)
            integer :: e, a, b, n
            self%element_lambda_max = 0.0_wp
            if (any(model%materials%density <= 0)) return
            do e = 1, model%mesh%element_count()
                associate (el => model%family(model%mesh%kind(e))%element, xe => model%mesh%element_coordinates(e), &
                           mat => model%materials(model%element_material(e)))
                    k_e = el%stiffness(xe, mat)
                    m_e = mass%element_matrix(el%mass_consistent(xe, mat), el%mass_lumped(xe, mat))
                end associate
                n = size(k_e, 1)
                call ke%init(n, n - 1)
                call me%init(n, n - 1)
                do b = 1, n
                    do a = 1, b
                        call ke%add(a, b, k_e(a, b))
                        call me%add(a, b, m_e(a, b))
                    end do
                end do
                call band_generalized_eigen(ke, me, n, n, lambda, error)
                if (allocated(error)) return
                self%element_lambda_max = max(self%element_lambda_max, lambda(1))
            end do
        end subroutine element_bound
    end subroutine dynamics_build_from

    !> Loads at time t: f_f - K_fp u_p - C_fp v_p(t) - M_fp a_p(t) + sum_k f_k(t) g_k,f (the
    !> constant u_p are in `load`; the timed ones are added here).
    subroutine dynamics_force(self, t, f)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(out) :: f(:)
        real(wp), allocatable :: up(:), vp(:), ap(:), w(:), w2(:)
        integer :: k, i
        f = self%load
        do k = 1, size(self%functions)
            f = f + self%functions(k)%fn%value(t)*self%timed_load(:, k)
        end do
        if (.not. any(self%timed_function > 0 .and. self%equation == 0)) return
        up = self%timed_motion(t, 0)
        vp = self%timed_motion(t, 1)
        ap = self%timed_motion(t, 2)
        allocate (w(size(up)), w2(size(up)))
        ! K (u_p + a1 v_p) + M (a_p + a0 v_p) over all dofs; its free rows leave F.
        call self%k_all%matvec(up + self%rayleigh_a1*vp, w)
        call self%m_all%matvec(ap + self%rayleigh_a0*vp, w2)
        w = w + w2
        do i = 1, size(self%equation)
            if (self%equation(i) > 0) f(self%equation(i)) = f(self%equation(i)) - w(i)
        end do
    end subroutine dynamics_force

    !> Static right-hand side at time t on the free dofs: f_f(t) - K_fp u_p(t) (the prescribed
    !> displacements at t, without the damping and inertia of their motion).
    subroutine dynamics_static_force(self, t, f)
        !> The operator.
        class(continuum_dynamics_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> Right-hand side (n_free) [N].
        real(wp), intent(out) :: f(:)
        real(wp), allocatable :: w(:)
        integer :: k, i
        f = self%load
        do k = 1, size(self%functions)
            f = f + self%functions(k)%fn%value(t)*self%timed_load(:, k)
        end do
        allocate (w(size(self%equation)))
        call self%k_all%matvec(self%timed_motion(t, 0), w)
        do i = 1, size(self%equation)
            if (self%equation(i) > 0) f(self%equation(i)) = f(self%equation(i)) - w(i)
        end do
    end subroutine dynamics_static_force

    !> Loads over all dofs at time t [N].
    function dynamics_loads_at(self, t) result(f)
        !> The operator.
        class(continuum_dynamics_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> Loads [N].
        real(wp), allocatable :: f(:)
        integer :: k
        f = self%load_all
        do k = 1, size(self%functions)
            f = f + self%functions(k)%fn%value(t)*self%timed_all(:, k)
        end do
    end function dynamics_loads_at

    !> Timed prescribed dofs over all dofs (0 elsewhere) at time t: value f(t) (derivative 0),
    !> value f'(t) (1) or value f''(t) (2).
    function dynamics_timed_motion(self, t, derivative) result(x)
        !> The operator.
        class(continuum_dynamics_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> 0, 1 or 2.
        integer, intent(in) :: derivative
        !> The motion [m, m/s, m/s^2].
        real(wp), allocatable :: x(:)
        integer :: i
        allocate (x(size(self%timed_value)), source=0.0_wp)
        do i = 1, size(x)
            if (self%timed_function(i) == 0 .or. self%equation(i) /= 0) cycle
            associate (fn => self%functions(self%timed_function(i))%fn)
                select case (derivative)
                case (0)
                    x(i) = self%timed_value(i)*fn%value(t)
                case (1)
                    x(i) = self%timed_value(i)*fn%rate(t)
                case default
                    x(i) = self%timed_value(i)*fn%acceleration(t)
                end select
            end associate
        end do
    end function dynamics_timed_motion

    !> r = K u + a1 K v + M (a + a0 v) - f(t) over all dofs [N]: on the prescribed dofs, the
    !> forces the supports apply; on the free dofs, the residual of the equation of motion
    !> (minus the coupling force in a coupled run).
    function dynamics_reactions(self, t, u, v, a) result(r)
        !> The operator.
        class(continuum_dynamics_t), intent(in) :: self
        !> Time [s].
        real(wp), intent(in) :: t
        !> Displacements, velocities and accelerations over all dofs.
        real(wp), intent(in) :: u(:), v(:), a(:)
        !> Reactions [N].
        real(wp), allocatable :: r(:)
        real(wp), allocatable :: w(:)
        allocate (r(size(u)), w(size(u)))
        call self%k_all%matvec(u + self%rayleigh_a1*v, r)
        call self%m_all%matvec(a + self%rayleigh_a0*v, w)
        r = r + w - self%loads_at(t)
    end function dynamics_reactions

    !> Start the audit from the integrator's initial state.
    subroutine audit_start(self, ops, model, integ, coupling, prescribed_coupling_work)
        !> The audit.
        class(continuum_audit_t), intent(inout) :: self
        !> The operator.
        type(continuum_dynamics_t), intent(in) :: ops
        !> The continuum (prescribed dofs).
        type(continuum_model_t), intent(in) :: model
        !> The integrator, initialised.
        class(time_integrator_t), intent(in) :: integ
        !> Force of a coupling on the body over all dofs at the integrator's time (a coupled
        !> run: -C^T lambda) [N]: the reactions are what the supports add to it and the loads.
        real(wp), intent(in), optional :: coupling(:)
        !> Work of that force through the prescribed dofs since the start [J] (added to the
        !> integrator's coupling work, which covers the free dofs).
        real(wp), intent(in), optional :: prescribed_coupling_work
        real(wp), allocatable :: a(:), w(:)
        self%u = model%expand(integ%u, integ%t)
        self%v = model%expand(integ%v, integ%t, 1)
        a = model%expand(integ%a, integ%t, 2)
        self%r = ops%reactions(integ%t, self%u, self%v, a)
        if (present(coupling)) self%r = self%r - coupling
        self%f = ops%loads_at(integ%t)
        allocate (w(size(self%u)))
        call ops%m_all%matvec(self%v, w)
        self%kinetic = 0.5_wp*dot_product(self%v, w)
        self%strain = ops%total_strain_energy(self%u)
        self%initial = self%kinetic + self%strain
        self%damping = 0.0_wp
        self%load_work = 0.0_wp
        self%reaction_work = 0.0_wp
        self%coupling_work = integ%coupling_work
        if (present(prescribed_coupling_work)) self%coupling_work = self%coupling_work + prescribed_coupling_work
        call resultant(self, model)
    end subroutine audit_start

    !> Add the step the integrator just made (trapezoidal rule between the last time and now).
    subroutine audit_advance(self, ops, model, integ, coupling, prescribed_coupling_work)
        !> The audit (started).
        class(continuum_audit_t), intent(inout) :: self
        !> The operator.
        type(continuum_dynamics_t), intent(in) :: ops
        !> The continuum (prescribed dofs).
        type(continuum_model_t), intent(in) :: model
        !> The integrator, after the step.
        class(time_integrator_t), intent(in) :: integ
        !> Force of a coupling on the body over all dofs at the integrator's time [N] (see
        !> `start`).
        real(wp), intent(in), optional :: coupling(:)
        !> Work of that force through the prescribed dofs since the start [J] (see `start`).
        real(wp), intent(in), optional :: prescribed_coupling_work
        real(wp), allocatable :: u(:), v(:), a(:), r(:), f(:), du(:), w(:), w2(:)
        u = model%expand(integ%u, integ%t)
        v = model%expand(integ%v, integ%t, 1)
        a = model%expand(integ%a, integ%t, 2)
        r = ops%reactions(integ%t, u, v, a)
        if (present(coupling)) r = r - coupling
        f = ops%loads_at(integ%t)
        du = u - self%u
        allocate (w(size(u)), w2(size(u)))
        ! Rayleigh: du.C (v_n + v_n+1)/2.
        call ops%k_all%matvec(ops%rayleigh_a1*(v + self%v), w)
        call ops%m_all%matvec(ops%rayleigh_a0*(v + self%v), w2)
        self%damping = self%damping + 0.5_wp*dot_product(du, w + w2)
        self%load_work = self%load_work + 0.5_wp*dot_product(du, f + self%f)
        self%reaction_work = self%reaction_work + 0.5_wp*dot_product(merge(du, 0.0_wp, model%prescribed), r + self%r)
        self%coupling_work = integ%coupling_work
        if (present(prescribed_coupling_work)) self%coupling_work = self%coupling_work + prescribed_coupling_work
        call ops%m_all%matvec(v, w)
        self%kinetic = 0.5_wp*dot_product(v, w)
        self%strain = ops%total_strain_energy(u)
        call move_alloc(u, self%u)
        call move_alloc(v, self%v)
        call move_alloc(r, self%r)
        call move_alloc(f, self%f)
        call resultant(self, model)
    end subroutine audit_advance

    !> Resultant of the reactions on the prescribed dofs.
    pure subroutine resultant(self, model)
        type(continuum_audit_t), intent(inout) :: self
        type(continuum_model_t), intent(in) :: model
        self%reaction_resultant(1) = sum(self%r(1::2), mask=model%prescribed(1::2))
        self%reaction_resultant(2) = sum(self%r(2::2), mask=model%prescribed(2::2))
    end subroutine resultant

    !> The accumulated scalars [J]: initial energy, damping, load work, reaction work.
    pure function audit_totals(self) result(totals)
        !> The audit.
        class(continuum_audit_t), intent(in) :: self
        !> (initial, damping, load_work, reaction_work).
        real(wp) :: totals(4)
        totals = [self%initial, self%damping, self%load_work, self%reaction_work]
    end function audit_totals

    !> Start from the integrator's state (restored from a checkpoint) and the accumulated
    !> scalars saved there: the state-dependent terms are recomputed, bit for bit.
    subroutine audit_resume(self, ops, model, integ, totals, coupling, prescribed_coupling_work)
        !> The audit.
        class(continuum_audit_t), intent(inout) :: self
        !> The operator.
        type(continuum_dynamics_t), intent(in) :: ops
        !> The continuum (prescribed dofs).
        type(continuum_model_t), intent(in) :: model
        !> The integrator, restored.
        class(time_integrator_t), intent(in) :: integ
        !> (initial, damping, load_work, reaction_work) from `totals` [J].
        real(wp), intent(in) :: totals(4)
        !> Force of a coupling on the body over all dofs, restored [N] (see `start`).
        real(wp), intent(in), optional :: coupling(:)
        !> Work of that force through the prescribed dofs, restored [J] (see `start`).
        real(wp), intent(in), optional :: prescribed_coupling_work
        call self%start(ops, model, integ, coupling, prescribed_coupling_work)
        self%initial = totals(1)
        self%damping = totals(2)
        self%load_work = totals(3)
        self%reaction_work = totals(4)
    end subroutine audit_resume

    !> kinetic + strain + damping - load, reaction and coupling works - initial [J].
    pure real(wp) function audit_balance(self) result(b)
        !> The audit.
        class(continuum_audit_t), intent(in) :: self
        b = self%kinetic + self%strain + self%damping - self%load_work - self%reaction_work - &
            self%coupling_work - self%initial
    end function audit_balance

    !> ku = K u.
    subroutine dynamics_stiffness_times(self, u, ku)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), contiguous, intent(in) :: u(:)
        real(wp), contiguous, intent(out) :: ku(:)
        type(error_t), allocatable :: error
        call self%k%matvec(u, ku, error)
    end subroutine dynamics_stiffness_times

    !> mv = M v.
    subroutine dynamics_mass_times(self, v, mv)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), contiguous, intent(in) :: v(:)
        real(wp), contiguous, intent(out) :: mv(:)
        type(error_t), allocatable :: error
        call self%m%matvec(v, mv, error)
    end subroutine dynamics_mass_times

    !> cv = a0 M v + a1 K v.
    subroutine dynamics_damping_times(self, v, cv)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), contiguous, intent(in) :: v(:)
        real(wp), contiguous, intent(out) :: cv(:)
        type(error_t), allocatable :: error
        call self%k%matvec(v, cv, error, alpha=self%rayleigh_a1)
        call self%m%matvec(v, cv, error, alpha=self%rayleigh_a0, beta=1.0_wp)
    end subroutine dynamics_damping_times

    !> True when C /= 0.
    pure logical function dynamics_is_damped(self)
        class(continuum_dynamics_t), intent(in) :: self
        dynamics_is_damped = self%rayleigh_a0 /= 0 .or. self%rayleigh_a1 /= 0
    end function dynamics_is_damped

    !> 1/2 u.K_ff u [J].
    real(wp) function dynamics_strain_energy(self, u)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), contiguous, intent(in) :: u(:)
        real(wp) :: ku(size(u))
        call self%stiffness_times(u, ku)
        dynamics_strain_energy = 0.5_wp*dot_product(u, ku)
    end function dynamics_strain_energy

    !> 1/2 v.M v [J].
    real(wp) function dynamics_kinetic_energy(self, v)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), contiguous, intent(in) :: v(:)
        real(wp) :: mv(size(v))
        call self%mass_times(v, mv)
        dynamics_kinetic_energy = 0.5_wp*dot_product(v, mv)
    end function dynamics_kinetic_energy

    !> CHOLMOD factor of c_m M + c_k K.
    subroutine dynamics_factor_combination(self, c_m, c_k, factor, error)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), intent(in) :: c_m
        real(wp), intent(in) :: c_k
        class(spd_factor_t), allocatable, intent(out) :: factor
        type(error_t), allocatable, intent(out) :: error
        type(sparse_matrix_t) :: a
        type(sparse_factor_t), allocatable :: f
        a = self%k
        a%values = c_m*self%m%values + c_k*self%k%values
        allocate (f)
        allocate (f%solver)
        call f%solver%factor(a, error)
        call move_alloc(f, factor)
    end subroutine dynamics_factor_combination

    !> x <- A^-1 x.
    subroutine sparse_factor_solve_vec(self, x, error)
        class(sparse_factor_t), intent(inout) :: self
        real(wp), contiguous, intent(inout) :: x(:)
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: b(size(x))
        b = x
        call self%solver%solve(b, x, error)
    end subroutine sparse_factor_solve_vec

    !> X <- A^-1 X.
    subroutine sparse_factor_solve_mat(self, x, error)
        class(sparse_factor_t), intent(inout) :: self
        real(wp), contiguous, intent(inout) :: x(:, :)
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: b(:, :)
        b = x
        call self%solver%solve(b, x, error)
    end subroutine sparse_factor_solve_mat

    !> Diagonal of M (lumped).
    subroutine dynamics_mass_diagonal(self, d)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), intent(out) :: d(:)
        integer :: p
        d = 0.0_wp
        do p = 1, self%m_triplets%nnz
            if (self%m_triplets%i(p) == self%m_triplets%j(p)) &
                d(self%m_triplets%i(p)) = d(self%m_triplets%i(p)) + self%m_triplets%v(p)
        end do
    end subroutine dynamics_mass_diagonal

    !> Upper bound of the largest eigenvalue of K phi = omega^2 M phi: the largest element
    !> eigenvalue (Irons and Treharne: the global one never exceeds it; prescribed dofs only
    !> lower it), computed in `build`. Conservative for critical time steps.
    subroutine dynamics_largest_eigenvalue(self, lambda_max, error)
        class(continuum_dynamics_t), intent(in) :: self
        real(wp), intent(out) :: lambda_max
        type(error_t), allocatable, intent(out) :: error
        lambda_max = self%element_lambda_max
        if (.not. self%element_lambda_max > 0) &
            call make_error(error, 'continuum: no element eigenvalue bound (a density is zero?)')
    end subroutine dynamics_largest_eigenvalue

    !> The n_modes lowest modes of K phi = omega^2 M phi on the free dofs, mass-normalised.
    !>
    !> Subspace iteration (Bathe, Finite Element Procedures, 11.6) with the CHOLMOD factor of
    !> K - sigma M: p = max(2 n_modes, n_modes + 8) vectors (at most n_free),
    !> Y = (K - sigma M)^-1 M X, Rayleigh-Ritz on span(Y) (M-orthonormalised by Gram-Schmidt, then
    !> the p x p eigenproblem of the projected K by LAPACK), until the
    !> wanted eigenvalues change by less than 1e-10 of the largest wanted one (at most 500
    !> iterations; relative to the largest so that zero eigenvalues of rigid modes converge).
    !> sigma = 0 when K_ff is positive definite; otherwise (rigid motions free) a small
    !> negative shift, 1e-8 times the mean of K_ii/M_ii.
    subroutine dynamics_solve_modes(self, n_modes, omega, shapes, error)
        !> The operator.
        class(continuum_dynamics_t), intent(in) :: self
        !> Number of modes (1..n_free).
        integer, intent(in) :: n_modes
        !> Circular frequencies [rad/s], ascending.
        real(wp), allocatable, intent(out) :: omega(:)
        !> Mode shapes (n_free, n_modes), mass-normalised.
        real(wp), allocatable, intent(out) :: shapes(:, :)
        !> Set when n_modes is out of range, the iteration does not converge, or on failure.
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: max_iterations = 500
        real(wp), parameter :: tolerance = 1.0e-10_wp
        class(spd_factor_t), allocatable :: factor
        real(wp), allocatable :: x(:, :), y(:, :), ky(:, :), my(:, :), lambda(:), previous(:), q(:, :), d(:)
        type(band_spd_t) :: kr, mr
        real(wp) :: sigma, norm
        integer :: n, p, i, j, iteration
        character(len=200) :: buf
        n = self%n_free
        if (n_modes < 1 .or. n_modes > n) then
            write (buf, '(a,i0,a,i0,a)') 'modal analysis: ', n_modes, ' modes asked but the model has ', &
                n, ' free dofs'
            call make_error(error, trim(buf))
            return
        end if
        p = min(max(2*n_modes, n_modes + 8), n)
        sigma = 0.0_wp
        call self%factor_combination(1.0_wp, 1.0_wp, factor, error)
        if (allocated(error)) return
        deallocate (factor)
        call self%factor_combination(0.0_wp, 1.0_wp, factor, error)
        if (allocated(error)) then
            deallocate (error)
            allocate (d(n))
            call self%mass_diagonal(d)
            sigma = -1.0e-8_wp*sum(diagonal(self%k)/d)/n
            call self%factor_combination(-sigma, 1.0_wp, factor, error)
            if (allocated(error)) return
        end if
        ! Start: smooth, independent vectors (sines of increasing frequency).
        allocate (x(n, p), y(n, p), ky(n, p), my(n, p), previous(p))
        do j = 1, p
            do i = 1, n
                x(i, j) = sin(real(i, wp)*real(j, wp)*pi/real(n + 1, wp)) + 1.0e-3_wp*j
            end do
        end do
        previous = huge(1.0_wp)
        do iteration = 1, max_iterations
            call self%m%matvec(x, y, error)
            if (allocated(error)) return
            call factor%solve(y, error)
            if (allocated(error)) return
            ! M-orthonormal basis of span(Y) (Gram-Schmidt, twice), then K projected on it.
            call self%m%matvec(y, my, error)
            if (allocated(error)) return
            do j = 1, p
                do i = 1, 2
                    y(:, j) = y(:, j) - matmul(y(:, 1:j - 1), matmul(transpose(my(:, 1:j - 1)), y(:, j)))
                end do
                call self%m%matvec(y(:, j), my(:, j), error)
                if (allocated(error)) return
                norm = sqrt(dot_product(y(:, j), my(:, j)))
                if (.not. norm > 0) then
                    call make_error(error, 'modal analysis of the continuum: the subspace lost its rank (a '// &
                                    'vector of M-norm zero or not finite: young and density at the ends of the '// &
                                    'range of double precision? check the magnitudes in [continuum] material)')
                    return
                end if
                y(:, j) = y(:, j)/norm
                my(:, j) = my(:, j)/norm
            end do
            call self%k%matvec(y, ky, error)
            if (allocated(error)) return
            call kr%init(p, p - 1)
            call mr%init(p, 0)
            do j = 1, p
                call mr%add(j, j, 1.0_wp)
                do i = 1, j
                    call kr%add(i, j, 0.5_wp*(dot_product(y(:, i), ky(:, j)) + dot_product(y(:, j), ky(:, i))))
                end do
            end do
            call band_generalized_eigen(kr, mr, 1, p, lambda, error, q)
            if (allocated(error)) return
            x = matmul(y, q)
            if (all(abs(lambda(1:n_modes) - previous(1:n_modes)) <= tolerance*maxval(abs(lambda(1:n_modes))))) exit
            previous = lambda
        end do
        if (iteration > max_iterations) then
            call make_error(error, 'modal analysis of the continuum: the subspace iteration did not converge')
            return
        end if
        shapes = x(:, 1:n_modes)
        ! Rigid-body eigenvalues are zero up to rounding and may come out slightly negative.
        omega = sqrt(max(lambda(1:n_modes), 0.0_wp))
    end subroutine dynamics_solve_modes

    !> Diagonal of a finalized sparse matrix.
    function diagonal(a) result(d)
        type(sparse_matrix_t), intent(in) :: a
        real(wp) :: d(a%n)
        integer :: j
        ! Lower triangle, rows sorted within each column: the diagonal comes first.
        do j = 1, a%n
            d(j) = a%values(a%colptr(j) + 1)
        end do
    end function diagonal

    !> 1/2 u.K u over all dofs [J].
    real(wp) function dynamics_total_strain_energy(self, u) result(energy)
        !> The operator.
        class(continuum_dynamics_t), intent(in) :: self
        !> Displacements of all dofs.
        real(wp), intent(in) :: u(:)
        real(wp), allocatable :: ku(:)
        allocate (ku(size(u)))
        call self%k_all%matvec(u, ku)
        energy = 0.5_wp*dot_product(u, ku)
    end function dynamics_total_strain_energy
end module fem_continuum_dynamics
