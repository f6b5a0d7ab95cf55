!> The time integrator's state in a checkpoint (driver_checkpoint): the Newmark or central
!> difference state of a beam or a 2D continuum, under a group such as '/fe'.
module driver_checkpoint_fem
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_internal_error
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use fem_newmark, only: time_integrator_t, newmark_t, central_difference_t
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
        type(h5_file_t), intent(inout) :: file
        !> Group, e.g. '/fe'.
        character(len=*), intent(in) :: group
        !> The integrator.
        class(time_integrator_t), intent(in) :: integ
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
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
        select type (integ)
        type is (newmark_t)
            call file%write_attribute(group, 'predicted', merge(1, 0, integ%predicted), error)
            if (allocated(error)) return
            call put_r1(file, group//'/fc_old', integ%fc_old, error)
        type is (central_difference_t)
            ! no state beyond the common one (init builds the rest from the deck)
        class default
            call make_internal_error(error, 'save_integrator', 'no checkpoint for the state of this time integrator')
        end select
    end subroutine save_integrator

    !> Read the state of a time integrator (built from the deck) from `group`.
    subroutine load_integrator(file, group, integ, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
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
        select type (integ)
        type is (newmark_t)
            call file%read_attribute(group, 'predicted', k, error)
            if (allocated(error)) return
            call require_range([k], 0, 1, group//'@predicted', error)
            if (allocated(error)) return
            integ%predicted = k /= 0
            call get_r1(file, group//'/fc_old', integ%fc_old, error)
        type is (central_difference_t)
            ! no state beyond the common one (init builds the rest from the deck)
        class default
            call make_internal_error(error, 'load_integrator', 'no checkpoint for the state of this time integrator')
        end select
    end subroutine load_integrator
end module driver_checkpoint_fem
