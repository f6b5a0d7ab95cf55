!> Checks of the state after every time step: a run stops at the first sign that it has gone
!> wrong, with a message naming the step, the time, the model and the body, and a likely
!> cause, instead of writing NaN or Inf to the end.
!>
!> - `check_beam_state`: displacements, velocities, accelerations and energy accounts of the
!>   beam are finite.
!> - `check_disks_state`: positions, rotations and velocities of the disks are finite and the
!>   centres stay in the box the detection can represent (dem_detection::coordinate_limit);
!>   energy accounts are finite.
!> - `check_walls_state`: the end points of the walls are finite and in the same box (a
!>   driven wall leaves it when its velocity times the time run is too large).
!> - Tunnelling (`step_start_t`, `check_tunnelling`): a disk whose centre crossed a wall
!>   within the step, or two candidate disks (pairs found by the detection of the step) whose
!>   centres passed each other while overlapping by more than half their radii, stop the run
!>   with the step to use instead.
!> - Energy created (`step_start_t`, `step_created_energy`, `creation_allowance`,
!>   `energy_creation_warning`): a step whose contacts gave the bodies energy beyond what the
!>   scheme makes near rest and the solver's tolerance (Newton's restitution, doc/theory.md
!>   2.4) is reported by the time loops, once, then counted.
module driver_guards
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: to_str, num => sci_text
    use dem_particles, only: particles_t
    use dem_walls, only: walls_t
    use dem_contacts, only: contact_set_t
    use dem_moreau_jean, only: energies_t, dem_system_t, mj_load_energy, mj_velocity_error_energy
    use dem_detection, only: coordinate_limit
    use core_sort, only: sort_index
    implicit none
    private
    public :: check_beam_state, check_disks_state, largest_speed, check_walls_state
    public :: step_start_t, take_step_start, check_tunnelling
    public :: step_created_energy, creation_allowance, step_creates_energy, energy_creation_warning, &
              energy_creation_summary

    !> Energy a step may create, relative to the disks' kinetic energy, before it is reported
    !> (creation_allowance): the error of a solve stopped at the sweeps' tolerance (1.7e-4 on
    !> the velocities by default) with a margin; an oblique impact at e = 0.9 creates 1.25 %
    !> of the disk's energy (doc/theory.md 2.4).
    real(wp), parameter :: creation_tolerance = 1.0e-3_wp
    !> Round-off of the end velocities relative to the sizes of their terms (step_creates_energy;
    !> the bonded block's guard uses the same 64 eps, dem_bonded_block).
    real(wp), parameter :: velocity_roundoff = 64.0_wp*epsilon(1.0_wp)

    !> Where the disks and walls were at the start of a step.
    type :: step_start_t
        !> Disk centres [m].
        real(wp), allocatable :: x(:), y(:)
        !> Wall end points [m].
        real(wp), allocatable :: wx1(:), wy1(:), wx2(:), wy2(:)
        !> Energy dissipated by the contacts since the start of the run [J/m].
        real(wp) :: dissipated = 0.0_wp
        !> Energy dissipated by the scheme (theta > 1/2) since the start of the run [J/m].
        real(wp) :: numerical = 0.0_wp
        !> Kinetic energy of the disks [J/m].
        real(wp) :: kinetic = 0.0_wp
    end type step_start_t

    character(len=*), parameter :: dof_name(3) = ['u    ', 'w    ', 'theta']

contains

    !> Error at the first non-finite displacement, velocity or acceleration of the beam, or
    !> non-finite energy account.
    subroutine check_beam_state(step, t, node_id, d, v, a, energies, error)
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Time reached [s].
        real(wp), intent(in) :: t
        !> Deck id of each node.
        integer, intent(in) :: node_id(:)
        !> Displacements, velocities, accelerations (3, n_nodes).
        real(wp), intent(in) :: d(:, :), v(:, :), a(:, :)
        !> Energy accounts (kinetic, strain, external work, damping) [J].
        real(wp), intent(in) :: energies(:)
        !> Set at the first non-finite value.
        type(error_t), allocatable, intent(out) :: error
        character(len=*), parameter :: cause = 'likely cause: a load, an initial condition or '// &
                                       'a Rayleigh coefficient far too large, or a time step above the '// &
                                       'stability limit of the scheme (check the magnitudes in [beam] '// &
                                       'and [initial], or lower [time] step)'
        call field(d, 'displacement')
        if (allocated(error)) return
        call field(v, 'velocity')
        if (allocated(error)) return
        call field(a, 'acceleration')
        if (allocated(error)) return
        if (.not. all(ieee_is_finite(energies))) then
            call make_error(error, when(step, t)//'beam: an energy account (kinetic, strain, '// &
                            'external work or damping) is not finite; '//cause)
        end if
    contains
        subroutine field(f, what)
            real(wp), intent(in) :: f(:, :)
            character(len=*), intent(in) :: what
            integer :: i, k
            do i = 1, size(f, 2)
                do k = 1, 3
                    if (ieee_is_finite(f(k, i))) cycle
                    call make_error(error, when(step, t)//'beam node '//to_str(node_id(i))//': '// &
                                    what//' '//trim(dof_name(k))//' is '//kind_of(f(k, i))//'; '//cause)
                    return
                end do
            end do
        end subroutine field
    end subroutine check_beam_state

    !> Error at the first disk with a non-finite position, rotation or velocity, or a centre
    !> beyond the representable box, or at a non-finite energy account.
    subroutine check_disks_state(step, t, p, en, initial_speed, error)
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Time reached [s].
        real(wp), intent(in) :: t
        !> The disks.
        type(particles_t), intent(in) :: p
        !> Energy accounts of the particles.
        type(energies_t), intent(in) :: en
        !> Largest speed of a disk at t = 0 (`largest_speed` of the initial state) [m/s]: when
        !> it is not 0 the likely causes name the initial velocity, with it.
        real(wp), intent(in) :: initial_speed
        !> Set at the first problem found.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: cause, initial
        real(wp) :: limit, value(6)
        character(len=16), parameter :: names(6) = [character(len=16) :: &
                                                    'x', 'y', 'rotation', 'velocity x', 'velocity y', 'angular velocity']
        integer :: i, k
        if (p%n == 0) return
        ! The deck's initial velocities are a likely cause as much as its forces: 1e150 m/s
        ! carries a disk 1e147 m in a step of 1e-3 s.
        initial = ''
        if (initial_speed > 0.0_wp) initial = 'an initial velocity (the disks start at up to '//num(initial_speed)// &
                                              ' m/s: [particles] initial_velocity, initial_rigid), '
        cause = 'likely cause: '//initial//'a force, an imposed velocity or gravity far too large (check the '// &
                'magnitudes in [particles]), or a time step too large (lower [time] step)'
        limit = coordinate_limit(minval(p%radius(1:p%n)))
        do i = 1, p%n
            value = [p%x(i), p%y(i), p%rot(i), p%vx(i), p%vy(i), p%w(i)]
            do k = 1, 6
                if (ieee_is_finite(value(k))) cycle
                call make_error(error, when(step, t)//'disk '//to_str(i)//': '//trim(names(k))// &
                                ' is '//kind_of(value(k))//'; '//cause)
                return
            end do
            if (max(abs(p%x(i)), abs(p%y(i))) > limit) then
                call make_error(error, when(step, t)//'disk '//to_str(i)//' is at ('//num(p%x(i))// &
                                ', '//num(p%y(i))//') m, beyond the box the run can represent (|x|, '// &
                                '|y| <= '//num(limit)//' m: 4.5e9 times the smallest radius); likely '// &
                                'cause: a disk escaping with no wall to stop it, or '//initial//'a force or '// &
                                'gravity far too large')
                return
            end if
        end do
        if (.not. all(ieee_is_finite([en%kinetic, en%potential, en%external_work, en%drive_work, &
                                      en%contact_dissipation, en%numerical_dissipation, en%coupling_work]))) then
            call make_error(error, when(step, t)//'particles: an energy account is not finite; '//cause)
        end if
    end subroutine check_disks_state

    !> Largest speed of the disks [m/s] (0 when there are none): that of the initial state is
    !> the `initial_speed` of check_disks_state.
    pure real(wp) function largest_speed(p) result(speed)
        !> The disks.
        type(particles_t), intent(in) :: p
        speed = 0.0_wp
        if (p%n > 0) speed = maxval(hypot(p%vx(1:p%n), p%vy(1:p%n)))
    end function largest_speed

    !> Error at the first wall with an end point that is not finite or lies beyond the box
    !> of check_disks_state (the box of the deck's walls, dem_detection::coordinate_limit):
    !> a driven wall moves there when its velocity times the time run is too large.
    subroutine check_walls_state(step, t, p, w, error)
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Time reached [s].
        real(wp), intent(in) :: t
        !> The disks (their smallest radius sets the box).
        type(particles_t), intent(in) :: p
        !> The walls.
        type(walls_t), intent(in) :: w
        !> Set at the first problem found.
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: limit, ends(4)
        integer :: i
        if (w%n == 0) return
        limit = coordinate_limit(minval(p%radius(1:p%n)))
        do i = 1, w%n
            ends = [w%x1(i), w%y1(i), w%x2(i), w%y2(i)]
            if (all(ieee_is_finite(ends))) then
                if (maxval(abs(ends)) <= limit) cycle
            end if
            call make_error(error, when(step, t)//'wall '//to_str(i)//' has moved to ('//num(ends(1))// &
                            ', '//num(ends(2))//') - ('//num(ends(3))//', '//num(ends(4))// &
                            ') m, beyond the box the run can represent (|x|, |y| <= '//num(limit)// &
                            ' m); likely cause: its velocity (vx, vy times its function) far too large '// &
                            'for the time run (check the wall record in [particles] and [time] end)')
            return
        end do
    end subroutine check_walls_state

    !> Record the disk centres and wall end points at the start of a step, the energy the
    !> contacts and the scheme dissipated so far and the kinetic energy.
    subroutine take_step_start(start, p, w, energies)
        !> The record (reused from step to step).
        type(step_start_t), intent(inout) :: start
        !> The disks.
        type(particles_t), intent(in) :: p
        !> The walls.
        type(walls_t), intent(in) :: w
        !> Energy audit of the disks at the start of the step.
        type(energies_t), intent(in) :: energies
        start%dissipated = energies%contact_dissipation
        start%numerical = energies%numerical_dissipation
        start%kinetic = energies%kinetic
        start%x = p%x(1:p%n)
        start%y = p%y(1:p%n)
        start%wx1 = w%x1(1:w%n)
        start%wy1 = w%y1(1:w%n)
        start%wx2 = w%x2(1:w%n)
        start%wy2 = w%y2(1:w%n)
    end subroutine take_step_start

    !> Error when, within the step just done, a disk centre crossed a wall (the segment swept
    !> by the centre relative to the wall meets the wall), or two disks passed each other
    !> (their centre line turned by more than 90 degrees while they overlapped by more than
    !> half the sum of their radii): the pairs among the step's contact candidates, and, when
    !> a disk moved farther than the alert distance (the detection may then have missed the
    !> pair), every pair with such a disk whose swept boxes meet (sort and sweep along x).
    !> The message blames the time step only when the step's motion went beyond what the
    !> detection sees and the contacts did not create the energy that carried the disk: given
    !> the contacts' dissipation at the end of the step (`dissipated`, and at its start in
    !> `start`), a step in which they gave the bodies at least half the kinetic energy of the
    !> crossing disk was a wrong solve (reactions that satisfy the contact laws dissipate, but
    !> for Newton's restitution with friction, which gives a disk at most a third of the energy
    !> it leaves a single impact with, doc/theory.md 2.4), and the message says so.
    subroutine check_tunnelling(step, t, h, alert, start, p, w, cs, error, dissipated)
        !> Steps done.
        integer(i8), intent(in) :: step
        !> Time reached [s].
        real(wp), intent(in) :: t
        !> Time step [s].
        real(wp), intent(in) :: h
        !> Alert distance [m].
        real(wp), intent(in) :: alert
        !> Disks and walls at the start of the step.
        type(step_start_t), intent(in) :: start
        !> The disks (end of the step).
        type(particles_t), intent(in) :: p
        !> The walls (end of the step).
        type(walls_t), intent(in) :: w
        !> The contact candidates of the step.
        type(contact_set_t), intent(in) :: cs
        !> Set at the first crossing found.
        type(error_t), allocatable, intent(out) :: error
        !> Energy dissipated by the contacts since the start of the run, at the end of the step
        !> [J/m].
        real(wp), intent(in) :: dissipated
        integer :: i, j, k, c
        real(wp) :: travel, created
        ! swept boxes of the disks over the step, and which disks moved beyond the alert
        ! distance (swept_pairs)
        real(wp), allocatable :: lo(:), hi(:), ylo(:), yhi(:)
        logical, allocatable :: fast(:)
        ! kinetic energy the contacts gave the bodies in the step (negative: dissipated)
        created = start%dissipated - dissipated
        do i = 1, p%n
            do k = 1, w%n
                if (.not. crosses_wall(i, k)) cycle
                ! the motion relative to the wall (a moving wall: its mid-point's displacement)
                travel = hypot((p%x(i) - start%x(i)) - 0.5_wp*((w%x1(k) - start%wx1(k)) + (w%x2(k) - start%wx2(k))), &
                               (p%y(i) - start%y(i)) - 0.5_wp*((w%y1(k) - start%wy1(k)) + (w%y2(k) - start%wy2(k))))
                call make_error(error, when(step, t)//'disk '//to_str(i)//' passed through wall '// &
                                to_str(k)//one_step(travel)//' (its centre moved '//num(travel)// &
                                ' m relative to the wall, its radius is '//num(p%radius(i))//' m): '// &
                                advice(travel, kinetic(i)))
                return
            end do
        end do
        do c = 1, cs%n
            i = cs%i1(c)
            j = cs%i2(c)
            if (i <= 0 .or. j <= 0) cycle
            if (.not. passed(i, j)) cycle
            travel = hypot((p%x(j) - p%x(i)) - (start%x(j) - start%x(i)), &
                           (p%y(j) - p%y(i)) - (start%y(j) - start%y(i)))
            call through_each_other(i, j)
            return
        end do
        call swept_pairs()
    contains
        !> The error for disks i and j passing each other.
        subroutine through_each_other(i, j)
            integer, intent(in) :: i, j
            travel = hypot((p%x(j) - p%x(i)) - (start%x(j) - start%x(i)), &
                           (p%y(j) - p%y(i)) - (start%y(j) - start%y(i)))
            call make_error(error, when(step, t)//'disks '//to_str(i)//' and '//to_str(j)// &
                            ' passed through each other'//one_step(travel)//' (relative motion '// &
                            num(travel)//' m, radii '//num(p%radius(i))//' and '// &
                            num(p%radius(j))//' m): '//advice(travel, max(kinetic(i), kinetic(j))))
        end subroutine through_each_other

        !> Kinetic energy of disk i at the end of the step [J/m].
        pure real(wp) function kinetic(i)
            integer, intent(in) :: i
            kinetic = 0.5_wp*(p%mass(i)*(p%vx(i)**2 + p%vy(i)**2) + p%inertia(i)*p%w(i)**2)
        end function kinetic

        !> Integer keys in the order of the (finite) reals x: the IEEE bit patterns, the 63 low
        !> bits flipped for negative numbers (whose patterns grow with the magnitude).
        pure function real_keys(x) result(k)
            real(wp), intent(in) :: x(:)
            integer(i8) :: k(size(x))
            integer :: a
            do a = 1, size(x)
                k(a) = transfer(x(a), 0_i8)
                if (k(a) < 0_i8) k(a) = ieor(k(a), huge(0_i8))
            end do
        end function real_keys

        !> The pairs with a disk that moved farther than the alert distance: sorted by the low
        !> x end of their swept boxes (start and end centres, plus the radius), each box is
        !> compared with those that start before its high end; a pair whose boxes meet in y
        !> too is tested with `passed`.
        subroutine swept_pairs()
            integer, allocatable :: order(:)
            real(wp) :: reach
            integer :: a, b, m
            m = p%n
            if (m < 2) return
            fast = hypot(p%x(1:m) - start%x, p%y(1:m) - start%y) > alert
            if (.not. any(fast)) return
            lo = min(start%x, p%x(1:m)) - p%radius(1:m)
            hi = max(start%x, p%x(1:m)) + p%radius(1:m)
            ylo = min(start%y, p%y(1:m)) - p%radius(1:m)
            yhi = max(start%y, p%y(1:m)) + p%radius(1:m)
            order = sort_index(real_keys(lo))
            ! only the boxes near a fast disk's are visited: ahead of it in the sorted order up
            ! to its own high end, behind it back to the widest box of a slow disk (a fast box
            ! behind is met when that fast disk is visited)
            reach = maxval(hi - lo, mask=.not. fast)
            if (all(fast)) reach = 0.0_wp
            do a = 1, m
                i = order(a)
                if (.not. fast(i)) cycle
                do b = a + 1, m
                    if (lo(order(b)) > hi(i)) exit
                    if (meet(i, order(b))) return
                end do
                do b = a - 1, 1, -1
                    if (lo(order(b)) < lo(i) - reach) exit
                    if (fast(order(b))) cycle
                    if (meet(i, order(b))) return
                end do
            end do
        end subroutine swept_pairs

        !> The boxes of disks i and j meet and the disks passed each other: the error set.
        logical function meet(i, j)
            integer, intent(in) :: i, j
            meet = .false.
            if (hi(j) < lo(i) .or. ylo(j) > yhi(i) .or. ylo(i) > yhi(j)) return
            if (.not. passed(min(i, j), max(i, j))) return
            call through_each_other(min(i, j), max(i, j))
            meet = .true.
        end function meet

        !> The centre path of disk i relative to wall k meets the wall: the signed distance to
        !> the wall's line changes sign, at a point between the wall's ends.
        logical function crosses_wall(i, k)
            integer, intent(in) :: i, k
            real(wp) :: s0, s1, f, px, py, ax, ay, bx, by, u
            crosses_wall = .false.
            s0 = side(start%x(i), start%y(i), start%wx1(k), start%wy1(k), start%wx2(k), start%wy2(k))
            s1 = side(p%x(i), p%y(i), w%x1(k), w%y1(k), w%x2(k), w%y2(k))
            if (s0*s1 >= 0.0_wp) return
            ! fraction of the step at which the centre is on the line (linear motion)
            f = s0/(s0 - s1)
            px = start%x(i) + f*(p%x(i) - start%x(i))
            py = start%y(i) + f*(p%y(i) - start%y(i))
            ax = start%wx1(k) + f*(w%x1(k) - start%wx1(k))
            ay = start%wy1(k) + f*(w%y1(k) - start%wy1(k))
            bx = start%wx2(k) + f*(w%x2(k) - start%wx2(k))
            by = start%wy2(k) + f*(w%y2(k) - start%wy2(k))
            u = ((px - ax)*(bx - ax) + (py - ay)*(by - ay))/((bx - ax)**2 + (by - ay)**2)
            crosses_wall = u >= 0.0_wp .and. u <= 1.0_wp
        end function crosses_wall

        !> Signed distance (times the wall length) of (x, y) to the line of the wall.
        pure real(wp) function side(x, y, x1, y1, x2, y2)
            real(wp), intent(in) :: x, y, x1, y1, x2, y2
            side = (x2 - x1)*(y - y1) - (y2 - y1)*(x - x1)
        end function side

        !> Disks i and j passed each other: the centre line d turned by more than 90 degrees
        !> (d0 . d1 < 0) and the relative path came closer than (r_i + r_j)/2.
        logical function passed(i, j)
            integer, intent(in) :: i, j
            real(wp) :: d0x, d0y, d1x, d1y, ex, ey, s, dmin
            d0x = start%x(j) - start%x(i)
            d0y = start%y(j) - start%y(i)
            d1x = p%x(j) - p%x(i)
            d1y = p%y(j) - p%y(i)
            passed = .false.
            if (d0x*d1x + d0y*d1y >= 0.0_wp) return
            ! closest point of the segment d0 -> d1 to the origin
            ex = d1x - d0x
            ey = d1y - d0y
            s = min(max(-(d0x*ex + d0y*ey)/(ex*ex + ey*ey), 0.0_wp), 1.0_wp)
            dmin = hypot(d0x + s*ex, d0y + s*ey)
            passed = dmin < 0.5_wp*(p%radius(i) + p%radius(j))
        end function passed

        !> What to do: a step under which the same motion stays within the alert distance.
        !> ' within one step' when the step's motion went beyond what the detection sees
        !> (else the crossing built up over several steps: advice says so).
        function one_step(travel) result(text)
            real(wp), intent(in) :: travel
            character(len=:), allocatable :: text
            text = ''
            if (.not. travel <= max(alert, 0.1_wp*minval(p%radius(1:p%n)))) text = ' within one step'
        end function one_step

        !> The cause of a crossing whose step moved the disk by `travel`, the disk (or the faster
        !> of the pair) carrying the kinetic energy `energy` at the end of the step.
        function advice(travel, energy) result(text)
            real(wp), intent(in) :: travel, energy
            character(len=:), allocatable :: text
            real(wp) :: reach
            reach = max(alert, 0.1_wp*minval(p%radius(1:p%n)))
            if (created > 0.0_wp .and. created >= 0.5_wp*energy) then
                ! reactions that satisfy the contact laws dissipate, but for Newton's restitution
                ! with friction, which gives a disk at most a third of the energy it leaves a
                ! single impact with (e = 1, a wall turned vertical: KE+ = 1.5 KE-, theory.md
                ! 2.4): at half of it the contacts of this step created the energy that carried
                ! the disk, a wrong solve (a stack at rest at a mass ratio of 5e5, its steps at
                ! the cap of an unreachable tolerance, sent a disk at 2 453 m/s through the
                ! floor, and the message said to lower the step to 4e-7 s)
                text = 'the time step is not the cause: the contact reactions of this step gave the bodies '// &
                       num(created)//' J/m of kinetic energy (the disk now carries '//num(energy)// &
                       ' J/m), more than reactions that satisfy the contact laws can give: the contact solve '// &
                       'of this step went wrong (/dem/solver of the results: an unconverged step; a [solver] '// &
                       'tolerance below what the solver can reach, or max_sweeps too low)'
                return
            end if
            if (.not. travel > 0.0_wp) then
                text = 'the time step is too large for the speed of the bodies; lower [time] step'
                return
            end if
            if (travel <= reach) then
                ! the step's motion stayed within what the detection sees: the crossing is an
                ! overlap that grew over several steps, not a step too large for the speed
                text = 'the motion of this step is within the '//num(reach)//' m the detection sees, so '// &
                       'the time step is not the cause: the contacts did not hold the disk back and the '// &
                       'overlap grew over several steps until the centre crossed (steps that did not '// &
                       'converge: raise [solver] max_sweeps; a wall driven into a jammed packing; a load '// &
                       'the packing cannot carry)'
                return
            end if
            text = 'the time step is too large for this speed; lower [time] step to '// &
                   num(real(h*reach/travel, wp))//' s or less (the motion of a step then stays within '// &
                   num(reach)//' m)'
        end function advice
    end subroutine check_tunnelling

    !> Energy the step just done created [J/m] (negative: dissipated): minus the change over
    !> the step of the contacts' and the scheme's dissipation (doc/theory.md 2.5), i.e. the
    !> kinetic and potential energy the bodies gained beyond the works of the loads, drives and
    !> coupling. Without active contacts it is at most zero (the scheme's part is
    !> (theta - 1/2)|v+ - v|_M^2 >= 0); the scheme's part is counted because at theta > 1/2
    !> an elastic impact shows as energy given by the contact (-r.u_theta < 0) that the
    !> scheme takes back.
    pure real(wp) function step_created_energy(start, energies) result(created)
        !> The record of the start of the step.
        type(step_start_t), intent(in) :: start
        !> Energy audit of the disks at the end of the step.
        type(energies_t), intent(in) :: energies
        created = (start%dissipated + start%numerical) - (energies%contact_dissipation + energies%numerical_dissipation)
    end function step_created_energy

    !> Energy a step may create without being reported [J/m] (doc/theory.md 2.5): the kinetic
    !> energy the step's loads alone would give the disks at rest (`load_energy`), since near
    !> rest the theta-scheme itself creates up to a fraction of it (a disk leaving its support
    !> at less than g h: (1 - theta)^2 of it; 0.34 of it measured in a deposit of 2 500 disks
    !> at e = 0.5, mu = 0.4), plus `creation_tolerance` times the larger kinetic energy of the
    !> disks at the start and the end of the step, plus the rounding of the two run totals the
    !> step's figure is the difference of.
    pure real(wp) function creation_allowance(start, energies, load_energy) result(allowance)
        !> The record of the start of the step.
        type(step_start_t), intent(in) :: start
        !> Energy audit of the disks at the end of the step.
        type(energies_t), intent(in) :: energies
        !> Kinetic energy the step's loads alone would give disks at rest
        !> (dem_moreau_jean::mj_load_energy) [J/m].
        real(wp), intent(in) :: load_energy
        allowance = creation_tolerance*max(start%kinetic, energies%kinetic) + load_energy + &
                    8.0_wp*epsilon(1.0_wp)*(abs(energies%contact_dissipation) + abs(energies%numerical_dissipation))
    end function creation_allowance

    !> Whether the step just done by `sys` (its record at the start in `start`) created energy
    !> beyond `creation_allowance` plus the kinetic energy e of velocities in error by the
    !> solver's tolerance plus round-off (`velocity_roundoff`) times the sizes of their terms
    !> (dem_moreau_jean::mj_velocity_error_energy): the time loops report such a step. Disks
    !> whose velocities are that error alone have at most e of kinetic energy, and a step
    !> creates at most its end kinetic energy; without the term a self-stressed structure at
    !> rest (no gravity, a load removed), whose reactions cancel on every disk, was reported at
    !> one step in three (doc/theory.md 2.5). Where the velocities are more than their error,
    !> creation_tolerance times the kinetic energy covers the error. The allowance's passes over
    !> the disks (mj_load_energy, then mj_velocity_error_energy) are made only for a step that
    !> created energy at all, then beyond the first allowance: seldom, most steps dissipate.
    logical function step_creates_energy(start, sys) result(creates)
        !> The record of the start of the step.
        type(step_start_t), intent(in) :: start
        !> The particle system after the step.
        type(dem_system_t), intent(in) :: sys
        real(wp) :: created, allowance
        created = step_created_energy(start, sys%energies)
        creates = .false.
        if (.not. created > 0.0_wp) return
        allowance = creation_allowance(start, sys%energies, mj_load_energy(sys))
        creates = created > allowance
        if (.not. creates) return
        creates = created > allowance + mj_velocity_error_energy(sys, sys%solver%tol + velocity_roundoff)
    end function step_creates_energy

    !> Warning for step `step` (ending at time `t`), whose contacts created the energy
    !> `created` while the disks' kinetic energy went from `kinetic0` to `kinetic`, with the
    !> causes that apply and what to change: `unconverged` steps before it ended off the
    !> contact laws (their reactions carry errors the later steps release); with restitution
    !> (`e_max` > 0, the largest of the laws), Newton's restitution with Coulomb friction at
    !> oblique impacts and pairs pushed together within a step (doc/theory.md 2.4). With
    !> neither, the cause is not one the code knows of, and the message says so.
    function energy_creation_warning(step, t, created, kinetic0, kinetic, e_max, unconverged) result(line)
        !> The step.
        integer(i8), intent(in) :: step
        !> Time at its end [s].
        real(wp), intent(in) :: t
        !> Energy created by the step [J/m].
        real(wp), intent(in) :: created
        !> Kinetic energy of the disks at the start and the end of the step [J/m].
        real(wp), intent(in) :: kinetic0, kinetic
        !> Largest restitution coefficient of the contact laws.
        real(wp), intent(in) :: e_max
        !> Steps of the run so far whose contact solve did not converge.
        integer, intent(in) :: unconverged
        character(len=:), allocatable :: line, causes
        causes = ''
        if (unconverged > 0) causes = to_str(unconverged)//' earlier step(s) ended unconverged, their reactions '// &
                                      'off the contact laws (raise [solver] max_sweeps or the tolerance until '// &
                                      'every step converges)'
        if (e_max > 0.0_wp) then
            if (len(causes) > 0) causes = causes//'; '
            causes = causes//"restitution e up to "//num(e_max)//": Newton's law with Coulomb friction can create "// &
                     'energy at oblique impacts when e is close to 1, and with e close to 1 so can pairs that other '// &
                     'disks push together within a step (doc/theory.md 2.4); a lower restitution ([contacts] law) '// &
                     'avoids both, a shorter [time] step reduces the second'
        end if
        if (len(causes) == 0) causes = 'every step converged and every law has e = 0: not a cause the code knows '// &
                                       'of (doc/theory.md 2.5); a shorter [time] step or a tighter [solver] '// &
                                       'tolerance tells whether it is the scheme'
        line = 'warning: '//when(step, t)//'the contacts created '//num(created)//' J/m of energy (kinetic '// &
               'energy of the disks '//num(kinetic0)//' -> '//num(kinetic)//' J/m): '//causes// &
               '; further such steps are only counted (total in the summary)'
    end function energy_creation_warning

    !> Summary line: `n` of the `n_steps` steps created energy beyond `creation_allowance`.
    function energy_creation_summary(n, n_steps) result(line)
        !> Steps that created energy.
        integer(i8), intent(in) :: n
        !> Steps done.
        integer(i8), intent(in) :: n_steps
        character(len=:), allocatable :: line
        line = 'steps whose contacts created energy: '//to_str(n)//' of '//to_str(n_steps)// &
               ' (doc/theory.md 2.4 and 2.5)'
    end function energy_creation_summary

    !> 'step k (t = ... s): '
    function when(step, t) result(text)
        integer(i8), intent(in) :: step
        real(wp), intent(in) :: t
        character(len=:), allocatable :: text
        character(len=24) :: buf
        write (buf, '(es12.5e3)') t
        text = 'step '//to_str(step)//' (t = '//trim(adjustl(buf))//' s): '
    end function when

    !> 'NaN', 'infinite'.
    pure function kind_of(x) result(text)
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        if (ieee_is_nan(x)) then
            text = 'NaN'
        else
            text = 'infinite'
        end if
    end function kind_of
end module driver_guards
