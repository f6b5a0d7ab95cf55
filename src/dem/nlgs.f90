!> Non-linear Gauss-Seidel (NLGS) over the contacts with the bi-potential local solver.
!>
!> Body velocities v (3, n) start at the free velocities; the solver adds M^-1 H r of the
!> warm-started reactions, then sweeps: for each active contact, u = H^T v + shift,
!> b = u - W r, local solve for r, v += M^-1 H dr. Each contact has the local unknowns
!> (r_n, r_t, M); a contact whose law has no moment length (e = 0: M = 0) is solved with the
!> two-component solver (bipotential_local_solve_scaled), the others with the
!> three-component one (rolling_local_solve_scaled). Cohesion: the unknown of the local
!> solve is the shifted reaction r_n + r_cohe h (doc/theory.md, "Cohesion"), the impulse
!> applied is r.
!> Convergence norm (LMGC90 'Quad'-like): after a sweep,
!>     sqrt(sum |W_aa dr_a|^2) / sqrt(sum |W_aa r_a|^2) <= tol,
!> i.e. the change of local velocities over the sweep relative to W r, where r is the
!> reaction actually applied (not shifted by the cohesion: the test is relative to the forces
!> the contacts carry, not to the strength of the bonds); the rotation rows are multiplied
!> by the mean radius of the pair so that all rows are velocities. Round-off bounds what a
!> sweep can resolve: a relative velocity is known to about eps times the velocities of the
!> two bodies, and the shifted unknown of a bond to about eps r_cohe h. Changes below that
!> noise, floor = (64 eps)^2 sum (|W_aa (r_cohe h, 0, 0)|^2 + |v_i|^2 + |v_j|^2) over the
!> contacts (v with rotations times the mean radius, taken when the solve starts), are not
!> counted: the error reported is sqrt(max(num - floor, 0) / den), so that a structure that
!> carries no force (rigid motion, unloaded bonds) converges instead of chasing round-off. The residual of the law in the final
!> state (scaled frame, bipotential_residual / rolling_residual) is reported too, with the
!> same normalisation.
!> Sweeps alternate direction when `symmetric` (symmetric Gauss-Seidel).
!> Acceleration (doc/theory.md 4.4): over-relaxation (`relaxation` omega, off by default;
!> each update P_K(r0 + omega (r_loc - r0)), back to omega = 1 when the error measured every
!> `check_every` sweeps rose), and Anderson mixing of the last `anderson` iterates (on by
!> default, depth 5; the map is `anderson_sweeps` sweeps in the fixed contact order, 2 by
!> default; the history restarts when |G(x) - x| grows; a drift of the sweeps, G(x) - x the
!> same map after map, is skipped to where its first reaction meets a face of its cone), after
!> `anderson_after` plain sweeps (default 10).
!> Cold start (`start`, an extension of `nlgs_start_t`; none by default): when no contact of
!> the solve carries a reaction yet (a fresh packing), the sweeps start from its estimate
!> instead of zero reactions, e.g. the hydrostatic estimate of dem_cold_start (doc/theory.md
!> 4.7).
!> The Siconos error (nlgs_siconos_error, doc/theory.md 4.5) of the final state is always
!> computed, from u = H^T (v_free + M^-1 H r) + shift in full; `criterion` (an extension of
!> `nlgs_criterion_t`, dem_nlgs_criterion: lmgc90_criterion_t, or siconos_criterion_t; when none
!> is set, the convergence norm of the sweeps as lmgc90_criterion_t) chooses which error stops
!> the sweeps. As a stopping test the Siconos error is evaluated from the velocities the sweeps
!> keep up to date (the same up to round-off, and one pass over the contacts instead of three),
!> only after the sweeps where it may be near the tolerance (dem_nlgs_criterion); once that is
!> below the tolerance it is computed again in full, and only that value stops the sweeps
!> (Siconos' "light, full final" evaluation).
!> With a block, its members are measured by the natural map of their equalities (u_hat on
!> their locked components: the problem the solve solves, in which their reactions may leave
!> their cones), and the final Siconos error is that of the contact problem, in full.
!> Blocked contacts (both bodies immobile along the normal: W_nn = 0) are taken out of the
!> solve with r = 0 and counted in the statistics (`nlgs_stats_t%n_blocked`).
!> The constants of each contact's scaled frame (bipotential_scaling) are computed once per
!> solve.
!>
!> Bilateral constraints (optional, e.g. the Arlequin coupling rows, coupling_bilateral):
!> an extension of `nlgs_bilateral_t` keeps linear velocity constraints on some disks
!> satisfied exactly. It is called once after the warm-started reactions are applied
!> (`restore`) and after every contact update that moved disks (`update`), and corrects the
!> velocities of its disks there. The contacts then solve the problem with the constraints
!> eliminated (give them the condensed Delassus blocks in cs%w for exact local solves). The
!> correction is linear and exact, so the velocities are a function of the reactions alone:
!> the Anderson step removes the swept contacts' impulses, applies the mixed ones and calls
!> `restore` (on the interface experiment 6.8 times fewer sweeps, doc/performance.md).
!>
!> Block (optional, e.g. the intact bonds of dem_bonded_block): an extension of
!> `nlgs_block_t` takes some active contacts out of the sweeps and solves them exactly as one
!> block (block Gauss-Seidel). `prepare` chooses its members after the blocked contacts are
!> taken out; `solve` is called once after the warm start and after every sweep that did not
!> converge; after each sweep `measure` gives the block's share of the convergence norm (the
!> change of the members' local velocities the next solve would make, and their |W r|), so
!> that `sweeps` counts block iterations. The Anderson steps mix the swept contacts'
!> reactions as without a block: with the members fixed within a solve and the block solved
!> exactly for the others' reactions, the velocities are a function of the swept reactions
!> alone, so the step removes the swept contacts' impulses, applies the mixed ones, restores
!> the bilateral constraints and solves the block again (instead of the solve after the
!> sweep); the map accelerated is block Gauss-Seidel. Released bonds (cohesive, swept) are
!> mixed too: with them kept at the sweeps' output and the others mixed, the interface
!> experiment's onset at 1e-6 diverged (a disk at 1e140 m by step 64); mixed, 1 of its 70
!> steps stops at the cap of 20 000 iterations instead of 12 (doc/performance.md, "Anderson
!> with the bonded block").
!>
!> Stall: with the members held the problem may have no solution (a wall of imposed velocity
!> pushing a bonded stack held on the floor by its bonds: the wall's contact asks a motion
!> the held block forbids). The block Gauss-Seidel then adds the same impulses at every
!> iteration: the reactions grow by a fixed step, the velocities and the norm's numerator stay
!> put, and the relative error falls only as the reactions grow (as 1/sweeps: 20 000 sweeps
!> left it at 1.9e-5 on that stack). A slow convergence has the same signature for as long as
!> it lasts (a bonded row hit by a disk 1.9e5 times heavier: the reactions grow linearly for
!> about a thousand sweeps, at a rate of the mass ratio), so the growth alone tells nothing;
!> what tells them apart is whether it moves anything. Without a solution the growth is a
!> self-stress, impulses in equilibrium (Farkas: a combination of the swept contacts' pushes
!> that, with the members held, moves no body), while a slow convergence moves the bodies
!> (the heavy disk slows down). At sweeps 2 stall_first, 4 stall_first, ... the solve compares
!> its state with that at half as many: a numerator not halved and a denominator sum |W r|^2
!> grown by stall_growth (4 for a linear growth), the growth d of the reactions moving the
!> bodies by at most stall_mobility = roundoff^2 of what its impulses would alone
!> (growth_mobility, |v - v_half|_M^2 / sum d_k^T W_kk d_k: 4e-33 on the wall-push stack,
!> 4.6e-7 on the row), and `must_yield` finding a member outside what it can hold: the solve
!> stops, unconverged, with `stalled` set, and the strategy releases a member and solves again
!> (dem_bonded_block). Any other pass runs to its tolerance or its cap; before the growth's
!> mobility was tested the row's first step stalled at 64 sweeps, its root bond released and
!> the step at the cap of 20 000 (999 sweeps without the test). A problem without solution
!> whose growth keeps moving bodies is not detected and the solve runs to its cap, unconverged:
!> the 6 x 4 stack of doc/theory.md 7.10 from its fifth step, the wall's two contacts carrying
!> friction near its bound, the growth's mobility falling as 1/sweeps^2 (1.2e-8 at 1 024
!> sweeps, 4.6e-11 at 16 384) but never to a self-stress's. `growth_seen` says that a test
!> found the signature whatever the growth moved, so that the strategy can give its block up
!> for such a pass when it meets its cap (dem_bonded_block).
!>
!> Correction (`correction`, an extension of `nlgs_correction_t`; none by default): before
!> the first sweep and after every `correction%every` sweeps it changes the reactions of the
!> swept contacts, e.g. the coarse correction of dem_coarse (`[solver] method = coarse`),
!> which scales the reactions of aggregates of consecutive contacts by the Galerkin solution
!> of a small system and so moves the weight through the whole height of a packing at once.
!> A correction must do nothing at a solution of the sweeps, so that the sweeps alone decide
!> convergence. Safeguard: when the error at a correction is larger than at the previous one
!> (the corrections undo what the sweeps between them did), the step goes on without
!> corrections: on the impacts of a deposit every coarse correction raised the error tenfold
!> and 13 to 16 % of the steps never converged.
!>
!> Files: this one holds the solve, the sweeps and their domain split; the submodules
!> dem_nlgs_anderson (nlgs_anderson.f90) and dem_nlgs_siconos (nlgs_siconos.f90) the
!> Anderson step and the Siconos error; the module dem_nlgs_criterion (nlgs_criterion.f90) the
!> stopping tests, as dem_coarse and dem_cold_start hold a correction and a start.
module dem_nlgs
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use core_kinds, only: wp, i8
    use core_constants, only: diagonal_floor
    use core_error, only: error_t
    use core_linalg, only: dense_spd_t, dot
    use dem_contacts, only: contact_set_t, contacts_apply_impulse, contacts_solver_velocity
!$  use omp_lib, only: omp_get_max_threads
    use dem_bipotential, only: bipotential_residual, bipotential_scaling, bipotential_local_solve_scaled, &
                               bipotential_n_scaling, rolling_scaling, rolling_local_solve_scaled, rolling_residual, &
                               rolling_n_scaling, rolling_projection, coulomb_projection
    implicit none
    private
    public :: nlgs_config_t, nlgs_stats_t, nlgs_solve, nlgs_apply_reactions, nlgs_residual
    public :: nlgs_bilateral_t, nlgs_block_t
    public :: nlgs_correction_t, nlgs_start_t
    public :: nlgs_siconos_error, siconos_error, siconos_ratio
    public :: nlgs_split_t, nlgs_split_build
    public :: nlgs_criterion_t, nlgs_criterion_name, nlgs_start_name
    public :: block_kept, block_given_up_energy, block_given_up_unconverged, block_given_up_reverted

    !> Values of nlgs_stats_t%block_given_up (and of /dem/solver/block_given_up): the bonded
    !> block solved the step, or the method has none, ...
    integer, parameter :: block_kept = 0
    !> ... it was given up by its energy guard (a pass created energy: dem_bonded_block), ...
    integer, parameter :: block_given_up_energy = 1
    !> ... or because a pass whose reactions grew as without a solution (growth_seen) ended
    !> unconverged at max_sweeps with a bond of the block outside its cone
    !> (nlgs_block_t%must_yield). The step was then solved again by the plain sweeps.
    integer, parameter :: block_given_up_unconverged = 2
    !> ... or it was given up so, but the plain sweeps ended unconverged too with a larger error
    !> (the step's norm) than the block's at its cap: the step ends on the block's answer,
    !> unconverged, as if it had been kept (its sweeps counting both solves).
    integer, parameter :: block_given_up_reverted = 3

    !> Stall of a solve with a block (module header, "Stall"): the test runs at sweeps
    !> 2 stall_first, 4 stall_first, ..., against the state at half as many sweeps.
    integer, parameter :: stall_first = 32
    !> ... when the norm's denominator sum |W r|^2 grew by at least this factor (reactions
    !> growing by a fixed step per sweep: |r|^2 quadruples when the sweeps double) ...
    real(wp), parameter :: stall_growth = 3.0_wp
    !> ... while its numerator (absolute) kept at least this fraction of its value.
    real(wp), parameter :: stall_residual = 0.5_wp
    !> A contact is blocked when W_nn <= blocked_ratio (W_nn + W_tt) (the floor of the scaled
    !> frame in dem_bipotential: below it the normal reaction would be unbounded).
    real(wp), parameter :: blocked_ratio = diagonal_floor
    !> Relative resolution of the shifted reactions of bonds (see the module header): 64
    !> machine epsilons.
    real(wp), parameter :: roundoff = 64.0_wp*epsilon(1.0_wp)
    !> Stall (stall_first): ... and the growth since the last test moves no body, its mobility
    !> (growth_mobility: 0 for a self-stress, 1 for one contact's impulse alone) at most
    !> roundoff^2, 2.0e-28 (the velocities are known to roundoff). A slow convergence moves
    !> bodies: a clamped bonded row of 5 disks hit by a disk 1.9e5 times heavier, 4.6e-7 (it
    !> scales as the mass ratio: the threshold at a ratio of 4e26); the wall-push stack 4e-33.
    real(wp), parameter :: stall_mobility = roundoff**2

    !> A correction of the swept contacts' reactions between sweeps (module header). It must
    !> change nothing at a solution of the sweeps.
    type, abstract :: nlgs_correction_t
        !> Sweeps between two corrections (one runs before the first sweep).
        integer :: every = 10
    contains
        !> Change the reactions of the contacts list and the velocities with them.
        procedure(correction_correct), deferred :: correct
    end type nlgs_correction_t

    !> The reactions a solve starts from when none of its contacts carries one yet (module
    !> header).
    type, abstract :: nlgs_start_t
    contains
        !> Set the reactions of the contacts list (all zero on entry).
        procedure(start_guess), deferred :: guess
        !> Name (the value of `[solver] cold_start`).
        procedure(start_name), deferred :: name
    end type nlgs_start_t

    abstract interface
        !> Name of a cold start.
        pure function start_name(self) result(name)
            import :: nlgs_start_t
            !> The start.
            class(nlgs_start_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function start_name

        !> Change the reactions of the contacts list, and vel by the impulses of the change.
        subroutine correction_correct(self, cs, list, im, vel)
            import :: nlgs_correction_t, contact_set_t, wp
            !> The correction.
            class(nlgs_correction_t), intent(in) :: self
            !> Contacts (reactions r).
            type(contact_set_t), intent(inout) :: cs
            !> The swept contacts, in the order of the sweeps.
            integer, intent(in) :: list(:)
            !> Inverse mass per DOF (3, n_disks).
            real(wp), intent(in) :: im(:, :)
            !> Disk velocities (3, n_disks), updated.
            real(wp), intent(inout) :: vel(:, :)
        end subroutine correction_correct

        !> Set the reactions of the contacts list, which are all zero.
        subroutine start_guess(self, cs, list, im, vfree)
            import :: nlgs_start_t, contact_set_t, wp
            !> The start.
            class(nlgs_start_t), intent(in) :: self
            !> Contacts (frames, friction); the reactions of list are set.
            type(contact_set_t), intent(inout) :: cs
            !> The contacts of the solve.
            integer, intent(in) :: list(:)
            !> Inverse mass per DOF (3, n_disks).
            real(wp), intent(in) :: im(:, :)
            !> Free velocities (3, n_disks).
            real(wp), intent(in) :: vfree(:, :)
        end subroutine start_guess
    end interface

    !> Solver settings.
    type :: nlgs_config_t
        !> Tolerance of the convergence norm.
        real(wp) :: tol = 1.0e-6_wp
        !> Maximum number of sweeps.
        integer :: max_sweeps = 1000
        !> Relative tolerance of the local predictor-corrector iterations.
        real(wp) :: local_tol = 1.0e-10_wp
        !> Maximum local iterations per contact visit.
        integer :: local_max_iter = 8
        !> Alternate the sweep direction.
        logical :: symmetric = .true.
        !> Correction of the reactions between sweeps (module header; e.g. dem_coarse's);
        !> none when not allocated.
        class(nlgs_correction_t), allocatable :: correction
        !> Start of a solve in which no contact carries a reaction yet (module header; e.g.
        !> dem_cold_start's hydrostatic estimate); zero reactions when not allocated. Not used
        !> with bilateral constraints or a block.
        class(nlgs_start_t), allocatable :: start
        !> Over-relaxation factor omega in (0, 2): each contact update becomes
        !> P_K(r0 + omega (r_loc - r0)) (module header); 1 is plain NLGS.
        real(wp) :: relaxation = 1.0_wp
        !> Safeguard of the over-relaxation: every check_every sweeps the error is compared
        !> with the one check_every sweeps earlier, and omega falls back to 1 for the rest of
        !> the solve when it rose.
        integer :: check_every = 10
        !> Stopping criterion (module header; dem_nlgs_criterion); when not allocated, the
        !> convergence norm of the sweeps (as lmgc90_criterion_t).
        class(nlgs_criterion_t), allocatable :: criterion
        !> Anderson acceleration of the sweeps (module header): depth (number of previous
        !> sweeps mixed); 0: none. Not used when intact bonds are swept without a block
        !> (nlgs_solve).
        integer :: anderson = 5
        !> Plain sweeps before the Anderson steps start: a solve that converges within them
        !> is not accelerated (near rest a plain sweep is cheaper, doc/performance.md).
        integer :: anderson_after = 10
        !> Sweeps per Anderson step: the map G accelerated is that many forward sweeps. An
        !> Anderson step costs about a sweep (its three passes over the contacts); with a map
        !> of 2 sweeps, half of that per sweep, and about as many sweeps in all
        !> (doc/performance.md, "Anderson over two sweeps").
        integer :: anderson_sweeps = 2
        !> Domain split of the sweeps over the OpenMP threads (nlgs_split_build): fewest contacts
        !> per block (smaller solves, and all solves on one thread, are serial).
        integer :: split_min = 2000
    end type nlgs_config_t

    !> Statistics of one solve.
    type :: nlgs_stats_t
        !> Sweeps done.
        integer :: sweeps = 0
        !> Contacts in the list and contacts in the solve (active, not blocked).
        integer :: n_contacts = 0, n_active = 0
        !> Active contacts left out of the solve because both bodies are immobile along the
        !> normal (fixed or imposed velocities, W_nn = 0): their reaction is set to zero.
        integer :: n_blocked = 0
        !> Local predictor-corrector iterations, all contacts and sweeps.
        integer(i8) :: local_iterations = 0_i8
        !> Contact updates (active contacts x sweeps).
        integer(i8) :: updates = 0_i8
        !> Convergence norm after the last sweep.
        real(wp) :: error = 0.0_wp
        !> Relative Signorini-Coulomb residual of the final state.
        real(wp) :: residual = 0.0_wp
        !> Siconos error of the final state (nlgs_siconos_error), whatever the criterion.
        real(wp) :: siconos_error = 0.0_wp
        !> Estimate of the round-off floor of the Siconos error at the final state
        !> (siconos_floor): set when a solve under the Siconos criterion stops unconverged,
        !> 0 otherwise. A tolerance below it cannot be reached by any number of sweeps.
        real(wp) :: siconos_floor = 0.0_wp
        !> Over-relaxation factor at the end of the solve (1 once the safeguard fell back).
        real(wp) :: relaxation = 1.0_wp
        !> error <= tol reached.
        logical :: converged = .true.
        !> Active contacts solved as a block (nlgs_block_t members), not swept.
        integer :: n_block = 0
        !> Corrections done (config%correction).
        integer :: corrections = 0
        !> Why the bonded block was given up for the step and the step solved again by the
        !> plain sweeps (dem_bonded_block): block_given_up_energy (its energy guard) or
        !> block_given_up_unconverged (unconverged at its cap, a bond outside its cone);
        !> block_given_up_reverted when so given up but the plain sweeps ended worse, the
        !> step ending on the block's answer; block_kept when it was not, and always with
        !> the other methods.
        integer :: block_given_up = block_kept
        !> The solve stopped before its cap because its problem, the block's members held, has
        !> no solution (module header, "Stall"): the reactions grew by a fixed step per
        !> sweep, the error unchanged, and a member must yield (nlgs_block_t%must_yield).
        logical :: stalled = .false.
        !> At one of the solve's stall tests (module header, "Stall") its reactions grew as in a
        !> problem without solution, the numerator not halved and the denominator grown by
        !> stall_growth, while a member must yield: the signature of a stall, whether or not
        !> the growth moved bodies (a stall is the case where it moved none).
        logical :: growth_seen = .false.
        !> Solves of the step (set by the time step, dem_moreau_jean::mj_solve; the counts above
        !> are summed over them, the rest is the last one's): 1, plus one for each re-check of
        !> the rule of activation that let in contacts the solve before had shut.
        integer :: solves = 1
        !> Contacts the re-checks let in.
        integer :: rechecked = 0
        !> Contacts the re-check after the last solve allowed still found shut, left out (0 when
        !> the solves ended before their cap): the step is then not converged.
        integer :: recheck_left = 0
    end type nlgs_stats_t

    !> History of the Anderson acceleration: differences of the sweep map's outputs g and
    !> residuals f = g - x over the last sweeps (ring buffer of `depth` columns), in the
    !> scaled reactions x = D r (D = sqrt of the diagonal of W, 3 per contact).
    type :: anderson_t
        integer :: depth = 0, used = 0, next = 1
        real(wp), allocatable :: df(:, :), dg(:, :), gram(:, :)
        !> The iterate x (the scaled reactions the next sweep starts from, valid when
        !> x_valid), the residual f and output g of the last map, the scaling D.
        real(wp), allocatable :: x(:), fprev(:), gprev(:), d(:)
        !> 1/D where D > 0, else 0 (no moment, or W_tt = 0).
        real(wp), allocatable :: dinv(:)
        !> Partial sums of the step by chunk of dot_chunk contacts (2 depth, chunks).
        real(wp), allocatable :: part(:, :)
        real(wp) :: fnorm_prev = huge(1.0_wp)
        logical :: started = .false., x_valid = .false.
        !> The last step mixed (the iterate x is an extrapolation, not a map's output): the plain
        !> output g of the map before it and |f| of that map, to fall back to when the next
        !> map's residual rises (anderson_mix).
        logical :: mixed = .false.
        real(wp), allocatable :: gplain(:)
        real(wp) :: fnorm_plain = huge(1.0_wp)
        !> Sweeps run since x was set (the map's sweeps so far).
        integer :: swept = 0
        !> |dG_j| of the columns of the history.
        real(wp), allocatable :: dgnorm(:)
    end type anderson_t

    !> Domain split of the sweeps (nlgs_split_build): the contacts of the solve in block order,
    !> order(start(b):start(b + 1) - 1) for block b (swept in parallel), then the interface,
    !> order(start(nb + 1):), swept after them. The scaled frames of the solve are stored in the
    !> same order, so that a block is swept over contiguous memory like the serial sweep.
    type :: nlgs_split_t
        !> Number of blocks (1: the serial sweep).
        integer :: nb = 1
        !> First position in `order` of each block, and of the interface (nb + 1).
        integer, allocatable :: start(:)
        !> The contacts of the solve, block after block, then the interface.
        integer, allocatable :: order(:)
    end type nlgs_split_t

    !> Contacts per chunk of the deterministic parallel sums of the Anderson step.
    integer, parameter :: dot_chunk = 1024
    !> Tikhonov term of the Anderson least-squares system, relative to its trace: far above
    !> the rounding of the Gram matrix (1e-16), far below its genuine eigenvalues.
    real(wp), parameter :: anderson_regularisation = 1.0e-12_wp
    !> Largest Anderson extrapolation |dG gamma|, relative to |g| (bounded above by
    !> sum |gamma_j| |dG_j|): beyond it the step is refused like one whose residual rose.
    !> When the map stagnates, a difference of the history can be almost zero and gamma huge
    !> (4.8e11 at a step of a 10-disk triangle, an extrapolation 3e8 times |g|); the sweeps
    !> from there "converged" to reactions 10^7 times too large, the relative error met
    !> because |r| and |u| were huge too, and the disks flew off (doc/theory.md 4.4). 10, an
    !> order of magnitude above the iterate, is seldom reached on the deposits and packings:
    !> 64.34 sweeps per step over 24 layouts of 200 disks against 64.33 without the bound
    !> (65.23 with a bound of 1), the 10^4-disk protocol unchanged (doc/performance.md).
    real(wp), parameter :: anderson_max_step = 10.0_wp
    !> Fallback of a mixed iterate (anderson_mix): when the residual of the map from it exceeds
    !> anderson_fallback times that of the map before it, the reactions go back to that map's
    !> output. A rise by itself is common and harmless (the mixing is not monotone): falling back
    !> at every rise (a factor 1) cost 19 to 25 % more sweeps on the interface experiment and
    !> the 200-disk deposit, for nothing, and a factor 10 still changed the path of the
    !> interface experiment's sliding layer (a fallback at step 325 of 1 500); an extrapolation
    !> that leaves the solution, as on the stack at a mass ratio of 5e5, raises it by orders of
    !> magnitude.
    real(wp), parameter :: anderson_fallback = 1.0e3_wp
    !> Drift of the sweeps (anderson_mix, drift_length): |f| / |f_prev| between 1 and
    !> drift_high, 1 - cos(f, f_prev) below drift_cosine; a face of a cone nearer than
    !> drift_slack times |r| counts as the one the reaction is on; the skip is taken when it is
    !> at least drift_min maps long.
    real(wp), parameter :: drift_high = 1.01_wp, drift_cosine = 1.0e-4_wp
    real(wp), parameter :: drift_slack = 1.0e-9_wp
    real(wp), parameter :: drift_min = 5.0_wp

    !> Stopping test of the sweeps (`[solver] criterion`, module header): the error of the
    !> iterate that is compared with the tolerance. The settings hold the choice; each solve
    !> works on a copy, which keeps the state of that solve.
    type, abstract :: nlgs_criterion_t
    contains
        !> Name (the value of `[solver] criterion`, /dem/solver@criterion).
        procedure(criterion_name), deferred :: name
        !> Start of a solve, the contacts' activity set.
        procedure(criterion_begin), deferred :: begin
        !> The error after a sweep, from the norm of the sweeps.
        procedure(criterion_measure), deferred :: measure
        !> The error that stops the sweeps is the Siconos error of the final state (then not
        !> computed again).
        procedure :: is_siconos_error => criterion_not_siconos
    end type nlgs_criterion_t

    abstract interface
        !> Name of a criterion.
        pure function criterion_name(self) result(name)
            import :: nlgs_criterion_t
            !> The criterion.
            class(nlgs_criterion_t), intent(in) :: self
            character(len=:), allocatable :: name
        end function criterion_name

        !> Start of a solve (contacts of the solve: the active ones; those of a block, held as
        !> bilateral constraints within the solve, are `held`).
        subroutine criterion_begin(self, cs, held)
            import :: nlgs_criterion_t, contact_set_t
            !> The criterion (the copy of a solve).
            class(nlgs_criterion_t), intent(inout) :: self
            !> Contacts (activity set).
            type(contact_set_t), intent(in) :: cs
            !> Contact k is held as a bilateral constraint in this solve (size >= cs%n; none
            !> when absent).
            logical, intent(in), optional :: held(:)
        end subroutine criterion_begin

        !> The error after sweep s: on entry the convergence norm of the sweeps, on exit the
        !> criterion's error, `evaluated` when it is exact (only an exact error below the
        !> tolerance stops the sweeps; otherwise an estimate).
        subroutine criterion_measure(self, s, needed, tol, cs, im, vfree, vel, vwork, bilateral, nq, error, evaluated)
            import :: nlgs_criterion_t, contact_set_t, wp
            !> The criterion (the copy of a solve).
            class(nlgs_criterion_t), intent(inout) :: self
            !> Sweeps done.
            integer, intent(in) :: s
            !> The solve needs the exact error after this sweep (the cap, a safeguard).
            logical, intent(in) :: needed
            !> Tolerance.
            real(wp), intent(in) :: tol
            !> Contacts (reactions).
            type(contact_set_t), intent(in) :: cs
            !> Inverse mass per DOF, free velocities and velocities (3, n_disks).
            real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :)
            !> Work array (3, n_disks).
            real(wp), intent(inout) :: vwork(:, :)
            !> Bilateral constraints changed the velocities (their impulses are not contacts).
            logical, intent(in) :: bilateral
            !> |q| of the Siconos error (siconos_free_norm).
            real(wp), intent(in) :: nq
            !> The convergence norm in, the criterion's error out.
            real(wp), intent(inout) :: error
            !> The error is exact.
            logical, intent(out) :: evaluated
        end subroutine criterion_measure
    end interface

    !> Linear velocity constraints kept satisfied during the sweeps (see the module header).
    type, abstract :: nlgs_bilateral_t
    contains
        !> Restore the constraints after arbitrary changes of the velocities.
        procedure(bilateral_restore), deferred :: restore
        !> Restore the constraints after a contact update changed the velocities of two bodies.
        procedure(bilateral_update), deferred :: update
        !> The constraints' share of the disks' mobility (used by a block solve).
        procedure(bilateral_mobility), deferred :: mobility
        !> Correct a velocity field so that the constraints hold, the constraints unchanged.
        procedure(bilateral_hold), deferred :: hold
    end type nlgs_bilateral_t

    abstract interface
        !> Correct vel so that the constraints hold again, after any change of vel.
        subroutine bilateral_restore(self, vel)
            import :: nlgs_bilateral_t, wp
            !> The constraints (their multipliers are updated).
            class(nlgs_bilateral_t), intent(inout) :: self
            !> Disk velocities (3, n_disks).
            real(wp), intent(inout) :: vel(:, :)
        end subroutine bilateral_restore

        !> Correct vel after only bodies a and b changed velocity since the last call.
        subroutine bilateral_update(self, a, b, vel)
            import :: nlgs_bilateral_t, wp
            !> The constraints (their multipliers are updated).
            class(nlgs_bilateral_t), intent(inout) :: self
            !> Bodies of the contact just updated: disk a (or -wall index, <= 0) and disk b.
            integer, intent(in) :: a, b
            !> Disk velocities (3, n_disks).
            real(wp), intent(inout) :: vel(:, :)
        end subroutine bilateral_update

        !> Correct vel as `restore` would, without changing the constraints' state (their
        !> multipliers): vel is a velocity field of the same multipliers as the one the
        !> constraints last held for (e.g. that one with other contact impulses).
        subroutine bilateral_hold(self, vel)
            import :: nlgs_bilateral_t, wp
            !> The constraints.
            class(nlgs_bilateral_t), intent(in) :: self
            !> Disk velocities (3, n_disks).
            real(wp), intent(inout) :: vel(:, :)
        end subroutine bilateral_hold

        !> Mobility of the constrained disks: an impulse p (3, n_disks) applied to the disks
        !> and followed by `restore` changes the velocities by M^-1 p - P^T D C D P p, with P
        !> picking the DOFs (dof(r), owner(r)) of the rows, D = diag(inverse mass of those
        !> DOFs) and C symmetric positive semi-definite (empty arrays: no share).
        subroutine bilateral_mobility(self, owner, dof, c)
            import :: nlgs_bilateral_t, wp
            !> The constraints.
            class(nlgs_bilateral_t), intent(in) :: self
            !> Disk and DOF (1 = x, 2 = y, 3 = rotation) of each row.
            integer, allocatable, intent(out) :: owner(:), dof(:)
            !> The matrix C (rows x rows).
            real(wp), allocatable, intent(out) :: c(:, :)
        end subroutine bilateral_mobility
    end interface

    !> Contacts solved exactly as one block inside the sweeps (see the module header).
    type, abstract :: nlgs_block_t
        !> Contact k is a member of the block in the current solve (size >= cs%n), set by
        !> `prepare`.
        logical, allocatable :: member(:)
    contains
        !> Choose the members among the active contacts and set the block up.
        procedure(block_prepare), deferred :: prepare
        !> Solve the members exactly for the current velocities of the other contacts.
        procedure(block_solve), deferred :: solve
        !> The members' share of the convergence norm.
        procedure(block_measure), deferred :: measure
        !> A member's reaction lies outside what it can hold as a bilateral constraint.
        procedure(block_must_yield), deferred :: must_yield
    end type nlgs_block_t

    abstract interface
        !> Choose the members (active contacts only) and set up their solve; reactions of the
        !> members may be changed (they are applied afterwards).
        subroutine block_prepare(self, cs, im, bilateral)
            import :: nlgs_block_t, contact_set_t, nlgs_bilateral_t, wp
            !> The block.
            class(nlgs_block_t), intent(inout) :: self
            !> Contacts (blocked ones already inactive).
            type(contact_set_t), intent(inout) :: cs
            !> Inverse mass per DOF (3, n_disks).
            real(wp), intent(in) :: im(:, :)
            !> Bilateral constraints of the solve, if any.
            class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        end subroutine block_prepare

        !> Solve the members for the current velocities: update their reactions and vel
        !> (restoring the bilateral constraints if any).
        subroutine block_solve(self, cs, im, vel, bilateral)
            import :: nlgs_block_t, contact_set_t, nlgs_bilateral_t, wp
            !> The block.
            class(nlgs_block_t), intent(inout) :: self
            !> Contacts.
            type(contact_set_t), intent(inout) :: cs
            !> Inverse mass per DOF (3, n_disks).
            real(wp), intent(in) :: im(:, :)
            !> Velocities (3, n_disks).
            real(wp), intent(inout) :: vel(:, :)
            !> Bilateral constraints of the solve, if any.
            class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        end subroutine block_solve

        !> The members' share of the convergence norm in the current state: num = sum of
        !> the squared change of their local velocities that `solve` would make, den = sum
        !> |W_aa r_a|^2 (rotation rows times the mean radius, as in the sweeps).
        subroutine block_measure(self, cs, vel, num, den)
            import :: nlgs_block_t, contact_set_t, wp
            !> The block.
            class(nlgs_block_t), intent(in) :: self
            !> Contacts.
            type(contact_set_t), intent(in) :: cs
            !> Velocities (3, n_disks).
            real(wp), intent(in) :: vel(:, :)
            !> Contributions to the convergence norm.
            real(wp), intent(out) :: num, den
        end subroutine block_measure

        !> Some member's reaction lies outside the set it can take while held (e.g. a bond
        !> outside its cone): the problem with the members held may then have no solution,
        !> and the strategy that chose them must release one.
        pure logical function block_must_yield(self, cs)
            import :: nlgs_block_t, contact_set_t
            !> The block.
            class(nlgs_block_t), intent(in) :: self
            !> Contacts (their reactions).
            type(contact_set_t), intent(in) :: cs
        end function block_must_yield
    end interface

    ! The procedures of the submodules (module header) that this file calls. The submodules
    ! repeat the arguments (`module subroutine`; the compiler checks them against these)
    ! rather than use `module procedure`, whose body fprettify does not indent.
    interface
        !> Forget the history of the Anderson acceleration (submodule dem_nlgs_anderson).
        pure module subroutine anderson_restart(aa)
            type(anderson_t), intent(inout) :: aa
        end subroutine anderson_restart

        !> Size the history and the scaling of the Anderson acceleration (dem_nlgs_anderson).
        module subroutine anderson_init(aa, depth, cs, list)
            type(anderson_t), intent(inout) :: aa
            integer, intent(in) :: depth
            type(contact_set_t), intent(in) :: cs
            integer, intent(in) :: list(:)
        end subroutine anderson_init

        !> The scaled reactions x = D r of the contacts list (dem_nlgs_anderson).
        module subroutine gather(cs, list, d, x, parallel)
            type(contact_set_t), intent(in) :: cs
            integer, intent(in) :: list(:)
            real(wp), intent(in) :: d(:)
            real(wp), intent(out) :: x(:)
            logical, intent(in) :: parallel
        end subroutine gather

        !> One Anderson step after the map's sweeps (dem_nlgs_anderson).
        module subroutine anderson_mix(aa, cs, list, im, vfree, vel, split, bilateral, others, judge_only)
            type(anderson_t), intent(inout) :: aa
            type(contact_set_t), intent(inout) :: cs
            integer, intent(in) :: list(:)
            real(wp), intent(in) :: im(:, :), vfree(:, :)
            real(wp), intent(inout) :: vel(:, :)
            type(nlgs_split_t), intent(in) :: split
            class(nlgs_bilateral_t), intent(inout), optional :: bilateral
            logical, intent(in) :: others
            logical, intent(in) :: judge_only
        end subroutine anderson_mix

        !> Siconos error of the current reactions, u computed in full (submodule
        !> dem_nlgs_siconos; the criterion siconos_criterion_t evaluates it).
        real(wp) module function siconos_error(cs, im, vfree, vel, vwork, bilateral, nq, held) result(err)
            !> Contacts (reactions r).
            type(contact_set_t), intent(in) :: cs
            !> Inverse mass, free velocities and velocities (3, n_disks); |q| (siconos_free_norm).
            real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :), nq
            !> Work array (3, n_disks).
            real(wp), intent(inout) :: vwork(:, :)
            !> Bilateral constraints changed the velocities (their impulses are not contacts).
            logical, intent(in) :: bilateral
            !> Contacts held as bilateral constraints (size >= cs%n; none when absent).
            logical, intent(in), optional :: held(:)
        end function siconos_error

        !> Estimate of the round-off floor of the Siconos error of the current reactions
        !> (submodule dem_nlgs_siconos).
        real(wp) module function siconos_floor(cs, im, vfree, vel, nq) result(floor)
            type(contact_set_t), intent(in) :: cs
            real(wp), intent(in) :: im(:, :), vfree(:, :), vel(:, :), nq
        end function siconos_floor

        !> Siconos error of the contact problem u = W r + q over the active contacts,
        !> sqrt(sum_a |r_a - P_K(r_a - u_hat_a)|^2) / max(|q|, |r|, |u|) (doc/theory.md 4.5;
        !> submodule dem_nlgs_siconos).
        module function nlgs_siconos_error(cs, im, vfree, vel) result(err)
            !> Contacts (reactions r).
            type(contact_set_t), intent(in) :: cs
            !> Inverse mass per DOF (3, n_disks).
            real(wp), intent(in) :: im(:, :)
            !> Free velocities (3, n_disks).
            real(wp), intent(in) :: vfree(:, :)
            !> Velocities (3, n_disks) of the reactions (vfree + M^-1 H r).
            real(wp), intent(in) :: vel(:, :)
            real(wp) :: err
        end function nlgs_siconos_error

        !> |q| over the active contacts (dem_nlgs_siconos).
        real(wp) module function siconos_free_norm(cs, im, vfree, bilateral) result(nq)
            type(contact_set_t), intent(in) :: cs
            real(wp), intent(in) :: im(:, :), vfree(:, :)
            class(nlgs_bilateral_t), intent(in), optional :: bilateral
        end function siconos_free_norm

        !> Siconos error of the contacts act from the velocities vel, |q| = nq, the contacts
        !> with held(k) measured as bilateral constraints (dem_nlgs_siconos; the criterion
        !> siconos_criterion_t evaluates it).
        pure real(wp) module function siconos_ratio(cs, act, vel, nq, held) result(err)
            !> Contacts (reactions r).
            type(contact_set_t), intent(in) :: cs
            !> The active contacts measured, in increasing order.
            integer, intent(in) :: act(:)
            !> Velocities (3, n_disks); |q| (siconos_free_norm).
            real(wp), intent(in) :: vel(:, :), nq
            !> Contacts held as bilateral constraints (size >= cs%n; none when absent).
            logical, intent(in), optional :: held(:)
        end function siconos_ratio
    end interface

contains

    !> Solve the contact problem of one step. On entry vel holds the free velocities, on
    !> exit the end-of-step velocities; cs%r holds the warm start on entry, the reactions on exit.
    subroutine nlgs_solve(config, cs, im, vel, stats, bilateral, block)
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        !> Contacts (frames, laws and activity set).
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        !> Statistics.
        type(nlgs_stats_t), intent(out) :: stats
        !> Bilateral constraints kept satisfied (default: none).
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        !> Contacts solved as one block (default: none).
        class(nlgs_block_t), intent(inout), optional :: block
        real(wp) :: num, den, num_b, den_b
        integer(i8) :: nloc
        integer, allocatable :: list(:)
        ! per contact of the solve, constant over the solve: the scaled frame of its local
        ! problem (bipotential_scaling, or rolling_scaling for a law with moments)
        real(wp), allocatable :: sc(:, :)
        ! free velocities (the Siconos error is computed from them in full) and a work copy
        real(wp), allocatable :: vfree(:, :), vwork(:, :)
        ! |q| of the Siconos error (constant over the solve)
        real(wp) :: nq
        ! the stopping test of this solve (a copy of the settings' criterion; none: the norm of
        ! the sweeps, exact after every sweep), whether its error after the sweep is exact, and
        ! whether that error is the Siconos error of the final state
        class(nlgs_criterion_t), allocatable :: criterion
        logical :: evaluated, needed, siconos_stops
        real(wp) :: floor, omega, checked
        type(anderson_t) :: aa
        type(nlgs_split_t) :: split
        logical :: accelerate, correcting
        integer :: every
        real(wp) :: error_corrected
        logical :: mix_now
        integer :: s, k, n_swept, nb
        ! the stall test (module header, "Stall"): its next sweep and the norm's numerator and
        ! denominator at the one before
        integer :: stall_at
        real(wp) :: num_at, den_at
        ! ... and the reactions and velocities there, whose growth since is judged
        ! (growth_mobility)
        real(wp), allocatable :: r_at(:, :), v_at(:, :)
        stats%n_contacts = cs%n
        call skip_blocked(cs, stats%n_blocked)
        stats%n_active = count(cs%active(1:cs%n))
        stats%n_block = 0
        if (present(block)) then
            call block%prepare(cs, im, bilateral)
            stats%n_block = count(block%member(1:cs%n))
        end if
        n_swept = stats%n_active - stats%n_block
        allocate (list(n_swept), sc(rolling_n_scaling, n_swept))
        allocate (vfree, source=vel)
        allocate (vwork, mold=vel)
        ! |q| of the Siconos error, for the criterion and the final error
        nq = siconos_free_norm(cs, im, vfree, bilateral)
        siconos_stops = .false.
        if (allocated(config%criterion)) then
            allocate (criterion, source=config%criterion)
            if (stats%n_block > 0) then
                call criterion%begin(cs, block%member)
            else
                call criterion%begin(cs)
            end if
            siconos_stops = criterion%is_siconos_error()
        end if
        s = 0
        floor = 0.0_wp
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            if (present(block)) then
                if (block%member(k)) cycle
            end if
            s = s + 1
            list(s) = k
        end do
        nb = 1
!$      nb = omp_get_max_threads()
        if (present(bilateral) .or. stats%n_block > 0) nb = 1
        nb = max(1, min(nb, n_swept/max(config%split_min, 1)))
        call nlgs_split_build(split, cs, list, size(vel, 2), nb)
        ! the scaled frames in the order of the sweeps (split%order); like every loop of the
        ! solve, on the threads only when the sweeps are split (below, waking the threads costs
        ! more than the loop)
        !$omp parallel do schedule(static) private(k) if (split%nb > 1)
        do s = 1, n_swept
            k = split%order(s)
            if (cs%erol(k) > 0.0_wp) then
                call rolling_scaling(cs%w(:, k), cs%mu(k), cs%erol(k), sc(:, s))
            else
                call bipotential_scaling(cs%w(1, k), cs%w(2, k), cs%w(3, k), cs%mu(k), sc(1:bipotential_n_scaling, s))
            end if
        end do
        !$omp end parallel do
        if (allocated(config%start) .and. .not. present(bilateral) .and. stats%n_block == 0) then
            ! not on a step without active contacts: the estimate's O(N) pass would find nothing
            if (size(list) > 0) then
                if (all(cs%r(:, list) == 0.0_wp)) call config%start%guess(cs, list, im, vfree)
            end if
        end if
        call nlgs_apply_reactions(cs, im, vel)
        do k = 1, cs%n
            if (cs%active(k)) floor = floor + roundoff_floor(cs, k, vel)
        end do
        if (present(bilateral)) call bilateral%restore(vel)
        if (present(block)) call block%solve(cs, im, vel, bilateral)
        stats%converged = .true.
        stats%error = 0.0_wp
        omega = config%relaxation
        checked = huge(1.0_wp)
        ! the Anderson steps rebuild the velocities from the swept contacts (and the bilateral
        ! constraints' exact correction, and with a block its solve for the mixed reactions:
        ! the map is then block Gauss-Seidel, its reactions those of the swept contacts,
        ! released bonds included, also when the block released all its bonds: a lattice
        ! pulled apart by imposed velocities, whose block has no solution, took 1 564 plain
        ! sweeps for its released bonds, under 300 mixed); not when intact bonds are swept with no
        ! block, method = nlgs (on a bonded row the mixed iterates stop 4e-10 of the load away
        ! at a tolerance of 1e-14, plain sweeps within 1e-10; method = block solves them)
        accelerate = config%anderson > 0 .and. n_swept > 0
        if (accelerate .and. .not. present(block)) accelerate = all(cs%coh(list) == 0.0_wp)
        ! the correction changes swept contacts only: not with a block or bilateral rows
        correcting = allocated(config%correction) .and. .not. present(bilateral) .and. stats%n_block == 0 &
                     .and. n_swept > 0
        stats%corrections = 0
        error_corrected = huge(1.0_wp)
        ! (the period read only where there is a correction: .and. does not short-circuit)
        every = huge(1)
        if (correcting) every = config%correction%every
        if (correcting) then
            call config%correction%correct(cs, list, im, vel)
            stats%corrections = 1
        end if
        stall_at = stall_first
        num_at = 0.0_wp
        den_at = 0.0_wp
        if (stats%n_active > 0) then
            stats%converged = .false.
            do s = 1, config%max_sweeps
                if (accelerate .and. s > config%anderson_after) then
                    ! the map accelerated is anderson_sweeps sweeps in the fixed (bottom-up)
                    ! contact order, from x; the history is sized when a step first needs it
                    if (aa%depth == 0) call anderson_init(aa, config%anderson, cs, list)
                    if (.not. aa%x_valid) then
                        call gather(cs, list, aa%d, aa%x, split%nb > 1)
                        aa%x_valid = .true.
                        aa%swept = 0
                    end if
                    call split_sweep(config, omega, cs, im, vel, sc, split, .true., num, den, nloc, bilateral)
                    aa%swept = aa%swept + 1
                else
                    call split_sweep(config, omega, cs, im, vel, sc, split, &
                                     .not. (config%symmetric .and. mod(s, 2) == 0), num, den, nloc, bilateral)
                end if
                if (present(block)) then
                    call block%measure(cs, vel, num_b, den_b)
                    num = num + num_b
                    den = den + den_b
                end if
                stats%sweeps = s
                stats%local_iterations = stats%local_iterations + nloc
                stats%error = relative(max(num - floor, 0.0_wp), den)
                ! the exact error is needed at the cap, by the safeguard of the over-relaxation
                ! and by the correction's
                needed = s == config%max_sweeps .or. (omega /= 1.0_wp .and. mod(s, config%check_every) == 0) &
                         .or. (correcting .and. mod(s, every) == 0)
                evaluated = .true.
                if (allocated(criterion)) &
                    call criterion%measure(s, needed, config%tol, cs, im, vfree, vel, vwork, present(bilateral), nq, &
                                           stats%error, evaluated)
                if (evaluated .and. stats%error <= config%tol) then
                    stats%converged = .true.
                    exit
                end if
                if (s == stall_at .and. stats%n_block > 0) then
                    ! with the block's members held the problem has no solution: the reactions
                    ! grow by a fixed step per sweep and the error falls only by their growth (the
                    ! first test at 2 stall_first sweeps, against the state at stall_first), and
                    ! that growth moves no body (a self-stress; growing reactions that move bodies,
                    ! however slowly, are a slow convergence: module header, "Stall")
                    if (s > stall_first .and. num >= stall_residual*num_at .and. den >= stall_growth*den_at) then
                        if (block%must_yield(cs)) then
                            ! (the signature, whatever the growth moves: a strategy whose pass meets
                            ! its cap after it may give its block up, dem_bonded_block)
                            stats%growth_seen = .true.
                            if (growth_mobility(cs, im, vel, r_at, v_at) <= stall_mobility) then
                                stats%stalled = .true.
                                exit
                            end if
                        end if
                    end if
                    num_at = num
                    den_at = den
                    r_at = cs%r(:, 1:cs%n)
                    v_at = vel
                    stall_at = 2*s
                end if
                mix_now = accelerate .and. s > config%anderson_after
                if (mix_now) mix_now = aa%swept == max(config%anderson_sweeps, 1)
                ! with members, the block is solved after the Anderson step, for the mixed reactions
                if (present(block) .and. .not. (mix_now .and. stats%n_block > 0)) call block%solve(cs, im, vel, bilateral)
                ! safeguard of the over-relaxation
                if (omega /= 1.0_wp .and. mod(s, config%check_every) == 0) then
                    if (stats%error > checked) omega = 1.0_wp
                    checked = stats%error
                end if
                if (mix_now) then
                    ! after the last sweep only the judgement of the last mixed iterate (a mix
                    ! there would end the solve on an extrapolation no sweep judged: a stack at a
                    ! mass ratio of 5e5, every step at the cap of an unreachable tolerance, ended
                    ! a step on one that sent a disk at 2 453 m/s through the floor)
                    call anderson_mix(aa, cs, list, im, vfree, vel, split, bilateral, stats%n_block > 0, &
                                      s == config%max_sweeps)
                    aa%swept = 0
                    if (stats%n_block > 0) then
                        call block%solve(cs, im, vel, bilateral)
                        call gather(cs, list, aa%d, aa%x, .false.)
                    end if
                end if
                ! (not after the last sweep: the correction would not be judged either)
                if (correcting .and. mod(s, every) == 0 .and. s < config%max_sweeps) then
                    ! safeguard: no more corrections once the error at one is larger than at
                    ! the previous one
                    correcting = stats%error <= error_corrected
                    if (correcting) then
                        error_corrected = stats%error
                        call config%correction%correct(cs, list, im, vel)
                        stats%corrections = stats%corrections + 1
                        ! the correction is not a sweep: the history of the sweep map restarts
                        if (accelerate) call anderson_restart(aa)
                    end if
                end if
            end do
        end if
        stats%relaxation = omega
        stats%updates = int(n_swept, i8)*stats%sweeps
        stats%residual = nlgs_residual(cs, vel)
        if (siconos_stops .and. stats%converged .and. stats%n_block == 0) then
            ! the last error of the sweeps, computed in full (with a block, that of the
            ! problem with its members held: below, the error of the contact problem)
            stats%siconos_error = stats%error
        else
            stats%siconos_error = siconos_error(cs, im, vfree, vel, vwork, present(bilateral), nq)
        end if
        stats%siconos_floor = 0.0_wp
        if (siconos_stops .and. .not. stats%converged) &
            stats%siconos_floor = siconos_floor(cs, im, vfree, vel, nq)
    end subroutine nlgs_solve

    !> Name of the settings' stopping criterion (lmgc90 when none is set).
    pure function nlgs_criterion_name(config) result(name)
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        character(len=:), allocatable :: name
        if (allocated(config%criterion)) then
            name = config%criterion%name()
        else
            name = 'lmgc90'
        end if
    end function nlgs_criterion_name

    !> Name of the settings' cold start (zero when none is set: the sweeps start from zero
    !> reactions).
    pure function nlgs_start_name(config) result(name)
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        character(len=:), allocatable :: name
        if (allocated(config%start)) then
            name = config%start%name()
        else
            name = 'zero'
        end if
    end function nlgs_start_name

    !> No: the error that stops the sweeps is not the Siconos error.
    pure logical function criterion_not_siconos(self) result(yes)
        !> The criterion.
        class(nlgs_criterion_t), intent(in) :: self
        yes = .false.
    end function criterion_not_siconos

    !> How much the growth of the reactions since r_at moves the bodies (module header,
    !> "Stall"): d^T W d / sum_k d_k^T W_kk d_k for d = r - r_at over the active contacts, W_kk
    !> each contact's own Delassus block, with d^T W d = |vel - v_at|_M^2 (the velocities are
    !> those of the reactions: vel - v_at = M^-1 H d, the bilateral constraints' share
    !> included). 0 for a self-stress (impulses in equilibrium, which move nothing), 1 for the
    !> impulse of one contact alone; the velocities being known to roundoff, a quotient below
    !> roundoff^2 is a self-stress.
    pure real(wp) function growth_mobility(cs, im, vel, r_at, v_at) result(q)
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :), vel(:, :), r_at(:, :), v_at(:, :)
        real(wp) :: moved, alone, d(3)
        integer :: k
        moved = sum((vel - v_at)**2/max(im, tiny(1.0_wp)), mask=im > 0.0_wp)
        alone = 0.0_wp
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            d = cs%r(:, k) - r_at(:, k)
            alone = alone + dot_product(d, wmul(cs%w(:, k), d))
        end do
        if (alone > 0.0_wp) then
            q = moved/alone
        else
            q = merge(huge(1.0_wp), 0.0_wp, moved > 0.0_wp)
        end if
    end function growth_mobility

    !> Round-off floor of the convergence norm's denominator for contact k (module header).
    pure real(wp) function roundoff_floor(cs, k, vel) result(f)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: vel(:, :)
        integer :: a, b
        a = cs%i1(k)
        b = cs%i2(k)
        f = (cs%coh(k)*cs%w(1, k))**2 + (cs%coh(k)*cs%w(2, k))**2 + vel(1, b)**2 + vel(2, b)**2 &
            + (cs%amoy(k)*vel(3, b))**2
        if (a > 0) f = f + vel(1, a)**2 + vel(2, a)**2 + (cs%amoy(k)*vel(3, a))**2
        f = roundoff**2*f
    end function roundoff_floor

    !> sqrt(num/den), 0 for 0/0, huge for x/0.
    pure real(wp) function relative(num, den) result(q)
        real(wp), intent(in) :: num, den
        if (den > 0.0_wp) then
            q = sqrt(num/den)
        else if (num > 0.0_wp) then
            q = huge(1.0_wp)
        else
            q = 0.0_wp
        end if
    end function relative

    !> Take the blocked active contacts out of the solve (active = .false., r = 0) and count
    !> them: those whose normal direction is held by the fixities, W_nn <= blocked_ratio
    !> (W_nn + W_tt) (both bodies with fixed or imposed translations; W = 0 when their
    !> rotations are held too). Their normal reaction is not determined by the law (the imposed
    !> motion fixes u_n whatever r_n), so they are left out rather than given an unbounded
    !> reaction.
    pure subroutine skip_blocked(cs, n_blocked)
        type(contact_set_t), intent(inout) :: cs
        integer, intent(out) :: n_blocked
        integer :: k
        n_blocked = 0
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            if (cs%w(1, k) > blocked_ratio*(cs%w(1, k) + cs%w(3, k))) cycle
            cs%active(k) = .false.
            cs%r(:, k) = 0.0_wp
            n_blocked = n_blocked + 1
        end do
    end subroutine skip_blocked

    !> Add M^-1 H r of every active contact to vel.
    pure subroutine nlgs_apply_reactions(cs, im, vel)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        integer :: k
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            call contacts_apply_impulse(cs, k, im, vel, cs%r(1, k), cs%r(2, k), cs%r(3, k))
        end do
    end subroutine nlgs_apply_reactions

    !> W r for the 3x3 block w = (nn, nt, tt, nm, tm, mm).
    pure function wmul(w, r) result(v)
        real(wp), intent(in) :: w(6), r(3)
        real(wp) :: v(3)
        v(1) = w(1)*r(1) + w(2)*r(2) + w(4)*r(3)
        v(2) = w(2)*r(1) + w(3)*r(2) + w(5)*r(3)
        v(3) = w(4)*r(1) + w(5)*r(2) + w(6)*r(3)
    end function wmul

    !> |W r|^2 with the rotation row scaled by the length len (a velocity norm).
    pure real(wp) function wnorm2(w, r, len) result(q)
        real(wp), intent(in) :: w(6), r(3), len
        real(wp) :: v(3)
        v = wmul(w, r)
        q = v(1)**2 + v(2)**2 + (len*v(3))**2
    end function wnorm2

    !> One Gauss-Seidel sweep over the active contacts list(first), list(first + step), ...,
    !> list(last), with the scaled frames sc(:, first), sc(:, first + step), ... Per contact:
    !> local solve, relaxation, impulse applied to the bodies. num = sum |W dr|^2, den = sum
    !> |W r|^2 (r applied, not shifted), nloc = local iterations. With bilateral constraints,
    !> they are restored after each contact update. The work is done by sweep_contacts, on
    !> the arrays of the contact set.
    subroutine sweep(config, omega, cs, im, vel, list, sc, first, last, step, num, den, nloc, bilateral)
        type(nlgs_config_t), intent(in) :: config
        real(wp), intent(in) :: omega
        type(contact_set_t), intent(inout) :: cs
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: vel(:, :)
        integer, intent(in) :: list(:), first, last, step
        real(wp), intent(in), contiguous :: sc(:, :)
        real(wp), intent(out) :: num, den
        integer(i8), intent(out) :: nloc
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        num = 0.0_wp
        den = 0.0_wp
        nloc = 0_i8
        ! (no contact arrays to pass before the first contact)
        if ((last - first)*step < 0) return
        call sweep_contacts(config%local_tol, config%local_max_iter, omega, size(vel, 2), cs%n, cs%i1, cs%i2, &
                            cs%nrm, cs%lever, cs%shift, cs%w, cs%coh, cs%erol, cs%mu, cs%amoy, cs%r, cs%pcase, &
                            im, vel, size(list), list, size(sc, 2), sc, first, last, step, num, den, nloc, bilateral)
    end subroutine sweep

    !> The sweep on the arrays of the contact set (explicit shapes: the compiler keeps their
    !> addresses in registers instead of reloading the components' descriptors at every
    !> contact; the arithmetic is the same). The update is written out here rather than in a
    !> procedure of its own: this loop is the hot path of the solver, and whether gfortran
    !> inlined such a procedure depended on how many callers it had (one more caller made the
    !> sweep 35 % slower at 10^5 disks).
    subroutine sweep_contacts(local_tol, local_max_iter, omega, nd, n, i1s, i2s, nrm, lever, shift, w, coh, erol, &
                              mu, amoy, rc, pcases, im, vel, nl, list, ns, sc, first, last, step, num, den, nloc, &
                              bilateral)
        real(wp), intent(in) :: local_tol, omega
        integer, intent(in) :: local_max_iter, nd, n, nl, ns
        integer, intent(in) :: i1s(n), i2s(n)
        real(wp), intent(in) :: nrm(2, n), lever(2, n), shift(2, n), w(6, n), coh(n), erol(n), mu(n), amoy(n)
        real(wp), intent(inout) :: rc(3, n)
        integer, intent(inout) :: pcases(n)
        real(wp), intent(in) :: im(3, nd)
        real(wp), intent(inout) :: vel(3, nd)
        integer, intent(in) :: list(nl), first, last, step
        real(wp), intent(in) :: sc(rolling_n_scaling, ns)
        real(wp), intent(out) :: num, den
        integer(i8), intent(out) :: nloc
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        real(wp) :: u(3), r0(3), r(3), dr(3), wk(6), dvx, dvy, nx, ny, px, py
        integer :: a, k, it, pcase, i1, i2
        num = 0.0_wp
        den = 0.0_wp
        nloc = 0_i8
        do a = first, last, step
            k = list(a)
            ! u = H^T v + shift (contacts_solver_velocity, written out)
            i1 = i1s(k)
            i2 = i2s(k)
            dvx = vel(1, i2)
            dvy = vel(2, i2)
            u(2) = lever(2, k)*vel(3, i2) + shift(2, k)
            u(3) = vel(3, i2)
            if (i1 > 0) then
                dvx = dvx - vel(1, i1)
                dvy = dvy - vel(2, i1)
                u(2) = u(2) + lever(1, k)*vel(3, i1)
                u(3) = u(3) - vel(3, i1)
            end if
            nx = nrm(1, k)
            ny = nrm(2, k)
            u(1) = nx*dvx + ny*dvy + shift(1, k)
            u(2) = u(2) - ny*dvx + nx*dvy
            wk = w(:, k)
            r0 = [rc(1, k) + coh(k), rc(2, k), rc(3, k)]
            r = r0
            if (erol(k) > 0.0_wp) then
                call rolling_local_solve_scaled(sc(:, a), u - wmul(wk, r0), local_tol, local_max_iter, r, it, pcase)
            else
                ! no moment (r0(3) = 0, see contacts_set_laws): the two-component law
                call bipotential_local_solve_scaled(sc(1:bipotential_n_scaling, a), u(1) - wk(1)*r0(1) - wk(2)*r0(2), &
                                                    u(2) - wk(2)*r0(1) - wk(3)*r0(2), local_tol, local_max_iter, &
                                                    r(1), r(2), it, pcase)
            end if
            nloc = nloc + it
            pcases(k) = pcase
            if (omega /= 1.0_wp) call relax(omega, mu(k), erol(k), r0, r)
            dr = r - r0
            rc(1, k) = r(1) - coh(k)
            rc(2:3, k) = r(2:3)
            ! v += M^-1 H dr (contacts_apply_impulse, written out)
            px = dr(1)*nx - dr(2)*ny
            py = dr(1)*ny + dr(2)*nx
            vel(1, i2) = vel(1, i2) + im(1, i2)*px
            vel(2, i2) = vel(2, i2) + im(2, i2)*py
            vel(3, i2) = vel(3, i2) + im(3, i2)*(lever(2, k)*dr(2) + dr(3))
            if (i1 > 0) then
                vel(1, i1) = vel(1, i1) - im(1, i1)*px
                vel(2, i1) = vel(2, i1) - im(2, i1)*py
                vel(3, i1) = vel(3, i1) + im(3, i1)*(lever(1, k)*dr(2) - dr(3))
            end if
            num = num + wnorm2(wk, dr, amoy(k))
            den = den + wnorm2(wk, rc(:, k), amoy(k))
            if (present(bilateral)) call bilateral%update(i1s(k), i2s(k), vel)
        end do
    end subroutine sweep_contacts

    !> The domain split of the sweeps (OpenMP): nb contiguous blocks of the contact list (in
    !> contact order, i.e. bottom-up for disks numbered by height), swept at the same time,
    !> each in its own order; the contacts that touch a disk of another block (the interface)
    !> are swept after them, serially. nb = the number of OpenMP threads (1 without OpenMP or
    !> below split_min contacts per block, or with bilateral constraints): with nb = 1 the
    !> sweep is the serial one, and for a fixed nb the result does not depend on timing.
    subroutine nlgs_split_build(split, cs, list, n_disks, nb)
        !> The split.
        type(nlgs_split_t), intent(out) :: split
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Contacts of the solve, in sweep order.
        integer, intent(in) :: list(:)
        !> Number of disks.
        integer, intent(in) :: n_disks
        !> Number of blocks (OpenMP threads).
        integer, intent(in) :: nb
        integer, allocatable :: owner(:)
        integer :: n, b, a, k, lo, hi, nint, m
        logical, allocatable :: inter(:)
        n = size(list)
        split%nb = nb
        allocate (split%start(nb + 1))
        if (nb == 1) then
            split%start = [1, n + 1]
            split%order = list
            return
        end if
        allocate (owner(n_disks), source=0)
        allocate (inter(n), source=.false.)
        do b = 1, nb
            lo = 1 + int((int(b - 1, i8)*n)/nb)
            hi = int((int(b, i8)*n)/nb)
            do a = lo, hi
                k = list(a)
                call mark(cs%i2(k), b)
                if (cs%i1(k) > 0) call mark(cs%i1(k), b)
            end do
        end do
        do a = 1, n
            k = list(a)
            inter(a) = owner(cs%i2(k)) < 0
            if (cs%i1(k) > 0) inter(a) = inter(a) .or. owner(cs%i1(k)) < 0
        end do
        nint = count(inter)
        allocate (split%order(n))
        m = 0
        do b = 1, nb
            split%start(b) = m + 1
            lo = 1 + int((int(b - 1, i8)*n)/nb)
            hi = int((int(b, i8)*n)/nb)
            do a = lo, hi
                if (inter(a)) cycle
                m = m + 1
                split%order(m) = list(a)
            end do
        end do
        split%start(nb + 1) = m + 1
        split%order(m + 1:n) = pack(list, inter)
    contains
        subroutine mark(d, b)
            integer, intent(in) :: d, b
            if (owner(d) == 0) then
                owner(d) = b
            else if (owner(d) /= b) then
                owner(d) = -1
            end if
        end subroutine mark
    end subroutine nlgs_split_build

    !> One sweep with the domain split (nlgs_split_build), forward or backward: the blocks in
    !> parallel (each a plain sweep over its contiguous part of split%order and sc), the
    !> interface serially, after the blocks when forward, before them when backward.
    subroutine split_sweep(config, omega, cs, im, vel, sc, split, forward, num, den, nloc, bilateral)
        type(nlgs_config_t), intent(in) :: config
        real(wp), intent(in) :: omega
        type(contact_set_t), intent(inout) :: cs
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: vel(:, :)
        real(wp), intent(in), contiguous :: sc(:, :)
        type(nlgs_split_t), intent(in) :: split
        logical, intent(in) :: forward
        real(wp), intent(out) :: num, den
        integer(i8), intent(out) :: nloc
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        real(wp) :: nb_num(split%nb), nb_den(split%nb), inum, iden, lnum, lden
        integer(i8) :: nb_loc(split%nb), iloc, lloc
        integer :: b, n, fi
        n = size(split%order)
        if (split%nb == 1) then
            if (forward) then
                call sweep(config, omega, cs, im, vel, split%order, sc, 1, n, 1, num, den, nloc, bilateral)
            else
                call sweep(config, omega, cs, im, vel, split%order, sc, n, 1, -1, num, den, nloc, bilateral)
            end if
            return
        end if
        fi = split%start(split%nb + 1)
        if (.not. forward) call sweep(config, omega, cs, im, vel, split%order, sc, n, fi, -1, inum, iden, iloc)
        ! The sums go to locals of the thread, stored once per block: accumulating into
        ! nb_num(b) directly, the threads share a cache line and every update invalidates it
        ! on the other core (2 threads were 2.3 times slower than 1 at 10^5 disks).
        !$omp parallel do schedule(static, 1) num_threads(split%nb) private(lnum, lden, lloc)
        do b = 1, split%nb
            if (forward) then
                call sweep(config, omega, cs, im, vel, split%order, sc, split%start(b), split%start(b + 1) - 1, 1, &
                           lnum, lden, lloc)
            else
                call sweep(config, omega, cs, im, vel, split%order, sc, split%start(b + 1) - 1, split%start(b), -1, &
                           lnum, lden, lloc)
            end if
            nb_num(b) = lnum
            nb_den(b) = lden
            nb_loc(b) = lloc
        end do
        !$omp end parallel do
        if (forward) call sweep(config, omega, cs, im, vel, split%order, sc, fi, n, 1, inum, iden, iloc)
        num = 0.0_wp
        den = 0.0_wp
        nloc = iloc
        do b = 1, split%nb
            num = num + nb_num(b)
            den = den + nb_den(b)
            nloc = nloc + nb_loc(b)
        end do
        num = num + inum
        den = den + iden
    end subroutine split_sweep

    !> Over-relaxed update: r = P_K(r0 + omega (r - r0)) (Euclidean projection on the cone of
    !> the contact, shifted reactions), so that r stays admissible for omega > 1.
    pure subroutine relax(omega, mu, e, r0, r)
        real(wp), intent(in) :: omega, mu, e, r0(3)
        real(wp), intent(inout) :: r(3)
        real(wp) :: t(3)
        integer :: pcase
        t = r0 + omega*(r - r0)
        if (e > 0.0_wp) then
            call rolling_projection(t(1), t(2), t(3), mu, e, r(1), r(2), r(3), pcase)
        else
            call coulomb_projection(t(1), t(2), mu, r(1), r(2), pcase)
        end if
    end subroutine relax

    !> Relative residual of the contact laws in the current state:
    !> sqrt(sum res_a^2) / sqrt(sum |r'_a|^2) over active contacts, with res_a from
    !> bipotential_residual or rolling_residual (scaled frame, shifted reaction) and r' the
    !> applied reaction in the scaled frame (W_nn r_n^2 + W_tt r_t^2 + W_mm M^2); as for the
    !> sweeps, the round-off noise (the floor of the module header divided by W_nn, in the
    !> units of the scaled frame) is taken off the numerator.
    pure real(wp) function nlgs_residual(cs, vel) result(res)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Velocities (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        real(wp) :: u(3), r(3), num, den, noise
        integer :: k
        num = 0.0_wp
        den = 0.0_wp
        noise = 0.0_wp
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            call contacts_solver_velocity(cs, k, vel, u)
            r = [cs%r(1, k) + cs%coh(k), cs%r(2, k), cs%r(3, k)]
            if (cs%erol(k) > 0.0_wp) then
                num = num + rolling_residual(cs%w(:, k), u, cs%mu(k), cs%erol(k), r)**2
            else
                num = num + bipotential_residual(cs%w(1, k), cs%w(2, k), cs%w(3, k), u(1), u(2), cs%mu(k), r(1), r(2))**2
            end if
            den = den + cs%w(1, k)*cs%r(1, k)**2 + cs%w(3, k)*cs%r(2, k)**2 + cs%w(6, k)*cs%r(3, k)**2
            if (cs%w(1, k) > 0.0_wp) noise = noise + roundoff_floor(cs, k, vel)/cs%w(1, k)
        end do
        res = relative(max(num - noise, 0.0_wp), den)
    end function nlgs_residual
end module dem_nlgs
