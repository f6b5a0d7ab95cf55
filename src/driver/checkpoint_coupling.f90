!> The state of a coupled system in a checkpoint (driver_checkpoint): the finite-element
!> side under '/fe', the particles under '/dem', and the multipliers and constraint state of
!> the coupling under '/coupling'.
module driver_checkpoint_coupling
    use core_kinds, only: wp, i8
    use core_error, only: error_t, make_error
    use io_hdf5_file, only: h5_file_t
    use coupling_arlequin, only: coupled_system_t
    use driver_checkpoint_values, only: put_r1, get_r1, read_int_attr_1d, read_finite_attribute, require_range
    use driver_checkpoint_fem, only: save_integrator, load_integrator
    use driver_checkpoint_dem, only: save_dem, load_dem
    implicit none
    private
    public :: save_coupled, load_coupled

contains

    !> Write the state of a coupled system: beam, particles and coupling.
    subroutine save_coupled(file, sys, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system.
        type(coupled_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call save_integrator(file, '/fe', sys%fe, error)
        if (allocated(error)) return
        call save_dem(file, '/dem', sys%dem, error)
        if (allocated(error)) return
        call file%create_group('/coupling', error)
        if (allocated(error)) return
        associate (st => sys%stats)
            call file%write_attribute('/coupling', 'integers', &
                                      real([sys%step, st%sweeps, st%corrections, st%n_contacts, st%n_active, &
                                            merge(1, 0, st%converged)], wp), error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'scalars', [st%nlgs_error, st%free_residual, &
                                                               st%velocity_residual, st%position_residual, st%particle_residual, &
                                                               st%rotation_residual, st%lambda_norm], error)
            if (allocated(error)) return
        end associate
        call put_r1(file, '/coupling/lambda', sys%lambda, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/lambda_old', sys%lambda_old, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/g', sys%g, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/q', sys%q, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/cu0', sys%cu0, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/drift', sys%drift, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/start', sys%start, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/multiplier', sys%multiplier, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/cv', sys%cv, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/gv', sys%gv, error)
        if (.not. allocated(error)) call put_r1(file, '/coupling/fc', sys%fc, error)
    end subroutine save_coupled

    !> Read the state of a coupled system (built from the deck).
    subroutine load_coupled(file, sys, step, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system.
        type(coupled_system_t), intent(inout) :: sys
        !> Steps done at the checkpoint (/loop@step).
        integer(i8), intent(in) :: step
        !> Set on a read failure or a damaged value.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: iv(:)
        real(wp), allocatable :: s(:)
        call load_integrator(file, '/fe', sys%fe, step, error)
        if (allocated(error)) return
        call load_dem(file, '/dem', sys%dem, step, error)
        if (allocated(error)) return
        call read_int_attr_1d(file, '/coupling', 'integers', iv, error)
        if (allocated(error)) return
        call read_finite_attribute(file, '/coupling', 'scalars', s, 7, error)
        if (allocated(error)) return
        if (size(iv) /= 6) then
            call make_error(error, 'checkpoint: /coupling: wrong number of values')
            return
        end if
        ! step (that of /loop), sweeps, corrections, contacts, active, converged
        call require_range(iv(1:1), int(step), int(step), '/coupling@integers value 1 (the steps of /loop@step)', error)
        if (.not. allocated(error)) call require_range(iv(2:5), 0, huge(0), '/coupling@integers (counts)', &
                                                       error, first=2)
        if (.not. allocated(error)) call require_range(iv(6:6), 0, 1, '/coupling@integers value 6 (converged)', error)
        if (allocated(error)) return
        associate (st => sys%stats)
            sys%step = iv(1)
            st%sweeps = iv(2)
            st%corrections = iv(3)
            st%n_contacts = iv(4)
            st%n_active = iv(5)
            st%converged = iv(6) /= 0
            st%nlgs_error = s(1)
            st%free_residual = s(2)
            st%velocity_residual = s(3)
            st%position_residual = s(4)
            st%particle_residual = s(5)
            st%rotation_residual = s(6)
            st%lambda_norm = s(7)
        end associate
        call get_r1(file, '/coupling/lambda', sys%lambda, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/lambda_old', sys%lambda_old, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/g', sys%g, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/q', sys%q, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/cu0', sys%cu0, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/drift', sys%drift, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/start', sys%start, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/multiplier', sys%multiplier, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/cv', sys%cv, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/gv', sys%gv, error)
        if (.not. allocated(error)) call get_r1(file, '/coupling/fc', sys%fc, error)
    end subroutine load_coupled
end module driver_checkpoint_coupling
