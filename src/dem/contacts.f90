!> Contact pairs between disks, and between a wall and a disk, stored as structure of arrays.
!>
!> Contact k joins body i1(k) to disk i2(k); i1 < 0 means wall -i1. The normal n goes from
!> body i1 to disk i2 (from the wall into the disk), t = (-n_y, n_x). Local velocity of i2
!> relative to i1 at the contact point: u_n = n.(v2 - v1),
!> u_t = t.(v2 - v1) + c1 w1 + c2 w2 with lever arms c = -radius, and the relative rotation
!> w_r = w2 - w1. Reaction r = (r_n, r_t, M) (impulses per unit thickness): the force
!> r_n n + r_t t acts on i2 at the contact point, its opposite on i1, and the moment M acts
!> on i2, -M on i1. W = H^T M^-1 H is the local 3x3 Delassus block, stored as
!> (W_nn, W_nt, W_tt, W_nm, W_tm, W_mm) (doc/theory.md, "Contact kinematics").
!>
!> Order: by owner disk (i1 for disk pairs, i2 for wall contacts), then walls before disks,
!> then by the other index; the detection emits contacts in this order so that consecutive
!> contacts touch neighbouring memory, and the previous list is matched by merging as the
!> contacts are appended (warm start).
module dem_contacts
    use core_kinds, only: wp, i8
    use core_constants, only: relative_roundoff, diagonal_floor
    use dem_materials, only: materials_t, bond_e_default
    use dem_bipotential, only: case_separation, case_slip, case_roll, case_slip_roll
    use dem_bonds, only: break_none, break_tension, break_shear, break_moment, break_shear_moment
    use dem_activation, only: activation_t, pair_output_none
    implicit none
    private
    public :: contact_set_t, contact_law_t
    public :: status_open, status_stick, status_slip, status_cohesive, status_broken
    public :: contacts_begin_detection, contacts_append, contacts_append_owner
    public :: contacts_extend, contacts_fill
    public :: contacts_set_frames, contacts_set_laws, contacts_recheck, contacts_finish, contacts_impulses
    public :: contacts_local_velocity, contacts_count_status, contacts_bytes, contacts_moments_active
    public :: contacts_apply_impulse, contacts_solver_velocity, contacts_directions
    public :: contacts_list_problem, contacts_make_bonds, contacts_lost_bonds

    !> Contact status, no reaction (separated or not active this step).
    integer, parameter :: status_open = 0
    !> Contact status, reaction strictly inside the Coulomb cone.
    integer, parameter :: status_stick = 1
    !> Contact status, reaction on the boundary of the cone (sliding).
    integer, parameter :: status_slip = 2
    !> Contact status, cohesive bond, intact.
    integer, parameter :: status_cohesive = 3
    !> Contact status, cohesive bond broken for good (now a plain frictional contact).
    integer, parameter :: status_broken = 4
    !> Fewest contacts for which the frames and the laws are set on the OpenMP threads: where
    !> the sweeps split (2 blocks of 2000 contacts, dem_nlgs). Below it a parallel region costs
    !> more than the loop, and far more on a loaded machine (doc/performance.md, OpenMP).
    integer, parameter :: parallel_min = 4000
    !> A bond's reaction within this fraction of a bound of its cone is on it, for the rupture
    !> judgement (bond_break_mode) and the bonded block (dem_bonded_block). A bond exactly on
    !> its bound is a tie of the law that only the rounding settles, and the reactions of a
    !> bonded structure are known to about cond(W_BB) times the machine epsilon, not to the
    !> rounding of one reaction: the inner bonds of a clamped row of 13 disks pulled across
    !> at 1.05 times their shear capacity, all on the bound in the closed form, came out
    !> 6e-8 to 1.7e-7 inside it (the condition grows like N^4), and held at 1e-9. A local
    !> solve stops at local_tolerance (1e-10 by default).
    real(wp), parameter, public :: bond_on_bound = 1.0e-6_wp

    !> Parameters of the step needed to set the contact laws.
    type :: contact_law_t
        !> Time step [s].
        real(wp) :: h = 0.0_wp
        !> Theta of the scheme.
        real(wp) :: theta = 0.5_wp
        !> Gap ratio of the bonds (made at t = 0 by contacts_make_bonds on contacts with gap
        !> <= bond_ratio * mean radius of the pair): a bond that cannot take part in the solve
        !> (blocked) breaks when its gap opens beyond that.
        real(wp) :: bond_ratio = 1.0e-6_wp
        !> Round-off allowance of the activation, relative to the mean radius of the pair: a
        !> contact whose predicted gap is at most gap_allowance * mean radius is active.
        real(wp) :: gap_allowance = 1.0e-10_wp
    end type contact_law_t

    !> The contact list (structure of arrays, capacity >= n).
    type :: contact_set_t
        !> Number of contacts.
        integer :: n = 0
        !> Allocated length of the per-contact arrays.
        integer :: capacity = 0
        !> First body (disk index, or -wall index) and second body (disk index).
        integer, allocatable :: i1(:), i2(:)
        !> Unit normal (2, n) from i1 to i2.
        real(wp), allocatable :: nrm(:, :)
        !> Gap at the detection configuration [m] (negative: overlap).
        real(wp), allocatable :: gap(:)
        !> Lever arms (c1, c2) of the rotations in u_t [m].
        real(wp), allocatable :: lever(:, :)
        !> Delassus block (W_nn, W_nt, W_tt, W_nm, W_tm, W_mm) (6, n).
        real(wp), allocatable :: w(:, :)
        !> Constant velocity terms added to H^T v in the solver (wall motion, restitution
        !> target) (2, n).
        real(wp), allocatable :: shift(:, :)
        !> Reaction impulse (r_n, r_t, M) (3, n) [N s/m, N s].
        real(wp), allocatable :: r(:, :)
        !> End-of-step relative velocity (u_n, u_t, w_r) (3, n) [m/s, rad/s].
        real(wp), allocatable :: u(:, :)
        !> Friction coefficient of the current law (mu of the materials, or mu_b of an intact
        !> bond).
        real(wp), allocatable :: mu(:)
        !> Moment length of the current law [m] (rolling length e_r, or e_b of an intact bond);
        !> 0: the contact transmits no moment.
        real(wp), allocatable :: erol(:)
        !> Mean radius of the pair [m] (the length that scales moments in the solver's norm).
        real(wp), allocatable :: amoy(:)
        !> Projection case of the last local solve (dem_bipotential case_*).
        integer, allocatable :: pcase(:)
        !> Rupture mode of a bond that broke at this step (dem_bonds break_*), else break_none.
        integer, allocatable :: break_mode(:)
        !> Cohesive impulse r_cohe h of intact bonds (0 otherwise) [N s/m].
        real(wp), allocatable :: coh(:)
        !> Output of the pair at this step (2, n): the gap at the detection configuration and
        !> the normal relative velocity at the start of the step [m, m/s]; the next step's
        !> rule of activation may use it (dem_activation, the Siconos rule).
        real(wp), allocatable :: y(:, :)
        !> The pair's output at the previous step (2, n), carried over with the warm start
        !> (pair_output_none, 0 for a pair new to the list).
        real(wp), allocatable :: y_prev(:, :)
        !> Contact takes part in the solve this step.
        logical, allocatable :: active(:)
        !> status_open, status_stick, status_slip, status_cohesive or status_broken.
        integer, allocatable :: status(:)
        !> Previous list, for warm start: size, pairs, reactions, statuses.
        integer :: n_prev = 0
        !> Next entry of the previous list to compare with (merge).
        integer :: merge_pos = 1
        !> Pairs of the previous list.
        integer, allocatable :: prev_i1(:), prev_i2(:)
        !> Reactions of the previous list.
        real(wp), allocatable :: prev_r(:, :)
        !> Statuses of the previous list.
        integer, allocatable :: prev_status(:)
        !> Outputs of the previous list (y of the previous step).
        real(wp), allocatable :: prev_y(:, :)
    end type contact_set_t

contains

    !> Keep the current list as the previous one and start an empty list.
    subroutine contacts_begin_detection(cs)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        integer, allocatable :: ti(:)
        real(wp), allocatable :: tr(:, :)
        call move_alloc(cs%prev_i1, ti)
        if (allocated(cs%i1)) call move_alloc(cs%i1, cs%prev_i1)
        if (allocated(ti)) call move_alloc(ti, cs%i1)
        call move_alloc(cs%prev_i2, ti)
        if (allocated(cs%i2)) call move_alloc(cs%i2, cs%prev_i2)
        if (allocated(ti)) call move_alloc(ti, cs%i2)
        call move_alloc(cs%prev_status, ti)
        if (allocated(cs%status)) call move_alloc(cs%status, cs%prev_status)
        if (allocated(ti)) call move_alloc(ti, cs%status)
        call move_alloc(cs%prev_r, tr)
        if (allocated(cs%r)) call move_alloc(cs%r, cs%prev_r)
        if (allocated(tr)) call move_alloc(tr, cs%r)
        call move_alloc(cs%prev_y, tr)
        if (allocated(cs%y)) call move_alloc(cs%y, cs%prev_y)
        if (allocated(tr)) call move_alloc(tr, cs%y)
        cs%n_prev = cs%n
        cs%n = 0
        cs%merge_pos = 1
        ! the swapped-in arrays may be shorter than the others
        call grow_int(cs%i1, cs%capacity, 0)
        call grow_int(cs%i2, cs%capacity, 0)
        call grow_int(cs%status, cs%capacity, 0)
        call grow_real2(cs%r, 3, cs%capacity, 0)
        call grow_real2(cs%y, 2, cs%capacity, 0)
        ! the new list is usually about as long as the previous one; the slack beyond it is
        ! memory of every per-contact array (of the current and the previous list), so it is
        ! kept small: 1/16 here, growth by eighths below (with 1/8 and quarters, 1 039 bytes
        ! per disk at 10^4 disks against 926; doc/performance.md, issue 3's 1 KB per particle)
        call ensure_capacity(cs, cs%n_prev + cs%n_prev/16)
    end subroutine contacts_begin_detection

    !> Append a pair (in contact order) with its geometry; its reaction and status are carried
    !> over from the previous list when the pair was already there (warm start, by merging the
    !> two ordered lists), else r = 0 and open.
    subroutine contacts_append(cs, i1, i2, nx, ny, gap)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> First body (disk, or -wall) and second body (disk).
        integer, intent(in) :: i1, i2
        !> Unit normal from i1 to i2.
        real(wp), intent(in) :: nx, ny
        !> Gap [m].
        real(wp), intent(in) :: gap
        if (cs%n == cs%capacity) call ensure_capacity(cs, cs%n + 1)
        call append_one(cs, i1, i2, nx, ny, gap)
    end subroutine contacts_append

    !> Append the contacts of one owner disk, in contact order (as contacts_append for each):
    !> other(a) < 0 is wall -other(a) (pair (other(a), owner)), other(a) > owner is a disk
    !> (pair (owner, other(a))); walls first, then disks, each by increasing index.
    subroutine contacts_append_owner(cs, owner, other, nrm, gap)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Owner disk.
        integer, intent(in) :: owner
        !> Other bodies, sorted.
        integer, intent(in) :: other(:)
        !> Unit normals (2, :) from the first body of each pair to the second.
        real(wp), intent(in) :: nrm(:, :)
        !> Gaps [m].
        real(wp), intent(in) :: gap(:)
        integer :: a
        if (cs%n + size(other) > cs%capacity) call ensure_capacity(cs, cs%n + size(other))
        do a = 1, size(other)
            if (other(a) < 0) then
                call append_one(cs, other(a), owner, nrm(1, a), nrm(2, a), gap(a))
            else
                call append_one(cs, owner, other(a), nrm(1, a), nrm(2, a), gap(a))
            end if
        end do
    end subroutine contacts_append_owner

    !> Extend the list by m contacts, slots n + 1 to n + m, which contacts_fill then fills.
    subroutine contacts_extend(cs, m)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Number of slots to add (>= 0).
        integer, intent(in) :: m
        integer :: cap
        ! grow by eighths, as appending the contacts owner by owner does: the capacity, hence
        ! the memory, does not depend on how the list was cut (number of threads)
        cap = cs%capacity
        do while (cap < cs%n + m)
            cap = max(cap + cap/8, 64)
        end do
        if (cap > cs%capacity) call ensure_capacity(cs, cap)
        cs%n = cs%n + m
    end subroutine contacts_extend

    !> Store pairs (i1(a), i2(a)), in contact order, with their geometry at slots k0, k0 + 1, ...
    !> (reserved by contacts_extend); reaction and status as contacts_append gives them. The
    !> previous list is searched from its first pair not before (i1(1), i2(1)), found by
    !> bisection, instead of from where the last append stopped: calls on disjoint ranges of
    !> slots may run at the same time (OpenMP threads), and give exactly what contacts_append
    !> gives pair by pair, the previous list being in contact order (as the detection leaves
    !> it). Does not move the merge position of contacts_append.
    subroutine contacts_fill(cs, k0, i1, i2, nrm, gap)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Slot of the first pair.
        integer, intent(in) :: k0
        !> First body (disk, or -wall) and second body (disk) of each pair.
        integer, intent(in) :: i1(:), i2(:)
        !> Unit normals (2, :) from the first body of each pair to the second.
        real(wp), intent(in) :: nrm(:, :)
        !> Gaps [m].
        real(wp), intent(in) :: gap(:)
        integer(i8) :: key
        integer :: a, p, lo, hi, mid
        if (size(i1) == 0) return
        ! first previous pair whose key is not below the first new one
        key = pair_key(i1(1), i2(1))
        lo = 1
        hi = cs%n_prev + 1
        do while (lo < hi)
            mid = lo + (hi - lo)/2
            if (pair_key(cs%prev_i1(mid), cs%prev_i2(mid)) < key) then
                lo = mid + 1
            else
                hi = mid
            end if
        end do
        p = lo
        do a = 1, size(i1)
            call set_one(cs, k0 + a - 1, i1(a), i2(a), nrm(1, a), nrm(2, a), gap(a), p)
        end do
    end subroutine contacts_fill

    !> Append one pair (capacity available), merging with the previous list for the warm start.
    pure subroutine append_one(cs, i1, i2, nx, ny, gap)
        type(contact_set_t), intent(inout) :: cs
        integer, intent(in) :: i1, i2
        real(wp), intent(in) :: nx, ny, gap
        integer :: p
        cs%n = cs%n + 1
        p = cs%merge_pos
        call set_one(cs, cs%n, i1, i2, nx, ny, gap, p)
        cs%merge_pos = p
    end subroutine append_one

    !> Store one pair at slot k; p is the next entry of the previous list to compare with
    !> (merge for the warm start), advanced past the entries that come before the pair.
    pure subroutine set_one(cs, k, i1, i2, nx, ny, gap, p)
        type(contact_set_t), intent(inout) :: cs
        integer, intent(in) :: k, i1, i2
        real(wp), intent(in) :: nx, ny, gap
        integer, intent(inout) :: p
        integer(i8) :: key
        cs%i1(k) = i1
        cs%i2(k) = i2
        cs%nrm(1, k) = nx
        cs%nrm(2, k) = ny
        cs%gap(k) = gap
        ! the law and the output are set by contacts_set_laws; until then: none
        cs%y(:, k) = [pair_output_none, 0.0_wp]
        cs%mu(k) = 0.0_wp
        cs%erol(k) = 0.0_wp
        cs%coh(k) = 0.0_wp
        cs%amoy(k) = 0.0_wp
        cs%pcase(k) = case_separation
        cs%break_mode(k) = break_none
        ! skip the previous pairs that come before this one
        key = pair_key(i1, i2)
        do while (p <= cs%n_prev)
            if (pair_key(cs%prev_i1(p), cs%prev_i2(p)) >= key) exit
            p = p + 1
        end do
        if (p <= cs%n_prev) then
            if (cs%prev_i1(p) == i1 .and. cs%prev_i2(p) == i2) then
                cs%r(:, k) = cs%prev_r(:, p)
                cs%status(k) = cs%prev_status(p)
                cs%y_prev(:, k) = cs%prev_y(:, p)
                p = p + 1
                return
            end if
        end if
        cs%r(:, k) = 0.0_wp
        cs%status(k) = status_open
        cs%y_prev(:, k) = [pair_output_none, 0.0_wp]
    end subroutine set_one

    !> Grow every per-contact array to hold at least m contacts (keeps the first n).
    subroutine ensure_capacity(cs, m)
        type(contact_set_t), intent(inout) :: cs
        integer, intent(in) :: m
        integer :: cap
        if (m <= cs%capacity) return
        cap = max(cs%capacity + cs%capacity/8, m, 64)
        call grow_int(cs%i1, cap, cs%n)
        call grow_int(cs%i2, cap, cs%n)
        call grow_real2(cs%nrm, 2, cap, cs%n)
        call grow_real1(cs%gap, cap, cs%n)
        call grow_real2(cs%lever, 2, cap, cs%n)
        call grow_real2(cs%w, 6, cap, cs%n)
        call grow_real2(cs%shift, 2, cap, cs%n)
        call grow_real2(cs%r, 3, cap, cs%n)
        call grow_real2(cs%u, 3, cap, cs%n)
        call grow_real2(cs%y, 2, cap, cs%n)
        call grow_real2(cs%y_prev, 2, cap, cs%n)
        call grow_real1(cs%mu, cap, cs%n)
        call grow_real1(cs%erol, cap, cs%n)
        call grow_real1(cs%amoy, cap, cs%n)
        call grow_real1(cs%coh, cap, cs%n)
        call grow_int(cs%pcase, cap, cs%n)
        call grow_int(cs%break_mode, cap, cs%n)
        call grow_int(cs%status, cap, cs%n)
        call grow_logical(cs%active, cap, cs%n)
        cs%capacity = cap
    end subroutine ensure_capacity

    !> Sort key of a pair: (owner, other) in lexicographic order, owner = the disk i1 of a
    !> disk pair or the disk i2 of a wall contact, other = the other body (walls negative).
    !> What is wrong with a contact list read back (a checkpoint): a body index out of range,
    !> a disk in contact with itself, or the pairs out of the detection's order (which the
    !> warm-start matching relies on); '' when nothing.
    pure function contacts_list_problem(cs, n_disks, n_walls) result(problem)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Number of disks.
        integer, intent(in) :: n_disks
        !> Number of walls.
        integer, intent(in) :: n_walls
        character(len=:), allocatable :: problem
        character(len=120) :: buf
        integer :: k
        problem = ''
        do k = 1, cs%n
            if (cs%i2(k) < 1 .or. cs%i2(k) > n_disks .or. cs%i1(k) < -n_walls .or. cs%i1(k) == 0 &
                .or. cs%i1(k) > n_disks .or. cs%i1(k) == cs%i2(k)) then
                write (buf, '(a,i0,a,i0,a,i0,a,i0,a,i0,a)') 'contact ', k, ' joins bodies ', cs%i1(k), &
                    ' and ', cs%i2(k), ' (', n_disks, ' disks, ', n_walls, ' walls)'
                problem = trim(buf)
                return
            end if
            if (k == 1) cycle
            if (pair_key(cs%i1(k), cs%i2(k)) <= pair_key(cs%i1(k - 1), cs%i2(k - 1))) then
                write (buf, '(a,i0,a,i0,a)') 'contacts ', k - 1, ' and ', k, ' are out of order'
                problem = trim(buf)
                return
            end if
        end do
    end function contacts_list_problem

    pure integer(i8) function pair_key(i1, i2) result(key)
        integer, intent(in) :: i1, i2
        if (i1 > 0) then
            key = ishft(int(i1, i8), 32) + int(i2, i8)
        else
            key = ishft(int(i2, i8), 32) + int(i1, i8)
        end if
    end function pair_key

    !> Lever arms and Delassus blocks from radii and inverse masses per DOF (0 when fixed).
    !> Contacts are independent: the loop runs over the OpenMP threads (same result).
    subroutine contacts_set_frames(cs, radius, im)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Disk radii [m].
        real(wp), intent(in) :: radius(:)
        !> Inverse masses (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        integer :: k, a, b
        real(wp) :: nx, ny
        !$omp parallel do schedule(static) private(k, a, b, nx, ny) if (cs%n >= parallel_min)
        do k = 1, cs%n
            a = cs%i1(k)
            b = cs%i2(k)
            nx = cs%nrm(1, k)
            ny = cs%nrm(2, k)
            cs%lever(2, k) = -radius(b)
            cs%w(:, k) = block(im(:, b), cs%lever(2, k), 1.0_wp, nx, ny)
            cs%lever(1, k) = 0.0_wp
            if (a > 0) then
                cs%lever(1, k) = -radius(a)
                cs%w(:, k) = cs%w(:, k) + block(im(:, a), cs%lever(1, k), -1.0_wp, nx, ny)
            end if
        end do
        !$omp end parallel do
    contains
        ! block of one body: its generalised directions are s (n, 0), s (t, 0) + (0, c) and
        ! (0, s) for r_n, r_t and M (s = +1 on i2, -1 on i1), t = (-n_y, n_x)
        pure function block(imb, c, s, nx, ny) result(w)
            real(wp), intent(in) :: imb(3), c, s, nx, ny
            real(wp) :: w(6), tx, ty
            tx = -ny
            ty = nx
            w(1) = nx*nx*imb(1) + ny*ny*imb(2)
            w(2) = nx*tx*imb(1) + ny*ty*imb(2)
            w(3) = tx*tx*imb(1) + ty*ty*imb(2) + c*c*imb(3)
            w(4) = 0.0_wp
            w(5) = s*c*imb(3)
            w(6) = imb(3)
        end function block
    end subroutine contacts_set_frames

    !> Relative velocity (u_n, u_t, w_r) of contact k for body velocities vel (3, n_disks) and
    !> wall velocities wall_vel (2, n_walls), without the solver shifts.
    pure function contacts_local_velocity(cs, k, vel, wall_vel) result(u)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Contact index.
        integer, intent(in) :: k
        !> Disk velocities (vx, vy, w).
        real(wp), intent(in) :: vel(:, :)
        !> Wall velocities.
        real(wp), intent(in) :: wall_vel(:, :)
        real(wp) :: u(3)
        real(wp) :: dv(2), nx, ny
        integer :: a, b
        a = cs%i1(k)
        b = cs%i2(k)
        nx = cs%nrm(1, k)
        ny = cs%nrm(2, k)
        if (a > 0) then
            dv = vel(1:2, b) - vel(1:2, a)
            u(2) = cs%lever(1, k)*vel(3, a)
            u(3) = vel(3, b) - vel(3, a)
        else
            dv = vel(1:2, b) - wall_vel(:, -a)
            u(2) = 0.0_wp
            u(3) = vel(3, b)
        end if
        u(1) = nx*dv(1) + ny*dv(2)
        u(2) = u(2) - ny*dv(1) + nx*dv(2) + cs%lever(2, k)*vel(3, b)
    end function contacts_local_velocity

    !> Generalised directions (vx, vy, w) of the unit reaction components r_n, r_t, M of
    !> contact k (columns) on its body of side s (1: i1, sign -1; 2: i2, sign +1): g(dof,
    !> component). A body's share of H is g, its velocity's contribution to (u_n, u_t, w_r)
    !> is g^T v (the velocity map is the transpose of the impulse map).
    pure function contacts_directions(cs, k, s) result(g)
        !> Contacts (frames and levers).
        type(contact_set_t), intent(in) :: cs
        !> Contact index and side.
        integer, intent(in) :: k, s
        real(wp) :: g(3, 3)
        real(wp) :: sg, nx, ny
        sg = merge(1.0_wp, -1.0_wp, s == 2)
        nx = cs%nrm(1, k)
        ny = cs%nrm(2, k)
        g(:, 1) = [sg*nx, sg*ny, 0.0_wp]
        g(:, 2) = [-sg*ny, sg*nx, cs%lever(s, k)]
        g(:, 3) = [0.0_wp, 0.0_wp, sg]
    end function contacts_directions

    !> The impulse (drn, drt, drm) of contact k in its frame applied to the disks:
    !> vel += M^-1 H (drn, drt, drm). A wall (i1 <= 0) takes nothing.
    pure subroutine contacts_apply_impulse(cs, k, im, vel, drn, drt, drm)
        !> Contacts (frames and levers).
        type(contact_set_t), intent(in) :: cs
        !> Contact index.
        integer, intent(in) :: k
        !> Inverse mass per DOF (3, n_disks).
        real(wp), intent(in) :: im(:, :)
        !> Disk velocities (vx, vy, w) (3, n_disks), updated.
        real(wp), intent(inout) :: vel(:, :)
        !> Normal and tangential impulse and moment impulse.
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
    end subroutine contacts_apply_impulse

    !> Relative velocity of contact k as the contact solver sees it, H^T v + shift:
    !> (u_n, u_t, w_r). A wall's motion is in the shift (contacts_set_laws), unlike
    !> contacts_local_velocity.
    pure subroutine contacts_solver_velocity(cs, k, vel, u)
        !> Contacts (frames, levers and shifts).
        type(contact_set_t), intent(in) :: cs
        !> Contact index.
        integer, intent(in) :: k
        !> Disk velocities (vx, vy, w) (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> (u_n, u_t, w_r).
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
    end subroutine contacts_solver_velocity

    !> Intact bonds of the previous list that the detection did not find again (their pair
    !> beyond the alert distance): those bonds are gone from the list. The position update of a
    !> bond holds its velocity, not its gap, so a spinning bonded pair drifts apart by about
    !> d (omega h)^2 / 2 per step; after a long spin, or under `[contacts] alert = 0`, the gap
    !> exceeds the alert distance and the pair is not a candidate any more. Both lists are in
    !> contact order (pair_key): one merge.
    pure subroutine contacts_lost_bonds(cs, i1, i2)
        !> Contacts, after the detection of the step.
        type(contact_set_t), intent(in) :: cs
        !> Bodies of each lost bond: first (disk, or -wall) and second (disk).
        integer, allocatable, intent(out) :: i1(:), i2(:)
        integer(i8) :: key
        integer :: p, k
        allocate (i1(0), i2(0))
        k = 1
        if (allocated(cs%prev_status)) then
            do p = 1, cs%n_prev
                if (cs%prev_status(p) /= status_cohesive) cycle
                key = pair_key(cs%prev_i1(p), cs%prev_i2(p))
                do while (k <= cs%n)
                    if (pair_key(cs%i1(k), cs%i2(k)) >= key) exit
                    k = k + 1
                end do
                if (k <= cs%n) then
                    if (cs%i1(k) == cs%prev_i1(p) .and. cs%i2(k) == cs%prev_i2(p)) cycle
                end if
                ! rare (each bond is lost once): grown one by one
                i1 = [i1, cs%prev_i1(p)]
                i2 = [i2, cs%prev_i2(p)]
            end do
        end if
    end subroutine contacts_lost_bonds

    !> Make the bonds of a run on the contacts detected in the configuration at t = 0: a contact
    !> whose pair of materials has cohesion and whose gap is at most bond_ratio * mean radius
    !> of the pair (the radius of the disk for a wall) becomes an intact bond (status_cohesive);
    !> the other statuses are left as they are. Called once, before the first step, on the
    !> start positions (dem_moreau_jean): the first step's detection carries the statuses
    !> over by pair, so that whether a bond exists depends on the configuration at t = 0 only,
    !> not on the step, theta or the initial velocities (which move the configuration where
    !> the steps detect their contacts).
    pure subroutine contacts_make_bonds(cs, bond_ratio, radius, mat, wall_mat, materials)
        !> Contacts detected on the configuration at t = 0.
        type(contact_set_t), intent(inout) :: cs
        !> Gap ratio of the bonds (>= 0).
        real(wp), intent(in) :: bond_ratio
        !> Disk radii [m].
        real(wp), intent(in) :: radius(:)
        !> Disk and wall materials.
        integer, intent(in) :: mat(:), wall_mat(:)
        !> Material pair table.
        type(materials_t), intent(in) :: materials
        integer :: k, ma, mb
        real(wp) :: amoy
        do k = 1, cs%n
            call pair_of(cs, k, radius, mat, wall_mat, ma, mb, amoy)
            if (materials%cohesion(ma, mb) > 0.0_wp .and. cs%gap(k) <= bond_ratio*amoy) &
                cs%status(k) = status_cohesive
        end do
    end subroutine contacts_make_bonds

    !> Materials of contact k's two bodies and its mean radius (that of the disk against a
    !> wall).
    pure subroutine pair_of(cs, k, radius, mat, wall_mat, ma, mb, amoy)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> The contact.
        integer, intent(in) :: k
        !> Disk radii [m].
        real(wp), intent(in) :: radius(:)
        !> Disk and wall materials.
        integer, intent(in) :: mat(:), wall_mat(:)
        !> Materials of the first body (disk or wall) and of the second (disk).
        integer, intent(out) :: ma, mb
        !> Mean radius of the pair [m].
        real(wp), intent(out) :: amoy
        mb = mat(cs%i2(k))
        if (cs%i1(k) > 0) then
            ma = mat(cs%i1(k))
            amoy = 0.5_wp*(radius(cs%i1(k)) + radius(cs%i2(k)))
        else
            ma = wall_mat(-cs%i1(k))
            amoy = radius(cs%i2(k))
        end if
    end subroutine pair_of

    !> Material law, bonds, solver shifts and activation of every contact for the step.
    !> Intact bonds are always active, with Newton restitution: target = e max(-u_n(begin), 0)
    !> (a bond holds its gap, <= bond_ratio * mean radius, rather than pulling it shut with its
    !> cohesion). Whether any other contact is active, and its normal target u_n >= target
    !> (the solver shifts u_n by -target), is the rule's (dem_activation): by default the
    !> predicted gap g_p = g + theta h u_n(free) on the mid configuration, with the round-off
    !> allowance gap_allowance * mean radius (disks that touch at rest have g and g_p of either
    !> sign at the level of the rounding of their coordinates), the warm start r_n > 0 (a
    !> loaded contact stays in the solve even when the rounding or the solver tolerance left it
    !> slightly open), Newton restitution when g_p <= 0 and otherwise the gap term
    !> -max(g, 0)/(theta h): the contact may close its gap during the step but not overlap, so
    !> activating it changes the work of the solver, not the solution. A contact left out that
    !> the others' impulses shut within the step is let in after the solve by the rule's
    !> re-check (contacts_recheck), and the step solved again.
    !> There is no position correction (standard Moreau-Jean): with theta = 1 no contact
    !> overlaps beyond the allowance; with theta < 1 a step takes a contact at most
    !> (1 - theta) h |u_n| farther in, u_n its normal velocity at the start of the step
    !> (doc/theory.md 2.4), and the overlap is kept. (A full push-out -g/(theta h) of overlaps
    !> was tried and makes dense packings unstable.)
    !> The pair's output y = (g, u_n(begin)) is stored for the next step's rule.
    subroutine contacts_set_laws(cs, law, rule, radius, mat, wall_mat, materials, vel_begin, vel_free, &
                                 wall_vel_begin, wall_vel_end)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Step parameters.
        type(contact_law_t), intent(in) :: law
        !> Rule of activation of the contacts without a bond.
        class(activation_t), intent(in) :: rule
        !> Disk radii [m].
        real(wp), intent(in) :: radius(:)
        !> Disk and wall materials.
        integer, intent(in) :: mat(:), wall_mat(:)
        !> Material pair table.
        type(materials_t), intent(in) :: materials
        !> Disk velocities at the start of the step and free velocities (3, n_disks).
        real(wp), intent(in) :: vel_begin(:, :), vel_free(:, :)
        !> Wall velocities at the start and at the end of the step (2, n_walls).
        real(wp), intent(in) :: wall_vel_begin(:, :), wall_vel_end(:, :)
        integer :: k, ma, mb
        real(wp) :: ub(3), uf(3), uw(2), amoy, target, e
        logical :: active
        ! contacts are independent: the loop runs over the OpenMP threads (same result)
        !$omp parallel do schedule(static) private(k, ma, mb, ub, uf, uw, amoy, target, e, active) &
        !$omp if (cs%n >= parallel_min)
        do k = 1, cs%n
            call pair_of(cs, k, radius, mat, wall_mat, ma, mb, amoy)
            cs%amoy(k) = amoy
            e = materials%restitution(ma, mb)
            cs%coh(k) = 0.0_wp
            cs%mu(k) = materials%mu(ma, mb)
            cs%erol(k) = materials%rolling(ma, mb)
            if (cs%status(k) == status_cohesive) then
                cs%coh(k) = materials%cohesion(ma, mb)*amoy*law%h
                cs%mu(k) = materials%bond_mu(ma, mb)
                cs%erol(k) = materials%bond_e(ma, mb)
                if (cs%erol(k) == bond_e_default) cs%erol(k) = 0.5_wp*amoy
            end if
            ! a law without moment: the warm start of a bond that broke carries none
            if (cs%erol(k) <= 0.0_wp) cs%r(3, k) = 0.0_wp
            cs%pcase(k) = case_separation
            cs%break_mode(k) = break_none
            ub = contacts_local_velocity(cs, k, vel_begin, wall_vel_begin)
            uf = contacts_local_velocity(cs, k, vel_free, wall_vel_end)
            uw = 0.0_wp
            if (cs%i1(k) < 0) uw = -wall_term(cs%nrm(:, k), wall_vel_end(:, -cs%i1(k)))
            if (cs%status(k) == status_cohesive) then
                active = .true.
                target = e*max(-ub(1), 0.0_wp)
            else
                call rule%decide(law%h, law%theta, e, law%gap_allowance*amoy, cs%gap(k), ub(1), uf(1), &
                                 cs%r(1, k), cs%y_prev(:, k), active, target)
            end if
            cs%y(:, k) = [cs%gap(k), ub(1)]
            cs%shift(1, k) = uw(1) - target
            cs%shift(2, k) = uw(2)
            cs%active(k) = active
            if (.not. cs%active(k)) cs%r(:, k) = 0.0_wp
        end do
        !$omp end parallel do
    end subroutine contacts_set_laws

    !> After a solve: the rule's re-check (activation_t%recheck) of the contacts left out of
    !> it, neither active nor intact bonds, on the end-of-step velocities, and within `reach`.
    !> With `activate`
    !> those it lets in become active, with r = 0 and the normal target it gives (the solver
    !> shift as contacts_set_laws sets it); without, they are only counted. A contact that
    !> cannot move along its normal (W_nn at the floor of dem_nlgs's blocked contacts: both
    !> bodies fixed or imposed) is not re-checked: no impulse can shut it, and the solve would
    !> leave it out again. Contacts are independent: the loop runs over the OpenMP threads
    !> (same result).
    subroutine contacts_recheck(cs, law, rule, vel, wall_vel, reach, activate, added)
        !> Contacts, after the solve (frames, laws, activity set).
        type(contact_set_t), intent(inout) :: cs
        !> Step parameters.
        type(contact_law_t), intent(in) :: law
        !> Rule of activation of the contacts without a bond.
        class(activation_t), intent(in) :: rule
        !> End-of-step disk velocities (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> Wall velocities at the end of the step (2, n_walls).
        real(wp), intent(in) :: wall_vel(:, :)
        !> Gap [m] below which a contact left out is let in, shut or not (0: only those shut).
        real(wp), intent(in) :: reach
        !> Let the contacts in (else count them only).
        logical, intent(in) :: activate
        !> Contacts the re-check lets in.
        integer, intent(out) :: added
        integer :: k
        real(wp) :: u(3), uw(2), target
        logical :: active
        added = 0
        !$omp parallel do schedule(static) private(k, u, uw, target, active) reduction(+:added) &
        !$omp if (cs%n >= parallel_min)
        do k = 1, cs%n
            if (cs%active(k) .or. cs%status(k) == status_cohesive) cycle
            if (cs%w(1, k) <= diagonal_floor*(cs%w(1, k) + cs%w(3, k))) cycle
            u = contacts_local_velocity(cs, k, vel, wall_vel)
            call rule%recheck(law%h, law%theta, law%gap_allowance*cs%amoy(k), cs%gap(k), u(1), reach, active, target)
            if (.not. active) cycle
            added = added + 1
            if (.not. activate) cycle
            uw = 0.0_wp
            if (cs%i1(k) < 0) uw = -wall_term(cs%nrm(:, k), wall_vel(:, -cs%i1(k)))
            cs%shift(1, k) = uw(1) - target
            cs%r(:, k) = 0.0_wp
            cs%active(k) = .true.
        end do
        !$omp end parallel do
    end subroutine contacts_recheck

    !> Local components (n.v, t.v) of a wall velocity v.
    pure function wall_term(nrm, v) result(u)
        real(wp), intent(in) :: nrm(2), v(2)
        real(wp) :: u(2)
        u(1) = nrm(1)*v(1) + nrm(2)*v(2)
        u(2) = -nrm(2)*v(1) + nrm(1)*v(2)
    end function wall_term

    !> After the solve: end-of-step relative velocities, statuses, broken bonds.
    !> At a converged step, an intact bond breaks for good when its shifted reaction
    !> (r_n + r_cohe h, r_t, M) reaches a bound of its cone (break_mode records which):
    !>  - tension: the apex (full tension, the separation case of the law) and the contact
    !>    opens (u_n > 0);
    !>  - shear: the last local solve projected on the sliding face |r_t| = mu_b (r_n + r_cohe h);
    !>  - moment: it projected on the rolling face |M| = e_b (r_n + r_cohe h);
    !>  - shear and moment: on both (the edge of the cone).
    !> A bound with a zero coefficient (mu_b = 0 or e_b = 0) locks nothing: that component is
    !> free and does not break the bond. This depends on the converged forces, not on an
    !> opening of round-off size (which the solver tolerance does not resolve). A step that
    !> did not converge breaks no bond (it is reported by the solver statistics). A bond left
    !> out of the solve (blocked: both bodies immobile along the normal, see dem_nlgs) has no
    !> force to judge by: it breaks in tension when its end-of-step gap g + theta h u_n exceeds
    !> bond_ratio * mean radius.
    pure subroutine contacts_finish(cs, law, radius, vel, wall_vel, converged)
        !> Contacts.
        type(contact_set_t), intent(inout) :: cs
        !> Step parameters.
        type(contact_law_t), intent(in) :: law
        !> Disk radii [m].
        real(wp), intent(in) :: radius(:)
        !> End-of-step disk velocities (3, n_disks).
        real(wp), intent(in) :: vel(:, :)
        !> End-of-step wall velocities (2, n_walls).
        real(wp), intent(in) :: wall_vel(:, :)
        !> The solver converged at this step (default: yes).
        logical, intent(in), optional :: converged
        integer :: k
        real(wp) :: amoy, rn
        logical :: judge
        judge = .true.
        if (present(converged)) judge = converged
        do k = 1, cs%n
            cs%u(:, k) = contacts_local_velocity(cs, k, vel, wall_vel)
            cs%break_mode(k) = break_none
            if (cs%status(k) == status_cohesive) then
                if (cs%active(k)) then
                    if (judge) cs%break_mode(k) = bond_break_mode(cs, k)
                else
                    amoy = radius(cs%i2(k))
                    if (cs%i1(k) > 0) amoy = 0.5_wp*(amoy + radius(cs%i1(k)))
                    if (cs%gap(k) + law%theta*law%h*cs%u(1, k) > law%bond_ratio*amoy) &
                        cs%break_mode(k) = break_tension
                end if
                if (cs%break_mode(k) /= break_none) cs%status(k) = status_broken
            else if (cs%status(k) /= status_broken) then
                rn = cs%r(1, k)
                if (rn <= 0.0_wp) then
                    cs%status(k) = status_open
                else if (abs(cs%r(2, k)) >= cs%mu(k)*rn*(1.0_wp - relative_roundoff)) then
                    cs%status(k) = status_slip
                else
                    cs%status(k) = status_stick
                end if
            end if
        end do
    end subroutine contacts_finish

    !> Rupture mode of the active intact bond k at the end of a converged solve (see
    !> contacts_finish), break_none when it holds.
    pure integer function bond_break_mode(cs, k) result(mode)
        type(contact_set_t), intent(in) :: cs
        integer, intent(in) :: k
        logical :: shear, moment
        real(wp) :: rn
        mode = break_none
        if (cs%r(1, k) + cs%coh(k) <= 0.0_wp) then
            if (cs%u(1, k) > 0.0_wp) mode = break_tension
            return
        end if
        ! the case of the last local solve, or the reaction on the bound: a bond on its bound
        ! with zero slip is a tie of the law that either case solves (doc/theory.md 7.6)
        rn = cs%r(1, k) + cs%coh(k)
        shear = cs%mu(k) > 0.0_wp .and. (cs%pcase(k) == case_slip .or. cs%pcase(k) == case_slip_roll &
                                         .or. abs(cs%r(2, k)) >= (1.0_wp - bond_on_bound)*cs%mu(k)*rn)
        moment = cs%erol(k) > 0.0_wp .and. (cs%pcase(k) == case_roll .or. cs%pcase(k) == case_slip_roll &
                                            .or. abs(cs%r(3, k)) >= (1.0_wp - bond_on_bound)*cs%erol(k)*rn)
        if (shear .and. moment) then
            mode = break_shear_moment
        else if (shear) then
            mode = break_shear
        else if (moment) then
            mode = break_moment
        end if
    end function bond_break_mode

    !> Whether any contact of the list transmits moments (a moment length > 0).
    pure logical function contacts_moments_active(cs) result(yes)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        yes = any(cs%erol(1:cs%n) > 0.0_wp)
    end function contacts_moments_active

    !> Add the generalised contact impulses H r to p (3, n_disks).
    pure subroutine contacts_impulses(cs, p)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> Impulses (px, py, torque impulse) per disk.
        real(wp), intent(inout) :: p(:, :)
        integer :: k, a, b
        real(wp) :: f(2)
        do k = 1, cs%n
            a = cs%i1(k)
            b = cs%i2(k)
            f = cs%r(1, k)*cs%nrm(:, k) + cs%r(2, k)*[-cs%nrm(2, k), cs%nrm(1, k)]
            p(1:2, b) = p(1:2, b) + f
            p(3, b) = p(3, b) + cs%lever(2, k)*cs%r(2, k) + cs%r(3, k)
            if (a > 0) then
                p(1:2, a) = p(1:2, a) - f
                p(3, a) = p(3, a) + cs%lever(1, k)*cs%r(2, k) - cs%r(3, k)
            end if
        end do
    end subroutine contacts_impulses

    !> Number of contacts with the given status.
    pure integer function contacts_count_status(cs, status) result(m)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        !> One of the status_* values.
        integer, intent(in) :: status
        m = count(cs%status(1:cs%n) == status)
    end function contacts_count_status

    !> Memory held by the contact arrays (current and previous lists, full capacity) [bytes].
    pure integer(i8) function contacts_bytes(cs) result(b)
        !> Contacts.
        type(contact_set_t), intent(in) :: cs
        b = 0_i8
        if (allocated(cs%i1)) b = b + 4_i8*(size(cs%i1) + size(cs%i2))
        if (allocated(cs%nrm)) b = b + 8_i8*(size(cs%nrm) + size(cs%gap))
        if (allocated(cs%lever)) b = b + 8_i8*(size(cs%lever) + size(cs%w) + size(cs%shift) + size(cs%r) &
                                               + size(cs%u) + size(cs%mu) + size(cs%coh) + size(cs%erol) + size(cs%amoy))
        if (allocated(cs%y)) b = b + 8_i8*(size(cs%y) + size(cs%y_prev))
        if (allocated(cs%prev_y)) b = b + 8_i8*size(cs%prev_y)
        if (allocated(cs%status)) b = b + 4_i8*(size(cs%status) + size(cs%active) + size(cs%pcase) &
                                                + size(cs%break_mode))
        if (allocated(cs%prev_i1)) b = b + 4_i8*(size(cs%prev_i1) + size(cs%prev_i2))
        if (allocated(cs%prev_r)) b = b + 8_i8*size(cs%prev_r)
        if (allocated(cs%prev_status)) b = b + 4_i8*size(cs%prev_status)
    end function contacts_bytes

    !> Resize an integer array to cap, keeping its first `keep` entries.
    pure subroutine grow_int(a, cap, keep)
        integer, allocatable, intent(inout) :: a(:)
        integer, intent(in) :: cap, keep
        integer, allocatable :: tmp(:)
        if (allocated(a)) then
            if (size(a) >= cap) return
        end if
        allocate (tmp(cap))
        if (keep > 0) tmp(1:keep) = a(1:keep)
        call move_alloc(tmp, a)
    end subroutine grow_int

    !> Resize a logical array to cap, keeping its first `keep` entries.
    pure subroutine grow_logical(a, cap, keep)
        logical, allocatable, intent(inout) :: a(:)
        integer, intent(in) :: cap, keep
        logical, allocatable :: tmp(:)
        if (allocated(a)) then
            if (size(a) >= cap) return
        end if
        allocate (tmp(cap))
        if (keep > 0) tmp(1:keep) = a(1:keep)
        call move_alloc(tmp, a)
    end subroutine grow_logical

    !> Resize a real array to cap, keeping its first `keep` entries.
    pure subroutine grow_real1(a, cap, keep)
        real(wp), allocatable, intent(inout) :: a(:)
        integer, intent(in) :: cap, keep
        real(wp), allocatable :: tmp(:)
        if (allocated(a)) then
            if (size(a) >= cap) return
        end if
        allocate (tmp(cap))
        if (keep > 0) tmp(1:keep) = a(1:keep)
        call move_alloc(tmp, a)
    end subroutine grow_real1

    !> Resize a (rows, :) real array to (rows, cap), keeping its first `keep` columns.
    pure subroutine grow_real2(a, rows, cap, keep)
        real(wp), allocatable, intent(inout) :: a(:, :)
        integer, intent(in) :: rows, cap, keep
        real(wp), allocatable :: tmp(:, :)
        if (allocated(a)) then
            if (size(a, 2) >= cap) return
        end if
        allocate (tmp(rows, cap))
        if (keep > 0) tmp(:, 1:keep) = a(:, 1:keep)
        call move_alloc(tmp, a)
    end subroutine grow_real2
end module dem_contacts
