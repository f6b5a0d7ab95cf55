!> The time integrator's state in a checkpoint (driver_checkpoint): the state common to every
!> scheme of a beam or a 2D continuum, under a group such as '/fe', and what the scheme keeps
!> beyond it, which it puts and takes back itself (time_integrator_t%save_state, load_state)
!> as attributes and datasets of the same group (driver_checkpoint_state).
module driver_checkpoint_fem
    use core_kinds, only: wp, i8
    use core_error, only: error_t
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use fem_newmark, only: time_integrator_t
    use driver_checkpoint_state, only: h5_state_sink_t, h5_state_source_t
    use driver_checkpoint_values, only: put_r1, get_r1, read_finite_attribute, require_range, damaged, real_text
    implicit none
    private
    public :: save_integrator, load_integrator

    !> What the attribute 'scalars' of an integrator's group holds (for messages).
    character(len=*), parameter :: integrator_scalars(9) = [character(len=20) :: &
                                                            'time', 'time step', 'start time', 'kinetic energy', &
                                                            'strain energy', 'external work', 'damping dissipation', &
                                                            'initial energy', 'coupling work']

contains

    !> Write the state of a time integrator under `group`.
    subroutine save_integrator(file, group, integ, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout), target :: file
        !> Group, e.g. '/fe'.
        character(len=*), intent(in) :: group
        !> The integrator.
        class(time_integrator_t), intent(in) :: integ
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        type(h5_state_sink_t) :: sink
        call file%create_group(group, error)
        if (allocated(error)) return
        call file%write_attribute(group, 'scalars', [integ%t, integ%h, integ%t0, integ%kinetic, &
                                                     integ%strain, integ%external_work, integ%damping_dissipation, &
                                                     integ%initial_energy, integ%coupling_work], error)
        if (allocated(error)) return
        call file%write_attribute(group, 'step_count', integ%step_count, error)
        if (allocated(error)) return
        call put_r1(file, group//'/u', integ%u, error)
        if (allocated(error)) return
        call put_r1(file, group//'/v', integ%v, error)
        if (allocated(error)) return
        call put_r1(file, group//'/a', integ%a, error)
        if (allocated(error)) return
        call put_r1(file, group//'/u_old', integ%u_old, error)
        if (allocated(error)) return
        call put_r1(file, group//'/v_old', integ%v_old, error)
        if (allocated(error)) return
        call put_r1(file, group//'/f_old', integ%f_old, error)
        if (allocated(error)) return
        call put_r1(file, group//'/f_new', integ%f_new, error)
        if (allocated(error)) return
        sink%file => file
        sink%group = group
        call integ%save_state(sink, error)
    end subroutine save_integrator

    !> Read the state of a time integrator (built from the deck) from `group`.
    subroutine load_integrator(file, group, integ, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout), target :: file
        !> Group, e.g. '/fe'.
        character(len=*), intent(in) :: group
        !> The integrator (init done).
        class(time_integrator_t), intent(inout) :: integ
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure, a size mismatch or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: s(:)
        integer :: k
        type(h5_state_source_t) :: source
        call read_finite_attribute(file, group, 'scalars', s, 9, error, names=integrator_scalars)
        if (allocated(error)) return
        call file%read_attribute(group, 'step_count', k, error)
        if (allocated(error)) return
        call require_range([k], int(step), int(step), group//'@step_count (the steps of /loop@step)', error)
        if (allocated(error)) return
        ! the deck (same hash) gives the step; the time is t0 + steps * h exactly (fem_newmark)
        if (s(2) /= integ%h .or. s(1) /= s(3) + k*s(2)) then
            call damaged(error, group//'@scalars: time step '//real_text(s(2))//' s (the deck''s: '// &
                         real_text(integ%h)//' s) and time '//real_text(s(1))//' s do not match the '// &
                         to_str(k)//' steps from '//real_text(s(3))//' s')
            return
        end if
        integ%t = s(1)
        integ%h = s(2)
        integ%t0 = s(3)
        integ%kinetic = s(4)
        integ%strain = s(5)
        integ%external_work = s(6)
        integ%damping_dissipation = s(7)
        integ%initial_energy = s(8)
        integ%coupling_work = s(9)
        integ%step_count = k
        call get_r1(file, group//'/u', integ%u, error)
        if (allocated(error)) return
        call get_r1(file, group//'/v', integ%v, error)
        if (allocated(error)) return
        call get_r1(file, group//'/a', integ%a, error)
        if (allocated(error)) return
        call get_r1(file, group//'/u_old', integ%u_old, error)
        if (allocated(error)) return
        call get_r1(file, group//'/v_old', integ%v_old, error)
        if (allocated(error)) return
        call get_r1(file, group//'/f_old', integ%f_old, error)
        if (allocated(error)) return
        call get_r1(file, group//'/f_new', integ%f_new, error)
        if (allocated(error)) return
        source%file => file
        source%group = group
        call integ%load_state(source, error)
    end subroutine load_integrator
end module driver_checkpoint_fem
