!> The particles' state in a checkpoint (driver_checkpoint): the Moreau-Jean state of the
!> disks and walls, the contact list with its reactions and statuses for the warm start, the
!> bond ruptures so far, under a group such as '/dem', and the state of the solve method (the
!> factor of the bonded block in use), which the method puts and takes back itself under
!> '/dem/block' (driver_checkpoint_state).
module driver_checkpoint_dem
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use dem_contacts, only: contacts_list_problem, status_open, status_broken
    use dem_bipotential, only: case_slip_roll
    use dem_bonds, only: break_none, break_tension, break_lost
    use dem_moreau_jean, only: dem_system_t
    use driver_checkpoint_state, only: h5_state_sink_t, h5_state_source_t
    use driver_checkpoint_values, only: put_part, read_int_attr_1d, read_finite_attribute, require_finite, &
                                        require_range, damaged, real_text
    implicit none
    private
    public :: save_dem, load_dem

    !> What the attribute 'scalars' of a particle system's group holds (for messages).
    character(len=*), parameter :: dem_scalars(13) = [character(len=20) :: &
                                                      'time', 'detection seconds', 'solver seconds', 'kinetic energy', &
                                                      'potential energy', 'external work', 'drive work', &
                                                      'contact dissipation', 'numerical dissip.', 'initial energy', &
                                                      'coupling work', 'solver error', 'solver residual']

contains

    !> Write the mutable state of a particle system under `group`.
    subroutine save_dem(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_group(group, error)
        if (allocated(error)) return
        call save_counters(file, group, sys, error)
        if (allocated(error)) return
        call save_bodies(file, group, sys, error)
        if (allocated(error)) return
        call save_contacts(file, group, sys, error)
        if (allocated(error)) return
        call save_ruptures(file, group, sys, error)
        if (allocated(error)) return
        call save_block(file, group, sys, error)
    end subroutine save_dem

    !> Write the time, energies, solver statistics and counts of a particle system (attributes
    !> 'scalars', 'integers' and 'counts_i8' of `group`).
    subroutine save_counters(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        associate (e => sys%energies, st => sys%stats)
            call file%write_attribute(group, 'scalars', [sys%time, sys%time_detection, sys%time_solver, &
                                                         e%kinetic, e%potential, e%external_work, e%drive_work, &
                                                         e%contact_dissipation, e%numerical_dissipation, e%initial, &
                                                         e%coupling_work, st%error, st%residual], error)
            if (allocated(error)) return
            call file%write_attribute(group, 'integers', real([sys%step, merge(1, 0, sys%bonds_pending), &
                                                               st%sweeps, st%n_contacts, st%n_active, st%n_blocked, &
                                                               merge(1, 0, st%converged), sys%particles%n, sys%walls%n], wp), error)
            if (allocated(error)) return
            call file%write_attribute(group, 'counts_i8', real([st%local_iterations, st%updates], wp), error)
            if (allocated(error)) return
        end associate
    end subroutine save_counters

    !> Write the positions and velocities of the disks and walls.
    subroutine save_bodies(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        associate (p => sys%particles, w => sys%walls)
            n = p%n
            call put_part(file, group//'/x', p%x(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/y', p%y(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/rot', p%rot(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/vx', p%vx(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/vy', p%vy(1:n), error)
            if (.not. allocated(error)) call put_part(file, group//'/w', p%w(1:n), error)
            if (allocated(error)) return
            n = w%n
            if (n > 0) then
                call put_part(file, group//'/walls/x1', w%x1(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/y1', w%y1(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/x2', w%x2(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/y2', w%y2(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/vx', w%vx(1:n), error)
                if (.not. allocated(error)) call put_part(file, group//'/walls/vy', w%vy(1:n), error)
                if (allocated(error)) return
            end if
        end associate
    end subroutine save_bodies

    !> The state of the solve method kept between steps, which it puts itself
    !> (solve_method_t%save_state) under group/block (the factor of the bonded block in use,
    !> solver method = block: its bond graph and values, factored again at the restart).
    subroutine save_block(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout), target :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        type(h5_state_sink_t) :: sink
        if (.not. allocated(sys%method)) return
        sink%file => file
        sink%group = group//'/block'
        call sys%method%save_state(sink, error)
    end subroutine save_block

    !> Write the contact list with its reactions and statuses (the warm start of the next step).
    subroutine save_contacts(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g
        integer :: m
        g = group//'/contacts'
        associate (cs => sys%contacts)
            m = cs%n
            call file%create_group(g, error)
            if (allocated(error)) return
            call file%write_attribute(g, 'n', m, error)
            if (allocated(error) .or. m == 0) return
            call file%write_dataset(g//'/i1', cs%i1(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/i2', cs%i2(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/nrm', cs%nrm(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/gap', cs%gap(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/lever', cs%lever(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/w', cs%w(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/shift', cs%shift(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/r', cs%r(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/u', cs%u(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/y', cs%y(:, 1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/mu', cs%mu(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/erol', cs%erol(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/amoy', cs%amoy(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/coh', cs%coh(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/pcase', cs%pcase(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/break_mode', cs%break_mode(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/status', cs%status(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/active', &
                                                                merge(1, 0, cs%active(1:m)), error)
        end associate
    end subroutine save_contacts

    !> Write the log of bond ruptures so far.
    subroutine save_ruptures(file, group, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g
        integer :: m
        g = group//'/ruptures'
        associate (rl => sys%ruptures)
            m = rl%n
            call file%create_group(g, error)
            if (allocated(error)) return
            call file%write_attribute(g, 'n', m, error)
            if (allocated(error) .or. m == 0) return
            call file%write_dataset(g//'/i1', rl%i1(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/i2', rl%i2(1:m), error)
            ! steps <= max_steps = huge(0) (driver_config)
            if (.not. allocated(error)) call file%write_dataset(g//'/step', int(rl%step(1:m)), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/time', rl%time(1:m), error)
            if (.not. allocated(error)) call file%write_dataset(g//'/mode', rl%mode(1:m), error)
        end associate
    end subroutine save_ruptures

    !> Read the mutable state of a particle system (built from the deck, mj_init done).
    subroutine load_dem(file, group, sys, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system.
        type(dem_system_t), intent(inout) :: sys
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure, when the numbers of disks or walls differ, or on a damaged value.
        type(error_t), allocatable, intent(out) :: error
        call load_counters(file, group, sys, step, error)
        if (allocated(error)) return
        call load_bodies(file, group, sys, error)
        if (allocated(error)) return
        call load_contacts(file, group, sys, error)
        if (allocated(error)) return
        call load_ruptures(file, group, sys, step, error)
        if (allocated(error)) return
        call load_block(file, group, sys, error)
    end subroutine load_dem

    !> Read the time, energies, solver statistics and counts of a particle system, checking
    !> its numbers of disks and walls are the deck's.
    subroutine load_counters(file, group, sys, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system (built from the deck).
        type(dem_system_t), intent(inout) :: sys
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure, when the numbers of disks or walls differ, or on a damaged value.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: s(:), c(:)
        integer, allocatable :: iv(:)
        call read_finite_attribute(file, group, 'scalars', s, 13, error, names=dem_scalars)
        if (allocated(error)) return
        call read_int_attr_1d(file, group, 'integers', iv, error)
        if (allocated(error)) return
        call read_finite_attribute(file, group, 'counts_i8', c, 2, error)
        if (allocated(error)) return
        if (size(iv) /= 9) then
            call make_error(error, 'checkpoint: '//group//': wrong number of values')
            return
        end if
        if (iv(8) /= sys%particles%n .or. iv(9) /= sys%walls%n) then
            call make_error(error, 'checkpoint: '//group//': numbers of disks or walls differ from the deck')
            return
        end if
        ! step (that of /loop), bonds pending, sweeps, contacts, active, blocked, converged
        call require_range(iv(1:1), int(step), int(step), group//'@integers value 1 (the steps of /loop@step)', error)
        if (.not. allocated(error)) call require_range(iv(2:2), 0, 1, group//'@integers value 2 (bonds pending)', error)
        if (.not. allocated(error)) call require_range(iv(3:6), 0, huge(0), group//'@integers (counts '// &
                                                       'of sweeps and contacts)', error, first=3)
        if (.not. allocated(error)) call require_range(iv(7:7), 0, 1, group//'@integers value 7 (converged)', error)
        if (allocated(error)) return
        if (any(c < 0.0_wp) .or. any(c > 2.0_wp**62) .or. any(c /= aint(c))) then
            call damaged(error, group//'@counts_i8: '//real_text(c(1))//', '//real_text(c(2))// &
                         ' are not counts')
            return
        end if
        sys%time = s(1)
        sys%time_detection = s(2)
        sys%time_solver = s(3)
        associate (e => sys%energies, st => sys%stats)
            e%kinetic = s(4)
            e%potential = s(5)
            e%external_work = s(6)
            e%drive_work = s(7)
            e%contact_dissipation = s(8)
            e%numerical_dissipation = s(9)
            e%initial = s(10)
            e%coupling_work = s(11)
            st%error = s(12)
            st%residual = s(13)
            sys%step = iv(1)
            sys%bonds_pending = iv(2) /= 0
            st%sweeps = iv(3)
            st%n_contacts = iv(4)
            st%n_active = iv(5)
            st%n_blocked = iv(6)
            st%converged = iv(7) /= 0
            st%local_iterations = int(c(1), i8)
            st%updates = int(c(2), i8)
        end associate
    end subroutine load_counters

    !> Read the positions and velocities of the disks and walls.
    subroutine load_bodies(file, group, sys, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system (built from the deck).
        type(dem_system_t), intent(inout) :: sys
        !> Set on a read failure, another size or a value not finite.
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        associate (p => sys%particles, w => sys%walls)
            n = p%n
            call get_part(file, n, group//'/x', p%x, error)
            if (.not. allocated(error)) call get_part(file, n, group//'/y', p%y, error)
            if (.not. allocated(error)) call get_part(file, n, group//'/rot', p%rot, error)
            if (.not. allocated(error)) call get_part(file, n, group//'/vx', p%vx, error)
            if (.not. allocated(error)) call get_part(file, n, group//'/vy', p%vy, error)
            if (.not. allocated(error)) call get_part(file, n, group//'/w', p%w, error)
            if (allocated(error)) return
            n = w%n
            if (n > 0) then
                call get_part(file, n, group//'/walls/x1', w%x1, error)
                if (.not. allocated(error)) call get_part(file, n, group//'/walls/y1', w%y1, error)
                if (.not. allocated(error)) call get_part(file, n, group//'/walls/x2', w%x2, error)
                if (.not. allocated(error)) call get_part(file, n, group//'/walls/y2', w%y2, error)
                if (.not. allocated(error)) call get_part(file, n, group//'/walls/vx', w%vx, error)
                if (.not. allocated(error)) call get_part(file, n, group//'/walls/vy', w%vy, error)
                if (allocated(error)) return
            end if
        end associate
    end subroutine load_bodies

    !> Give the deck's solve method its state of group/block (save_block), which it checks
    !> against the system's disks and walls and takes back (solve_method_t%load_state).
    subroutine load_block(file, group, sys, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout), target :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system (built from the deck).
        type(dem_system_t), intent(inout) :: sys
        !> Set on a read failure, a damaged value, or a state of another method than the deck's.
        type(error_t), allocatable, intent(out) :: error
        type(h5_state_source_t) :: source
        source%file => file
        source%group = group//'/block'
        if (.not. allocated(sys%method)) then
            ! the deck (whose hash the checkpoint matches) chose the strategy
            if (.not. source%is_empty()) call source%damaged('the deck solves no bonded block ([solver] method)', error)
            return
        end if
        call sys%method%load_state(source, sys%particles%n, sys%walls%n, error)
    end subroutine load_block

    !> Read the first n values of a per-body array (the array keeps its size).
    subroutine get_part(file, n, path, x, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Number of bodies (0: nothing read).
        integer, intent(in) :: n
        !> Path of the dataset.
        character(len=*), intent(in) :: path
        !> The per-body array.
        real(wp), intent(inout) :: x(:)
        !> Set on a read failure, another size or a value not finite.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: v(:)
        if (n == 0) return
        call file%read_dataset(path, v, error)
        if (allocated(error)) return
        if (size(v) /= n .or. size(x) < n) then
            call make_error(error, 'checkpoint: '//path//': size differs from the deck')
            return
        end if
        call require_finite(v, path, error)
        if (allocated(error)) return
        x(1:n) = v
    end subroutine get_part

    !> Read the contact list with its reactions and statuses, replacing the system's.
    subroutine load_contacts(file, group, sys, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system (built from the deck).
        type(dem_system_t), intent(inout) :: sys
        !> Set on a read failure or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g, problem
        integer, allocatable :: active(:)
        integer :: m
        g = group//'/contacts'
        associate (cs => sys%contacts)
            call file%read_attribute(g, 'n', m, error)
            if (allocated(error)) return
            call require_range([m], 0, huge(0), g//'@n', error)
            if (allocated(error)) return
            if (allocated(cs%i1)) deallocate (cs%i1, cs%i2, cs%nrm, cs%gap, cs%lever, cs%w, cs%shift, &
                                              cs%r, cs%u, cs%mu, cs%erol, cs%amoy, cs%coh, cs%pcase, &
                                              cs%break_mode, cs%status, cs%active)
            if (allocated(cs%y)) deallocate (cs%y)
            if (allocated(cs%y_prev)) deallocate (cs%y_prev)
            cs%n = m
            cs%capacity = m
            cs%n_prev = 0
            cs%merge_pos = 1
            if (m == 0) then
                allocate (cs%i1(0), cs%i2(0), cs%nrm(2, 0), cs%gap(0), cs%lever(2, 0), cs%w(6, 0), &
                          cs%shift(2, 0), cs%r(3, 0), cs%u(3, 0), cs%mu(0), cs%erol(0), cs%amoy(0), &
                          cs%coh(0), cs%pcase(0), cs%break_mode(0), cs%status(0), cs%active(0), &
                          cs%y(2, 0), cs%y_prev(2, 0))
                return
            end if
            call file%read_dataset(g//'/i1', cs%i1, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/i2', cs%i2, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/nrm', cs%nrm, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/gap', cs%gap, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/lever', cs%lever, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/w', cs%w, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/shift', cs%shift, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/r', cs%r, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/u', cs%u, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/y', cs%y, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/mu', cs%mu, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/erol', cs%erol, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/amoy', cs%amoy, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/coh', cs%coh, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/pcase', cs%pcase, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/break_mode', cs%break_mode, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/status', cs%status, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/active', active, error)
            if (allocated(error)) return
            call check_contact_sizes(g, m, sys, active, error)
            if (allocated(error)) return
            call require_finite([cs%nrm], g//'/nrm', error)
            if (.not. allocated(error)) call require_finite(cs%gap, g//'/gap', error)
            if (.not. allocated(error)) call require_finite([cs%lever], g//'/lever', error)
            if (.not. allocated(error)) call require_finite([cs%w], g//'/w', error)
            if (.not. allocated(error)) call require_finite([cs%shift], g//'/shift', error)
            if (.not. allocated(error)) call require_finite([cs%r], g//'/r', error)
            if (.not. allocated(error)) call require_finite([cs%u], g//'/u', error)
            if (.not. allocated(error)) call require_finite([cs%y], g//'/y', error)
            if (.not. allocated(error)) call require_finite(cs%mu, g//'/mu', error)
            if (.not. allocated(error)) call require_finite(cs%erol, g//'/erol', error)
            if (.not. allocated(error)) call require_finite(cs%amoy, g//'/amoy', error)
            if (.not. allocated(error)) call require_finite(cs%coh, g//'/coh', error)
            ! codes: dem_contacts status_*, dem_bipotential case_* (0 before a solve),
            ! dem_bonds break_*
            if (.not. allocated(error)) call require_range(cs%status, status_open, status_broken, g//'/status', error)
            if (.not. allocated(error)) call require_range(cs%pcase, 0, case_slip_roll, g//'/pcase', error)
            if (.not. allocated(error)) &
                call require_range(cs%break_mode, break_none, break_lost, g//'/break_mode', error)
            if (.not. allocated(error)) call require_range(active, 0, 1, g//'/active', error)
            if (allocated(error)) return
            cs%active = active /= 0
            ! the outputs of the previous step are not needed after the step's laws
            allocate (cs%y_prev(2, m), source=0.0_wp)
            problem = contacts_list_problem(cs, sys%particles%n, sys%walls%n)
            if (len(problem) > 0) then
                call make_error(error, 'checkpoint: '//problem//': the checkpoint is damaged')
                return
            end if
        end associate
    end subroutine load_contacts

    !> Every per-contact dataset holds the n contacts of the list.
    subroutine check_contact_sizes(g, m, sys, active, error)
        !> Group of the contacts (for the message).
        character(len=*), intent(in) :: g
        !> Number of contacts (g@n).
        integer, intent(in) :: m
        !> The system, its contacts read.
        type(dem_system_t), intent(in) :: sys
        !> The dataset 'active' read.
        integer, intent(in) :: active(:)
        !> Set when a size differs.
        type(error_t), allocatable, intent(out) :: error
        associate (cs => sys%contacts)
            if (size(cs%i1) /= m .or. size(cs%i2) /= m .or. size(cs%gap) /= m .or. size(cs%mu) /= m .or. &
                size(cs%erol) /= m .or. size(cs%amoy) /= m .or. size(cs%coh) /= m .or. &
                size(cs%pcase) /= m .or. size(cs%break_mode) /= m .or. size(cs%status) /= m .or. &
                size(active) /= m .or. any(shape(cs%nrm) /= [2, m]) .or. any(shape(cs%lever) /= [2, m]) .or. &
                any(shape(cs%w) /= [6, m]) .or. any(shape(cs%shift) /= [2, m]) .or. &
                any(shape(cs%r) /= [3, m]) .or. any(shape(cs%u) /= [3, m]) .or. any(shape(cs%y) /= [2, m])) &
                call damaged(error, g//': a dataset does not hold the '//to_str(m)//' contacts of '//g//'@n')
        end associate
    end subroutine check_contact_sizes

    !> Read the log of bond ruptures so far.
    subroutine load_ruptures(file, group, sys, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group of the particle system, e.g. '/dem'.
        character(len=*), intent(in) :: group
        !> The system (built from the deck).
        type(dem_system_t), intent(inout) :: sys
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g
        integer, allocatable :: rupture_step(:)
        integer :: m
        g = group//'/ruptures'
        associate (rl => sys%ruptures)
            call file%read_attribute(g, 'n', m, error)
            if (allocated(error)) return
            call require_range([m], 0, huge(0), g//'@n', error)
            if (allocated(error)) return
            rl%n = m
            if (allocated(rl%i1)) deallocate (rl%i1, rl%i2, rl%step, rl%time, rl%mode)
            if (m == 0) return
            call file%read_dataset(g//'/i1', rl%i1, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/i2', rl%i2, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/step', rupture_step, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/time', rl%time, error)
            if (.not. allocated(error)) call file%read_dataset(g//'/mode', rl%mode, error)
            if (allocated(error)) return
            if (size(rl%i1) /= m .or. size(rl%i2) /= m .or. size(rupture_step) /= m .or. &
                size(rl%time) /= m .or. size(rl%mode) /= m) then
                call damaged(error, g//': a dataset does not hold the '//to_str(m)//' ruptures of '//g//'@n')
                return
            end if
            call require_range(rl%i1, -sys%walls%n, sys%particles%n, g//'/i1', error)
            if (.not. allocated(error)) call require_range(rl%i2, 1, sys%particles%n, g//'/i2', error)
            if (.not. allocated(error)) call require_range(rupture_step, 1, int(step), g//'/step', error)
            if (.not. allocated(error)) call require_finite(rl%time, g//'/time', error)
            ! dem_bonds break_tension .. break_lost (a bond the detection lost, logged like a
            ! rupture: a checkpoint after one was refused as damaged)
            if (.not. allocated(error)) call require_range(rl%mode, break_tension, break_lost, g//'/mode', error)
            if (allocated(error)) return
            rl%step = int(rupture_step, i8)
        end associate
    end subroutine load_ruptures
end module driver_checkpoint_dem
