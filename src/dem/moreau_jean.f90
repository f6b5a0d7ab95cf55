!> Moreau-Jean theta-scheme for the discrete domain (doc/theory.md section 2), and the system that holds
!> everything one simulation of disks needs (no module state: two systems can coexist).
!>
!> One step from t to t + h:
!>   1. free velocities v_free = v + h M^-1 F_theta (F_theta = (1 - theta) F(t) + theta F(t + h));
!>      imposed and fixed DOFs take their values at t + h;
!>   2. detection on the mid configuration q + (1 - theta) h v (warm start by pair), or on
!>      q + h v with Siconos' rule of activation (`scheme%activation`, dem_activation); at
!>      the first step it is preceded by the making of the bonds on the contacts closed in
!>      the configuration at t = 0 (carried over by pair);
!>   3. contact laws (by default activation on the predicted gap with a round-off allowance,
!>      or on the previous reaction; Newton restitution or gap term; cohesion), frames;
!>   4. NLGS with the bi-potential local solver: v+ and the impulses (blocked contacts, whose
!>      bodies are both immobile along the normal, are left out and counted in `stats`); the
!>      rule of activation re-checks the contacts it left out on v+, and the step is solved
!>      again with those the impulses shut (mj_solve);
!>   5. q+ = q + h [(1 - theta) v + theta v+]; bonds pulled beyond their cohesion break;
!>      energies.
!> Energy audit (per unit thickness), exact for the discrete scheme up to round-off:
!>   kinetic + potential - external_work - drive_work + contact_dissipation
!>   + numerical_dissipation = initial,
!> with numerical_dissipation = (theta - 1/2) sum |v+ - v|_M^2 (zero for theta = 1/2),
!> contact_dissipation = - sum r . u_theta (>= 0 for dissipative contacts), drive_work the work
!> of imposed velocities and moving walls on the disks.
!>
!> Coupled steps (Arlequin, coupling_arlequin): `mj_step` is also available in four parts,
!> `mj_free_velocities` (1 and the detection configuration), `mj_detect` (2, 3; contacts are
!> activated on the velocities found in `vel`, which the coupling may have changed),
!> `mj_solve` (4, optionally with bilateral constraints kept by the NLGS) and `mj_end_step`
!> (5); in that order they are `mj_step`, bit for bit. An external impulse applied to the
!> disks during the step (e.g. the coupling multipliers) is recorded in `coupling_impulse`:
!> the audit counts its work as `coupling_work` (coupling_work . v_theta), so that
!>   kinetic + potential - external_work - drive_work - coupling_work + contact_dissipation
!>   + numerical_dissipation = initial.
module dem_moreau_jean
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use dem_particles, only: particles_t, particles_inverse_mass, particles_constrained_velocity, &
                             particles_forces, particles_kinetic_energy, particles_potential_energy, &
                             particles_bytes
    use dem_walls, only: walls_t, walls_velocity, walls_advance
    use dem_materials, only: materials_t
    use dem_contacts, only: contact_set_t, contact_law_t, contacts_set_frames, contacts_make_bonds, contacts_lost_bonds, &
                            status_cohesive, contacts_set_laws, contacts_finish, contacts_impulses, contacts_local_velocity, &
                            contacts_bytes, contacts_recheck
    use dem_detection, only: detector_t, detect_contacts, detector_bytes
    use dem_nlgs, only: nlgs_config_t, nlgs_stats_t, nlgs_bilateral_t, nlgs_apply_reactions, block_kept
    use dem_solve_method, only: solve_method_t, sweeps_method_t
    use dem_bonds, only: rupture_log_t, break_none, break_lost
    use dem_activation, only: activation_t, activation_predicted_t
    implicit none
    private
    public :: mj_config_t, energies_t, dem_system_t, mj_init, mj_step, energies_balance, dem_system_bytes
    public :: mj_free_velocities, mj_detect, mj_solve, mj_end_step, mj_load_energy, mj_velocity_error_energy, &
              mj_bonds_at_start, mj_bonds_made

    !> Most contact solves of a step (mj_solve): the first, and one after each re-check of the
    !> rule of activation that let in contacts the solve before had shut (with those within
    !> reach of the step, so that a chain of contacts pushed shut in turn joins at once); at
    !> the cap the step is reported unconverged.
    integer, parameter, public :: mj_max_solves = 10

    !> Time-stepping settings.
    type :: mj_config_t
        !> Time step [s].
        real(wp) :: h = 1.0e-4_wp
        !> Theta in [1/2, 1]. theta = 1/2 conserves energy in free flight and at e = 1 impacts;
        !> theta = 1 never lets a contact overlap (with MULTICOR's rule of activation, which
        !> re-checks the contacts it left out: mj_solve).
        real(wp) :: theta = 0.5_wp
        !> Alert distance of the detection [m].
        real(wp) :: alert = 0.0_wp
        !> Gap ratio of the bonds, which are created before the first step on the contacts with
        !> cohesion and gap <= bond_ratio * mean radius in the configuration at t = 0
        !> (dem_contacts, contacts_make_bonds), and broken for good once the solution needs
        !> more tension than the cohesion (dem_contacts, contacts_finish).
        real(wp) :: bond_ratio = 1.0e-6_wp
        !> Round-off allowance of the contact activation and of the detection, relative to the
        !> (mean) radius: contacts whose predicted gap is at most this are active
        !> (dem_contacts, contacts_set_laws).
        real(wp) :: gap_allowance = 1.0e-10_wp
        !> How the contacts enter the step (dem_activation; `[time] contact_scheme`): where
        !> they are detected, which are active, their normal targets. mj_init sets MULTICOR's
        !> rule (activation_predicted_t) when none is given.
        class(activation_t), allocatable :: activation
    end type mj_config_t

    !> Energies and works per unit thickness [J/m] since the start.
    type :: energies_t
        !> Kinetic energy.
        real(wp) :: kinetic = 0.0_wp
        !> Gravity potential energy.
        real(wp) :: potential = 0.0_wp
        !> Work of the loads (not gravity).
        real(wp) :: external_work = 0.0_wp
        !> Work of imposed velocities and moving walls on the disks.
        real(wp) :: drive_work = 0.0_wp
        !> Energy dissipated by the contacts.
        real(wp) :: contact_dissipation = 0.0_wp
        !> Energy dissipated by the scheme (theta > 1/2).
        real(wp) :: numerical_dissipation = 0.0_wp
        !> kinetic + potential at the start.
        real(wp) :: initial = 0.0_wp
        !> Work of the external coupling impulses (`dem_system_t%coupling_impulse`).
        real(wp) :: coupling_work = 0.0_wp
    end type energies_t

    !> One discrete-element simulation: model, settings, contacts, solver state, statistics.
    type :: dem_system_t
        !> Disks.
        type(particles_t) :: particles
        !> Walls.
        type(walls_t) :: walls
        !> Contact law per pair of materials.
        type(materials_t) :: materials
        !> Time-stepping settings.
        type(mj_config_t) :: scheme
        !> Solver settings.
        type(nlgs_config_t) :: solver
        !> Global strategy of the contact solve (`[solver] method`, dem_solve_method), with
        !> its state kept from step to step (the bonded block's factor,
        !> dem_bonded_block::bonded_block_method_t). mj_init sets the NLGS sweeps
        !> (sweeps_method_t) when none is given.
        class(solve_method_t), allocatable :: method
        !> Contact list.
        type(contact_set_t) :: contacts
        !> Detection workspace.
        type(detector_t) :: detector
        !> Statistics of the last solve.
        type(nlgs_stats_t) :: stats
        !> Energy audit.
        type(energies_t) :: energies
        !> Current time [s].
        real(wp) :: time = 0.0_wp
        !> Steps done.
        integer :: step = 0
        !> Wall-clock time spent in detection and in the solver [s].
        real(wp) :: time_detection = 0.0_wp, time_solver = 0.0_wp
        !> Bonds are still to be created (before the first step, on the configuration at t = 0).
        logical :: bonds_pending = .true.
        !> Intact bonds lost by the detection of the last step (log_lost_bonds).
        integer :: bonds_lost = 0
        !> Bond ruptures since the start (pair, step, time, mode).
        type(rupture_log_t) :: ruptures
        !> Work arrays (3, n): start and current velocities, inverse mass, loads, impulses.
        real(wp), allocatable :: vel0(:, :), vel(:, :), im(:, :), load(:, :), impulse(:, :)
        !> Work arrays: the detection configuration of the disks and walls (the mid
        !> configuration, or q + h v with Siconos' rule of activation).
        real(wp), allocatable :: xm(:), ym(:), wx1(:), wy1(:), wx2(:), wy2(:)
        !> Wall velocities at the start and the end of the step (2, n_walls).
        real(wp), allocatable :: wall_v0(:, :), wall_v1(:, :)
        !> Impulse (3, n) applied to the disks during the current step by an external coupling
        !> (set to zero by `mj_free_velocities`; the coupling adds its impulse to `vel` and
        !> records it here before `mj_end_step`) [N s/m, N s].
        real(wp), allocatable :: coupling_impulse(:, :)
    end type dem_system_t

contains

    !> Check the settings, size the work arrays and start the energy audit. Call once after
    !> the model is built and before the first step.
    subroutine mj_init(sys, error)
        !> System.
        type(dem_system_t), intent(inout) :: sys
        !> Error on invalid settings or material indices.
        type(error_t), allocatable, intent(out) :: error
        integer :: n, nw
        call check_settings(sys, error)
        if (allocated(error)) return
        if (.not. allocated(sys%scheme%activation)) allocate (activation_predicted_t :: sys%scheme%activation)
        if (.not. allocated(sys%method)) allocate (sweeps_method_t :: sys%method)
        n = sys%particles%n
        nw = sys%walls%n
        if (allocated(sys%vel0)) deallocate (sys%vel0, sys%vel, sys%im, sys%load, sys%impulse, sys%xm, &
                                             sys%ym, sys%wx1, sys%wy1, sys%wx2, sys%wy2, sys%wall_v0, sys%wall_v1)
        if (allocated(sys%coupling_impulse)) deallocate (sys%coupling_impulse)
        allocate (sys%vel0(3, n), sys%vel(3, n), sys%im(3, n), sys%load(3, n), sys%impulse(3, n))
        allocate (sys%coupling_impulse(3, n), source=0.0_wp)
        allocate (sys%xm(n), sys%ym(n), sys%wx1(nw), sys%wy1(nw), sys%wx2(nw), sys%wy2(nw))
        allocate (sys%wall_v0(2, nw), sys%wall_v1(2, nw))
        sys%energies = energies_t()
        sys%energies%kinetic = particles_kinetic_energy(sys%particles)
        sys%energies%potential = particles_potential_energy(sys%particles)
        sys%energies%initial = sys%energies%kinetic + sys%energies%potential
    end subroutine mj_init

    !> Validate the time-stepping and solver settings and the material indices.
    subroutine check_settings(sys, error)
        type(dem_system_t), intent(in) :: sys
        type(error_t), allocatable, intent(out) :: error
        integer :: mmax
        mmax = 0
        if (sys%particles%n > 0) mmax = maxval(sys%particles%mat(1:sys%particles%n))
        if (sys%walls%n > 0) mmax = max(mmax, maxval(sys%walls%mat(1:sys%walls%n)))
        if (.not. (sys%scheme%h > 0.0_wp)) then
            call make_error(error, 'DEM time step h must be > 0')
        else if (sys%scheme%theta < 0.5_wp .or. sys%scheme%theta > 1.0_wp) then
            call make_error(error, 'DEM theta must be in [0.5, 1]')
        else if (sys%scheme%alert < 0.0_wp .or. sys%scheme%bond_ratio < 0.0_wp .or. &
                 sys%scheme%gap_allowance < 0.0_wp) then
            call make_error(error, 'DEM alert distance, bond_ratio and gap_allowance must be >= 0')
        else if (sys%solver%tol <= 0.0_wp .or. sys%solver%max_sweeps < 1 .or. &
                 sys%solver%local_max_iter < 1) then
            call make_error(error, 'DEM solver needs tol > 0, max_sweeps >= 1, local_max_iter >= 1')
        else if (mmax > sys%materials%n) then
            call make_error(error, 'DEM material index exceeds the number of materials in the table')
        else if (sys%particles%n > 0) then
            if (minval(sys%particles%mat(1:sys%particles%n)) < 1) &
                call make_error(error, 'DEM material indices must be >= 1')
        end if
    end subroutine check_settings

    !> Advance the system by one time step.
    subroutine mj_step(sys)
        !> System (mj_init done).
        type(dem_system_t), intent(inout) :: sys
        call mj_free_velocities(sys)
        call mj_detect(sys)
        call mj_solve(sys)
        call mj_end_step(sys)
    end subroutine mj_step

    !> Contact law parameters of the current step.
    pure type(contact_law_t) function step_law(sys) result(law)
        type(dem_system_t), intent(in) :: sys
        law = contact_law_t(h=sys%scheme%h, theta=sys%scheme%theta, bond_ratio=sys%scheme%bond_ratio, &
                            gap_allowance=sys%scheme%gap_allowance)
    end function step_law

    !> Part 1 of a step: start velocities vel0, free velocities vel (loads and gravity,
    !> imposed DOFs), wall velocities, detection configuration; coupling_impulse = 0.
    subroutine mj_free_velocities(sys)
        !> System (mj_init done).
        type(dem_system_t), intent(inout) :: sys
        call free_velocities(sys)
        call mid_configuration(sys)
        sys%coupling_impulse = 0.0_wp
    end subroutine mj_free_velocities

    !> Part 2 of a step: detection (on the configuration of the rule of activation), frames
    !> and Delassus blocks, contact laws; contacts are activated on the velocities in `vel`
    !> (the free velocities, plus whatever a coupling added since `mj_free_velocities`).
    !> At the first step the bonds are made first, on the configuration at t = 0 (make_bonds).
    subroutine mj_detect(sys)
        !> System, after `mj_free_velocities`.
        type(dem_system_t), intent(inout) :: sys
        integer(i8) :: c0, c1, c2, rate
        real(wp) :: alert
        call system_clock(c0, rate)
        alert = detection_alert(sys)
        if (sys%bonds_pending) call make_bonds(sys, alert)
        call detect_contacts(sys%detector, sys%xm, sys%ym, sys%particles%radius, alert, &
                             sys%wx1, sys%wy1, sys%wx2, sys%wy2, sys%contacts)
        call log_lost_bonds(sys)
        call system_clock(c1)
        call contacts_set_frames(sys%contacts, sys%particles%radius, sys%im)
        call contacts_set_laws(sys%contacts, step_law(sys), sys%scheme%activation, sys%particles%radius, sys%particles%mat, &
                               sys%walls%mat, sys%materials, sys%vel0, sys%vel, sys%wall_v0, sys%wall_v1)
        call system_clock(c2)
        sys%time_detection = sys%time_detection + real(c1 - c0, wp)/real(rate, wp)
        sys%time_solver = sys%time_solver + real(c2 - c1, wp)/real(rate, wp)
    end subroutine mj_detect

    !> Part 3 of a step: the contact solve by the system's strategy (`method`: the NLGS
    !> sweeps, or the intact bonds as a direct block with sweeps over the others) from the
    !> velocities in `vel`; end-of-step velocities in `vel`.
    !> Then the rule of activation re-checks the contacts it left out on the end-of-step
    !> velocities (activation_t%recheck, contacts_recheck): a contact the free motion left open
    !> may have been shut by the other contacts' impulses. When a re-check finds such contacts,
    !> it lets them in and, with them, every contact left out within reach of the step, whose
    !> gap the fastest motion of the step could close (below 2 theta h v_max, v_max the largest
    !> speed of a disk's rim or of a wall at the end of the solve): in a chain of contacts
    !> pushed shut in turn (a column falling on its support) the next links join at once
    !> instead of one per solve, and a contact let in that stays open carries no reaction. The
    !> step is then solved again warm-started from the reactions found, until a re-check finds
    !> none, for at most mj_max_solves solves (stats%solves) and [solver] max_sweeps sweeps over
    !> all of them; at either cap, contacts still shut are counted (stats%recheck_left) and the
    !> step is not converged. The velocities the solve starts from again are the end-of-step
    !> ones without the contact impulses (the strategy applies the reactions again), so that
    !> the multipliers of bilateral constraints stay those of the velocities. With MULTICOR's
    !> rule no contact then ends shut beyond the round-off allowance (doc/theory.md 2.4);
    !> Siconos' rule never lets one in, and its step is one solve.
    subroutine mj_solve(sys, bilateral)
        !> System, after `mj_detect`.
        type(dem_system_t), intent(inout) :: sys
        !> Bilateral velocity constraints kept satisfied by the solver (default: none).
        class(nlgs_bilateral_t), intent(inout), optional :: bilateral
        integer(i8) :: c0, c1, rate
        type(nlgs_stats_t) :: first, round
        type(nlgs_config_t) :: rest
        integer :: added, within
        call system_clock(c0, rate)
        call sys%method%solve(sys%solver, sys%contacts, sys%im, sys%vel, sys%stats, bilateral)
        first = sys%stats
        rest = sys%solver
        do
            rest%max_sweeps = sys%solver%max_sweeps - sys%stats%sweeps
            call contacts_recheck(sys%contacts, step_law(sys), sys%scheme%activation, sys%vel, sys%wall_v1, 0.0_wp, &
                                  sys%stats%solves < mj_max_solves .and. rest%max_sweeps > 0, added)
            if (added == 0) exit
            if (sys%stats%solves == mj_max_solves .or. rest%max_sweeps <= 0) then
                sys%stats%recheck_left = added
                sys%stats%converged = .false.
                exit
            end if
            call contacts_recheck(sys%contacts, step_law(sys), sys%scheme%activation, sys%vel, sys%wall_v1, &
                                  reach(sys), .true., within)
            ! back to the velocities without the contact impulses (the strategy applies them again)
            sys%contacts%r(:, 1:sys%contacts%n) = -sys%contacts%r(:, 1:sys%contacts%n)
            call nlgs_apply_reactions(sys%contacts, sys%im, sys%vel)
            sys%contacts%r(:, 1:sys%contacts%n) = -sys%contacts%r(:, 1:sys%contacts%n)
            call sys%method%solve(rest, sys%contacts, sys%im, sys%vel, round, bilateral)
            call add_round(sys%stats, round, added + within)
        end do
        ! the blocked contacts were taken out of the list's active set by the first solve
        sys%stats%n_blocked = first%n_blocked
        call system_clock(c1)
        sys%time_solver = sys%time_solver + real(c1 - c0, wp)/real(rate, wp)
    end subroutine mj_solve

    !> Gap [m] within which a contact left out could be shut in the step (mj_solve): 2 theta h
    !> v_max, v_max the largest speed of a point of a disk's rim, |v| + R |omega|, or of a wall,
    !> at the end of the solve (two such points closing on each other).
    pure function reach(sys) result(gap)
        !> System, after a solve.
        type(dem_system_t), intent(in) :: sys
        real(wp) :: gap, v_max
        integer :: i
        v_max = 0.0_wp
        do i = 1, sys%particles%n
            v_max = max(v_max, sqrt(sys%vel(1, i)**2 + sys%vel(2, i)**2) + sys%particles%radius(i)*abs(sys%vel(3, i)))
        end do
        do i = 1, size(sys%wall_v1, 2)
            v_max = max(v_max, sqrt(sys%wall_v1(1, i)**2 + sys%wall_v1(2, i)**2))
        end do
        gap = 2.0_wp*sys%scheme%theta*sys%scheme%h*v_max
    end function reach

    !> The statistics of the step after one more solve `round` (mj_solve), which `added`
    !> contacts joined: its state (error, convergence, active set) with the work of both.
    pure subroutine add_round(stats, round, added)
        !> Statistics of the step so far; on exit, of the step with the round.
        type(nlgs_stats_t), intent(inout) :: stats
        !> Statistics of the solve just done.
        type(nlgs_stats_t), intent(in) :: round
        !> Contacts the re-check before it let in.
        integer, intent(in) :: added
        type(nlgs_stats_t) :: total
        total = round
        total%sweeps = stats%sweeps + round%sweeps
        total%local_iterations = stats%local_iterations + round%local_iterations
        total%updates = stats%updates + round%updates
        total%corrections = stats%corrections + round%corrections
        if (round%block_given_up == block_kept) total%block_given_up = stats%block_given_up
        total%solves = stats%solves + 1
        total%rechecked = stats%rechecked + added
        stats = total
    end subroutine add_round

    !> Part 4 of a step: statuses and broken bonds (logged in `ruptures`; bonds are judged
    !> at converged steps only), energy audit (coupling_impulse included), new configuration
    !> and velocities, time.
    subroutine mj_end_step(sys)
        !> System, after `mj_solve`.
        type(dem_system_t), intent(inout) :: sys
        integer :: k
        call contacts_finish(sys%contacts, step_law(sys), sys%particles%radius, sys%vel, sys%wall_v1, &
                             sys%stats%converged)
        call audit_energies(sys)
        call update_configuration(sys)
        ! the time of the step count (runs start at t = 0), not a sum of steps: the same value
        ! as the continuum's and the beam's t0 + n h, where the sum drifted by a few ulps
        ! (/dem/time 0.009999999999999929 against /continuum/time 0.01 after 500 steps)
        sys%step = sys%step + 1
        sys%time = real(sys%step, wp)*sys%scheme%h
        sys%bonds_pending = .false.
        associate (cs => sys%contacts)
            do k = 1, cs%n
                if (cs%break_mode(k) == break_none) cycle
                call sys%ruptures%add(cs%i1(k), cs%i2(k), int(sys%step, i8), sys%time, cs%break_mode(k))
            end do
        end associate
    end subroutine mj_end_step

    !> Intact bonds the step's detection did not find again (contacts_lost_bonds): logged
    !> as ruptures of mode break_lost at this step and counted in `bonds_lost` (the driver
    !> warns), where they vanished from the list unreported.
    subroutine log_lost_bonds(sys)
        !> System, after the step's detection.
        type(dem_system_t), intent(inout) :: sys
        integer, allocatable :: i1(:), i2(:)
        integer :: k
        call contacts_lost_bonds(sys%contacts, i1, i2)
        sys%bonds_lost = size(i1)
        do k = 1, size(i1)
            call sys%ruptures%add(i1(k), i2(k), int(sys%step + 1, i8), real(sys%step + 1, wp)*sys%scheme%h, &
                                  break_lost)
        end do
    end subroutine log_lost_bonds

    !> Alert distance of a step's detection [m]: `[contacts] alert` widened by the round-off
    !> allowance (touching disks must be found whatever the sign of their rounded gap) and,
    !> with cohesion, to the largest gap of a bond.
    pure real(wp) function detection_alert(sys) result(alert)
        !> The system.
        type(dem_system_t), intent(in) :: sys
        real(wp) :: rmax
        alert = sys%scheme%alert
        if (sys%particles%n > 0) then
            rmax = maxval(sys%particles%radius(1:sys%particles%n))
            alert = alert + sys%scheme%gap_allowance*rmax
            ! a bond is made on a gap of up to bond_ratio times the pair's radius: with cohesion
            ! the search reaches that far, or an `alert` below it lost the bond at the first
            ! step (at the default, a quarter of the mean radius, it changes nothing)
            if (any(sys%materials%cohesion > 0.0_wp)) &
                alert = max(alert, (sys%scheme%bond_ratio + sys%scheme%gap_allowance)*rmax)
        end if
    end function detection_alert

    !> The bonds of the run, made on the configuration at the start of the first step (t = 0,
    !> before any motion): the contacts detected there (alert distance widened by bond_ratio
    !> times the largest radius, so that every pair within a bond's gap is found), bonds on
    !> those with cohesion and a gap of at most bond_ratio * mean radius (contacts_make_bonds).
    !> This list becomes the previous list of the step's detection, which carries the bonds
    !> over by pair; its reactions are zero and its outputs none, as those of a pair new to the
    !> list, so that only the bonds differ from a first step without this list.
    subroutine make_bonds(sys, alert)
        !> System at the start of its first step.
        type(dem_system_t), intent(inout) :: sys
        !> Alert distance of the step's detection [m].
        real(wp), intent(in) :: alert
        call find_bonds(sys%particles, sys%walls, sys%materials, sys%scheme%bond_ratio, alert, sys%detector, &
                        sys%contacts)
    end subroutine make_bonds

    !> The contacts of the disks and walls as they are (detection with the alert distance
    !> widened by bond_ratio times the largest radius), those with cohesion and a gap of at
    !> most bond_ratio * mean radius marked as intact bonds (contacts_make_bonds).
    subroutine find_bonds(particles, walls, materials, bond_ratio, alert, det, cs)
        !> Disks.
        type(particles_t), intent(in) :: particles
        !> Walls.
        type(walls_t), intent(in) :: walls
        !> Material pair table.
        type(materials_t), intent(in) :: materials
        !> Gap ratio of the bonds.
        real(wp), intent(in) :: bond_ratio
        !> Alert distance of the step's detection [m].
        real(wp), intent(in) :: alert
        !> Detection workspace.
        type(detector_t), intent(inout) :: det
        !> The contacts found, bonds marked.
        type(contact_set_t), intent(inout) :: cs
        real(wp), allocatable :: wx1(:), wy1(:), wx2(:), wy2(:)
        integer :: n, nw
        n = particles%n
        nw = walls%n
        if (n == 0) return
        allocate (wx1(nw), wy1(nw), wx2(nw), wy2(nw))
        if (nw > 0) then
            wx1 = walls%x1(1:nw)
            wy1 = walls%y1(1:nw)
            wx2 = walls%x2(1:nw)
            wy2 = walls%y2(1:nw)
        end if
        call detect_contacts(det, particles%x(1:n), particles%y(1:n), particles%radius, &
                             alert + bond_ratio*maxval(particles%radius(1:n)), wx1, wy1, wx2, wy2, cs)
        call contacts_make_bonds(cs, bond_ratio, particles%radius, particles%mat, walls%mat, materials)
    end subroutine find_bonds

    !> The bonds the first step makes (make_bonds), counted by pair of materials, without
    !> changing the system: found as the first step finds them, on the configuration at hand
    !> (that at t = 0 before the first step).
    function mj_bonds_at_start(sys) result(bonds)
        !> The system (its settings, materials, disks and walls; `mj_init` not needed).
        type(dem_system_t), intent(in) :: sys
        !> bonds(a, b) = bonds(b, a): the bonds between a body of material a and one of b.
        integer, allocatable :: bonds(:, :)
        type(detector_t) :: det
        type(contact_set_t) :: cs
        integer :: k, ma, mb
        allocate (bonds(sys%materials%n, sys%materials%n), source=0)
        call find_bonds(sys%particles, sys%walls, sys%materials, sys%scheme%bond_ratio, detection_alert(sys), det, cs)
        do k = 1, cs%n
            if (cs%status(k) /= status_cohesive) cycle
            mb = sys%particles%mat(cs%i2(k))
            if (cs%i1(k) > 0) then
                ma = sys%particles%mat(cs%i1(k))
            else
                ma = sys%walls%mat(-cs%i1(k))
            end if
            bonds(ma, mb) = bonds(ma, mb) + 1
            if (ma /= mb) bonds(mb, ma) = bonds(mb, ma) + 1
        end do
    end function mj_bonds_at_start

    !> Bonds made at t = 0 by a run that has taken steps: those intact now and those broken or
    !> lost since (each logged once in `ruptures`).
    pure integer function mj_bonds_made(sys) result(n)
        !> The system.
        type(dem_system_t), intent(in) :: sys
        n = sys%ruptures%n
        if (sys%contacts%n > 0) n = n + count(sys%contacts%status(1:sys%contacts%n) == status_cohesive)
    end function mj_bonds_made

    !> vel0 = current velocities, im, theta-weighted loads, vel = free velocities, wall velocities.
    subroutine free_velocities(sys)
        type(dem_system_t), intent(inout) :: sys
        real(wp) :: t, h, th
        integer :: k
        t = sys%time
        h = sys%scheme%h
        th = sys%scheme%theta
        associate (p => sys%particles)
            sys%vel0(1, :) = p%vx(1:p%n)
            sys%vel0(2, :) = p%vy(1:p%n)
            sys%vel0(3, :) = p%w(1:p%n)
            call particles_inverse_mass(p, sys%im)
            call particles_forces(p, t, sys%impulse)
            call particles_forces(p, t + h, sys%load)
            sys%load = (1.0_wp - th)*sys%impulse + th*sys%load
            sys%vel(1, :) = sys%vel0(1, :) + h*sys%im(1, :)*(sys%load(1, :) + p%mass(1:p%n)*p%gravity(1))
            sys%vel(2, :) = sys%vel0(2, :) + h*sys%im(2, :)*(sys%load(2, :) + p%mass(1:p%n)*p%gravity(2))
            sys%vel(3, :) = sys%vel0(3, :) + h*sys%im(3, :)*sys%load(3, :)
            call particles_constrained_velocity(p, t + h, sys%vel)
        end associate
        do k = 1, sys%walls%n
            sys%wall_v0(:, k) = walls_velocity(sys%walls, k, t)
            sys%wall_v1(:, k) = walls_velocity(sys%walls, k, t + h)
        end do
    end subroutine free_velocities

    !> Configuration q + a h v of disks and walls where the contacts are detected: the mid
    !> configuration a = 1 - theta with MULTICOR's rule of activation, a = 1 with Siconos'
    !> (dem_activation).
    subroutine mid_configuration(sys)
        type(dem_system_t), intent(inout) :: sys
        real(wp) :: a
        a = sys%scheme%activation%offset(sys%scheme%theta)*sys%scheme%h
        sys%xm = sys%particles%x(1:sys%particles%n) + a*sys%vel0(1, :)
        sys%ym = sys%particles%y(1:sys%particles%n) + a*sys%vel0(2, :)
        if (sys%walls%n == 0) return
        sys%wx1 = sys%walls%x1(1:sys%walls%n) + a*sys%wall_v0(1, :)
        sys%wy1 = sys%walls%y1(1:sys%walls%n) + a*sys%wall_v0(2, :)
        sys%wx2 = sys%walls%x2(1:sys%walls%n) + a*sys%wall_v0(1, :)
        sys%wy2 = sys%walls%y2(1:sys%walls%n) + a*sys%wall_v0(2, :)
    end subroutine mid_configuration

    !> q+ = q + h [(1 - theta) v + theta v+], v = v+, walls moved.
    subroutine update_configuration(sys)
        type(dem_system_t), intent(inout) :: sys
        real(wp) :: h, th
        h = sys%scheme%h
        th = sys%scheme%theta
        associate (p => sys%particles)
            p%x(1:p%n) = p%x(1:p%n) + h*((1.0_wp - th)*sys%vel0(1, :) + th*sys%vel(1, :))
            p%y(1:p%n) = p%y(1:p%n) + h*((1.0_wp - th)*sys%vel0(2, :) + th*sys%vel(2, :))
            p%rot(1:p%n) = p%rot(1:p%n) + h*((1.0_wp - th)*sys%vel0(3, :) + th*sys%vel(3, :))
            p%vx(1:p%n) = sys%vel(1, :)
            p%vy(1:p%n) = sys%vel(2, :)
            p%w(1:p%n) = sys%vel(3, :)
        end associate
        call walls_advance(sys%walls, sys%time, h, th)
        sys%energies%kinetic = particles_kinetic_energy(sys%particles)
        sys%energies%potential = particles_potential_energy(sys%particles)
    end subroutine update_configuration

    !> Works of the step (see the module header): loads, drives, contacts, scheme.
    subroutine audit_energies(sys)
        type(dem_system_t), intent(inout) :: sys
        real(wp) :: h, th, dv(3), vm(3), m(3), p(3)
        integer :: i
        h = sys%scheme%h
        th = sys%scheme%theta
        call contact_works(sys)
        sys%impulse = 0.0_wp
        call contacts_impulses(sys%contacts, sys%impulse)
        associate (e => sys%energies, pt => sys%particles)
            do i = 1, pt%n
                m = [pt%mass(i), pt%mass(i), pt%inertia(i)]
                dv = sys%vel(:, i) - sys%vel0(:, i)
                vm = (1.0_wp - th)*sys%vel0(:, i) + th*sys%vel(:, i)
                e%external_work = e%external_work + h*dot_product(sys%load(:, i), vm)
                e%numerical_dissipation = e%numerical_dissipation + (th - 0.5_wp)*dot_product(m, dv*dv)
                e%coupling_work = e%coupling_work + dot_product(sys%coupling_impulse(:, i), vm)
                ! support impulse on constrained DOFs (zero work where the DOF is fixed)
                p = m*dv - h*(sys%load(:, i) + [pt%mass(i)*pt%gravity, 0.0_wp]) - sys%impulse(:, i) &
                    - sys%coupling_impulse(:, i)
                e%drive_work = e%drive_work + sum(merge(p*vm, 0.0_wp, sys%im(:, i) == 0.0_wp))
            end do
        end associate
    end subroutine audit_energies

    !> Contact dissipation -sum r.u_theta (r = (r_n, r_t, M), u = (u_n, u_t, w_r)) and work of
    !> moving walls sum r.(n.vw, t.vw)_theta,
    !> over the contacts of the solve (inactive and blocked contacts have r = 0 and are skipped).
    subroutine contact_works(sys)
        type(dem_system_t), intent(inout) :: sys
        real(wp) :: th, u(3), vw(2), nx, ny
        integer :: k, a
        th = sys%scheme%theta
        associate (cs => sys%contacts, e => sys%energies)
            do k = 1, cs%n
                if (.not. cs%active(k)) cycle
                u = (1.0_wp - th)*contacts_local_velocity(cs, k, sys%vel0, sys%wall_v0) + th*cs%u(:, k)
                e%contact_dissipation = e%contact_dissipation - dot_product(cs%r(:, k), u)
                a = cs%i1(k)
                if (a > 0) cycle
                vw = (1.0_wp - th)*sys%wall_v0(:, -a) + th*sys%wall_v1(:, -a)
                nx = cs%nrm(1, k)
                ny = cs%nrm(2, k)
                e%drive_work = e%drive_work + cs%r(1, k)*(nx*vw(1) + ny*vw(2)) + cs%r(2, k)*(-ny*vw(1) + nx*vw(2))
            end do
        end associate
    end subroutine contact_works

    !> Memory held by the system: disks, walls, contacts, detection and work arrays [bytes].
    pure integer(i8) function dem_system_bytes(sys) result(b)
        !> System.
        type(dem_system_t), intent(in) :: sys
        b = particles_bytes(sys%particles) + contacts_bytes(sys%contacts) + detector_bytes(sys%detector)
        b = b + 48_i8*sys%walls%n
        if (allocated(sys%vel0)) b = b + 8_i8*(size(sys%vel0) + size(sys%vel) + size(sys%im) + size(sys%load) &
                                               + size(sys%impulse) + size(sys%xm) + size(sys%ym))
        if (allocated(sys%coupling_impulse)) b = b + 8_i8*size(sys%coupling_impulse)
    end function dem_system_bytes

    !> Kinetic energy that the loads, the weight and the coupling impulse of the step just done
    !> would give the free DOFs of disks at rest, sum |h F_theta + coupling impulse|^2 / (2 m)
    !> [J/m]: the scale of the energy a step can create near rest (doc/theory.md 2.5).
    pure real(wp) function mj_load_energy(sys) result(e)
        !> System, after a step.
        type(dem_system_t), intent(in) :: sys
        real(wp) :: f(3)
        integer :: i
        e = 0.0_wp
        if (.not. allocated(sys%load)) return
        associate (p => sys%particles)
            do i = 1, p%n
                f = sys%scheme%h*(sys%load(:, i) + [p%mass(i)*p%gravity, 0.0_wp]) + sys%coupling_impulse(:, i)
                e = e + 0.5_wp*sum(sys%im(:, i)*f*f)
            end do
        end associate
    end function mj_load_energy

    !> Kinetic energy [J/m] of velocity errors of `relative` times the sizes of the terms that
    !> make up the end velocities of the step just done, v+ = v + M^-1 (h F_theta + coupling
    !> impulse) + sum_k M^-1 H_k r_k: per free DOF |v| + |M^-1 (h F_theta + coupling impulse)|
    !> + sum_k |M^-1 H_k| |r_k| over the active contacts (|n_x r_n - n_y r_t| <= |r_n| + |r_t|,
    !> and the same for y; the rotation |lever r_t| + |r_m|). A solve stopped at a relative
    !> tolerance, and rounded, leaves velocities in error by about that much: when reactions
    !> that cancel on every disk (a self-stress at rest) make terms far larger than v+, that is
    !> the scale of the energy the step's contacts seem to create (doc/theory.md 2.5).
    pure real(wp) function mj_velocity_error_energy(sys, relative) result(e)
        !> System, after a step.
        type(dem_system_t), intent(in) :: sys
        !> Relative error of the velocities (e.g. the solver's tolerance plus round-off).
        real(wp), intent(in) :: relative
        real(wp), allocatable :: a(:, :)
        real(wp) :: p
        integer :: i, j, k
        e = 0.0_wp
        if (.not. allocated(sys%vel0)) return
        associate (pt => sys%particles, cs => sys%contacts)
            a = abs(sys%vel0)
            do i = 1, pt%n
                a(:, i) = a(:, i) + sys%im(:, i)*abs(sys%scheme%h*(sys%load(:, i) + [pt%mass(i)*pt%gravity, 0.0_wp]) &
                                                     + sys%coupling_impulse(:, i))
            end do
            do k = 1, cs%n
                if (.not. cs%active(k)) cycle
                p = abs(cs%r(1, k)) + abs(cs%r(2, k))
                j = cs%i2(k)
                a(1:2, j) = a(1:2, j) + sys%im(1:2, j)*p
                a(3, j) = a(3, j) + sys%im(3, j)*(abs(cs%lever(2, k)*cs%r(2, k)) + abs(cs%r(3, k)))
                i = cs%i1(k)
                if (i <= 0) cycle
                a(1:2, i) = a(1:2, i) + sys%im(1:2, i)*p
                a(3, i) = a(3, i) + sys%im(3, i)*(abs(cs%lever(1, k)*cs%r(2, k)) + abs(cs%r(3, k)))
            end do
            do i = 1, pt%n
                do j = 1, 3
                    if (sys%im(j, i) > 0.0_wp) e = e + 0.5_wp*(relative*a(j, i))**2/sys%im(j, i)
                end do
            end do
        end associate
    end function mj_velocity_error_energy

    !> Closing error of the energy audit [J/m] (zero up to round-off).
    pure real(wp) function energies_balance(e) result(b)
        !> Energies.
        type(energies_t), intent(in) :: e
        b = e%kinetic + e%potential - e%external_work - e%drive_work + e%contact_dissipation &
            + e%numerical_dissipation - e%initial - e%coupling_work
    end function energies_balance
end module dem_moreau_jean
