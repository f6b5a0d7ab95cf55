!> The coupled time step of the Arlequin DEM-FEM coupling (doc/theory.md section 6), written once
!> for every FE model: a weighted FE model (any `dynamic_operator_t`: the planar beam, the 2D
!> continuum) integrated by Newmark, weighted disks (Moreau-Jean, contacts), glued in the
!> overlap by Lagrange multipliers through a coupling operator C (any `coupling_map_t`),
!> explicitly in the coupling, at velocity level.
!>
!> The builders (coupling_arlequin for a beam, coupling_arlequin2d for a 2D continuum) set the
!> weighted FE model, C, the disks' weights alpha and the coupled disks, and the multiplier
!> space, then call `complete_coupled_system`, which weights the disks, initialises both
!> integrators and assembles the multiplier matrix. Nothing below depends on the kind of FE
!> model: adding one adds a builder, not a branch.
!>
!> Multiplier space (`space`, coupling_multiplier_space): one multiplier per coupled DOF
!> (every coupled disk centre follows C u), or a mediator space on FE nodes: the constraint is
!> then Pi (q - C u) = 0, the disks receive Pi^T lambda and the FE -(Pi C)^T lambda, and
!> A_m = Pi A Pi^T; the rows (coupling_bilateral) use B = Pi^T A_m^-1 Pi in place of A^-1:
!> `lambda` is always the force mu on the coupled DOFs (mu = Pi^T lambda_m), `multiplier` the
!> multipliers themselves. The statistics' position/velocity/rotation residuals are those of
!> the imposed constraint (Pi e with a mediator space), `particle_residual` the per-disk
!> residual ||e||.
!>
!> Small displacements: C, the weights and h are constant (C is built on the reference
!> configuration), so A = h gamma (W + C S^-1 C^T) is assembled, factored and inverted once.
!> FE dofs prescribed in time (u_p(t), a 2D continuum's `displacement` with a function) enter
!> C u as C_p u_p(t) and C v as C_p v_p(t) (`coupling_map_t%add_prescribed`; none for a beam):
!> they do not respond to the multipliers, so A is unchanged. The multipliers' force on them,
!> -C_p^T lambda, is taken by the supports: its work is counted with the FE side's coupling
!> work (`prescribed_coupling_work`), so that the audit still closes.
!> The DEM is per unit thickness: `thickness` t turns its masses and impulses into absolute
!> ones (W = ((1 - alpha) m t)^-1); energies are reported in J (DEM energies times t).
!>
!> Time discretisation of the coupling force. The FE (Newmark) sees -C^T lambda_{n+1} as a
!> force at t_{n+1}: it enters v_{n+1} with weight gamma h and v_{n+2} with (1 - gamma) h
!> (through a_{n+1}). The particles receive the same impulse in the same steps:
!> h [(1 - gamma) lambda_n + gamma lambda_{n+1}] in step n+1. Momentum is thus exchanged
!> exactly, and with gamma = theta = 1/2, beta = 1/4 (both schemes trapezoidal in position)
!> the coupling works of the two sides cancel up to the drift term (below): the energy
!> balance of the coupled system closes to round-off. (Giving the whole impulse h lambda_{n+1}
!> to the particles instead leaves a net coupling work (lambda_{n+1} - lambda_n)/2 . C du per
!> step, first order in h.)
!>
!> Step (`arlequin_step`):
!> 1. FE Newmark prediction (no coupling force): v_c,free; DEM free velocities (loads,
!>    gravity) plus the share (1 - gamma) h lambda_n of the previous multipliers;
!> 2. free residual g = G v_free - C v_c,free + e_n/h, e_n = q_n - C (u_n - u_0) the position
!>    residual at the start of the step (drift term: the constraint imposed at t_{n+1} is
!>    G v - C v_c = -e_n/h, which pulls q - C u back instead of letting it drift);
!> 3. lambda = -A^-1 g applied to the disks (an estimate used to activate the contacts);
!> 4. contacts (detection, laws) and the joint solve: NLGS over the contacts with lambda
!>    eliminated exactly at every contact update (coupling_bilateral, where the choice is
!>    justified); contacts touching coupled disks get condensed Delassus blocks;
!> 5. DEM update; FE correction with -C^T lambda; residuals and statistics.
!> The velocity constraint holds to round-off after every step whatever the NLGS tolerance
!> (lambda is re-solved after each contact update); with theta = 1/2 and average
!> acceleration, e_{n+1} = (e_n - e_{n-1})/2: round-off errors of q - C u decay (|z| = 0.71).
!> The particle displacements q of the coupled DOFs are accumulated with the DEM's own update
!> rule, at the scale of the displacements (the coordinates carry a rounding of ulp(x) per
!> step that would otherwise enter e).
!>
!> Energy audit (`coupled_energies`): FE kinetic + strain (weighted), DEM kinetic + potential
!> (weighted, times t), external works of both, Rayleigh, contact and numerical dissipation,
!> coupling works of both sides. The FE terms are those of `accounts` (coupling_fe_accounts):
!> the whole FE body's when its driver sets them (a 2D continuum: its audit over all dofs,
!> with the reactions' work on the prescribed dofs), else the integrator's (free dofs; a
!> beam, whose supports are fixed).
!> `balance` = total energy + dissipation - works - initial, which
!> equals the net coupling work (zero up to the drift term and round-off with the schemes
!> above; a first-step impulse that removes inconsistent initial velocities dissipates energy
!> like a plastic impact).
module coupling_coupled_step
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, gib
    use fem_dynamic_operator, only: dynamic_operator_t
    use fem_newmark, only: newmark_t
    use dem_particles, only: particles_inverse_mass, dof_x, dof_y, dof_rot
    use dem_local_problem, only: local_problem_t, local_problem_build
    use dem_moreau_jean, only: dem_system_t, mj_init, mj_free_velocities, mj_detect, mj_solve, &
                               mj_end_step, energies_balance
    use coupling_weights, only: overlap_weight_t
    use coupling_map, only: coupling_map_t
    use coupling_lambda, only: coupling_system_t, fe_coupling_force
    use coupling_bilateral, only: coupling_rows_t
    use coupling_multiplier_space, only: multiplier_space_t, disk_space_t
    use coupling_fe_accounts, only: fe_accounts_t, fe_energies_t, integrator_accounts_t
    implicit none
    private
    public :: coupled_system_t, coupled_stats_t, coupled_energies_t
    public :: notice_iface
    public :: complete_coupled_system, disk_space, arlequin_step, coupled_energies, coordinate_residual
    public :: multipliers_particles, multipliers_nodes
    public :: velocity_mismatch_t, velocity_mismatch

    !> One multiplier per coupled DOF (the reference work).
    integer, parameter :: multipliers_particles = 1
    !> Multipliers on the FE nodes carrying coupled points (mediator space).
    integer, parameter :: multipliers_nodes = 2

    !> Statistics of the last coupled step (norms over the translation rows unless said).
    type :: coupled_stats_t
        !> NLGS sweeps of the joint contact/multiplier solve.
        integer :: sweeps = 0
        !> Multiplier corrections made during the solve (restores and contact updates on
        !> coupled disks).
        integer :: corrections = 0
        !> Contacts in the list and active contacts.
        integer :: n_contacts = 0, n_active = 0
        !> The NLGS reached its tolerance.
        logical :: converged = .true.
        !> NLGS convergence norm after the last sweep.
        real(wp) :: nlgs_error = 0.0_wp
        !> ||g||: free velocity residual before the multipliers [m/s].
        real(wp) :: free_residual = 0.0_wp
        !> ||G v - C v_c + e_n/h|| after the step [m/s] (round-off); ||Pi (...)|| with the
        !> mediator space.
        real(wp) :: velocity_residual = 0.0_wp
        !> ||q - C (u - u_0)|| after the step [m] (round-off); ||Pi (...)|| with the mediator
        !> space.
        real(wp) :: position_residual = 0.0_wp
        !> ||q - C (u - u_0)|| per disk [m]: the position residual with multipliers on the
        !> particles, free in the kernel of Pi with the mediator space.
        real(wp) :: particle_residual = 0.0_wp
        !> Same for the rotation rows [rad] (0 without rotation rows).
        real(wp) :: rotation_residual = 0.0_wp
        !> ||lambda|| over all multipliers (mediator ones with multipliers_nodes) [N, N.m].
        real(wp) :: lambda_norm = 0.0_wp
    end type coupled_stats_t

    !> How far the velocities of the coupled disks are from the FE field at their points, in the
    !> current state (before the first step: the initial velocities of the deck).
    type :: velocity_mismatch_t
        !> ||G v - C v_c|| over the translation rows [m/s] and the rotation rows [rad/s]
        !> (||Pi (...)|| with the mediator space: what the multipliers impose).
        real(wp) :: translation = 0.0_wp, rotation = 0.0_wp
        !> The larger of ||G v|| and ||C v_c|| over the same rows (their scale).
        real(wp) :: translation_scale = 0.0_wp, rotation_scale = 0.0_wp
        !> The disk of the row with the largest |G v - C v_c| (0: no row).
        integer :: disk = 0
        !> Largest radius of the coupled disks [m]: turns the rotation rows into velocities.
        real(wp) :: radius = 0.0_wp
    end type velocity_mismatch_t

    !> Energy audit of the coupled system [J] (DEM terms already multiplied by the thickness).
    type :: coupled_energies_t
        !> FE kinetic and strain energy (weighted).
        real(wp) :: fe_kinetic = 0.0_wp, fe_strain = 0.0_wp
        !> FE external work (its loads in full, its self-weight weighted) and Rayleigh dissipation.
        real(wp) :: fe_external_work = 0.0_wp, fe_damping = 0.0_wp
        !> Work of the FE supports' reactions on the prescribed dofs (zero where they are fixed).
        real(wp) :: fe_reaction_work = 0.0_wp
        !> Work of the coupling forces -C^T lambda on the FE.
        real(wp) :: fe_coupling_work = 0.0_wp
        !> DEM kinetic and gravity potential energy (weighted).
        real(wp) :: dem_kinetic = 0.0_wp, dem_potential = 0.0_wp
        !> DEM work of loads, and of imposed velocities and moving walls.
        real(wp) :: dem_external_work = 0.0_wp, dem_drive_work = 0.0_wp
        !> DEM contact and numerical (theta > 1/2) dissipation.
        real(wp) :: dem_contact_dissipation = 0.0_wp, dem_numerical_dissipation = 0.0_wp
        !> Work of the multipliers on the disks.
        real(wp) :: dem_coupling_work = 0.0_wp
        !> Total energy at the start.
        real(wp) :: initial = 0.0_wp
        !> Net coupling work fe_coupling_work + dem_coupling_work (ideally zero).
        real(wp) :: coupling_work = 0.0_wp
        !> Balance residual: energies + dissipations - external works - initial.
        real(wp) :: balance = 0.0_wp
    end type coupled_energies_t

    !> A coupled simulation: both domains, the coupling and its state.
    type :: coupled_system_t
        !> Weighted FE model (the beam's band matrices, the continuum's sparse ones).
        class(dynamic_operator_t), allocatable :: model
        !> FE time integrator (Newmark, split predict/correct).
        type(newmark_t) :: fe
        !> Discrete domain, masses weighted by (1 - alpha) (loads in full).
        type(dem_system_t) :: dem
        !> Shape and floor of the weight alpha (for a beam also the overlap interval).
        type(overlap_weight_t) :: weight
        !> Coupling operator C at the coupled disks.
        class(coupling_map_t), allocatable :: op
        !> Factored A.
        type(coupling_system_t) :: multipliers
        !> Coupling rows as NLGS bilateral constraints (holds A^-1 or B).
        type(coupling_rows_t) :: rows
        !> The multiplier space (per coupled DOF, or a mediator space on FE nodes).
        class(multiplier_space_t), allocatable :: space
        !> The space imposes only a projection Pi e (multipliers on the nodes); for messages.
        logical :: on_nodes = .false.
        !> FE node (model numbering) of each mediator node, increasing (empty without a
        !> mediator space).
        integer, allocatable :: mediator_nodes(:)
        !> Multipliers after a step: lambda (per DOF) or lambda_m (mediator) [N, N.m].
        real(wp), allocatable :: multiplier(:)
        !> Out-of-plane thickness of the particle domain [m].
        real(wp) :: thickness = 0.0_wp
        !> Contacts on coupled disks use the condensed Delassus blocks.
        logical :: condensed = .true.
        !> Disk of each coupled point (n_points).
        integer, allocatable :: coupled(:)
        !> Weight alpha of every disk (n_disks): its mass is (1 - alpha) times the physical one.
        real(wp), allocatable :: alpha(:)
        !> Forces of the multipliers on the coupled DOFs (lambda, or Pi^T lambda_m) at t_{n+1}
        !> (after a step) and t_n [N, N.m] (n_rows).
        real(wp), allocatable :: lambda(:), lambda_old(:)
        !> Free residual g of the last step [m/s, rad/s] (n_rows).
        real(wp), allocatable :: g(:)
        !> Displacement of the coupled DOFs since the start, accumulated [m, rad] (n_rows).
        real(wp), allocatable :: q(:)
        !> C u at the start [m, rad] (n_rows).
        real(wp), allocatable :: cu0(:)
        !> Position residual e = q - C (u - u_0) at the current time [m, rad] (n_rows).
        real(wp), allocatable :: drift(:)
        !> Coordinates of the coupled DOFs at the start (x, y or rotation) (n_rows).
        real(wp), allocatable :: start(:)
        !> Statistics of the last step (after the build: the initial residuals).
        type(coupled_stats_t) :: stats
        !> Steps done.
        integer :: step = 0
        !> Work arrays (n_rows): C v, G v; (n_free): FE coupling force.
        real(wp), allocatable :: cv(:), gv(:), fc(:)
        !> C_p u_p(t) at the current time: the coupled rows' share of FE dofs prescribed in time
        !> [m, rad] (n_rows; zero without such dofs).
        real(wp), allocatable :: cp(:)
        !> Work of the multipliers through the prescribed FE dofs since the start,
        !> sum of (lambda_n + lambda_n+1)/2 . (C_p u_p(t_n+1) - C_p u_p(t_n)) [J]: the FE side's
        !> coupling work on those dofs is its negative.
        real(wp) :: prescribed_coupling_work = 0.0_wp
        !> The FE side's energy accounts: the integrator's (`complete_coupled_system`), or those
        !> its driver sets after every step (a 2D continuum's whole body, coupling_fe_accounts).
        class(fe_accounts_t), allocatable :: accounts
    end type coupled_system_t

    abstract interface
        !> Receives one line telling what a long set-up is doing.
        subroutine notice_iface(line)
            !> The line.
            character(len=*), intent(in) :: line
        end subroutine notice_iface
    end interface

    !> Rows from which the set-up of the dense multiplier matrices is announced: it grows as
    !> the rows cubed, about 3 s of CPU for 4 320 rows and 11 s for 7 680 on the machine of
    !> doc/performance.md (the seconds before the first step of a run or the line of --check).
    integer, parameter :: notice_rows = 4000

contains

    !> Finish a coupled system whose builder set the weighted FE model (`model`), C (`op`),
    !> the disks (`dem`: unweighted, before mj_init; `dem%scheme%h` is the common step), every
    !> disk's weight (`alpha`), the coupled disks (`coupled`), `thickness`, `condensed` and
    !> `weight`: weight the disks by (1 - alpha), initialise both integrators, assemble and
    !> factor A = h gamma (W + C S^-1 C^T), take the multiplier space and form its B, and set
    !> the initial residuals. The initial configuration is taken as consistent: the constraint
    !> is q - q_0 = C (u - u_0).
    subroutine complete_coupled_system(sys, space, u0, v0, error, beta, gamma, memory_limit, notice)
        !> The coupled system (see above).
        type(coupled_system_t), intent(inout) :: sys
        !> The multiplier space over the rows of C (moved into `sys`).
        class(multiplier_space_t), allocatable, intent(inout) :: space
        !> FE initial displacements and velocities on the free DOFs (n_free).
        real(wp), intent(in) :: u0(:), v0(:)
        !> Set when an integrator cannot start or the multiplier matrix is singular.
        type(error_t), allocatable, intent(out) :: error
        !> Newmark beta and gamma (default 1/4, 1/2: average acceleration, which makes the
        !> coupled energy balance exact with theta = 1/2).
        real(wp), intent(in), optional :: beta, gamma
        !> Bytes the dense multiplier matrices may take (multiplier_bytes; < 0: no limit):
        !> beyond it, an error instead of an allocation that fails or exhausts the machine.
        integer(i8), intent(in), optional :: memory_limit
        !> Where to announce a set-up of notice_rows rows or more (default: silent).
        procedure(notice_iface), optional :: notice
        real(wp), allocatable :: im(:, :), iw(:)
        real(wp) :: h
        integer :: n, r
        n = sys%dem%particles%n
        ! The integrator's energy accounts until the FE side's driver sets others.
        if (allocated(sys%accounts)) deallocate (sys%accounts)
        allocate (integrator_accounts_t :: sys%accounts)
        call scale_disks(sys)
        call mj_init(sys%dem, error)
        if (allocated(error)) return
        ! FE integrator on the common step.
        h = sys%dem%scheme%h
        if (present(beta)) sys%fe%beta = beta
        if (present(gamma)) sys%fe%gamma = gamma
        call sys%fe%init(sys%model, h, sys%dem%time, u0, v0, error)
        if (allocated(error)) return
        if (present(memory_limit)) then
            if (memory_limit >= 0 .and. multiplier_bytes(sys%op%n_rows) > memory_limit) then
                call make_error(error, 'coupling: '//to_str(sys%op%n_rows)//' rows ('// &
                                to_str(sys%op%n_points)//' coupled disks, '//to_str(sys%op%rows_per_point)// &
                                ' rows each): the dense multiplier matrices ('//to_str(sys%op%n_rows)//' x '// &
                                to_str(sys%op%n_rows)//') need about '//gib(multiplier_bytes(sys%op%n_rows))// &
                                ' of memory and '//gib(memory_limit)//' are available: couple fewer disks (a '// &
                                'smaller overlap), or run on a machine with more memory')
                return
            end if
        end if
        if (present(notice) .and. sys%op%n_rows >= notice_rows) then
            call notice('coupling: '//to_str(sys%op%n_rows)//' rows ('//to_str(sys%op%n_points)// &
                        ' coupled disks): setting up the dense multiplier matrices ('// &
                        gib(multiplier_bytes(sys%op%n_rows))//'); the time grows as the rows cubed')
        end if
        ! Rows: owner disk and DOF, weighted inverse masses per unit thickness.
        call init_rows(sys)
        allocate (im(3, n))
        call particles_inverse_mass(sys%dem%particles, im)
        allocate (iw(sys%op%n_rows))
        do r = 1, sys%op%n_rows
            iw(r) = im(sys%rows%dof(r), sys%rows%owner(r))/sys%thickness
        end do
        call sys%multipliers%assemble(sys%op, sys%fe, error, inverse_mass=sys%fe%gamma*iw)
        if (allocated(error)) return
        call move_alloc(space, sys%space)
        call sys%space%inverse(sys%multipliers%a, sys%rows%ainv, error)
        if (allocated(error)) return
        sys%on_nodes = sys%space%projected()
        if (.not. allocated(sys%mediator_nodes)) allocate (sys%mediator_nodes(0))
        sys%rows%response = h*sys%fe%gamma*iw
        sys%rows%scale = h*sys%fe%gamma/sys%thickness
        call init_state(sys)
    end subroutine complete_coupled_system

    !> The space of one multiplier per row of C (x, y and optionally the rotation per point).
    subroutine disk_space(op, space)
        !> The coupling operator.
        class(coupling_map_t), intent(in) :: op
        !> The space.
        class(multiplier_space_t), allocatable, intent(out) :: space
        integer :: p, k
        allocate (space, source=disk_space_t([((k, k=1, op%rows_per_point), p=1, op%n_points)]))
    end subroutine disk_space

    !> Masses and inertias of the disks times (1 - alpha) (their gravity follows through the
    !> mass). Their loads (`force`, `moment`) are applied in full: a load is given to the disks
    !> only, the FE side carries no share of it, so weighting it would drop a share alpha.
    subroutine scale_disks(sys)
        type(coupled_system_t), intent(inout) :: sys
        integer :: i
        associate (p => sys%dem%particles)
            do i = 1, p%n
                p%mass(i) = (1 - sys%alpha(i))*p%mass(i)
                p%inertia(i) = (1 - sys%alpha(i))*p%inertia(i)
            end do
        end associate
    end subroutine scale_disks

    !> Owner disk and DOF of every row, point of every disk.
    subroutine init_rows(sys)
        type(coupled_system_t), intent(inout) :: sys
        integer :: p, k, r
        associate (rows => sys%rows, op => sys%op)
            rows%n_rows = op%n_rows
            rows%rows_per_point = op%rows_per_point
            allocate (rows%point_of(sys%dem%particles%n), source=0)
            allocate (rows%owner(op%n_rows), rows%dof(op%n_rows))
            do p = 1, op%n_points
                rows%point_of(sys%coupled(p)) = p
                do k = 1, op%rows_per_point
                    r = op%row_of(p, k)
                    rows%owner(r) = sys%coupled(p)
                    rows%dof(r) = k
                end do
            end do
            allocate (rows%lambda(op%n_rows), rows%target(op%n_rows), rows%delta(op%n_rows), &
                      source=0.0_wp)
        end associate
    end subroutine init_rows

    !> Multipliers, references of the constraint, initial residuals.
    subroutine init_state(sys)
        type(coupled_system_t), intent(inout) :: sys
        integer :: nr, r
        nr = sys%op%n_rows
        allocate (sys%lambda(nr), sys%lambda_old(nr), sys%g(nr), sys%q(nr), sys%drift(nr), &
                  sys%cv(nr), sys%gv(nr), sys%cu0(nr), sys%start(nr), source=0.0_wp)
        allocate (sys%fc(sys%op%n_free), source=0.0_wp)
        allocate (sys%multiplier(sys%space%n_mult), source=0.0_wp)
        allocate (sys%cp(nr), source=0.0_wp)
        call sys%op%add_prescribed(sys%fe%t, 0, sys%cp)
        sys%prescribed_coupling_work = 0.0_wp
        call sys%op%apply(sys%fe%u, sys%cu0)
        sys%cu0 = sys%cu0 + sys%cp
        associate (p => sys%dem%particles)
            do r = 1, nr
                select case (sys%rows%dof(r))
                case (dof_x)
                    sys%start(r) = p%x(sys%rows%owner(r))
                case (dof_y)
                    sys%start(r) = p%y(sys%rows%owner(r))
                case default
                    sys%start(r) = p%rot(sys%rows%owner(r))
                end select
            end do
        end associate
        call disk_velocities(sys, sys%gv)
        call sys%op%apply(sys%fe%v, sys%cv)
        call sys%op%add_prescribed(sys%fe%t, 1, sys%cv)
        sys%g = sys%gv - sys%cv
        sys%stats = coupled_stats_t()
        sys%stats%free_residual = constraint_norm(sys, sys%g, .false.)
        sys%stats%velocity_residual = sys%stats%free_residual
        sys%step = 0
    end subroutine init_state

    !> The velocity mismatch of the coupled disks with the FE field in the current state. Before
    !> the first step it is that of the initial velocities: the first step's multipliers remove
    !> it with an impulse that dissipates its energy like a plastic impact (the balance of
    !> coupled_energies shows it).
    function velocity_mismatch(sys) result(m)
        !> The coupled system (built).
        type(coupled_system_t), intent(in) :: sys
        type(velocity_mismatch_t) :: m
        real(wp), allocatable :: gv(:), cv(:)
        integer :: r
        allocate (gv(sys%op%n_rows), cv(sys%op%n_rows))
        call disk_velocities(sys, gv)
        call sys%op%apply(sys%fe%v, cv)
        call sys%op%add_prescribed(sys%fe%t, 1, cv)
        m%translation = constraint_norm(sys, gv - cv, .false.)
        m%rotation = constraint_norm(sys, gv - cv, .true.)
        m%translation_scale = max(constraint_norm(sys, gv, .false.), constraint_norm(sys, cv, .false.))
        m%rotation_scale = max(constraint_norm(sys, gv, .true.), constraint_norm(sys, cv, .true.))
        if (sys%op%n_rows == 0) return
        r = maxloc(abs(gv - cv), 1)
        m%disk = sys%rows%owner(r)
        m%radius = maxval(sys%dem%particles%radius(sys%rows%owner))
    end function velocity_mismatch

    !> Velocities of the coupled DOFs from the disks' state (n_rows).
    pure subroutine disk_velocities(sys, gv)
        type(coupled_system_t), intent(in) :: sys
        real(wp), intent(out) :: gv(:)
        integer :: r, i
        associate (p => sys%dem%particles)
            do r = 1, sys%op%n_rows
                i = sys%rows%owner(r)
                select case (sys%rows%dof(r))
                case (dof_x)
                    gv(r) = p%vx(i)
                case (dof_y)
                    gv(r) = p%vy(i)
                case default
                    gv(r) = p%w(i)
                end select
            end do
        end associate
    end subroutine disk_velocities

    !> Euclidean norm of v over the translation rows, or over the rotation rows.
    pure real(wp) function row_norm(sys, v, rotation) result(nrm)
        type(coupled_system_t), intent(in) :: sys
        real(wp), intent(in) :: v(:)
        logical, intent(in) :: rotation
        nrm = norm2(merge(v, 0.0_wp, (sys%rows%dof == dof_rot) .eqv. rotation))
    end function row_norm

    !> Norm of the imposed part of a row vector v (Pi v over the translation or rotation
    !> multipliers; v itself per coupled DOF).
    pure real(wp) function constraint_norm(sys, v, rotation) result(nrm)
        type(coupled_system_t), intent(in) :: sys
        real(wp), intent(in) :: v(:)
        logical, intent(in) :: rotation
        nrm = sys%space%constraint_norm(v, rotation)
    end function constraint_norm

    !> Bytes of the dense multiplier matrices of a coupled system of n_rows rows at their
    !> peak, while the system is built: A (factored), A^-1 or B, and a work matrix of the
    !> same size (each n_rows x n_rows reals).
    pure integer(i8) function multiplier_bytes(n_rows) result(bytes)
        !> Rows of the coupling (multipliers on the coupled DOFs).
        integer, intent(in) :: n_rows
        real(wp) :: total
        total = 3.0_wp*real(storage_size(1.0_wp)/8, wp)*real(n_rows, wp)**2
        if (total < 2.0_wp**62) then
            bytes = int(total, i8)
        else
            bytes = huge(0_i8)
        end if
    end function multiplier_bytes

    !> Advance the coupled system by one time step (see the module description).
    subroutine arlequin_step(sys, error, lp)
        !> The coupled system (built).
        type(coupled_system_t), intent(inout) :: sys
        !> Set on failure of the FE solves.
        type(error_t), allocatable, intent(out) :: error
        !> If present: the local contact problem the step solved, with the coupling rows
        !> condensed (dem_local_problem; for an FCLIB export).
        type(local_problem_t), intent(out), optional :: lp
        real(wp), allocatable :: vfree(:, :)
        real(wp) :: h, gam, th, imp
        integer :: r, i, d
        h = sys%fe%h
        gam = sys%fe%gamma
        th = sys%dem%scheme%theta
        call sys%fe%predict(sys%model, error)
        if (allocated(error)) return
        call mj_free_velocities(sys%dem)
        ! The share (1 - gamma) h lambda_n of the previous multipliers acts in this step (on
        ! the FE through a_n in the prediction), per unit thickness on the disks.
        do r = 1, sys%op%n_rows
            i = sys%rows%owner(r)
            d = sys%rows%dof(r)
            imp = h*(1 - gam)*sys%lambda_old(r)/sys%thickness
            sys%dem%vel(d, i) = sys%dem%vel(d, i) + sys%dem%im(d, i)*imp
            sys%dem%coupling_impulse(d, i) = sys%dem%coupling_impulse(d, i) + imp
        end do
        ! Free residual with the drift term, first multipliers (contacts are activated on the
        ! velocities they give), contacts and the joint solve.
        call sys%op%apply(sys%fe%v, sys%cv)
        ! (The FE time is still t_n after the prediction.)
        call sys%op%add_prescribed(sys%fe%t + h, 1, sys%cv)
        call sys%rows%gather(sys%dem%vel, sys%gv)
        sys%g = sys%gv - sys%cv + sys%drift/h
        call sys%rows%begin(sys%dem%vel, sys%g)
        call sys%rows%restore(sys%dem%vel)
        call mj_detect(sys%dem)
        if (sys%condensed) call sys%rows%condense(sys%dem%contacts, sys%dem%im)
        ! (the velocities at zero contact impulses with the rows held)
        if (present(lp)) allocate (vfree, source=sys%dem%vel)
        call mj_solve(sys%dem, sys%rows)
        if (present(lp)) call local_problem_build(sys%dem%contacts, sys%dem%im, vfree, lp, sys%rows, sys%dem%vel)
        sys%lambda = sys%rows%lambda
        do r = 1, sys%op%n_rows
            i = sys%rows%owner(r)
            d = sys%rows%dof(r)
            sys%dem%coupling_impulse(d, i) = sys%dem%coupling_impulse(d, i) + &
                                             h*gam*sys%lambda(r)/sys%thickness
            ! Displacement of the coupled DOF, by the DEM's own update rule.
            sys%q(r) = sys%q(r) + h*((1 - th)*sys%dem%vel0(d, i) + th*sys%dem%vel(d, i))
        end do
        call mj_end_step(sys%dem)
        call fe_coupling_force(sys%op, sys%lambda, sys%fc)
        call sys%fe%correct(sys%model, sys%fc, error)
        if (allocated(error)) return
        call finish_step(sys)
    end subroutine arlequin_step

    !> Residuals and statistics after a step; lambda_old = lambda.
    subroutine finish_step(sys)
        type(coupled_system_t), intent(inout) :: sys
        associate (st => sys%stats)
            st%sweeps = sys%dem%stats%sweeps
            st%corrections = sys%rows%corrections
            st%n_contacts = sys%dem%stats%n_contacts
            st%n_active = sys%dem%stats%n_active
            st%converged = sys%dem%stats%converged
            st%nlgs_error = sys%dem%stats%error
            st%free_residual = constraint_norm(sys, sys%g, .false.)
            ! Velocity constraint at t_{n+1} with the drift term of the step.
            call disk_velocities(sys, sys%gv)
            call sys%op%apply(sys%fe%v, sys%cv)
            call sys%op%add_prescribed(sys%fe%t, 1, sys%cv)
            sys%gv = sys%gv - sys%cv + sys%drift/sys%fe%h
            st%velocity_residual = constraint_norm(sys, sys%gv, .false.)
            ! Work through the prescribed dofs, then the new position residual.
            sys%gv = 0.0_wp
            call sys%op%add_prescribed(sys%fe%t, 0, sys%gv)
            sys%prescribed_coupling_work = sys%prescribed_coupling_work + &
                                           0.5_wp*dot_product(sys%lambda_old + sys%lambda, sys%gv - sys%cp)
            sys%cp = sys%gv
            call sys%op%apply(sys%fe%u, sys%cv)
            sys%drift = sys%q - (sys%cv + sys%cp - sys%cu0)
            st%position_residual = constraint_norm(sys, sys%drift, .false.)
            st%rotation_residual = constraint_norm(sys, sys%drift, .true.)
            st%particle_residual = row_norm(sys, sys%drift, .false.)
            call sys%space%recover(sys%lambda, sys%multiplier)
            st%lambda_norm = norm2(sys%multiplier)
        end associate
        sys%lambda_old = sys%lambda
        sys%step = sys%step + 1
    end subroutine finish_step

    !> Largest |(x - x_0) - C (u - u_0)| over the translation rows, from the disks' actual
    !> coordinates [m]: the position residual including the rounding of the coordinates
    !> (about ulp(x) per step, a random walk).
    real(wp) function coordinate_residual(sys) result(res)
        !> The coupled system.
        type(coupled_system_t), intent(in) :: sys
        real(wp) :: cu(sys%op%n_rows), xr
        integer :: r, i
        call sys%op%apply(sys%fe%u, cu)
        cu = cu + sys%cp
        res = 0.0_wp
        do r = 1, sys%op%n_rows
            i = sys%rows%owner(r)
            select case (sys%rows%dof(r))
            case (dof_x)
                xr = sys%dem%particles%x(i)
            case (dof_y)
                xr = sys%dem%particles%y(i)
            case default
                cycle
            end select
            res = max(res, abs((xr - sys%start(r)) - (cu(r) - sys%cu0(r))))
        end do
    end function coordinate_residual

    !> Energy audit of the coupled system [J] (see the module description).
    pure function coupled_energies(sys) result(e)
        !> The coupled system.
        type(coupled_system_t), intent(in) :: sys
        type(coupled_energies_t) :: e
        real(wp) :: t
        type(fe_energies_t) :: fe
        t = sys%thickness
        ! On the free dofs (the integrator's), and on the prescribed ones (FE dofs prescribed in time).
        e%fe_coupling_work = sys%fe%coupling_work - sys%prescribed_coupling_work
        ! The whole FE body's (its audit closes with the coupling work on all its dofs), or the
        ! integrator's (free dofs), as the FE side set them.
        fe = sys%accounts%energies(sys%fe, e%fe_coupling_work)
        e%fe_kinetic = fe%kinetic
        e%fe_strain = fe%strain
        e%fe_external_work = fe%external_work
        e%fe_damping = fe%damping
        e%fe_reaction_work = fe%reaction_work
        associate (d => sys%dem%energies)
            e%dem_kinetic = t*d%kinetic
            e%dem_potential = t*d%potential
            e%dem_external_work = t*d%external_work
            e%dem_drive_work = t*d%drive_work
            e%dem_contact_dissipation = t*d%contact_dissipation
            e%dem_numerical_dissipation = t*d%numerical_dissipation
            e%dem_coupling_work = t*d%coupling_work
            e%initial = fe%initial + t*d%initial
            e%coupling_work = e%fe_coupling_work + e%dem_coupling_work
            ! Each side's own audit (its coupling work included) closes to round-off; their
            ! sum without the coupling works is the balance of the coupled system.
            e%balance = fe%balance + t*energies_balance(d) + e%coupling_work
        end associate
    end function coupled_energies
end module coupling_coupled_step
