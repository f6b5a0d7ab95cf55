!> The intact bonds of a step solved directly, as one block of bilateral constraints
!> (block Gauss-Seidel with the NLGS sweeps over the other contacts; doc/theory.md,
!> "Bonded block").
!>
!> B is the set of active intact bonds (status_cohesive, not blocked). While a bond holds,
!> its reaction lies inside its cone and the law asks u = 0 for every locked component: the
!> normal one always, the tangential one when mu_b > 0, the rotation when e_b > 0 (a bound
!> with a zero coefficient locks nothing: that component carries no reaction, as in the
!> sweeps). The cohesion shifts only the reaction (r_n + r_cohe h in the cone), not the
!> velocity, so the equality u_B = H_B^T v + shift = 0 holds with the same solver shift as
!> the sweeps use. With the other reactions fixed, the change of the bond reactions dr solves
!>     (W_BB + eps I) dr = -u_B,   W_BB = H_B^T M_eff^-1 H_B,
!> where M_eff^-1 is M^-1 minus the share of the bilateral constraints of the solve (the
!> Arlequin coupling rows, `nlgs_bilateral_t%mobility`): the rows join the block exactly, and
!> `restore` then applies their multipliers. W_BB is sparse (one 3x3 block per pair of bonds
!> that share a disk; a dense corner among the bonds on coupled disks) and is factored by
!> CHOLMOD (core_sparse) as a simplicial L D L^T, the form whose rows CHOLMOD can delete
!> (below); on the reference stack its solves cost no more than the supernodal L L^T's.
!>
!> Scaling and regularisation: the factor is of S W_BB S + E, S = diag(H_B^T M^-1 H_B)^(-1/2)
!> (W_BB's own diagonal without coupling rows) and E diagonal, eps_force = 1e-8 on the force
!> components (r_n, r_t) and eps_moment = 1e-12 on the moments; the passes solve for y = S^-1
!> dr. W_nn and W_tt are in 1/kg, W_mm in 1/(kg m^2): the former eps = 1e-12 max diag(W_BB)
!> was, for the force components, 1e-12 W_mm/W_nn ~ 2e-12/R^2 of their diagonal: 2e-8 for
!> R = 1 cm, but 200 for micrometre grains in metres (R = 1e-7 m), whose bonds then converged
!> by 2.5e-5 per pass, every step unconverged with the bond carrying 2.4 % of the load. Scaled,
!> every diagonal entry is 1 and the block, its convergence and its choice among redundant
!> reactions are the same in any unit of length. With the coupling rows the scaled diagonal of
!> W_BB is below 1 (a glued disk's mobility less the beam's share): its entries round off as
!> those of H_B^T M^-1 H_B, to which E is relative. Redundant bonds (a closed loop, e.g. a
!> triangle of a hexagonal stack, or bonds between disks glued to a beam) make W_BB singular:
!> its kernel holds the self-stresses, which the velocities do not see; E makes the matrix
!> definite. The two values are those the former eps had, per component, at the centimetre
!> scale where the decks and tests were made: the least norm (below) multiplies the rounding of
!> the kernel (relative u ~ 1e-16 of the entries) by about u/eps^2, 1 for eps_force, which the
!> kernels of the force components need (a lattice torn by imposed velocities, whose block has
!> no solution: with 1e-12 its reactions reached 5e6 and flung disks at 1 600 m/s; the glued
!> stack below gained energy), while the bending modes of a long row, eigenvalues down to about
!> 1e-7 of the diagonal, need a small eps on the moments to converge in a few passes (1e-8
!> there: errors of 9e-6 on a clamped row of 50 disks). The moments' self-stresses in loops are
!> then set to about u/eps_moment^2 = 1e-8 relative (a lattice at two units of length: moments
!> equal to 1.1e-7, forces to 1e-12).
!>
!> Least norm: each pass takes y = (A + E)^-1 A (A + E)^-1 S (-u_B), A = S W_BB S, dr = S y
!> (two solves with the same factor, `solve_least_norm`; W_BB (W_BB + eps I)^-2 when E = eps I,
!> as written below): the change of (A + E)^-1 S (-u_B) to a relative eps/lambda on an
!> eigen-component lambda >> eps, and none on the kernel. The metric of the least norm is
!> y^T E y = sum eps_c W_uu dr_u^2: each component weighted by its own mobility, independent
!> of the units. The first solve alone
!> multiplies by 1/eps the part of -u_B in the kernel, which no change of the reactions
!> removes: round-off of the velocities, or targets of bonds and coupling rows that disagree
!> by a little. That part became a self-stress of the bonds and the coupling rows 10^12 times
!> its size, which grew from step to step (larger reactions, larger round-off) until a bond
!> broke and released it as kinetic energy: a cohesive stack with all its layers glued to a
!> beam gained 1 J on 2e-7 J of external work, every step reported converged. Both the least
!> norm and the scale of eps are needed: with the rows' share the kernel's computed
!> eigenvalues are the rounding of the larger entries, near eps of max diag(W_BB), where
!> W (W + eps I)^-2 still amplifies by 1/(4 eps) (the stack, at a tolerance of 1e-8, gained
!> 1 J with the least norm alone, 654 J with the scale alone).
!>
!> The bias (a relative error of about 2 eps/lambda on an eigen-component lambda of W_BB) is
!> removed by iterative refinement with the same factor, the residual being recomputed from
!> the velocities themselves (-u_B after the impulses are applied, not W_BB x: the reactions
!> of a long chain are poorly determined by W_BB, whose condition grows like N^4, and the
!> velocity residual is the exact one): each pass contracts a component by
!> 1 - lambda^2/(lambda + eps)^2 and, for a singular but consistent system, converges to the
!> solution of least norm. The residual is measured in velocities, rotations times the mean
!> radius (as the noise below and `measure`; in rad/s the rotations' round-off, 1/R times the
!> rest, stalled the scaled passes and made every stale factor look worn: 890 factorisations in
!> 1000 steps of the reference stack instead of 2). It stops at the round-off of the velocities
!> (64 eps |v|, as the NLGS's floor), when the residual no longer halves, or after max_passes.
!>
!> Reuse: the symbolic analysis is kept while the bond graph (the pairs of B and their
!> locked components, in order) does not change. The values of W_BB change at every step in
!> a moving structure (the frames turn with the disks), but only by the rotation of the
!> frames over a step, so a factor of older values is a near-exact solver: the refinement
!> with it contracts by about that relative change per pass. The factor is therefore kept
!> while a refinement pass reduces the residual by at least stale_contraction (1e-2), and
!> refactored with the current values as soon as one does not; with the same values
!> (bitwise) it is always exact. On the reference stack (doc/performance.md, "Bonded
!> block") 1000 steps need 2 numerical factorisations and about 3 refinement passes per
!> step, against one factorisation per step for a refactor at every step, which cost 40 %
!> of the block's time.
!>
!> Released bonds leave the factor (`delete_slots`): the unknowns of the analysed pattern
!> are those of its slots, one per bond of B at the analysis. When a bond leaves B (released
!> by the outer check, or broken at the end of a step) its slot dies: its rows and columns of
!> W_BB + eps I become those of the identity, and the factor is modified accordingly
!> (CHOLMOD's row deletion, `sparse_solver_t%delete_rows`) instead of a new analysis and
!> factorisation of B without it; its right-hand side is zero, so its change is zero, and
!> the factor solves the other slots exactly as a new one would (to rounding). Its reaction
!> then comes from the sweeps, as before. B is matched against the live slots: the same
!> bonds (a reuse as above), or the same but some (deleted), or else (a new or returning
!> bond) the pattern of B is analysed afresh, as it is when the dead rows would exceed
!> max_dead_fraction of the unknowns (their fill stays in the factor and every solve pays for
!> it). A dead slot's entries are zeros and its diagonal 1 in the values, so a refactor with
!> the current values (stale factor) keeps it dead, and the stale test compares the live
!> entries only. Within a step the values do not change: the passes after a release keep
!> those of the first (and their scaling). The factor keeps the scaling S it was made with
!> (scale_factored): a stale factor solves with it, as the matrix it factored. A checkpoint
!> holds the values of the last factorisation, its scaling, the dead slots and the slots
!> deleted since, in order; the restart factors those values and
!> deletes them again, so that the factor, and the run, stay bitwise the same.
!>
!> Outer check (`bonded_block_solve`): after a converged solve every bond of B is checked
!> against its cone, r_n + r_cohe h >= 0, |r_t| <= mu_b (r_n + r_cohe h), |M| <= e_b (r_n +
!> r_cohe h). A bond outside it cannot hold as a bilateral constraint: the one farthest
!> outside (cone_excess) leaves B for the rest of the step, joins the sweeps with its own
!> (cohesive) law, and the step is solved again from the current reactions (its slot deleted
!> from the factor, above), one bond per pass (released together, the overloaded bonds of a
!> clamped bonded row were swept against the rigid rest of the block and never converged;
!> once the root yields the others are back inside their cones). When the block's equalities have no solution (`consistent`), every
!> bond outside its cone is released at once. A bond left in B on a bound is judged at it
!> (bound_case). This is the problem the plain NLGS solves, so the
!> judgement of dem_contacts (contacts_finish) then breaks it exactly as after the NLGS.
!> Stall: a pass whose problem has no solution with the bonds held (a wall of imposed velocity
!> pushing a stack that its bonds hold on the floor) never converges, its reactions growing by
!> a fixed step per iteration along a self-stress that moves no body; dem_nlgs stops it
!> (`nlgs_stats_t%stalled`, when a bond lies outside its cone, `must_yield`, and the growth
!> moves nothing: a slow convergence, whose growth moves bodies, is not stopped) and it is
!> judged as a converged pass, the step solved again from the reactions at its start, the
!> grown ones carrying a self-stress of arbitrary size (before: every step at the cap, no bond
!> released, the wall through the disks; doc/theory.md 7.10, "Stall").
!> A pass is converged by the error of the problem it solves, the bonds of B held: the norm of
!> the sweeps with the block's share |u_B|^2, or with criterion = siconos the Siconos error
!> with the members measured by their equalities (nlgs criterion `begin`, `held`). Measured
!> against their cones, bonds that must yield kept the error of every pass at their excess
!> (7.2e-2 on a bonded row hit by a disk, at the cap of 50 000 iterations): the outer check
!> never ran and no bond was released (doc/theory.md 7.10, "The stopping test of a pass").
!>
!> Cap and energy guard (`bonded_block_solve`; doc/theory.md 7.10): config%max_sweeps bounds the
!> block iterations of the step, all passes together; a step out of them with a bond still
!> outside its cone ends unconverged. The norm of the passes is relative to sum |W r|^2, which
!> the self-stresses of a lattice's loops inflate without any velocity: such a pass meets the
!> tolerance after an iteration or two whatever its velocities, and a release then clips a
!> bond's share of the self-stress and throws the rest of the loop apart (a bonded lattice
!> thrown into a corner: 1.3 J/m of free kinetic energy, 2.5e7 J/m after 67 passes of one
!> step, each at the tolerance). After each pass the energy the reactions created,
!> |v|_M^2/2 - |v_free|_M^2/2 + r.s = r.u - |H r|^2_{M^-1}/2 (s the solver shifts), at most
!> -|H r|^2_{M^-1}/2 at a solution, is compared with created_fraction of the kinetic energy
!> plus the round-off of the terms (`bonded_block_creates_energy`: 64 eps of the energies and
!> of sum |r.s|, and the kinetic energy of velocities in error by 64 eps of |v_free| + sum
!> |M^-1 H_k| |r_k|; without it a self-stressed lattice at rest, its load removed and no
!> gravity, whose velocities and created energy are round-off alone, 1e-60 J/m from 1e-66
!> J/m free, was given up at a step in six);
!> above it the block is given up for the step, which the plain sweeps solve again from the
!> free velocities and zero reactions (the warm start carries the self-stresses) with a cap
!> of their own. Not with bilateral constraints (their multipliers work on the disks too),
!> and only in a step whose block held bonds: without intact bonds the step is method =
!> nlgs's, bit for bit, its unconverged steps included.
!> The block is given up the same way when a pass ends at the cap unconverged, not stalled,
!> after one of its stall tests saw the reactions grow as without a solution (nlgs_stats_t%
!> growth_seen: the signature, the growth moving bodies), with a bond of B outside its cone
!> at its end (must_yield): a problem without solution whose growth moves bodies, which the
!> stall test cannot tell from a slow convergence (the audit's 6 x 4 stack pushed by a wall,
!> turning about its last floor bond: every step from the fifth at the cap, no bond broken,
!> the wall 1.9e-4 m into the disks; now 24 ruptures, 20 with method = nlgs, the wall out
!> of the disks but for the (1 - theta) h v of a contact made within a step). A pass that
!> met the cap converging (the thrown lattice at max_sweeps = 100 with anderson = 0 or
!> criterion = siconos), or with the few iterations that releases left it (the same lattice:
!> the step, not the pass, is out of iterations), keeps the block. A slow convergence with
!> a solution can meet the cap with the same signature (a clamped bonded row hit by heavy
!> disks, which needs 999 iterations, at max_sweeps = 200: plain sweeps at 5.4e-3 where
!> the block reached 3.3e-4): the block's state at the cap is kept, and when the plain
!> sweeps end unconverged with a larger error the give-up is taken back, the step ending on
!> the block's answer as if it had been kept (block_given_up_reverted). stats%block_given_up
!> tells the cases apart.
!>
!> Released bonds that hold a part alone (`condense`): a released bond whose two bodies are
!> not connected through B carries the part beyond it by itself, a rigid body or a structure
!> of B. The plain sweep updates it with its own block W_kk (its two disks), where the part
!> answers with the condensed block S = W_kk - W_kB W_BB^-1 W_Bk, so each block iteration
!> contracts its error by about 1 - S/W_kk: for the root of a clamped row of 8 disks released
!> in shear, whose moment stays inside its cone and turns the 7 other disks as one body,
!> S/W_kk = 4.3e-3 on the rotation, and the pass took 2 000 to 3 000 iterations. When a pass
!> is still going after condense_after iterations, such bonds (S_ii <= released_ratio W_ii on
!> a locked component) take a step of their local law with S after each block solve, the
!> block solved again after each (block Gauss-Seidel on the Schur complement: alone, the
!> bond is then solved in one step). Bonds closing a loop of B (a lattice) keep the plain
!> sweeps: the loop locks them in some directions, and a condensed step costs a block solve.
!> Not with bilateral constraints (a coupled run): their share of W_kB is not in S.
module dem_bonded_block
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use core_state, only: state_sink_t, state_source_t
    use core_sparse, only: sparse_matrix_t, sparse_solver_t, sparse_ldlt, sparse_stats_t
    use dem_contacts, only: contact_set_t, status_cohesive, bond_on_bound, contacts_directions
    use dem_bipotential, only: case_stick, case_slip, case_roll, case_slip_roll, rolling_local_solve, &
                               bipotential_local_solve
    use dem_nlgs, only: nlgs_config_t, nlgs_stats_t, nlgs_solve, nlgs_apply_reactions, nlgs_block_t, &
                        nlgs_bilateral_t, block_kept, block_given_up_energy, block_given_up_unconverged, &
                        block_given_up_reverted
    use dem_solve_method, only: solve_method_t
    implicit none
    private
    public :: bonded_block_t, bonded_block_counts_t, bonded_block_method_t, bonded_block_eps_force, bonded_block_eps_moment, &
              bonded_block_restore, bonded_block_creates_energy

    !> Regularisation of the scaled block S W_BB S (module header, "Scaling and
    !> regularisation"): eps on the force components (r_n, r_t), ...
    real(wp), parameter :: bonded_block_eps_force = 1.0e-8_wp
    !> ... and on the moments.
    real(wp), parameter :: bonded_block_eps_moment = 1.0e-12_wp
    !> Largest number of passes (solve and refinements) per block solve.
    integer, parameter :: max_passes = 6
    !> A kept factor of older values is refactored when a pass reduces the residual by less
    !> than this factor.
    real(wp), parameter :: stale_contraction = 1.0e-2_wp
    !> Relative resolution of a relative velocity (64 machine epsilons of the velocities of
    !> the two bodies, as in dem_nlgs): the refinement stops below it.
    real(wp), parameter :: roundoff = 64.0_wp*epsilon(1.0_wp)
    !> A reaction of the block within this fraction of a bound is on it (bound_case), as for
    !> the rupture judgement of dem_contacts.
    real(wp), parameter :: on_bound = bond_on_bound
    !> The bonds' equalities are met when their residual is below this fraction of the
    !> velocities (a consistent system refines down to roundoff, an inconsistent one keeps a
    !> residual of the order of the velocities).
    real(wp), parameter :: consistent_ratio = 1.0e-6_wp

    !> A kept factor whose dead rows (bonds that left B, deleted from it) would exceed this
    !> fraction of its unknowns is replaced by the analysis and factorisation of B alone: the
    !> dead rows keep their share of the factor's fill, which every solve pays for.
    real(wp), parameter :: max_dead_fraction = 0.25_wp

    !> Block iterations of a solve (its warm start included) before the released bonds take
    !> condensed steps (`solve`). A condensed step costs a block solve where a plain update
    !> costs one contact, and the released bonds of a pass that converges sooner need none
    !> (warm-started from the pass before); a pass still going after them is one where the
    !> plain sweeps crawl.
    integer, parameter :: condense_after = 30
    !> A released bond takes condensed steps when its condensed block is at most this
    !> fraction of its own on a locked component (S_ii <= released_ratio W_ii): the plain
    !> sweeps contract by about 1 - S_ii/W_ii on it, 0.99 or slower (a clamped row of 8
    !> disks whose root is released in shear: 4.3e-3 on the rotation).
    real(wp), parameter :: released_ratio = 1.0e-2_wp
    !> Floor of the condensed block of a released bond, relative to its own block W_kk
    !> (`condense`): S + released_floor W_kk. S is a difference, W_kk - W_kB X, which loses
    !> the digits of S/W_kk; the floor keeps it definite and changes the step of a component
    !> by released_floor/(S_ii/W_ii), 2.3e-4 for the row above.
    real(wp), parameter :: released_floor = 1.0e-6_wp
    !> Energy guard (module header, "Cap and energy guard"): a pass may create at most this fraction of the larger
    !> kinetic energy of the free and the end velocities (created_energy).
    real(wp), parameter :: created_fraction = 0.1_wp

    !> Counts since the block was created (for statistics and benchmarks).
    type :: bonded_block_counts_t
        !> Symbolic analyses (bond graph changed).
        integer(i8) :: analyses = 0
        !> Numerical factorisations.
        integer(i8) :: factorisations = 0
        !> Set-ups that kept the previous factor (graph unchanged; values unchanged, or the
        !> factor still contracts the refinement well).
        integer(i8) :: reuses = 0
        !> Block solves (each with its refinement passes).
        integer(i8) :: solves = 0
        !> Refinement passes.
        integer(i8) :: refinements = 0
        !> Bonds moved out of the block by the outer check.
        integer(i8) :: releases = 0
        !> Steps solved again after a release.
        integer(i8) :: resolves = 0
        !> Bonds deleted from a kept factor (identity rows) as they left B.
        integer(i8) :: deletions = 0
        !> Set-ups whose factorisation failed (the bonds were then swept as by the NLGS).
        integer(i8) :: failures = 0
        !> Steps whose block solve was given up (energy guard, or unconverged at the cap) and
        !> solved by the plain sweeps.
        integer(i8) :: give_ups = 0
    end type bonded_block_counts_t

    !> The bonded block and its factor (kept from step to step: see the module header).
    type, extends(nlgs_block_t) :: bonded_block_t
        !> Counts.
        type(bonded_block_counts_t) :: counts
        !> Contact k left the block at this step (outer check); set by bonded_block_solve.
        logical, allocatable :: excluded(:)
        !> Number of slots (the bonds of the analysed pattern) and of their unknowns.
        integer :: nb = 0, nu = 0
        !> Number of bonds in B (the live slots).
        integer :: n_live = 0
        !> Contact index of the bond of each slot in B, 0 for a dead slot (nb).
        integer, allocatable :: bond(:)
        !> First unknown of each slot (nb + 1).
        integer, allocatable :: first(:)
        !> Component (1 = r_n, 2 = r_t, 3 = M) of each unknown (nu).
        integer, allocatable :: comp(:)
        !> Bond graph of the analysed pattern: pairs and locked components (bitmask) of each
        !> slot.
        integer, allocatable :: key_i1(:), key_i2(:), key_rows(:)
        !> The slot's bond has left B: its rows are those of the identity in the factor (nb).
        logical, allocatable :: dead(:)
        !> Slots deleted from the factor since its numerical factorisation, in order (the
        !> others dead were identity rows of the values factored).
        integer, allocatable :: deleted(:)
        !> Number of entries of `deleted` in use.
        integer :: n_deleted = 0
        !> The step is being solved again after a release (set by bonded_block_solve): the
        !> values of W_BB are those of the pass before.
        logical :: resolving = .false.
        !> A pattern is analysed.
        logical :: analysed = .false.
        !> A factor of the current pattern is held.
        logical :: factored = .false.
        !> The factor is of older values than the current ones (kept while it contracts).
        logical :: stale = .false.
        !> A refactorisation failed during this solve: the block is not solved.
        logical :: lost = .false.
        !> The last solve met the bonds' equalities (residual within `consistent_ratio` of
        !> the velocities): false when they have no solution, e.g. bonds between bodies
        !> whose velocities are imposed apart (the regularised solve then leaves a residual
        !> of the order of the velocities, with reactions of order 1/eps).
        logical :: consistent = .true.
        !> S W_BB S + E (lower triangle; module header, "Scaling and regularisation").
        type(sparse_matrix_t) :: mat
        !> Its factorisation.
        type(sparse_solver_t) :: solver
        !> Position of each diagonal entry in mat%values (nu).
        integer(i8), allocatable :: diag(:)
        !> Entries of the assembly (row, column, value) in assembly order, their number, and
        !> the position of each in mat%values (the order depends on the graph only, so the
        !> positions found once per pattern refill the values at the next steps).
        integer, allocatable :: ti(:), tj(:)
        !> Values of the assembled triplets (see `ti`).
        real(wp), allocatable :: tv(:)
        !> Number of triplets in use in ti, tj, tv.
        integer :: nt = 0
        !> Entries of H_B^T M^-1 H_B among them (the first; the coupling rows' share follows).
        integer :: nt_plain = 0
        !> Position of each triplet in mat%values (see `ti`).
        integer(i8), allocatable :: pos(:)
        !> Values of the last factorisation.
        real(wp), allocatable :: values_factored(:)
        !> Scaling S of the current values (nu): mat%values holds S W_BB S + E.
        real(wp), allocatable :: scale(:)
        !> Scaling of the values of the factor (values_factored), with which `solve_least_norm`
        !> scales the right-hand side and the change.
        real(wp), allocatable :: scale_factored(:)
        !> Work arrays (nu).
        real(wp), allocatable :: rhs(:), x(:), y(:)
        !> Bonds released by the outer check that are swept in this solve (contacts), their
        !> number, and their Delassus blocks condensed on the block (6, n_released: nn, nt,
        !> tt, nm, tm, mm; `condense`), computed at the first solve after `prepare`.
        integer, allocatable :: released(:)
        !> Number of entries of `released` in use.
        integer :: n_released = 0
        !> Condensed blocks of the released bonds (see `released`).
        real(wp), allocatable :: condensed(:, :)
        !> The condensed blocks are those of the current set-up.
        logical :: condensed_ready = .false.
        !> Block solves since `prepare` (the warm start's included).
        integer :: iterations = 0
        !> Local solver settings for the released bonds' condensed step (from nlgs_config_t).
        real(wp) :: local_tol = 1.0e-10_wp
        !> See `local_tol`.
        integer :: local_max_iter = 8
        !> Restart (`bonded_block_restore`): values of the factor in use at the checkpoint,
        !> factored at the next `prepare` when its bond graph is the restored key, and the
        !> slots then deleted from it, in order.
        real(wp), allocatable :: restore_values(:)
        !> See `restore_values`: their scaling.
        real(wp), allocatable :: restore_scale(:)
        !> See `restore_values`.
        integer, allocatable :: restore_deleted(:)
    contains
        !> See `nlgs_block_t%prepare`.
        procedure :: prepare
        !> See `nlgs_block_t%solve`.
        procedure :: solve
        !> See `nlgs_block_t%measure`.
        procedure :: measure
        !> See `nlgs_block_t%must_yield`.
        procedure :: must_yield
    end type bonded_block_t

    !> The global strategy `[solver] method = block` (dem_solve_method): the bonded block,
    !> kept from step to step, and the sweeps over the other contacts (bonded_block_solve).
    type, extends(solve_method_t) :: bonded_block_method_t
        !> The block and its factor.
        type(bonded_block_t) :: block
    contains
        !> See `solve_method_t%solve`.
        procedure :: solve => bonded_block_solve
        !> 'block'.
        procedure :: name => bonded_block_name
        !> The factor in use: its bond graph and values (`bonded_block_save_state`).
        procedure :: save_state => bonded_block_save_state
        !> See `save_state`.
        procedure :: load_state => bonded_block_load_state
    end type bonded_block_method_t

contains

    !> 'block'.
    pure function bonded_block_name(self, config) result(name)
        !> The strategy.
        class(bonded_block_method_t), intent(in) :: self
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        character(len=:), allocatable :: name
        name = 'block'
    end function bonded_block_name

    !> Restart from a checkpoint: the block had a factor of `values` (mat%values with eps,
    !> values_factored) for the bond graph (key_i1, key_i2, key_rows). The next `prepare`
    !> whose bond graph is that one factors these values instead of the current ones, so
    !> that the same (possibly stale) factor is used as in the uninterrupted run and the
    !> results stay bitwise the same; otherwise it proceeds as usual.
    subroutine bonded_block_restore(block, key_i1, key_i2, key_rows, values, scale, dead, deleted)
        !> The block (new).
        type(bonded_block_t), intent(inout) :: block
        !> Bond graph of the factor: pairs and locked components (bitmask) of each slot.
        integer, intent(in) :: key_i1(:), key_i2(:), key_rows(:)
        !> Values of the factor.
        real(wp), intent(in) :: values(:)
        !> Their scaling S (scale_factored: the values are S W_BB S + E), one per unknown.
        real(wp), intent(in) :: scale(:)
        !> Dead slots (identity rows in the factor), and those of them deleted from it after
        !> its factorisation, in order.
        logical, intent(in) :: dead(:)
        !> See `dead`.
        integer, intent(in) :: deleted(:)
        block%key_i1 = key_i1
        block%key_i2 = key_i2
        block%key_rows = key_rows
        block%dead = dead
        block%restore_values = values
        block%restore_scale = scale
        block%restore_deleted = deleted
        block%analysed = .false.
        block%factored = .false.
    end subroutine bonded_block_restore

    !> Put the factor in use, if any: the bond graph (key_i1, key_i2, key_rows) and the values
    !> factored with their scaling (values, scale), and the slots whose bonds left the block
    !> (dead, as 0 or 1, when any: identity rows, some deleted from the factor after its
    !> factorisation: deleted, in order, replayed at the restart). A restart factors these
    !> values again (`bonded_block_load_state`).
    subroutine bonded_block_save_state(self, sink, error)
        !> The strategy.
        class(bonded_block_method_t), intent(in) :: self
        !> Where the state goes.
        class(state_sink_t), intent(inout) :: sink
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        associate (b => self%block)
            if (.not. (b%factored .and. allocated(b%values_factored))) return
            if (size(b%key_i1) == 0) return
            call sink%put_integers('key_i1', b%key_i1, error)
            if (.not. allocated(error)) call sink%put_integers('key_i2', b%key_i2, error)
            if (.not. allocated(error)) call sink%put_integers('key_rows', b%key_rows, error)
            if (.not. allocated(error)) call sink%put_reals('values', b%values_factored, error)
            if (.not. allocated(error)) call sink%put_reals('scale', b%scale_factored, error)
            if (.not. any(b%dead)) return
            if (.not. allocated(error)) call sink%put_integers('dead', merge(1, 0, b%dead), error)
            if (.not. allocated(error) .and. b%n_deleted > 0) &
                call sink%put_integers('deleted', b%deleted(1:b%n_deleted), error)
        end associate
    end subroutine bonded_block_save_state

    !> Take back the factor put by `bonded_block_save_state` and restore it
    !> (`bonded_block_restore`); nothing when none is stored, or one of an earlier build without
    !> its scaling: its values are those of W_BB + eps I, not of S W_BB S + eps I, and the
    !> restart then factors the current values (the run goes on within the solver's tolerance,
    !> not bitwise).
    subroutine bonded_block_load_state(self, source, n_disks, n_walls, error)
        !> The strategy (built from the deck).
        class(bonded_block_method_t), intent(inout) :: self
        !> Where the state comes from.
        class(state_source_t), intent(in) :: source
        !> Numbers of disks and walls of the system (the range of the bond graph's bodies).
        integer, intent(in) :: n_disks, n_walls
        !> Set on a read failure or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: k1(:), k2(:), kr(:), dead(:), deleted(:)
        real(wp), allocatable :: v(:), scale(:)
        if (.not. source%has('values')) return
        if (.not. source%has('scale')) return
        call source%get_reals('scale', scale, error)
        if (allocated(error)) return
        call source%get_integers('key_i1', k1, error)
        if (.not. allocated(error)) call source%get_integers('key_i2', k2, error)
        if (.not. allocated(error)) call source%get_integers('key_rows', kr, error)
        if (.not. allocated(error)) call source%get_reals('values', v, error)
        if (allocated(error)) return
        if (size(k2) /= size(k1) .or. size(kr) /= size(k1)) then
            call source%damaged('key_i1, key_i2 and key_rows differ in size', error)
            return
        end if
        allocate (dead(size(k1)), deleted(0))
        dead = 0
        if (source%has('dead')) call source%get_integers('dead', dead, error)
        if (allocated(error)) return
        if (source%has('deleted')) call source%get_integers('deleted', deleted, error)
        if (allocated(error)) return
        if (size(dead) /= size(k1)) then
            call source%damaged('dead and key_i1 differ in size', error)
            return
        end if
        call source%require_range('dead', dead, 0, 1, error)
        if (.not. allocated(error)) call source%require_range('deleted', deleted, 1, size(k1), error)
        if (allocated(error)) return
        if (size(deleted) > 0) then
            if (any(dead(deleted) == 0)) then
                call source%damaged('a slot of deleted is not dead', error)
                return
            end if
        end if
        call source%require_range('key_i1', k1, -n_walls, n_disks, error)
        if (.not. allocated(error)) call source%require_range('key_i2', k2, 1, n_disks, error)
        if (allocated(error)) return
        if (size(scale) /= sum(popcnt(kr))) then
            call source%damaged('scale has not one value per unknown of key_rows', error)
            return
        end if
        call bonded_block_restore(self%block, k1, k2, kr, v, scale, dead == 1, deleted)
    end subroutine bonded_block_load_state

    !> Solve the contact problem of one step with the intact bonds as a direct block and
    !> the NLGS sweeps over the other contacts (block Gauss-Seidel), then the outer check of
    !> the bonds' cones (module header). Arguments as nlgs_solve; config%max_sweeps bounds the
    !> block iterations of the whole step, every pass included, and stats%sweeps counts them.
    !> In a step whose block held intact bonds, a pass whose reactions created energy
    !> (created_energy above created_fraction of the kinetic energy) is given up: the step is
    !> solved again from its free velocities and zero reactions by the plain sweeps (as method
    !> = nlgs), with a cap of its own (module header, "Cap and energy guard"), and
    !> stats%block_given_up is block_given_up_energy; so is a step whose last pass met the cap
    !> unconverged after its reactions grew as without a solution (nlgs_stats_t%growth_seen),
    !> with a bond outside its cone, with block_given_up_unconverged, unless the plain sweeps
    !> end unconverged with a larger error than the block's at its cap: the step then ends on
    !> the block's answer (block_given_up_reverted). A step without intact
    !> bonds (none in the deck, or all broken) is the sweeps of method = nlgs, bit for bit,
    !> converged or not.
    subroutine bonded_block_solve(self, config, cs, im, vel, stats, bilateral)
        !> The strategy and its block (kept between steps).
        class(bonded_block_method_t), intent(inout) :: self
        !> Settings.
        type(nlgs_config_t), intent(in) :: config
        !> Contacts (frames, laws and activity set).
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Velocities (3, n_disks): free velocities in, end-of-step velocities out.
        real(wp), intent(inout) :: vel(:, :)
        !> Statistics.
        type(nlgs_stats_t), intent(out) :: stats
        !> Bilateral constraints kept satisfied (default: none).
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        type(nlgs_stats_t) :: pass, at_cap
        type(nlgs_config_t) :: left
        integer :: k, released, n_blocked, sweeps, worst, given_up
        real(wp) :: excess
        integer(i8) :: updates, local
        real(wp), allocatable :: vfree(:, :), r_start(:, :), r_cap(:, :), v_cap(:, :)
        integer, allocatable :: pcase_cap(:)
        logical, allocatable :: member_cap(:)
        logical :: held, cap_growing
        associate (block => self%block)
            if (allocated(block%excluded)) then
                if (size(block%excluded) < cs%n) deallocate (block%excluded)
            end if
            if (.not. allocated(block%excluded)) allocate (block%excluded(max(cs%n, 1)))
            block%excluded = .false.
            block%local_tol = config%local_tol
            block%local_max_iter = config%local_max_iter
            ! the start of the step, for the plain sweeps if the block is given up
            vfree = vel
            left = config
            sweeps = 0
            updates = 0_i8
            local = 0_i8
            n_blocked = -1
            given_up = block_kept
            held = .false.
            cap_growing = .false.
            block%resolving = .false.
            do
                left%max_sweeps = config%max_sweeps - sweeps
                ! the start of the pass, to which a stalled one returns
                r_start = cs%r(:, 1:cs%n)
                call nlgs_solve(left, cs, im, vel, pass, bilateral, block)
                if (n_blocked < 0) n_blocked = pass%n_blocked
                sweeps = sweeps + pass%sweeps
                updates = updates + pass%updates
                local = local + pass%local_iterations
                ! the guard judges a step whose block held bonds (at its first pass: the passes
                ! after a release start from the block's reactions); without intact bonds the
                ! passes are the sweeps of method = nlgs, and so is the step, bit for bit (a
                ! bond-free hexagonal stack at max_sweeps = 2 was given up at step 16, its plain
                ! sweeps restarted from zero reactions, where nlgs keeps its warm start)
                held = held .or. pass%n_block > 0
                ! (not judged when the block's equalities have no solution: its reactions are of
                ! order 1/eps by construction, and the releases below set them free; a lattice
                ! pulled apart at step 1 was given up there, its bonds never released)
                if (held .and. .not. present(bilateral) .and. block%consistent) then
                    if (bonded_block_creates_energy(cs, im, vel, vfree)) then
                        given_up = block_given_up_energy
                        exit
                    end if
                end if
                ! a stalled pass has no solution with its bonds held: its reactions grow without
                ! bound along a self-stress that loads some bond outside its cone (module header,
                ! "Stall"), and no number of iterations converges it; it is judged as a converged one
                cap_growing = .not. (pass%converged .or. pass%stalled) .and. pass%growth_seen
                if (.not. (pass%converged .or. pass%stalled)) exit
                ! release only the bond farthest outside its cone: the others may come back inside
                ! once it yields, and bonds released together are swept against the rigid rest of
                ! the block, whose Gauss-Seidel converges too slowly to judge them (module header)
                worst = 0
                excess = 0.0_wp
                released = 0
                do k = 1, cs%n
                    if (.not. block%member(k)) cycle
                    if (outside_cone(cs, k)) then
                        if (.not. block%consistent) then
                            ! no solution with every bond held: its reactions are of order 1/eps
                            ! and tell nothing of which bond yields first; release them all
                            block%excluded(k) = .true.
                            released = released + 1
                        else if (worst == 0 .or. cone_excess(cs, k) > excess) then
                            worst = k
                            excess = cone_excess(cs, k)
                        end if
                    end if
                end do
                if (released > 0) worst = -1
                if (worst == 0) then
                    ! bonds of the block whose reaction lies on a bound have reached it: judged
                    ! as the sweeps judge a bond projected onto it (contacts_finish breaks them)
                    do k = 1, cs%n
                        if (block%member(k)) cs%pcase(k) = bound_case(cs, k)
                    end do
                    exit
                end if
                if (worst > 0) then
                    block%excluded(worst) = .true.
                    released = 1
                end if
                if (sweeps >= config%max_sweeps) then
                    ! no iteration left for the step solved again: it ends unconverged, the bonds
                    ! outside their cones held (contacts_finish judges no bond of such a step),
                    ! its error at least their largest relative excess over their bounds
                    pass%converged = .false.
                    do k = 1, cs%n
                        if (block%member(k)) pass%error = max(pass%error, relative_excess(cs, k))
                    end do
                    exit
                end if
                ! (counted here, once the step is solved again: at the cap no pass runs them)
                block%counts%releases = block%counts%releases + released
                block%counts%resolves = block%counts%resolves + 1
                block%resolving = .true.
                ! back to the velocities without the contact impulses (nlgs_solve applies the
                ! current reactions again: the warm start of the next pass; after a stall those
                ! at the start of the pass, the stalled ones carrying a self-stress grown with
                ! its iterations, of no meaning: a pass whose growth moved bodies, however
                ! slowly, is not stalled and keeps its reactions)
                cs%r(:, 1:cs%n) = -cs%r(:, 1:cs%n)
                call nlgs_apply_reactions(cs, im, vel)
                if (pass%stalled) then
                    cs%r(:, 1:cs%n) = r_start
                else
                    cs%r(:, 1:cs%n) = -cs%r(:, 1:cs%n)
                end if
            end do
            block%resolving = .false.
            ! a pass that ran to the cap after its reactions grew as without a solution (the
            ! signature of a stall, the growth moving bodies), a bond outside its cone, has no
            ! solution with its bonds held for all the stall test can tell; the plain sweeps judge
            ! each bond by its own law (module header, "Cap and energy guard"). A pass that met
            ! the cap converging, or with the few iterations that releases left it, keeps the block
            if (given_up == block_kept .and. cap_growing .and. .not. present(bilateral)) then
                if (block%must_yield(cs)) given_up = block_given_up_unconverged
            end if
            if (given_up == block_given_up_unconverged) then
                ! the block's answer at its cap (reactions, velocities, the cases of the last
                ! local solves, its members), kept if the plain sweeps end worse: a slow
                ! convergence with a solution meets the cap with the same signature (module
                ! header, "Cap and energy guard")
                at_cap = pass
                r_cap = cs%r(:, 1:cs%n)
                v_cap = vel
                pcase_cap = cs%pcase(1:cs%n)
                member_cap = block%member
            end if
            if (given_up /= block_kept) then
                ! the plain sweeps from the free velocities (the bonds swept with their cones),
                ! from zero reactions: the block's carry self-stresses (the kernel of W_BB) that
                ! the sweeps, clipping them to the cones, turn into kinetic energy (the lattice of
                ! the module header: 1.0 J/m created from a warm start, 0.14 J/m free)
                block%member = .false.
                vel = vfree
                cs%r(:, 1:cs%n) = 0.0_wp
                left%max_sweeps = config%max_sweeps
                call nlgs_solve(left, cs, im, vel, pass, bilateral)
                sweeps = sweeps + pass%sweeps
                updates = updates + pass%updates
                local = local + pass%local_iterations
                if (given_up == block_given_up_unconverged .and. .not. pass%converged) then
                    ! unconverged too, and farther from a solution by the step's own norm: the
                    ! block's answer is the better one, and the step ends on it as without the
                    ! give-up (unconverged, its bonds held), its count keeping both solves (and
                    ! when the sweeps' error is not a number)
                    if (.not. (pass%error <= at_cap%error)) then
                        given_up = block_given_up_reverted
                        cs%r(:, 1:cs%n) = r_cap
                        vel = v_cap
                        cs%pcase(1:cs%n) = pcase_cap
                        block%member = member_cap
                        pass = at_cap
                    end if
                end if
                if (given_up /= block_given_up_reverted) block%counts%give_ups = block%counts%give_ups + 1
            end if
            stats = pass
            stats%block_given_up = given_up
            stats%n_blocked = n_blocked
            stats%sweeps = sweeps
            stats%updates = updates
            stats%local_iterations = local
        end associate
    end subroutine bonded_block_solve

    !> The energy guard (module header, "Cap and energy guard"): the reactions `cs%r` took the
    !> free velocities `vfree` to `vel` and created more energy (created_energy) than
    !> created_fraction of the larger kinetic energy of the two, beyond the round-off of the
    !> identity's terms. That round-off is roundoff (64 eps) times the sum of their sizes,
    !> the kinetic energies and sum_k |r_k . s_k|, plus what an error of roundoff times
    !> |v_free| + sum_k |M^-1 H_k| |r_k| per velocity does to the end kinetic energy K:
    !> e_noise + 2 sqrt(K e_noise), e_noise the kinetic energy of that error. Self-stressed
    !> bonds at rest (no gravity, a load removed) have end velocities of that error alone,
    !> K and the free one round-off: without the allowance K > 0.1 max(K, K_free) as often as
    !> not, and the block was given up (doc/theory.md 7.10).
    pure logical function bonded_block_creates_energy(cs, im, vel, vfree) result(creates)
        !> Contacts (frames, shifts, activity set and reactions).
        type(contact_set_t), intent(in) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> End velocities vfree + M^-1 H r (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> Free velocities (3, n_disks).
        real(wp), intent(in) :: vfree(:, :)
        real(wp) :: kfree, kend, created, noise, allowance
        kfree = kinetic_energy(im, vfree)
        kend = kinetic_energy(im, vel)
        created = created_energy(cs, im, vel, kfree)
        creates = .not. created <= created_fraction*max(kfree, kend)
        if (.not. creates) return
        ! (only for a pass that failed the plain comparison: the other passes, nearly all, pay
        ! nothing for it)
        noise = roundoff**2*kinetic_energy(im, velocity_sizes(cs, im, vfree))
        allowance = roundoff*(kend + kfree + shift_work_size(cs)) + 2.0_wp*sqrt(kend*noise) + noise
        creates = .not. created <= created_fraction*max(kfree, kend) + allowance
    end function bonded_block_creates_energy

    !> The sizes of the terms of v = v_free + M^-1 H r per DOF (3, n_disks): |v_free| + sum_k
    !> |M^-1 H_k| |r_k| over the active contacts (|n_x r_n - n_y r_t| <= |r_n| + |r_t|, and
    !> the same for y; the rotation |lever r_t| + |r_m|). The velocities are rounded to about
    !> epsilon times these (bonded_block_creates_energy).
    pure function velocity_sizes(cs, im, vfree) result(a)
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :), vfree(:, :)
        real(wp), allocatable :: a(:, :)
        real(wp) :: p
        integer :: k, i, j
        a = abs(vfree)
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            p = abs(cs%r(1, k)) + abs(cs%r(2, k))
            j = cs%i2(k)
            a(1:2, j) = a(1:2, j) + im(1:2, j)*p
            a(3, j) = a(3, j) + im(3, j)*(abs(cs%lever(2, k)*cs%r(2, k)) + abs(cs%r(3, k)))
            i = cs%i1(k)
            if (i > 0) then
                a(1:2, i) = a(1:2, i) + im(1:2, i)*p
                a(3, i) = a(3, i) + im(3, i)*(abs(cs%lever(1, k)*cs%r(2, k)) + abs(cs%r(3, k)))
            end if
        end do
    end function velocity_sizes

    !> sum_k |r_k . s_k| over the active contacts (the shifts' term of created_energy, in size).
    pure real(wp) function shift_work_size(cs) result(w)
        type(contact_set_t), intent(in) :: cs
        integer :: k
        w = 0.0_wp
        do k = 1, cs%n
            if (cs%active(k)) w = w + abs(cs%r(1, k)*cs%shift(1, k)) + abs(cs%r(2, k)*cs%shift(2, k))
        end do
    end function shift_work_size

    !> Kinetic energy 1/2 v^T M v of the disks [J/m] (the DOFs with a mass: im > 0).
    pure real(wp) function kinetic_energy(im, vel) result(e)
        real(wp), intent(in) :: im(:, :), vel(:, :)
        e = 0.5_wp*sum(vel**2/max(im, tiny(1.0_wp)), mask=im > 0.0_wp)
    end function kinetic_energy

    !> Energy the reactions created [J/m] (module header, "Cap and energy guard"): the kinetic energy
    !> of the velocities `vel` less that of the free velocities, `kfree`, and less the work
    !> -r.s of the contacts' shifts s (a wall's motion, a restitution target, a gap term),
    !> i.e. sum_k r_k . u_k - 1/2 |M^-1/2 H r|^2 for the velocities vel = v_free + M^-1 H r:
    !> at most -1/2 |M^-1/2 H r|^2 <= 0 at a solution, whose every reaction dissipates
    !> (r_k . u_k <= 0, doc/theory.md 2.5).
    pure real(wp) function created_energy(cs, im, vel, kfree) result(created)
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :), vel(:, :), kfree
        integer :: k
        created = kinetic_energy(im, vel) - kfree
        do k = 1, cs%n
            if (cs%active(k)) created = created + cs%r(1, k)*cs%shift(1, k) + cs%r(2, k)*cs%shift(2, k)
        end do
    end function created_energy

    !> The reaction of bond k lies outside its cone (a bound with a zero coefficient locks
    !> nothing and is not checked).
    pure logical function outside_cone(cs, k) result(out)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp) :: rn
        rn = cs%r(1, k) + cs%coh(k)
        out = rn < 0.0_wp
        if (cs%mu(k) > 0.0_wp) out = out .or. abs(cs%r(2, k)) > cs%mu(k)*rn
        if (cs%erol(k) > 0.0_wp) out = out .or. abs(cs%r(3, k)) > cs%erol(k)*rn
    end function outside_cone

    !> How far the reaction of bond k lies outside its cone, relative to the bound it exceeds
    !> (largest ratio of a component to its bound, minus 1; a tension beyond the cohesion
    !> ranks first, by its excess over r_cohe h).
    pure real(wp) function cone_excess(cs, k) result(excess)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp) :: rn
        rn = cs%r(1, k) + cs%coh(k)
        if (rn < 0.0_wp) then
            excess = huge(1.0_wp)
            if (cs%coh(k) > 0.0_wp) excess = min(huge(1.0_wp), 1.0e10_wp*(1.0_wp - rn/cs%coh(k)))
            return
        end if
        excess = 0.0_wp
        if (cs%mu(k) > 0.0_wp .and. abs(cs%r(2, k)) > cs%mu(k)*rn) &
            excess = max(excess, abs(cs%r(2, k))/max(cs%mu(k)*rn, tiny(1.0_wp)) - 1.0_wp)
        if (cs%erol(k) > 0.0_wp .and. abs(cs%r(3, k)) > cs%erol(k)*rn) &
            excess = max(excess, abs(cs%r(3, k))/max(cs%erol(k)*rn, tiny(1.0_wp)) - 1.0_wp)
    end function cone_excess

    !> How far the reaction of bond k lies outside its cone, relative to the bound it exceeds
    !> (largest ratio of a component to its bound, minus 1; a tension beyond the cohesion by
    !> its excess over r_cohe h; 0 inside the cone).
    pure real(wp) function relative_excess(cs, k) result(excess)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp) :: rn
        rn = cs%r(1, k) + cs%coh(k)
        ! a tension beyond the cohesion: its excess itself (cone_excess ranks it first, scaled)
        if (rn < 0.0_wp .and. cs%coh(k) > 0.0_wp) then
            excess = min(huge(1.0_wp), -rn/cs%coh(k))
        else
            excess = cone_excess(cs, k)
        end if
    end function relative_excess

    !> Case of the reaction of bond k of the block, which lies inside its cone: on a bound
    !> (within on_bound of it, relative) case_slip, case_roll or case_slip_roll, else
    !> case_stick. A bond of the block carries exactly a bound when a released neighbour
    !> yields at its own and the two take the same load (two bonds of a row in shear: both
    !> reached the bound, and the plain sweeps break both).
    pure integer function bound_case(cs, k) result(c)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp) :: rn
        logical :: shear, moment
        rn = cs%r(1, k) + cs%coh(k)
        shear = cs%mu(k) > 0.0_wp .and. abs(cs%r(2, k)) >= (1.0_wp - on_bound)*cs%mu(k)*rn
        moment = cs%erol(k) > 0.0_wp .and. abs(cs%r(3, k)) >= (1.0_wp - on_bound)*cs%erol(k)*rn
        if (rn <= 0.0_wp) then
            c = case_stick
        else if (shear .and. moment) then
            c = case_slip_roll
        else if (shear) then
            c = case_slip
        else if (moment) then
            c = case_roll
        else
            c = case_stick
        end if
    end function bound_case

    !> Choose B (active intact bonds not excluded) and set up the factor of W_BB + eps I
    !> (module header, "Reuse" and "Released bonds"): when B is the live slots of the
    !> analysed pattern, or some of them, the bonds that left are deleted from the factor
    !> (identity rows) and the factor is kept; otherwise the pattern of B is analysed and
    !> factored afresh.
    subroutine prepare(self, cs, im, bilateral)
        !> The block.
        class(bonded_block_t), intent(inout) :: self
        !> Contacts (blocked ones already inactive).
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Bilateral constraints of the solve, if any.
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        type(error_t), allocatable :: error
        integer :: k, b, u, i, nc
        integer, allocatable :: cur(:), newly(:)
        logical :: match, excl, restoring, fresh, reassemble, ok
        real(wp), allocatable :: current(:)
        if (allocated(self%member)) then
            if (size(self%member) < cs%n) deallocate (self%member)
        end if
        if (.not. allocated(self%member)) allocate (self%member(max(cs%n, 1)))
        self%member = .false.
        self%lost = .false.
        self%condensed_ready = .false.
        self%n_released = 0
        self%iterations = 0
        do k = 1, cs%n
            excl = .false.
            if (allocated(self%excluded)) then
                if (k <= size(self%excluded)) excl = self%excluded(k)
            end if
            self%member(k) = cs%active(k) .and. cs%status(k) == status_cohesive .and. .not. excl
        end do
        nc = count(self%member(1:cs%n))
        allocate (cur(nc))
        i = 0
        do k = 1, cs%n
            if (.not. self%member(k)) cycle
            i = i + 1
            cur(i) = k
            ! components that are not locked carry no reaction (see contacts_set_laws)
            if (cs%mu(k) <= 0.0_wp) cs%r(2, k) = 0.0_wp
            if (cs%erol(k) <= 0.0_wp) cs%r(3, k) = 0.0_wp
        end do
        self%n_live = nc
        if (nc == 0) then
            ! no bond in B: the slots stay (the factor is kept for a later step)
            if (allocated(self%bond)) self%bond = 0
            if (allocated(self%restore_values)) deallocate (self%restore_values)
            return
        end if
        ! B among the live slots of the analysed pattern (or of the restored factor)?
        restoring = allocated(self%restore_values)
        match = self%analysed .or. restoring
        if (match) call match_slots(self, cs, cur, match, newly)
        if (match) then
            ! too many dead rows: the factor carries their fill for nothing, start afresh
            u = 0
            do b = 1, self%nb
                if (self%dead(b) .or. any(newly == b)) u = u + popcnt(self%key_rows(b))
            end do
            match = real(u, wp) <= max_dead_fraction*real(self%nu, wp)
        end if
        fresh = .not. match
        if (fresh) then
            ! the pattern of B: every slot live
            restoring = .false.
            if (allocated(self%restore_values)) deallocate (self%restore_values)
            self%analysed = .false.
            self%factored = .false.
            self%nb = nc
            self%key_i1 = cs%i1(cur)
            self%key_i2 = cs%i2(cur)
            self%key_rows = [(rows_mask(cs, cur(b)), b=1, nc)]
            self%bond = cur
            if (allocated(self%dead)) deallocate (self%dead)
            allocate (self%dead(nc))
            self%dead = .false.
            self%n_deleted = 0
            call set_unknowns(self)
        else if (restoring) then
            call set_unknowns(self)
        end if
        if (.not. fresh) then
            do i = 1, size(newly)
                self%dead(newly(i)) = .true.
            end do
        end if
        ! the values: the live slots' entries of this step (unchanged within a step, so kept
        ! when the step is solved again after a release), zero rows and columns for the dead
        ! slots with 1 on their diagonal
        reassemble = fresh .or. restoring .or. .not. self%resolving .or. present(bilateral)
        if (reassemble) then
            self%nt = 0
            call assemble(self, cs, im, bilateral)
            if (fresh .or. restoring) then
                call self%mat%init(self%nu, int(self%nt, i8))
                do i = 1, self%nt
                    call self%mat%add(self%ti(i), self%tj(i), self%tv(i))
                end do
                call self%mat%finalize(error)
                if (allocated(error)) then
                    call give_up(self)
                    return
                end if
                if (allocated(self%pos)) deallocate (self%pos, self%diag)
                allocate (self%pos(self%nt), self%diag(self%nu))
                do i = 1, self%nt
                    self%pos(i) = self%mat%position(self%ti(i), self%tj(i))
                end do
                do u = 1, self%nu
                    self%diag(u) = self%mat%position(u, u)
                end do
            else
                self%mat%values = 0.0_wp
                do i = 1, self%nt
                    self%mat%values(self%pos(i)) = self%mat%values(self%pos(i)) + self%tv(i)
                end do
            end if
            ! Jacobi scaling: S W_BB S + E, S = diag(H_B^T M^-1 H_B)^(-1/2) (module header)
            call scale_values(self, ok)
            if (.not. ok) then
                call give_up(self)
                return
            end if
        end if
        call clear_dead(self)
        call size_work(self)
        if (fresh .or. restoring) then
            call self%solver%analyse(self%mat, error, kind=sparse_ldlt)
            if (allocated(error)) then
                call give_up(self)
                return
            end if
            self%analysed = .true.
            self%counts%analyses = self%counts%analyses + 1
        end if
        if (restoring) then
            if (size(self%restore_values) == size(self%mat%values) .and. size(self%restore_scale) == self%nu) then
                ! the factor of the checkpoint with its deletions, then the current values as
                ! after a reuse
                current = self%mat%values
                self%mat%values = self%restore_values
                deallocate (self%restore_values)
                call refactor(self)
                self%scale_factored = self%restore_scale
                self%mat%values = current
                if (self%factored) call delete_slots(self, self%restore_deleted)
                if (self%factored) call delete_slots(self, newly)
                if (.not. self%factored) call give_up(self)
                if (.not. self%factored) return
                self%stale = live_values_differ(self)
                return
            end if
            deallocate (self%restore_values)
            call refactor(self)
            if (.not. self%factored) call give_up(self)
            return
        end if
        if (self%factored) then
            ! keep the factor, without the bonds that left B; `solve` refactors if it no
            ! longer contracts well
            call delete_slots(self, newly)
            if (.not. self%factored) then
                call give_up(self)
                return
            end if
            self%stale = live_values_differ(self)
            self%counts%reuses = self%counts%reuses + 1
            return
        end if
        call refactor(self)
        if (.not. self%factored) call give_up(self)
    end subroutine prepare

    !> Match B (contacts `cur`, in order) with the live slots of the analysed pattern: B is
    !> those slots, or those slots but some (`newly`, which leave B and are deleted from the
    !> factor). Sets bond(b) to the contact of each slot in B, 0 for the others.
    subroutine match_slots(self, cs, cur, match, newly)
        type(bonded_block_t), intent(inout) :: self
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: cur(:)
        logical, intent(out) :: match
        integer, allocatable, intent(out) :: newly(:)
        integer :: b, i, k, n
        allocate (newly(size(self%key_i1)))
        n = 0
        match = allocated(self%dead)
        if (match) match = size(self%dead) == size(self%key_i1)
        if (.not. match) return
        if (allocated(self%bond)) then
            if (size(self%bond) /= size(self%key_i1)) deallocate (self%bond)
        end if
        if (.not. allocated(self%bond)) allocate (self%bond(size(self%key_i1)))
        self%bond = 0
        i = 1
        do b = 1, size(self%key_i1)
            if (self%dead(b)) cycle
            if (i <= size(cur)) then
                k = cur(i)
                if (self%key_i1(b) == cs%i1(k) .and. self%key_i2(b) == cs%i2(k) .and. &
                    self%key_rows(b) == rows_mask(cs, k)) then
                    self%bond(b) = k
                    i = i + 1
                    cycle
                end if
            end if
            n = n + 1
            newly(n) = b
        end do
        match = i == size(cur) + 1
        newly = newly(1:n)
    end subroutine match_slots

    !> Unknowns of the slots (first, comp; nb, nu) from the locked components of the key.
    subroutine set_unknowns(self)
        type(bonded_block_t), intent(inout) :: self
        integer :: b, c, u
        self%nb = size(self%key_rows)
        if (allocated(self%first)) deallocate (self%first)
        allocate (self%first(self%nb + 1))
        u = 1
        do b = 1, self%nb
            self%first(b) = u
            u = u + popcnt(self%key_rows(b))
        end do
        self%first(self%nb + 1) = u
        self%nu = u - 1
        if (allocated(self%comp)) deallocate (self%comp)
        allocate (self%comp(self%nu))
        u = 1
        do b = 1, self%nb
            do c = 1, 3
                if (.not. btest(self%key_rows(b), c - 1)) cycle
                self%comp(u) = c
                u = u + 1
            end do
        end do
    end subroutine set_unknowns

    !> Delete the unknowns of the slots `slots` from the factor (identity rows: the factor
    !> then solves W_BB + eps I of the other slots exactly) and note them in `deleted`
    !> (factored = .false. on failure).
    subroutine delete_slots(self, slots)
        type(bonded_block_t), intent(inout) :: self
        integer, intent(in) :: slots(:)
        type(error_t), allocatable :: error
        integer, allocatable :: rows(:)
        integer :: i, u
        if (size(slots) == 0) return
        rows = [((u, u=self%first(slots(i)), self%first(slots(i) + 1) - 1), i=1, size(slots))]
        call self%solver%delete_rows(rows, error)
        if (allocated(error)) then
            self%factored = .false.
            return
        end if
        if (.not. allocated(self%deleted)) allocate (self%deleted(self%nb))
        if (size(self%deleted) < self%nb) then
            rows = self%deleted(1:self%n_deleted)
            deallocate (self%deleted)
            allocate (self%deleted(self%nb))
            self%deleted(1:self%n_deleted) = rows
        end if
        do i = 1, size(slots)
            self%n_deleted = self%n_deleted + 1
            self%deleted(self%n_deleted) = slots(i)
        end do
        self%counts%deletions = self%counts%deletions + size(slots)
    end subroutine delete_slots

    !> The unknowns of the dead slots.
    pure function dead_unknowns(self) result(d)
        type(bonded_block_t), intent(in) :: self
        logical :: d(self%nu)
        integer :: b
        do b = 1, self%nb
            d(self%first(b):self%first(b + 1) - 1) = self%dead(b)
        end do
    end function dead_unknowns

    !> Rows and columns of the dead slots set to those of the identity in mat%values.
    subroutine clear_dead(self)
        type(bonded_block_t), intent(inout) :: self
        logical :: d(self%nu)
        integer(i8) :: p
        integer :: i, j
        d = dead_unknowns(self)
        if (.not. any(d)) return
        do j = 1, self%nu
            do p = self%mat%colptr(j) + 1, self%mat%colptr(j + 1)
                i = int(self%mat%rowind(p)) + 1
                if (d(i) .or. d(j)) self%mat%values(p) = merge(1.0_wp, 0.0_wp, i == j)
            end do
        end do
    end subroutine clear_dead

    !> The current values differ from those of the factor on the live slots (the dead ones
    !> are identity rows in both: deleted from the factor, or already so when factored).
    pure logical function live_values_differ(self) result(differ)
        type(bonded_block_t), intent(in) :: self
        logical :: d(self%nu)
        integer(i8) :: p
        integer :: i, j
        d = dead_unknowns(self)
        differ = .false.
        do j = 1, self%nu
            if (d(j)) cycle
            do p = self%mat%colptr(j) + 1, self%mat%colptr(j + 1)
                i = int(self%mat%rowind(p)) + 1
                if (d(i)) cycle
                if (self%mat%values(p) /= self%values_factored(p)) then
                    differ = .true.
                    return
                end if
            end do
        end do
    end function live_values_differ

    !> Disk of side s (1: i1, 2: i2) of slot b, <= 0 for a wall (from the key: the same for
    !> a dead slot, whose contact may be gone).
    pure integer function slot_body(self, b, s)
        type(bonded_block_t), intent(in) :: self
        integer, intent(in) :: b, s
        if (s == 1) then
            slot_body = self%key_i1(b)
        else
            slot_body = self%key_i2(b)
        end if
    end function slot_body

    !> Numerical factorisation of the current values (factored = .false. on failure). W_BB +
    !> eps I is positive definite, so a pivot D(j) < 0 of the L D L^T factor (which CHOLMOD
    !> accepts: it stops only on a zero pivot) is a breakdown of the factorisation, treated
    !> as a failure as the L L^T factor's pivot <= 0 was.
    subroutine refactor(self)
        type(bonded_block_t), intent(inout) :: self
        type(error_t), allocatable :: error
        type(sparse_stats_t) :: figures
        self%factored = .false.
        call self%solver%factor(self%mat, error)
        if (allocated(error)) return
        figures = self%solver%stats()
        if (figures%negative_pivots > 0) return
        self%factored = .true.
        self%stale = .false.
        self%values_factored = self%mat%values
        self%scale_factored = self%scale
        self%n_deleted = 0
        self%counts%factorisations = self%counts%factorisations + 1
    end subroutine refactor

    !> The factorisation failed (it should not with eps > 0): no block this solve, the bonds
    !> are swept as by the plain NLGS, and the next set-up analyses again.
    subroutine give_up(self)
        type(bonded_block_t), intent(inout) :: self
        self%member = .false.
        self%nb = 0
        self%nu = 0
        self%n_live = 0
        self%analysed = .false.
        self%factored = .false.
        self%counts%failures = self%counts%failures + 1
    end subroutine give_up

    !> Work arrays of size nu.
    subroutine size_work(self)
        type(bonded_block_t), intent(inout) :: self
        if (allocated(self%rhs)) then
            if (size(self%rhs) == self%nu) return
            deallocate (self%rhs, self%x, self%y)
        end if
        allocate (self%rhs(self%nu), self%x(self%nu), self%y(self%nu))
    end subroutine size_work

    !> Locked components of bond k as a bitmask: bit 0 normal (always), bit 1 tangential
    !> (mu_b > 0), bit 2 rotation (e_b > 0).
    pure integer function rows_mask(cs, k) result(mask)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        mask = 1
        if (cs%mu(k) > 0.0_wp) mask = ibset(mask, 1)
        if (cs%erol(k) > 0.0_wp) mask = ibset(mask, 2)
    end function rows_mask

    !> Assemble W_BB = H_B^T M_eff^-1 H_B as entries (push): one product per pair of
    !> bonds that share a disk, then the bilateral constraints' share. Every entry of a block
    !> is added, zero or not, so that the pattern depends on the graph only; the entries of
    !> a dead slot are zeros (its contact may be gone: its disks come from the key).
    subroutine assemble(self, cs, im, bilateral)
        type(bonded_block_t), intent(inout) :: self
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :)
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        integer, allocatable :: start(:), inc_b(:), inc_s(:), fill(:)
        integer :: nd, b, s, d, e1, e2, b1, b2, s1, s2, p, q
        real(wp) :: g1(3, 3), g2(3, 3), v
        nd = size(im, 2)
        ! incidence: the (bond, side) pairs of each disk, by disk, bonds in order
        allocate (start(nd + 1), fill(nd), inc_b(2*self%nb), inc_s(2*self%nb))
        start = 0
        do b = 1, self%nb
            do s = 1, 2
                d = slot_body(self, b, s)
                if (d > 0) start(d + 1) = start(d + 1) + 1
            end do
        end do
        start(1) = 1
        do d = 1, nd
            start(d + 1) = start(d + 1) + start(d)
        end do
        fill = start(1:nd)
        do b = 1, self%nb
            do s = 1, 2
                d = slot_body(self, b, s)
                if (d <= 0) cycle
                inc_b(fill(d)) = b
                inc_s(fill(d)) = s
                fill(d) = fill(d) + 1
            end do
        end do
        do d = 1, nd
            do e1 = start(d), start(d + 1) - 1
                b1 = inc_b(e1)
                s1 = inc_s(e1)
                g1 = 0.0_wp
                if (self%bond(b1) > 0) g1 = contacts_directions(cs, self%bond(b1), s1)
                do e2 = e1, start(d + 1) - 1
                    b2 = inc_b(e2)
                    s2 = inc_s(e2)
                    g2 = 0.0_wp
                    if (self%bond(b2) > 0) g2 = contacts_directions(cs, self%bond(b2), s2)
                    do p = self%first(b1), self%first(b1 + 1) - 1
                        do q = self%first(b2), self%first(b2 + 1) - 1
                            if (b1 == b2 .and. q > p) cycle
                            v = sum(g1(:, self%comp(p))*im(:, d)*g2(:, self%comp(q)))
                            call push(self, p, q, v)
                        end do
                    end do
                end do
            end do
        end do
        self%nt_plain = self%nt
        if (present(bilateral)) call add_mobility(self, cs, im, bilateral)
    end subroutine assemble

    !> Diagonal of H_B^T M^-1 H_B (the first nt_plain entries of the assembly, summed in
    !> their order): W_BB's own without coupling rows, else the mobility of the bonds' disks
    !> before the rows take their share.
    pure function plain_diagonal(self) result(d)
        type(bonded_block_t), intent(in) :: self
        real(wp) :: d(self%nu)
        integer :: i
        d = 0.0_wp
        do i = 1, self%nt_plain
            if (self%ti(i) == self%tj(i)) d(self%ti(i)) = d(self%ti(i)) + self%tv(i)
        end do
    end function plain_diagonal

    !> Regularisation of unknown u of the scaled block: bonded_block_eps_moment on a moment,
    !> bonded_block_eps_force on a force (module header).
    pure real(wp) function eps_of(self, u) result(eps)
        type(bonded_block_t), intent(in) :: self
        integer, intent(in) :: u
        eps = merge(bonded_block_eps_moment, bonded_block_eps_force, self%comp(u) == 3)
    end function eps_of

    !> Scale the assembled values of W_BB (mat%values) to S W_BB S and add E on the live
    !> unknowns (module header, "Scaling and regularisation"): S = diag(H_B^T M^-1 H_B)^(-1/2)
    !> on the live unknowns, 1 on the dead ones and on an unknown whose row is zero (a
    !> component whose two bodies cannot move along it); E from `eps_of`.
    subroutine scale_values(self, ok)
        !> The block (mat%values and scale set).
        type(bonded_block_t), intent(inout) :: self
        !> False when no live unknown has a positive diagonal (nothing to solve: the caller
        !> gives up).
        logical, intent(out) :: ok
        real(wp) :: d(self%nu)
        logical :: dead(self%nu)
        integer(i8) :: p
        integer :: i, j, u
        logical :: any_live
        d = plain_diagonal(self)
        dead = dead_unknowns(self)
        if (allocated(self%scale)) then
            if (size(self%scale) /= self%nu) deallocate (self%scale)
        end if
        if (.not. allocated(self%scale)) allocate (self%scale(self%nu))
        any_live = .false.
        do u = 1, self%nu
            self%scale(u) = 1.0_wp
            if (dead(u) .or. .not. d(u) > 0.0_wp) cycle
            self%scale(u) = 1.0_wp/sqrt(d(u))
            any_live = .true.
        end do
        do j = 1, self%nu
            do p = self%mat%colptr(j) + 1, self%mat%colptr(j + 1)
                i = int(self%mat%rowind(p)) + 1
                self%mat%values(p) = self%mat%values(p)*(self%scale(i)*self%scale(j))
            end do
        end do
        ok = any_live
        if (.not. ok) return
        do u = 1, self%nu
            if (dead(u)) cycle
            self%mat%values(self%diag(u)) = self%mat%values(self%diag(u)) + eps_of(self, u)
        end do
    end subroutine scale_values

    !> Append the entry (i, j, v) to the assembly (either triangle, each pair once; every
    !> unknown meets its diagonal entry, since every bond has a disk).
    pure subroutine push(self, i, j, v)
        type(bonded_block_t), intent(inout) :: self
        integer, intent(in) :: i, j
        real(wp), intent(in) :: v
        integer, allocatable :: ti(:), tj(:)
        real(wp), allocatable :: tv(:)
        integer :: cap
        if (.not. allocated(self%ti)) allocate (self%ti(64), self%tj(64), self%tv(64))
        if (self%nt == size(self%ti)) then
            cap = 2*size(self%ti)
            allocate (ti(cap), tj(cap), tv(cap))
            ti(1:self%nt) = self%ti(1:self%nt)
            tj(1:self%nt) = self%tj(1:self%nt)
            tv(1:self%nt) = self%tv(1:self%nt)
            call move_alloc(ti, self%ti)
            call move_alloc(tj, self%tj)
            call move_alloc(tv, self%tv)
        end if
        self%nt = self%nt + 1
        self%ti(self%nt) = i
        self%tj(self%nt) = j
        self%tv(self%nt) = v
    end subroutine push

    !> Add the bilateral constraints' share -U^T C U of W_BB, U = D P H_B (nlgs_bilateral_t
    !> %mobility), on the unknowns of the bonds that touch a constrained disk.
    subroutine add_mobility(self, cs, im, bilateral)
        type(bonded_block_t), intent(inout) :: self
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :)
        class(nlgs_bilateral_t), intent(inout) :: bilateral
        integer, allocatable :: owner(:), dof(:), touched(:)
        real(wp), allocatable :: c(:, :), um(:, :), cu(:, :)
        integer :: nr, nt, b, s, d, r, p, i, j
        real(wp) :: g(3, 3)
        logical, allocatable :: constrained(:)
        call bilateral%mobility(owner, dof, c)
        nr = size(owner)
        if (nr == 0) return
        allocate (constrained(size(im, 2)))
        constrained = .false.
        constrained(owner) = .true.
        ! unknowns of the bonds touching a constrained disk
        allocate (touched(self%nu))
        nt = 0
        do b = 1, self%nb
            if (.not. any([(touches(b, s), s=1, 2)])) cycle
            do p = self%first(b), self%first(b + 1) - 1
                nt = nt + 1
                touched(nt) = p
            end do
        end do
        if (nt == 0) return
        allocate (um(nr, nt))
        um = 0.0_wp
        do i = 1, nt
            p = touched(i)
            b = bond_of(p)
            if (self%bond(b) <= 0) cycle
            do s = 1, 2
                if (.not. touches(b, s)) cycle
                d = slot_body(self, b, s)
                g = contacts_directions(cs, self%bond(b), s)
                do r = 1, nr
                    if (owner(r) /= d) cycle
                    um(r, i) = um(r, i) + im(dof(r), d)*g(dof(r), self%comp(p))
                end do
            end do
        end do
        cu = matmul(c, um)
        do j = 1, nt
            do i = j, nt
                call push(self, touched(i), touched(j), -dot_product(um(:, i), cu(:, j)))
            end do
        end do
    contains
        pure logical function touches(bb, ss)
            integer, intent(in) :: bb, ss
            integer :: dd
            dd = slot_body(self, bb, ss)
            touches = .false.
            if (dd > 0) touches = constrained(dd)
        end function touches
        pure integer function bond_of(pp)
            integer, intent(in) :: pp
            integer :: lo
            do lo = 1, self%nb
                if (self%first(lo + 1) > pp) exit
            end do
            bond_of = lo
        end function bond_of
    end subroutine add_mobility

    !> Disk of side s (1: i1, 2: i2) of contact k, <= 0 for a wall.
    pure integer function body(cs, k, s)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k, s
        if (s == 1) then
            body = cs%i1(k)
        else
            body = cs%i2(k)
        end if
    end function body

    !> The block's share of the convergence norm: num = |u_B|^2 over the locked components
    !> (what the next solve changes in the bonds' local velocities; rotations times the mean
    !> radius), den = sum |W_bb r_b|^2.
    subroutine measure(self, cs, vel, num, den)
        !> The block.
        class(bonded_block_t), intent(in) :: self
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Velocities (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> Contributions to the convergence norm.
        real(wp), intent(out) :: num, den
        real(wp) :: u(3), wr(3)
        integer :: b, k, p
        num = 0.0_wp
        den = 0.0_wp
        if (self%lost) then
            num = huge(1.0_wp)/4.0_wp
            return
        end if
        do b = 1, self%nb
            k = self%bond(b)
            if (k <= 0) cycle
            u = relative_velocity(cs, k, vel)
            u(3) = cs%amoy(k)*u(3)
            do p = self%first(b), self%first(b + 1) - 1
                num = num + u(self%comp(p))**2
            end do
            wr = wmul(cs%w(:, k), cs%r(:, k))
            den = den + wr(1)**2 + wr(2)**2 + (cs%amoy(k)*wr(3))**2
        end do
    end subroutine measure

    !> A bond of B lies outside its cone (outside_cone): the problem with it held may have no
    !> solution, and the outer check of bonded_block_solve would release one.
    pure logical function must_yield(self, cs)
        !> The block.
        class(bonded_block_t), intent(in) :: self
        !> Contacts (their reactions).
        type(contact_set_t), intent(in) :: cs
        integer :: k
        must_yield = .false.
        do k = 1, cs%n
            if (.not. self%member(k)) cycle
            if (outside_cone(cs, k)) then
                must_yield = .true.
                return
            end if
        end do
    end function must_yield

    !> Solve the block for the current velocities (module header): (W_BB + eps I) dr = -u_B
    !> with iterative refinement, r += dr, vel += M_eff^-1 H_B dr. Then each bond released
    !> by the outer check takes one step of its local law with its block condensed on B
    !> (`condense`), followed by the block's correction (block Gauss-Seidel on the Schur
    !> complement: alone, the released bond is then solved in one step, where the plain
    !> sweep, seeing only its own disks, contracts by 1 - S/W_kk; doc/theory.md 7.10).
    subroutine solve(self, cs, im, vel, bilateral)
        !> The block.
        class(bonded_block_t), intent(inout) :: self
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        !> Bilateral constraints of the solve, if any.
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        integer :: j
        call solve_direct(self, cs, im, vel, bilateral)
        ! not with bilateral constraints: their share of the cross terms W_kB is not in the
        ! condensed block, and the plain sweeps handle the released bonds as before
        if (present(bilateral) .or. self%n_live == 0 .or. self%lost) return
        self%iterations = self%iterations + 1
        if (self%iterations <= condense_after) return
        if (.not. self%condensed_ready) call condense(self, cs, im)
        do j = 1, self%n_released
            call condensed_step(self, cs, im, vel, j)
            call solve_direct(self, cs, im, vel)
            if (self%lost) return
        end do
    end subroutine solve

    !> The released bonds of the solve that hold a part of the structure alone and their
    !> Delassus blocks condensed on B: S = W_kk - W_kB (W_BB + eps I)^-1 W_Bk, the change of
    !> the bond's relative velocity per unit reaction once the block has restored u_B = 0,
    !> from three unit impulses (one solve each, with the current factor), plus
    !> released_floor W_kk. A released bond (excluded by the outer check, active, intact)
    !> takes condensed steps when it is a bridge of the bond graph: its two bodies are not
    !> connected through B (walls and disks fixed in all three directions count as one
    !> body, the ground). The part it holds then moves through it alone, as a rigid body or
    !> a structure of B, whose inertia the plain sweep, seeing the bond's two disks, misses
    !> (a clamped row: 5 238 sweeps for 8 disks); of those, the ones with S_ii <=
    !> released_ratio W_ii on a locked component, on which the plain sweeps crawl, are kept.
    !> A bond closing a loop of B has its motion locked by the loop in some directions (S = 0
    !> there): the plain sweeps converge on it as before, at the cost of one contact update,
    !> where a condensed step costs a block solve.
    subroutine condense(self, cs, im)
        type(bonded_block_t), intent(inout) :: self
        type(contact_set_t), intent(in) :: cs
        real(wp), intent(in) :: im(:, :)
        type(error_t), allocatable :: error
        real(wp), allocatable :: dv(:, :)
        integer, allocatable :: parent(:)
        real(wp) :: sm(3, 3), dr(3), u(3), ratio
        integer :: k, j, c, d, b, p, n, kept
        kept = 0
        self%condensed_ready = .true.
        self%n_released = 0
        if (.not. allocated(self%excluded)) return
        n = min(cs%n, size(self%excluded))
        if (.not. any(self%excluded(1:n))) return
        ! connected parts of the bond graph of B (union-find over the disks, 0 the ground)
        allocate (parent(0:size(im, 2)))
        parent = [(d, d=0, size(im, 2))]
        do b = 1, self%nb
            if (self%bond(b) > 0) call join(node(self%bond(b), 1), node(self%bond(b), 2))
        end do
        if (allocated(self%released)) deallocate (self%released)
        allocate (self%released(count(self%excluded(1:n))))
        do k = 1, n
            if (.not. self%excluded(k)) cycle
            if (.not. cs%active(k) .or. cs%status(k) /= status_cohesive) cycle
            if (root(node(k, 1)) == root(node(k, 2))) cycle
            self%n_released = self%n_released + 1
            self%released(self%n_released) = k
        end do
        if (self%n_released == 0) return
        if (allocated(self%condensed)) deallocate (self%condensed)
        allocate (self%condensed(6, self%n_released))
        allocate (dv(3, size(im, 2)))
        do j = 1, self%n_released
            k = self%released(j)
            do c = 1, 3
                dv = 0.0_wp
                dr = 0.0_wp
                dr(c) = 1.0_wp
                call add_impulse(cs, k, dr, im, dv)
                do b = 1, self%nb
                    u = 0.0_wp
                    if (self%bond(b) > 0) u = local_change(cs, self%bond(b), dv)
                    do p = self%first(b), self%first(b + 1) - 1
                        self%rhs(p) = -u(self%comp(p))
                    end do
                end do
                call solve_least_norm(self, error)
                if (allocated(error)) then
                    ! cannot happen with a factor held; the released bonds are then swept
                    ! as by the plain sweeps
                    self%n_released = 0
                    return
                end if
                do b = 1, self%nb
                    if (self%bond(b) <= 0) cycle
                    dr = 0.0_wp
                    do p = self%first(b), self%first(b + 1) - 1
                        dr(self%comp(p)) = self%x(p)
                    end do
                    call add_impulse(cs, self%bond(b), dr, im, dv)
                end do
                sm(:, c) = local_change(cs, k, dv)
            end do
            ! symmetric (the product is, up to the solve's round-off), with the floor
            self%condensed(:, j) = [sm(1, 1), 0.5_wp*(sm(1, 2) + sm(2, 1)), sm(2, 2), &
                                    0.5_wp*(sm(1, 3) + sm(3, 1)), 0.5_wp*(sm(2, 3) + sm(3, 2)), sm(3, 3)] &
                                   + released_floor*cs%w(:, k)
            ratio = sm(1, 1)/cs%w(1, k)
            if (cs%mu(k) > 0.0_wp) ratio = min(ratio, sm(2, 2)/max(cs%w(3, k), tiny(1.0_wp)))
            if (cs%erol(k) > 0.0_wp) ratio = min(ratio, sm(3, 3)/max(cs%w(6, k), tiny(1.0_wp)))
            if (ratio <= released_ratio) then
                kept = kept + 1
                self%released(kept) = k
                self%condensed(:, kept) = self%condensed(:, j)
            end if
        end do
        self%n_released = kept
    contains
        ! node of side s of contact kk in the graph: its disk, or 0 for a wall or a disk
        ! fixed in all three directions
        pure integer function node(kk, ss)
            integer, intent(in) :: kk, ss
            node = body(cs, kk, ss)
            if (node <= 0) then
                node = 0
            else if (all(im(:, node) == 0.0_wp)) then
                node = 0
            end if
        end function node
        integer function root(i)
            integer, intent(in) :: i
            root = i
            do while (parent(root) /= root)
                parent(root) = parent(parent(root))
                root = parent(root)
            end do
        end function root
        subroutine join(i1, i2)
            integer, intent(in) :: i1, i2
            integer :: a1, a2
            a1 = root(i1)
            a2 = root(i2)
            if (a1 /= a2) parent(max(a1, a2)) = min(a1, a2)
        end subroutine join
    end subroutine condense

    !> One step of the local law of the released bond j (contact k) with its condensed
    !> block: u = b + S r with b = u_k - S r_k (shifted reactions), the reaction set to the
    !> solution and its change applied to the velocities (the block's correction follows).
    subroutine condensed_step(self, cs, im, vel, j)
        type(bonded_block_t), intent(inout) :: self
        type(contact_set_t), intent(inout) :: cs
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: vel(:, :)
        integer, intent(in) :: j
        real(wp) :: u(3), r0(3), r(3), dr(3), sw(6)
        integer :: k, it, pcase
        k = self%released(j)
        sw = self%condensed(:, j)
        u = relative_velocity(cs, k, vel)
        r0 = [cs%r(1, k) + cs%coh(k), cs%r(2, k), cs%r(3, k)]
        r = r0
        if (cs%erol(k) > 0.0_wp) then
            call rolling_local_solve(sw, u - wmul(sw, r0), cs%mu(k), cs%erol(k), self%local_tol, &
                                     self%local_max_iter, r, it, pcase)
        else
            call bipotential_local_solve(sw(1), sw(2), sw(3), u(1) - sw(1)*r0(1) - sw(2)*r0(2), &
                                         u(2) - sw(2)*r0(1) - sw(3)*r0(2), cs%mu(k), self%local_tol, &
                                         self%local_max_iter, r(1), r(2), it, pcase)
        end if
        cs%pcase(k) = pcase
        dr = r - r0
        cs%r(1, k) = r(1) - cs%coh(k)
        cs%r(2:3, k) = r(2:3)
        call add_impulse(cs, k, dr, im, vel)
    end subroutine condensed_step

    !> x = S (A + E)^-1 A (A + E)^-1 S rhs = S ((A + E)^-1 S rhs - (A + E)^-1 E (A + E)^-1 S rhs),
    !> A = S W S, with the factor of A + E and its scaling S (scale_factored): the reaction change
    !> of least norm (module header, "Least norm"). The first solve alone amplifies by 1/eps the
    !> part of rhs that no change of the bonds' reactions can remove; the second takes it out.
    subroutine solve_least_norm(self, error)
        !> The block (rhs in, x out, y work).
        type(bonded_block_t), intent(inout) :: self
        !> Set if CHOLMOD fails.
        type(error_t), allocatable, intent(out) :: error
        integer :: u
        self%rhs = self%scale_factored*self%rhs
        self%x = 0.0_wp
        call self%solver%solve(self%rhs, self%x, error)
        if (allocated(error)) return
        do u = 1, self%nu
            self%rhs(u) = eps_of(self, u)*self%x(u)
        end do
        self%y = 0.0_wp
        call self%solver%solve(self%rhs, self%y, error)
        if (allocated(error)) return
        self%x = self%scale_factored*(self%x - self%y)
    end subroutine solve_least_norm

    !> The direct solve of `solve`, without the released bonds' steps.
    subroutine solve_direct(self, cs, im, vel, bilateral)
        !> The block.
        class(bonded_block_t), intent(inout) :: self
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Velocities (3, n_disks).
        real(wp), intent(inout) :: vel(:, :)
        !> Bilateral constraints of the solve, if any.
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        type(error_t), allocatable :: error
        real(wp) :: u(3), rnorm, prev, noise
        integer :: b, k, p, it
        if (self%n_live == 0 .or. self%lost) return
        noise = 0.0_wp
        do b = 1, self%nb
            if (self%bond(b) > 0) noise = noise + velocity_scale2(cs, self%bond(b), vel)
        end do
        noise = roundoff*sqrt(noise)
        prev = huge(1.0_wp)
        it = 0
        self%consistent = .true.
        do
            ! the residual of the bonds, -u_B, from the velocities themselves; its norm in
            ! velocities (rotations times the mean radius, as the noise and `measure`)
            do b = 1, self%nb
                k = self%bond(b)
                ! a dead slot: an identity row with a zero right-hand side, a zero change
                u = 0.0_wp
                if (k > 0) u = relative_velocity(cs, k, vel)
                do p = self%first(b), self%first(b + 1) - 1
                    self%rhs(p) = -u(self%comp(p))
                end do
                if (k > 0) u(3) = cs%amoy(k)*u(3)
                do p = self%first(b), self%first(b + 1) - 1
                    self%y(p) = u(self%comp(p))
                end do
            end do
            rnorm = norm2(self%y)
            self%consistent = rnorm <= max(noise, consistent_ratio*noise/roundoff)
            if (rnorm <= noise) exit
            if (rnorm > stale_contraction*prev) then
                if (self%stale) then
                    ! the kept factor no longer contracts well: factor the current values
                    call refactor(self)
                    if (.not. self%factored) then
                        ! cannot happen with eps > 0 short of a CHOLMOD failure; the step
                        ! is then reported unconverged (measure) and the next set-up
                        ! starts afresh
                        self%lost = .true.
                        self%analysed = .false.
                        self%counts%failures = self%counts%failures + 1
                        return
                    end if
                else if (rnorm > 0.5_wp*prev) then
                    exit
                end if
            end if
            if (it == max_passes) exit
            it = it + 1
            prev = rnorm
            call solve_least_norm(self, error)
            if (allocated(error)) return
            if (it == 1) then
                self%counts%solves = self%counts%solves + 1
            else
                self%counts%refinements = self%counts%refinements + 1
            end if
            do b = 1, self%nb
                k = self%bond(b)
                if (k <= 0) cycle
                do p = self%first(b), self%first(b + 1) - 1
                    cs%r(self%comp(p), k) = cs%r(self%comp(p), k) + self%x(p)
                end do
                call apply_change(cs, k, im, vel, b)
                cs%pcase(k) = case_stick
            end do
            if (present(bilateral)) call bilateral%restore(vel)
        end do
    contains
        ! vel += M^-1 H dr for the change x of bond b (contact k)
        subroutine apply_change(cs, k, im, vel, b)
            type(contact_set_t), intent(in) :: cs
            integer, intent(in) :: k, b
            real(wp), intent(in) :: im(:, :)
            real(wp), intent(inout) :: vel(:, :)
            real(wp) :: dr(3)
            integer :: pp
            dr = 0.0_wp
            do pp = self%first(b), self%first(b + 1) - 1
                dr(self%comp(pp)) = self%x(pp)
            end do
            call add_impulse(cs, k, dr, im, vel)
        end subroutine apply_change
    end subroutine solve_direct

    !> |v_1|^2 + |v_2|^2 of the bodies of contact k (rotations times the mean radius).
    pure real(wp) function velocity_scale2(cs, k, vel) result(q)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: vel(:, :)
        integer :: s, d
        q = 0.0_wp
        do s = 1, 2
            d = body(cs, k, s)
            if (d > 0) q = q + vel(1, d)**2 + vel(2, d)**2 + (cs%amoy(k)*vel(3, d))**2
        end do
    end function velocity_scale2

    !> Relative velocity H^T v + shift of contact k: (u_n, u_t, w_r), as the sweeps see it.
    pure function relative_velocity(cs, k, vel) result(u)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: vel(:, :)
        real(wp) :: u(3)
        real(wp) :: g(3, 3)
        integer :: s, d
        u = [cs%shift(1, k), cs%shift(2, k), 0.0_wp]
        do s = 1, 2
            d = body(cs, k, s)
            if (d <= 0) cycle
            g = contacts_directions(cs, k, s)
            u = u + matmul(transpose(g), vel(:, d))
        end do
    end function relative_velocity

    !> v += M^-1 H dr for contact k: the change of the velocities of its bodies for an impulse
    !> dr in its frame (the transpose of `local_change`).
    pure subroutine add_impulse(cs, k, dr, im, v)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: dr(3)
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: v(:, :)
        real(wp) :: g(3, 3)
        integer :: s, d
        do s = 1, 2
            d = body(cs, k, s)
            if (d <= 0) cycle
            g = contacts_directions(cs, k, s)
            v(:, d) = v(:, d) + im(:, d)*matmul(g, dr)
        end do
    end subroutine add_impulse

    !> H^T dv of contact k (the change of its relative velocity for a change dv of the
    !> velocities, without the shift).
    pure function local_change(cs, k, dv) result(u)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: dv(:, :)
        real(wp) :: u(3)
        real(wp) :: g(3, 3)
        integer :: s, d
        u = 0.0_wp
        do s = 1, 2
            d = body(cs, k, s)
            if (d <= 0) cycle
            g = contacts_directions(cs, k, s)
            u = u + matmul(transpose(g), dv(:, d))
        end do
    end function local_change

    !> W r for the 3x3 block w = (nn, nt, tt, nm, tm, mm).
    pure function wmul(w, r) result(v)
        real(wp), intent(in) :: w(6), r(3)
        real(wp) :: v(3)
        v(1) = w(1)*r(1) + w(2)*r(2) + w(4)*r(3)
        v(2) = w(2)*r(1) + w(3)*r(2) + w(5)*r(3)
        v(3) = w(4)*r(1) + w(5)*r(2) + w(6)*r(3)
    end function wmul
end module dem_bonded_block
