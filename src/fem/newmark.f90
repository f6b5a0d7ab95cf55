!> Time integrators of M a + C v + K u = F(t) for any `dynamic_operator_t` (the frame model, the 2D
!> continuum; doc/theory.md, sections 5.4-5.5).
!>
!> `time_integrator_t` holds the state (t, u, v, a) and the energy accounts, and defers
!> `init` and `step` to the schemes:
!> - `newmark_t`: implicit Newmark (beta, gamma) in acceleration form, default average
!>   acceleration (1/4, 1/2); the effective matrix M + gamma h C + beta h^2 K is factored
!>   once in `init` (by the model: band Cholesky for beams, CHOLMOD for the continuum).
!> - `central_difference_t`: explicit (beta = 0, gamma = 1/2) with lumped mass; refuses a
!>   step above the critical one.
!>
!> Energy accounts, updated every step (trapezoidal rule, exact for average acceleration):
!> W += 1/2 (F_n + F_{n+1}).(u_{n+1} - u_n), D += (u_{n+1} - u_n).C (v_n + v_{n+1})/2,
!> and `energy_balance()` = kinetic + strain + D - W - W_c - (initial kinetic + strain),
!> W_c being the work of the coupling forces (same rule, zero without coupling).
!>
!> Coupled steps (Arlequin, doc/theory.md section 6.5) split `newmark_t%step` in two:
!> `predict` advances to t_{n+1} without coupling force (the free state: u, v, a), then
!> `correct(f_c)` adds the response to an extra force f_c (= -C^T lambda) and finishes the
!> step. The scheme being linear, a = a_free + S^-1 f_c, u = u_free + beta h^2 S^-1 f_c,
!> v = v_free + gamma h S^-1 f_c with S = M + gamma h C + beta h^2 K (`solve_effective`);
!> `predict` + `correct(0)` is bit-identical to `step`.
module fem_newmark
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    use core_state, only: state_sink_t, state_source_t
    use fem_dynamic_operator, only: dynamic_operator_t, spd_factor_t
    implicit none
    private
    public :: time_integrator_t, newmark_t, central_difference_t, critical_time_step, newmark_critical_step
    public :: model_out_of_range, make_time_integrator

    !> State and energy accounts common to all time integrators.
    type, abstract :: time_integrator_t
        !> Current time [s].
        real(wp) :: t = 0.0_wp
        !> Time step [s].
        real(wp) :: h = 0.0_wp
        !> Initial time [s].
        real(wp) :: t0 = 0.0_wp
        !> Number of steps done since `init`.
        integer :: step_count = 0
        !> Displacements, velocities, accelerations on the free DOFs (n_free).
        real(wp), allocatable :: u(:), v(:), a(:)
        !> Kinetic energy 1/2 v.M v [J].
        real(wp) :: kinetic = 0.0_wp
        !> Strain energy 1/2 u.K u [J].
        real(wp) :: strain = 0.0_wp
        !> Work of the external forces since `init` [J].
        real(wp) :: external_work = 0.0_wp
        !> Energy dissipated by the Rayleigh damping since `init` [J].
        real(wp) :: damping_dissipation = 0.0_wp
        !> Kinetic + strain energy at `init` [J].
        real(wp) :: initial_energy = 0.0_wp
        !> Work of the coupling forces since `init` [J] (see `newmark_t%correct`).
        real(wp) :: coupling_work = 0.0_wp
        !> Work arrays (n_free): previous u, v, F; F at the new time; scratch.
        real(wp), allocatable :: u_old(:), v_old(:), f_old(:), f_new(:), work(:), work2(:)
    contains
        !> Set the step, the initial state and the initial acceleration; prepare the scheme.
        procedure(integrator_init), deferred :: init
        !> Advance one step.
        procedure(integrator_step), deferred :: step
        !> kinetic + strain + dissipation - external work - initial energy [J].
        procedure :: energy_balance
        !> Whether the scheme is stable only below a critical time step (what a state that
        !> blows up is blamed on). Default: yes (a scheme that says nothing may have a limit).
        procedure :: conditionally_stable => integrator_conditionally_stable
        !> Common part of `init` for the schemes (state, work arrays, energies).
        procedure, non_overridable :: start_state
        !> a = F(t) - K u - C v with the current state.
        procedure, non_overridable :: initial_residual
        !> Energy accounts, time and step count after a step.
        procedure, non_overridable :: finish_step
        !> Put the state of the scheme beyond the common one (the components above) into a
        !> checkpoint (deferred: a new scheme cannot be built without saying what it keeps).
        procedure(integrator_save_state), deferred :: save_state
        !> Take it back from a checkpoint (after `init` from the deck).
        procedure(integrator_load_state), deferred :: load_state
    end type time_integrator_t

    abstract interface
        !> Prepare the integrator: time step h from time t0 with displacements u0 and
        !> velocities v0 (n_free); computes a0 from M a0 = F(t0) - K u0 - C v0.
        subroutine integrator_init(self, model, h, t0, u0, v0, error)
            import :: time_integrator_t, dynamic_operator_t, wp, error_t
            !> The integrator.
            class(time_integrator_t), intent(inout) :: self
            !> The model.
            class(dynamic_operator_t), intent(in) :: model
            !> Time step [s].
            real(wp), intent(in) :: h
            !> Initial time [s].
            real(wp), intent(in) :: t0
            !> Initial displacements and velocities (n_free).
            real(wp), intent(in) :: u0(:), v0(:)
            !> Set on invalid parameters or a failed factorisation.
            type(error_t), allocatable, intent(out) :: error
        end subroutine integrator_init

        !> Advance one time step.
        subroutine integrator_step(self, model, error)
            import :: time_integrator_t, dynamic_operator_t, error_t
            !> The integrator.
            class(time_integrator_t), intent(inout) :: self
            !> The model (the same as at `init`).
            class(dynamic_operator_t), intent(in) :: model
            !> Set on failure of the linear solve.
            type(error_t), allocatable, intent(out) :: error
        end subroutine integrator_step

        !> Put the state of the scheme beyond the common one into a checkpoint.
        subroutine integrator_save_state(self, sink, error)
            import :: time_integrator_t, state_sink_t, error_t
            !> The integrator.
            class(time_integrator_t), intent(in) :: self
            !> Where the state goes.
            class(state_sink_t), intent(inout) :: sink
            !> Set when the state cannot be written.
            type(error_t), allocatable, intent(out) :: error
        end subroutine integrator_save_state

        !> Take the state of the scheme beyond the common one back from a checkpoint.
        subroutine integrator_load_state(self, source, error)
            import :: time_integrator_t, state_source_t, error_t
            !> The integrator.
            class(time_integrator_t), intent(inout) :: self
            !> Where the state comes from.
            class(state_source_t), intent(in) :: source
            !> Set when the state cannot be read or does not fit.
            type(error_t), allocatable, intent(out) :: error
        end subroutine integrator_load_state
    end interface

    !> Start of the message of a model whose highest natural frequency no time step resolves
    !> (newmark_t%init); the drivers attach it to the stiffness and density lines.
    character(len=*), parameter :: model_out_of_range = &
                                   'the stiffness and density of the model give a highest natural frequency '// &
                                   'that no time step resolves in double precision'

    !> Implicit Newmark scheme; unconditionally stable for gamma >= 1/2 and beta >= gamma/2
    !> (and free of spurious high-frequency oscillation for beta >= (gamma + 1/2)^2/4).
    !> For beta < gamma/2 it is only conditionally stable: `init` refuses a step above
    !> h_crit = 1/(omega_max sqrt(gamma/2 - beta)) (the undamped limit; damping only raises
    !> it). Set beta and gamma before `init`.
    type, extends(time_integrator_t) :: newmark_t
        !> Newmark beta.
        real(wp) :: beta = 0.25_wp
        !> Newmark gamma.
        real(wp) :: gamma = 0.5_wp
        !> Factored effective matrix M + gamma h C + beta h^2 K.
        class(spd_factor_t), allocatable :: s
        !> True between `predict` and `correct`.
        logical :: predicted = .false.
        !> Coupling force of the previous step (n_free), for the coupling work.
        real(wp), allocatable :: fc_old(:)
    contains
        !> See `time_integrator_t%init`.
        procedure :: init => newmark_init
        !> See `time_integrator_t%step`.
        procedure :: step => newmark_step
        !> Free prediction of the step (no coupling force): u, v, a at t_{n+1}.
        procedure :: predict => newmark_predict
        !> Add the response to a coupling force and finish the step.
        procedure :: correct => newmark_correct
        !> See `time_integrator_t%conditionally_stable`: when 2 beta < gamma.
        procedure :: conditionally_stable => newmark_conditionally_stable
        procedure, private :: solve_effective_vec, solve_effective_mat
        !> x = S^-1 b with S = M + gamma h C + beta h^2 K (one or several right-hand sides).
        generic :: solve_effective => solve_effective_vec, solve_effective_mat
        procedure, private :: free_solve
        !> `predicted` and the coupling force `fc_old`.
        procedure :: save_state => newmark_save_state
        !> See `save_state`.
        procedure :: load_state => newmark_load_state
    end type newmark_t

    !> Explicit central-difference scheme (Newmark beta = 0, gamma = 1/2), lumped mass.
    !> Mass-proportional damping is treated implicitly (diagonal), stiffness-proportional
    !> damping explicitly with the half-step velocity, which lowers the critical step to
    !> 2/omega_max (sqrt(1 + xi^2) - xi), xi = a1 omega_max/2.
    type, extends(time_integrator_t) :: central_difference_t
        !> Critical time step used by the check in `init` [s].
        real(wp) :: h_crit = 0.0_wp
        !> 1/(m_ii (1 + a0 h/2)) (n_free).
        real(wp), allocatable :: inv_mass(:)
    contains
        !> See `time_integrator_t%init`.
        procedure :: init => central_difference_init
        !> See `time_integrator_t%step`.
        procedure :: step => central_difference_step
        !> Nothing beyond the common state (`init` builds the rest from the deck).
        procedure :: save_state => central_difference_save_state
        !> See `save_state`.
        procedure :: load_state => central_difference_load_state
        !> See `time_integrator_t%conditionally_stable`: yes.
        procedure :: conditionally_stable => central_difference_conditionally_stable
    end type central_difference_t

contains

    !> The time integrator named by a deck word of [time] scheme: 'average_acceleration' or
    !> 'newmark' (a `newmark_t` with the given beta and gamma), 'central_difference'. The schema
    !> refuses any other word, so another one here is a bug. `init` is left to the caller.
    subroutine make_time_integrator(scheme, beta, gamma, integ, error)
        !> The deck word.
        character(len=*), intent(in) :: scheme
        !> Newmark beta and gamma in effect (used by the Newmark schemes).
        real(wp), intent(in) :: beta, gamma
        !> The integrator, not yet initialised.
        class(time_integrator_t), allocatable, intent(out) :: integ
        !> Set (internal error) for a word that names no scheme.
        type(error_t), allocatable, intent(out) :: error
        type(newmark_t) :: newmark
        select case (scheme)
        case ('average_acceleration', 'newmark')
            newmark%beta = beta
            newmark%gamma = gamma
            allocate (integ, source=newmark)
        case ('central_difference')
            allocate (central_difference_t :: integ)
        case default
            call make_internal_error(error, 'make_time_integrator', 'time scheme '''//scheme// &
                                     ''' is none of average_acceleration, newmark, central_difference '// &
                                     '(the schema should have refused it)')
        end select
    end subroutine make_time_integrator

    !> kinetic + strain + damping_dissipation - external_work - initial energy [J]; zero up
    !> to rounding for average acceleration.
    pure real(wp) function energy_balance(self)
        !> The integrator.
        class(time_integrator_t), intent(in) :: self
        energy_balance = self%kinetic + self%strain + self%damping_dissipation &
                         - self%external_work - self%coupling_work - self%initial_energy
    end function energy_balance

    !> See `time_integrator_t%conditionally_stable`: yes.
    pure logical function integrator_conditionally_stable(self)
        !> The integrator.
        class(time_integrator_t), intent(in) :: self
        integrator_conditionally_stable = .true.
    end function integrator_conditionally_stable

    !> Newmark is stable whatever the step for 2 beta >= gamma (gamma >= 1/2, undamped
    !> limit), only below h_crit otherwise.
    pure logical function newmark_conditionally_stable(self)
        !> The integrator.
        class(newmark_t), intent(in) :: self
        newmark_conditionally_stable = 2*self%beta < self%gamma
    end function newmark_conditionally_stable

    !> Central differences are stable only below 2/omega_max (less with stiffness damping).
    pure logical function central_difference_conditionally_stable(self)
        !> The integrator.
        class(central_difference_t), intent(in) :: self
        central_difference_conditionally_stable = .true.
    end function central_difference_conditionally_stable

    !> Common part of `init`: checks, state, work arrays, energies; leaves
    !> F(t0) - K u0 - C v0 in `a` (to be multiplied by M^-1 by the scheme).
    subroutine start_state(self, model, h, t0, u0, v0, error)
        !> The integrator.
        class(time_integrator_t), intent(inout) :: self
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        !> Time step and initial time [s].
        real(wp), intent(in) :: h, t0
        !> Initial displacements and velocities (n_free).
        real(wp), intent(in) :: u0(:), v0(:)
        !> Set when h <= 0 or the sizes are wrong.
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        n = model%n_free
        if (.not. (h > 0)) then
            call make_error(error, 'time integration: the time step must be > 0')
            return
        end if
        if (size(u0) /= n .or. size(v0) /= n) then
            call make_error(error, 'time integration: initial displacements and velocities '// &
                            'must have one value per free DOF')
            return
        end if
        self%h = h
        self%t0 = t0
        self%t = t0
        self%step_count = 0
        self%u = u0
        self%v = v0
        ! (Re)allocate the state and work arrays once; `step` never allocates.
        self%a = u0
        self%u_old = u0
        self%v_old = v0
        self%f_old = u0
        self%f_new = u0
        self%work = u0
        self%work2 = u0
        call model%external_force(t0, self%f_old)
        self%kinetic = model%kinetic_energy(self%v)
        self%strain = model%strain_energy(self%u)
        self%initial_energy = self%kinetic + self%strain
        self%external_work = 0.0_wp
        self%damping_dissipation = 0.0_wp
        self%coupling_work = 0.0_wp
        call self%initial_residual(model)
    end subroutine start_state

    !> a = F(t) - K u - C v with the current state (F(t) in f_old).
    subroutine initial_residual(self, model)
        !> The integrator.
        class(time_integrator_t), intent(inout) :: self
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        call model%stiffness_times(self%u, self%work)
        self%a = self%f_old - self%work
        if (model%is_damped()) then
            call model%damping_times(self%v, self%work)
            self%a = self%a - self%work
        end if
    end subroutine initial_residual

    !> Energy accounts and time after u, v, a were advanced from (u_old, v_old, f_old)
    !> with loads f_new.
    subroutine finish_step(self, model)
        !> The integrator.
        class(time_integrator_t), intent(inout) :: self
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        ! work = u_{n+1} - u_n
        self%work = self%u - self%u_old
        self%external_work = self%external_work + &
                             0.5_wp*dot_product(self%f_old + self%f_new, self%work)
        if (model%is_damped()) then
            self%v_old = self%v_old + self%v
            call model%damping_times(self%v_old, self%work2)
            self%damping_dissipation = self%damping_dissipation + &
                                       0.5_wp*dot_product(self%work, self%work2)
        end if
        call model%mass_times(self%v, self%work)
        self%kinetic = 0.5_wp*dot_product(self%v, self%work)
        call model%stiffness_times(self%u, self%work)
        self%strain = 0.5_wp*dot_product(self%u, self%work)
        self%f_old = self%f_new
        self%step_count = self%step_count + 1
        self%t = self%t0 + self%step_count*self%h
    end subroutine finish_step

    !> Newmark: check (beta, gamma), factor M + gamma h C + beta h^2 K, compute a0.
    subroutine newmark_init(self, model, h, t0, u0, v0, error)
        !> The integrator (beta and gamma set beforehand).
        class(newmark_t), intent(inout) :: self
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        !> Time step [s].
        real(wp), intent(in) :: h
        !> Initial time [s].
        real(wp), intent(in) :: t0
        !> Initial displacements and velocities (n_free).
        real(wp), intent(in) :: u0(:), v0(:)
        !> Set on invalid parameters or a failed factorisation.
        type(error_t), allocatable, intent(out) :: error
        class(spd_factor_t), allocatable :: mf
        real(wp) :: h_crit
        character(len=320) :: buf
        if (self%gamma < 0.5_wp .or. self%beta < 0.0_wp) then
            call make_error(error, 'Newmark scheme: gamma >= 1/2 and beta >= 0 are required '// &
                            '(gamma < 1/2 amplifies the solution); average acceleration is '// &
                            'beta = 1/4, gamma = 1/2')
            return
        end if
        if (self%beta < 0.5_wp*self%gamma) then
            h_crit = newmark_critical_step(model, self%beta, self%gamma, error)
            if (allocated(error)) return
            if (h > h_crit) then
                write (buf, '(a,es10.3e3,a,es10.3e3,a,g0.4,a,g0.4,a)') 'time step ', h, &
                    ' s exceeds the critical time step ', h_crit, ' s of the Newmark scheme with beta = ', &
                    self%beta, ' < gamma/2 (gamma = ', self%gamma, &
                    '), which is only conditionally stable (h_crit = 1/(omega_max sqrt(gamma/2 - beta))); '// &
                    'reduce [time] step or use beta >= gamma/2'
                call make_error(error, trim(buf))
                return
            end if
        else
            call check_round_off(model, h, error)
            if (allocated(error)) return
        end if
        call self%start_state(model, h, t0, u0, v0, error)
        if (allocated(error)) return
        self%predicted = .false.
        self%fc_old = 0*u0
        call model%factor_combination(1.0_wp, 0.0_wp, mf, error)
        if (allocated(error)) return
        call mf%solve(self%a, error)
        if (allocated(error)) return
        call model%factor_combination(1.0_wp + self%gamma*h*model%rayleigh_a0, &
                                      self%gamma*h*model%rayleigh_a1 + self%beta*h**2, self%s, error)
        if (allocated(error)) error%message = 'Newmark effective matrix M + gamma h C + '// &
                                              'beta h^2 K: '//error%message
    end subroutine newmark_init

    !> Newmark step: predictor, solve for a_{n+1}, corrector, energies.
    subroutine newmark_step(self, model, error)
        !> The integrator.
        class(newmark_t), intent(inout) :: self
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        !> Set on failure of the solve, or when a prediction awaits its correction.
        type(error_t), allocatable, intent(out) :: error
        if (self%predicted) then
            call make_error(error, 'Newmark step: a prediction awaits its correction (call '// &
                            'correct, not step, after predict)')
            return
        end if
        call self%free_solve(model, error)
        if (allocated(error)) return
        call self%finish_step(model)
    end subroutine newmark_step

    !> Predictor, solve for a_{n+1} and corrector without coupling force; time, step count
    !> and energies are not advanced.
    subroutine free_solve(self, model, error)
        class(newmark_t), intent(inout) :: self
        class(dynamic_operator_t), intent(in) :: model
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: h
        h = self%h
        self%u_old = self%u
        self%v_old = self%v
        call model%external_force(self%t0 + (self%step_count + 1)*h, self%f_new)
        ! Predictors (u~, v~) in u and v.
        self%u = self%u + h*self%v + h**2*(0.5_wp - self%beta)*self%a
        self%v = self%v + h*(1.0_wp - self%gamma)*self%a
        ! (M + gamma h C + beta h^2 K) a_{n+1} = F_{n+1} - K u~ - C v~
        call model%stiffness_times(self%u, self%work)
        self%a = self%f_new - self%work
        if (model%is_damped()) then
            call model%damping_times(self%v, self%work)
            self%a = self%a - self%work
        end if
        call self%s%solve(self%a, error)
        if (allocated(error)) return
        self%u = self%u + self%beta*h**2*self%a
        self%v = self%v + self%gamma*h*self%a
    end subroutine free_solve

    !> First half of a coupled step: the state (u, v, a) becomes the free prediction at
    !> t_{n+1} (the end-of-step values without coupling force); t, step count and energies
    !> stay at t_n until `correct`.
    subroutine newmark_predict(self, model, error)
        !> The integrator (initialised).
        class(newmark_t), intent(inout) :: self
        !> The model (the same as at `init`).
        class(dynamic_operator_t), intent(in) :: model
        !> Set when the previous prediction was not corrected, or on failure of the solve.
        type(error_t), allocatable, intent(out) :: error
        if (self%predicted) then
            call make_error(error, 'Newmark predict: the previous prediction was not '// &
                            'corrected (call correct once after each predict)')
            return
        end if
        call self%free_solve(model, error)
        if (allocated(error)) return
        self%predicted = .true.
    end subroutine newmark_predict

    !> Second half of a coupled step: with da = S^-1 f_c, a += da, u += beta h^2 da,
    !> v += gamma h da; then energies (coupling work W_c += 1/2 (f_c,n + f_c,n+1).du) and time.
    subroutine newmark_correct(self, model, f_coupling, error)
        !> The integrator, after `predict`.
        class(newmark_t), intent(inout) :: self
        !> The model (the same as at `init`).
        class(dynamic_operator_t), intent(in) :: model
        !> Coupling force at t_{n+1} on the free DOFs (n_free) [N, N.m], e.g. -C^T lambda.
        real(wp), contiguous, intent(in) :: f_coupling(:)
        !> Set without a prediction, on a wrong size or failure of the solve.
        type(error_t), allocatable, intent(out) :: error
        if (.not. self%predicted) then
            call make_error(error, 'Newmark correct: no prediction to correct (call predict '// &
                            'first)')
            return
        end if
        if (size(f_coupling) /= size(self%u)) then
            call make_error(error, 'Newmark correct: the coupling force must have one value '// &
                            'per free DOF')
            return
        end if
        self%work = f_coupling
        call self%s%solve(self%work, error)
        if (allocated(error)) return
        self%a = self%a + self%work
        self%u = self%u + self%beta*self%h**2*self%work
        self%v = self%v + self%gamma*self%h*self%work
        self%coupling_work = self%coupling_work + &
                             0.5_wp*dot_product(self%fc_old + f_coupling, self%u - self%u_old)
        self%fc_old = f_coupling
        self%predicted = .false.
        call self%finish_step(model)
    end subroutine newmark_correct

    !> Put `predicted` (0 or 1) and the coupling force of the previous step `fc_old`.
    subroutine newmark_save_state(self, sink, error)
        !> The integrator.
        class(newmark_t), intent(in) :: self
        !> Where the state goes.
        class(state_sink_t), intent(inout) :: sink
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call sink%put_integer('predicted', merge(1, 0, self%predicted), error)
        if (allocated(error) .or. .not. allocated(self%fc_old)) return
        call sink%put_reals('fc_old', self%fc_old, error)
    end subroutine newmark_save_state

    !> Take back `predicted` and `fc_old` (see `newmark_save_state`).
    subroutine newmark_load_state(self, source, error)
        !> The integrator (init done).
        class(newmark_t), intent(inout) :: self
        !> Where the state comes from.
        class(state_source_t), intent(in) :: source
        !> Set on a read failure or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        call source%get_integer('predicted', 0, 1, k, error)
        if (allocated(error)) return
        self%predicted = k /= 0
        call source%get_reals('fc_old', self%fc_old, error)
    end subroutine newmark_load_state

    !> Nothing to put.
    subroutine central_difference_save_state(self, sink, error)
        !> The integrator.
        class(central_difference_t), intent(in) :: self
        !> Where the state goes.
        class(state_sink_t), intent(inout) :: sink
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
    end subroutine central_difference_save_state

    !> Nothing to take back.
    subroutine central_difference_load_state(self, source, error)
        !> The integrator (init done).
        class(central_difference_t), intent(inout) :: self
        !> Where the state comes from.
        class(state_source_t), intent(in) :: source
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
    end subroutine central_difference_load_state

    !> x = S^-1 b, S = M + gamma h C + beta h^2 K (factored at `init`). The FE velocity
    !> responds to a force f at t_{n+1} by gamma h S^-1 f, the displacement by beta h^2 S^-1 f.
    subroutine solve_effective_vec(self, b, x, error)
        !> The integrator (initialised).
        class(newmark_t), intent(inout) :: self
        !> Right-hand side (n_free).
        real(wp), intent(in) :: b(:)
        !> Solution (n_free).
        real(wp), contiguous, intent(out) :: x(:)
        !> Set when the integrator is not initialised or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        if (size(x) /= size(b)) then
            call make_internal_error(error, 'Newmark solve_effective', 'b and x differ in size')
            return
        end if
        x = b
        call self%s%solve(x, error)
    end subroutine solve_effective_vec

    !> X = S^-1 B for several right-hand sides (columns).
    subroutine solve_effective_mat(self, b, x, error)
        !> The integrator (initialised).
        class(newmark_t), intent(inout) :: self
        !> Right-hand sides (n_free, k).
        real(wp), intent(in) :: b(:, :)
        !> Solutions (n_free, k).
        real(wp), contiguous, intent(out) :: x(:, :)
        !> Set when the integrator is not initialised or sizes disagree.
        type(error_t), allocatable, intent(out) :: error
        if (any(shape(x) /= shape(b))) then
            call make_internal_error(error, 'Newmark solve_effective', 'b and x differ in shape')
            return
        end if
        x = b
        call self%s%solve(x, error)
    end subroutine solve_effective_mat

    !> Refuse a step whose omega_max h exceeds 1/sqrt(epsilon) (6.7e7): the unconditionally
    !> stable Newmark solve then loses the motion to round-off. The accelerations come from
    !> M + beta h^2 K, where the highest modes' stiffness outweighs the mass by (omega_max h)^2,
    !> and the energy error is about epsilon (omega_max h)^2 / 4 of the energy (measured on the
    !> steel cantilever of input/cantilever.dat: 1e-5 at omega_max h = 4e5, 0.06 at 4e7, and
    !> with E = 2e26 Pa, omega_max h = 1.3e9, a strain energy 3000 times the static one and the
    !> tip on the wrong side, exit 0). omega_max from the model (for the continuum its element
    !> bound, at most about 2 times larger). When the step that would pass is below 1e-6 h, or
    !> omega_max is beyond double precision, no time step is a remedy: the message blames the
    !> model (it starts with model_out_of_range, which the drivers attach to the stiffness and
    !> density lines). An eigensolver failure is not refused (the run's guards remain).
    subroutine check_round_off(model, h, error)
        class(dynamic_operator_t), intent(in) :: model
        real(wp), intent(in) :: h
        type(error_t), allocatable, intent(out) :: error
        real(wp), parameter :: limit = 1.0_wp/sqrt(epsilon(1.0_wp))
        type(error_t), allocatable :: failed
        real(wp) :: h_crit, h_pass
        character(len=400) :: buf
        h_crit = critical_time_step(model, failed)
        if (allocated(failed) .or. h_crit >= huge(1.0_wp)) return
        h_pass = 0.5_wp*limit*h_crit
        if (h <= h_pass) return
        if (.not. 2.0_wp/h_crit <= huge(1.0_wp)) then
            buf = model_out_of_range//' (omega_max beyond double precision): the Newmark solve would lose '// &
                  'the motion to round-off; a stiffness or density is far out of range'
        else if (h_pass < 1.0e-6_wp*h) then
            write (buf, '(a,es10.3e3,a,es10.3e3,a)') model_out_of_range//' (omega_max = ', &
                2.0_wp/h_crit, ' rad/s: omega_max h <= 1/sqrt(epsilon) = 6.7e7 would need a step of ', h_pass, &
                ' s): the Newmark solve would lose the motion to round-off; a stiffness or density is far '// &
                'out of range'
        else
            write (buf, '(a,es10.3e3,a,es10.3e3,a,es10.3e3,a,es10.3e3,a,es10.3e3,a)') 'time step ', h, &
                ' s with the highest natural frequency omega_max = ', 2.0_wp/h_crit, &
                ' rad/s of the model gives omega_max h = ', 2.0_wp*h/h_crit, ', above 1/sqrt(epsilon) = ', &
                limit, ': the Newmark solve would lose the motion to round-off (energy errors of about '// &
                'epsilon (omega_max h)^2 / 4 of the energy); lower [time] step below ', h_pass, &
                ' s, or check the stiffness and density'
        end if
        call make_error(error, trim(buf))
    end subroutine check_round_off

    !> Critical time step 2/omega_max of the undamped central-difference scheme [s], with
    !> omega_max^2 the largest eigenvalue of K phi = omega^2 M phi.
    real(wp) function critical_time_step(model, error) result(h_crit)
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        !> Set on eigensolver failure (h_crit is then 0).
        type(error_t), allocatable, intent(out), optional :: error
        type(error_t), allocatable :: err
        real(wp) :: lambda_max
        h_crit = 0.0_wp
        call model%largest_eigenvalue(lambda_max, err)
        if (allocated(err)) then
            if (present(error)) call move_alloc(err, error)
            return
        end if
        h_crit = huge(1.0_wp)
        if (lambda_max > 0) h_crit = 2.0_wp/sqrt(lambda_max)
    end function critical_time_step

    !> Critical time step of the Newmark scheme with beta < gamma/2 [s]:
    !> 1/(omega_max sqrt(gamma/2 - beta)), the undamped limit (2/omega_max for central
    !> differences, beta = 0 and gamma = 1/2); omega_max^2 is the largest eigenvalue of
    !> K phi = omega^2 M phi.
    real(wp) function newmark_critical_step(model, beta, gamma, error) result(h_crit)
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        !> Newmark beta (< gamma/2).
        real(wp), intent(in) :: beta
        !> Newmark gamma (>= 1/2).
        real(wp), intent(in) :: gamma
        !> Set on eigensolver failure (h_crit is then 0).
        type(error_t), allocatable, intent(out) :: error
        h_crit = critical_time_step(model, error)
        if (allocated(error)) return
        if (h_crit < huge(1.0_wp)) h_crit = 0.5_wp*h_crit/sqrt(0.5_wp*gamma - beta)
    end function newmark_critical_step

    !> Central difference: lumped mass required; refuses h above the critical step.
    subroutine central_difference_init(self, model, h, t0, u0, v0, error)
        !> The integrator.
        class(central_difference_t), intent(inout) :: self
        !> The model (lumped mass).
        class(dynamic_operator_t), intent(in) :: model
        !> Time step [s].
        real(wp), intent(in) :: h
        !> Initial time [s].
        real(wp), intent(in) :: t0
        !> Initial displacements and velocities (n_free).
        real(wp), intent(in) :: u0(:), v0(:)
        !> Set when the mass is not lumped, h is too large, or on eigensolver failure.
        type(error_t), allocatable, intent(out) :: error
        if (.not. model%has_diagonal_mass()) then
            call make_error(error, 'the central-difference scheme needs a lumped mass matrix: '// &
                            'ask for lumped mass or use the Newmark scheme')
            return
        end if
        call check_critical_step(self, model, h, error)
        if (allocated(error)) return
        call self%start_state(model, h, t0, u0, v0, error)
        if (allocated(error)) return
        self%inv_mass = self%a
        call model%mass_diagonal(self%inv_mass)
        self%a = self%a/self%inv_mass
        self%inv_mass = 1.0_wp/(self%inv_mass*(1.0_wp + 0.5_wp*h*model%rayleigh_a0))
    end subroutine central_difference_init

    !> Store the critical step (reduced by stiffness damping) and refuse h above it.
    subroutine check_critical_step(self, model, h, error)
        class(central_difference_t), intent(inout) :: self
        class(dynamic_operator_t), intent(in) :: model
        real(wp), intent(in) :: h
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: xi
        character(len=240) :: buf
        character(len=:), allocatable :: what
        self%h_crit = critical_time_step(model, error)
        if (allocated(error)) return
        what = '(2/omega_max)'
        if (model%rayleigh_a1 > 0) then
            xi = model%rayleigh_a1/self%h_crit
            self%h_crit = self%h_crit*(sqrt(1.0_wp + xi**2) - xi)
            what = '(2/omega_max, reduced by the stiffness-proportional damping)'
        end if
        if (h > self%h_crit) then
            write (buf, '(a,es10.3e3,a,es10.3e3,a)') 'time step ', h, &
                ' s exceeds the critical time step ', self%h_crit, &
                ' s of the central-difference scheme '//what//'; reduce [time] step'
            call make_error(error, trim(buf))
        end if
    end subroutine check_critical_step

    !> Central-difference step: u_{n+1} = u + h v + h^2/2 a, then a_{n+1} from the lumped
    !> mass, v_{n+1} = v + h/2 (a_n + a_{n+1}).
    subroutine central_difference_step(self, model, error)
        !> The integrator.
        class(central_difference_t), intent(inout) :: self
        !> The model.
        class(dynamic_operator_t), intent(in) :: model
        !> Never set (kept for the common interface).
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: h
        h = self%h
        self%u_old = self%u
        self%v_old = self%v
        call model%external_force(self%t0 + (self%step_count + 1)*h, self%f_new)
        self%u = self%u + h*self%v + 0.5_wp*h**2*self%a
        ! Half-step velocity v_{n+1/2} = v + h/2 a.
        self%v = self%v + 0.5_wp*h*self%a
        call model%stiffness_times(self%u, self%work)
        self%a = self%f_new - self%work
        if (model%is_damped()) then
            ! C v_{n+1/2}; the mass part a0 M is also taken at n+1 through inv_mass.
            call model%damping_times(self%v, self%work)
            self%a = self%a - self%work
        end if
        self%a = self%a*self%inv_mass
        self%v = self%v + 0.5_wp*h*self%a
        call self%finish_step(model)
    end subroutine central_difference_step
end module fem_newmark
