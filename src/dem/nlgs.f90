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
!> eliminated (give them the condensed Delassus blocks in cs%w for exact local solves).
!>
!> Block (optional, e.g. the intact bonds of dem_bonded_block): an extension of
!> `nlgs_block_t` takes some active contacts out of the sweeps and solves them exactly as one
!> block (block Gauss-Seidel). `prepare` chooses its members after the blocked contacts are
!> taken out; `solve` is called once after the warm start and after every sweep that did not
!> converge; after each sweep `measure` gives the block's share of the convergence norm (the
!> change of the members' local velocities the next solve would make, and their |W r|), so
!> that `sweeps` counts block iterations.
module dem_nlgs
    use core_kinds, only: wp, i8
    use core_constants, only: diagonal_floor
    use dem_contacts, only: contact_set_t
    use dem_bipotential, only: bipotential_residual, bipotential_scaling, bipotential_local_solve_scaled, &
                               bipotential_n_scaling, rolling_scaling, rolling_local_solve_scaled, rolling_residual, &
                               rolling_n_scaling
    implicit none
    private
    public :: nlgs_config_t, nlgs_stats_t, nlgs_solve, nlgs_apply_reactions, nlgs_residual
    public :: nlgs_bilateral_t, nlgs_block_t
    public :: nlgs_method_nlgs, nlgs_method_block

    !> Global strategy: Gauss-Seidel sweeps over every contact.
    integer, parameter :: nlgs_method_nlgs = 1
    !> Global strategy: intact bonds solved directly as one block, sweeps over the others
    !> (dem_bonded_block).
    integer, parameter :: nlgs_method_block = 2

    !> A contact is blocked when W_nn <= blocked_ratio (W_nn + W_tt) (the floor of the scaled
    !> frame in dem_bipotential: below it the normal reaction would be unbounded).
    real(wp), parameter :: blocked_ratio = diagonal_floor
    !> Relative resolution of the shifted reactions of bonds (see the module header): 64
    !> machine epsilons.
    real(wp), parameter :: roundoff = 64.0_wp*epsilon(1.0_wp)

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
        !> Global strategy (nlgs_method_nlgs or nlgs_method_block), chosen by the caller.
        integer :: method = nlgs_method_nlgs
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
        !> error <= tol reached.
        logical :: converged = .true.
        !> Active contacts solved as a block (nlgs_block_t members), not swept.
        integer :: n_block = 0
    end type nlgs_stats_t

    !> Linear velocity constraints kept satisfied during the sweeps (see the module header).
    type, abstract :: nlgs_bilateral_t
    contains
        !> Restore the constraints after arbitrary changes of the velocities.
        procedure(bilateral_restore), deferred :: restore
        !> Restore the constraints after a contact update changed the velocities of two bodies.
        procedure(bilateral_update), deferred :: update
        !> The constraints' share of the disks' mobility (used by a block solve).
        procedure(bilateral_mobility), deferred :: mobility
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
        real(wp) :: floor
        integer :: s, k, n_swept
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
        s = 0
        floor = 0.0_wp
        do k = 1, cs%n
            if (.not. cs%active(k)) cycle
            if (present(block)) then
                if (block%member(k)) cycle
            end if
            s = s + 1
            list(s) = k
            if (cs%erol(k) > 0.0_wp) then
                call rolling_scaling(cs%w(:, k), cs%mu(k), cs%erol(k), sc(:, s))
            else
                call bipotential_scaling(cs%w(1, k), cs%w(2, k), cs%w(3, k), cs%mu(k), sc(1:bipotential_n_scaling, s))
            end if
        end do
        call nlgs_apply_reactions(cs, im, vel)
        do k = 1, cs%n
            if (cs%active(k)) floor = floor + roundoff_floor(cs, k, vel)
        end do
        if (present(bilateral)) call bilateral%restore(vel)
        if (present(block)) call block%solve(cs, im, vel, bilateral)
        stats%converged = .true.
        stats%error = 0.0_wp
        if (stats%n_active > 0) then
            stats%converged = .false.
            do s = 1, config%max_sweeps
                if (config%symmetric .and. mod(s, 2) == 0) then
                    call sweep(config, cs, im, vel, list, sc, n_swept, 1, -1, num, den, nloc, bilateral)
                else
                    call sweep(config, cs, im, vel, list, sc, 1, n_swept, 1, num, den, nloc, bilateral)
                end if
                if (present(block)) then
                    call block%measure(cs, vel, num_b, den_b)
                    num = num + num_b
                    den = den + den_b
                end if
                stats%sweeps = s
                stats%local_iterations = stats%local_iterations + nloc
                stats%error = relative(max(num - floor, 0.0_wp), den)
                if (stats%error <= config%tol) then
                    stats%converged = .true.
                    exit
                end if
                if (present(block)) call block%solve(cs, im, vel, bilateral)
            end do
        end if
        stats%updates = int(n_swept, i8)*stats%sweeps
        stats%residual = nlgs_residual(cs, vel)
    end subroutine nlgs_solve

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
            call apply(cs, k, im, vel, cs%r(1, k), cs%r(2, k), cs%r(3, k))
        end do
    end subroutine nlgs_apply_reactions

    !> vel += M^-1 H (drn, drt, drm) for contact k.
    pure subroutine apply(cs, k, im, vel, drn, drt, drm)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: vel(:, :)
        real(wp), intent(in) :: drn, drt, drm
        real(wp) :: px, py
        integer :: a, b
        a = cs%i1(k)
        b = cs%i2(k)
        px = drn*cs%nrm(1, k) - drt*cs%nrm(2, k)
        py = drn*cs%nrm(2, k) + drt*cs%nrm(1, k)
        vel(1, b) = vel(1, b) + im(1, b)*px
        vel(2, b) = vel(2, b) + im(2, b)*py
        vel(3, b) = vel(3, b) + im(3, b)*(cs%lever(2, k)*drt + drm)
        if (a > 0) then
            vel(1, a) = vel(1, a) - im(1, a)*px
            vel(2, a) = vel(2, a) - im(2, a)*py
            vel(3, a) = vel(3, a) + im(3, a)*(cs%lever(1, k)*drt - drm)
        end if
    end subroutine apply

    !> Relative velocity H^T v + shift of contact k: (u_n, u_t, w_r).
    pure subroutine local_velocity(cs, k, vel, u)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        real(wp), intent(in) :: vel(:, :)
        real(wp), intent(out) :: u(3)
        real(wp) :: dvx, dvy, ut
        integer :: a, b
        a = cs%i1(k)
        b = cs%i2(k)
        dvx = vel(1, b)
        dvy = vel(2, b)
        ut = cs%lever(2, k)*vel(3, b) + cs%shift(2, k)
        u(3) = vel(3, b)
        if (a > 0) then
            dvx = dvx - vel(1, a)
            dvy = dvy - vel(2, a)
            ut = ut + cs%lever(1, k)*vel(3, a)
            u(3) = u(3) - vel(3, a)
        end if
        u(1) = cs%nrm(1, k)*dvx + cs%nrm(2, k)*dvy + cs%shift(1, k)
        u(2) = ut - cs%nrm(2, k)*dvx + cs%nrm(1, k)*dvy
    end subroutine local_velocity

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
    !> list(last). num = sum |W dr|^2, den = sum |W r|^2 (r applied, not shifted), nloc =
    !> local iterations. With bilateral constraints, they are restored after each contact
    !> update.
    subroutine sweep(config, cs, im, vel, list, sc, first, last, step, num, den, nloc, bilateral)
        type(nlgs_config_t), intent(in) :: config
        type(contact_set_t), intent(inout) :: cs
        real(wp), intent(in) :: im(:, :)
        real(wp), intent(inout) :: vel(:, :)
        integer, intent(in) :: list(:), first, last, step
        real(wp), intent(in), contiguous :: sc(:, :)
        real(wp), intent(out) :: num, den
        integer(i8), intent(out) :: nloc
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        real(wp) :: u(3), r0(3), r(3), dr(3), wk(6)
        integer :: a, k, it, pcase
        num = 0.0_wp
        den = 0.0_wp
        nloc = 0_i8
        do a = first, last, step
            k = list(a)
            call local_velocity(cs, k, vel, u)
            wk = cs%w(:, k)
            r0 = [cs%r(1, k) + cs%coh(k), cs%r(2, k), cs%r(3, k)]
            r = r0
            if (cs%erol(k) > 0.0_wp) then
                call rolling_local_solve_scaled(sc(:, a), u - wmul(wk, r0), config%local_tol, config%local_max_iter, &
                                                r, it, pcase)
            else
                ! no moment (r0(3) = 0, see contacts_set_laws): the two-component law
                call bipotential_local_solve_scaled(sc(1:bipotential_n_scaling, a), u(1) - wk(1)*r0(1) - wk(2)*r0(2), &
                                                    u(2) - wk(2)*r0(1) - wk(3)*r0(2), config%local_tol, &
                                                    config%local_max_iter, r(1), r(2), it, pcase)
            end if
            nloc = nloc + it
            cs%pcase(k) = pcase
            dr = r - r0
            cs%r(1, k) = r(1) - cs%coh(k)
            cs%r(2:3, k) = r(2:3)
            call apply(cs, k, im, vel, dr(1), dr(2), dr(3))
            if (present(bilateral)) call bilateral%update(cs%i1(k), cs%i2(k), vel)
            num = num + wnorm2(wk, dr, cs%amoy(k))
            den = den + wnorm2(wk, cs%r(:, k), cs%amoy(k))
        end do
    end subroutine sweep

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
            call local_velocity(cs, k, vel, u)
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
