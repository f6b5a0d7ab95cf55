!> Coupling results in the run's HDF5 file (layout in doc/output.md, group /coupling): the
!> overlap and the coupled disks, the multipliers and the energy audit at the stored outputs,
!> and the constraint residuals and solver effort of EVERY time step (buffered in memory and
!> written in chunks). The beam's fields go to /fem (driver_results) and the disks' to /dem
!> (driver_results_dem), as in uncoupled runs.
!>
!> Rows of the multipliers: one per coupled DOF, `/coupling/rows/particle` and
!> `/coupling/rows/dof` (1 = x, 2 = y, 3 = rotation) say which; lambda (n_rows) is in N
!> (N.m for rotation rows), the force the beam exerts on the disk through the glue.
module driver_results_coupled
    use core_kinds, only: wp
    use core_error, only: error_t, make_internal_error
    use io_hdf5_file, only: h5_file_t
    use coupling_arlequin, only: coupled_system_t, coupled_energies_t, coupled_energies, &
                                 coordinate_residual, coupled_beam_operator
    use coupling_operator, only: coupling_operator_t
    implicit none
    private
    public :: coupled_writer_t, energy_names, write_beam_overlap

    !> Steps of statistics kept in memory before they are written.
    integer, parameter :: stats_buffer = 4096
    !> Datasets of /coupling/energy (besides time), in the order of `energy_values`.
    !&<
    character(len=*), parameter :: energy_names(16) = [character(len=23) :: 'fe_kinetic', &
        'fe_strain', 'fe_external_work', 'fe_damping', 'fe_coupling_work', 'dem_kinetic', &
        'dem_potential', 'dem_external_work', 'dem_drive_work', 'contact_dissipation', &
        'numerical_dissipation', 'dem_coupling_work', 'external_work', 'coupling_work', 'balance', &
        'fe_reaction_work']
    !> Real per-step datasets of /coupling, in the order of the buffer's columns.
    character(len=*), parameter :: step_names(6) = [character(len=19) :: 'g_norm', &
        'position_residual', 'velocity_residual', 'rotation_residual', 'coordinate_residual', &
        'lambda_norm']
    !> Units of step_names.
    character(len=*), parameter :: step_units(6) = [character(len=5) :: 'm/s', 'm', 'm/s', &
        'rad', 'm', 'N']
    !&>

    !> Writes the coupling part of a results file.
    type :: coupled_writer_t
        !> Multiplier rows.
        integer :: n_rows = 0
        !> Outputs stored so far.
        integer :: n_out = 0
        !> Steps buffered, and recorded in all.
        integer :: n_buffered = 0, n_steps = 0
        !> Buffered per-step reals (stats_buffer, size(step_names)).
        real(wp), allocatable :: values(:, :)
        !> Buffered sweeps and multiplier corrections per step.
        integer, allocatable :: sweeps(:), corrections(:)
        !> Largest position, velocity and coordinate residuals over the steps.
        real(wp) :: max_position = 0.0_wp, max_velocity = 0.0_wp, max_coordinate = 0.0_wp
        !> Largest |balance| over the outputs [J].
        real(wp) :: max_balance = 0.0_wp
    contains
        !> Write the overlap and the coupled disks, create every series.
        procedure :: begin => writer_begin
        !> Store the multipliers and the energy audit (an output).
        procedure :: store => writer_store
        !> Record the residuals and the solver effort of the step just done.
        procedure :: record_step => writer_record_step
        !> Write what is buffered and the closing attributes.
        procedure :: finish => writer_finish
        !> Write the buffered per-step values now (before a checkpoint).
        procedure :: flush_buffer => writer_flush_buffer
        !> Take over a results file written by `begin` (restart; counters set by the caller).
        procedure :: resume => writer_resume
    end type coupled_writer_t

contains

    !> Write /coupling/{particles, alpha, alpha_disks, rows}, the settings as attributes of
    !> /coupling, and create the series (any FE model; a beam adds `write_beam_overlap`).
    subroutine writer_begin(self, file, sys, error)
        !> The writer.
        class(coupled_writer_t), intent(inout) :: self
        !> A results file open for writing.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system (built).
        type(coupled_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        self%n_rows = sys%op%n_rows
        self%n_out = 0
        self%n_buffered = 0
        self%n_steps = 0
        self%max_position = 0.0_wp
        self%max_velocity = 0.0_wp
        self%max_coordinate = 0.0_wp
        self%max_balance = 0.0_wp
        allocate (self%values(stats_buffer, size(step_names)), self%sweeps(stats_buffer), &
                  self%corrections(stats_buffer))
        call file%write_dataset('/coupling/particles', sys%coupled, error)
        if (allocated(error)) return
        call real_dataset('/coupling/alpha', sys%alpha(sys%coupled), '', error)
        if (allocated(error)) return
        call real_dataset('/coupling/alpha_disks', sys%alpha, '', error)
        if (allocated(error)) return
        call file%write_dataset('/coupling/rows/particle', sys%rows%owner, error)
        if (allocated(error)) return
        call file%write_dataset('/coupling/rows/dof', sys%rows%dof, error)
        if (allocated(error)) return
        call attributes(error)
        if (allocated(error)) return
        call real_series('/coupling/time', [integer ::], 's', error)
        if (allocated(error)) return
        call real_series('/coupling/lambda', [self%n_rows], 'N, N.m', error)
        if (allocated(error)) return
        call real_series('/coupling/energy/time', [integer ::], 's', error)
        if (allocated(error)) return
        do k = 1, size(energy_names)
            call real_series('/coupling/energy/'//trim(energy_names(k)), [integer ::], 'J', &
                             error)
            if (allocated(error)) return
        end do
        do k = 1, size(step_names)
            call real_series('/coupling/'//trim(step_names(k)), [integer ::], &
                             trim(step_units(k)), error)
            if (allocated(error)) return
        end do
        call file%create_int_series('/coupling/sweeps', error)
        if (allocated(error)) return
        call file%create_int_series('/coupling/corrections', error)
    contains
        subroutine attributes(error)
            type(error_t), allocatable, intent(out) :: error
            call file%write_attribute('/coupling', 'weight', trim(sys%weight%shape), error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'alpha_min', sys%weight%alpha_min, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'thickness', sys%thickness, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'n_points', sys%op%n_points, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'n_rows', sys%op%n_rows, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'rotation', &
                                      merge(1, 0, sys%op%rows_per_point == 3), error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'time_step', sys%fe%h, error)
            if (allocated(error)) return
            ! the closing attributes (`finish`), created now with their types so that the end of
            ! the run overwrites them in place (a kill while the file is closed leaves it readable:
            ! doc/output.md, restart)
            call file%write_attribute('/coupling', 'steps', 0, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'max_position_residual', 0.0_wp, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'max_velocity_residual', 0.0_wp, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'max_coordinate_residual', 0.0_wp, error)
            if (allocated(error)) return
            call file%write_attribute('/coupling', 'max_abs_balance', 0.0_wp, error)
        end subroutine attributes

        subroutine real_dataset(path, values, units, error)
            character(len=*), intent(in) :: path, units
            real(wp), intent(in) :: values(:)
            type(error_t), allocatable, intent(out) :: error
            call file%write_dataset(path, values, error)
            if (allocated(error) .or. len(units) == 0) return
            call file%write_attribute(path, 'units', units, error)
        end subroutine real_dataset

        subroutine real_series(path, record_shape, units, error)
            character(len=*), intent(in) :: path, units
            integer, intent(in) :: record_shape(:)
            type(error_t), allocatable, intent(out) :: error
            call file%create_series(path, record_shape, error)
            if (allocated(error)) return
            call file%write_attribute(path, 'units', units, error)
        end subroutine real_series
    end subroutine writer_begin

    !> The beam's overlap interval and the coupled disks' abscissas and offsets:
    !> /coupling/{overlap, abscissa, offset} (a system built by coupling_arlequin).
    subroutine write_beam_overlap(file, sys, error)
        !> A results file open for writing (`begin` done).
        type(h5_file_t), intent(inout) :: file
        !> The coupled system of a beam (built).
        type(coupled_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        type(coupling_operator_t) :: op
        call coupled_beam_operator(sys, op, error)
        if (allocated(error)) return
        call put('/coupling/overlap', [sys%weight%s_fe, sys%weight%s_particle], error)
        if (allocated(error)) return
        call put('/coupling/abscissa', op%abscissa, error)
        if (allocated(error)) return
        call put('/coupling/offset', op%offset, error)
    contains
        subroutine put(path, values, error)
            character(len=*), intent(in) :: path
            real(wp), intent(in) :: values(:)
            type(error_t), allocatable, intent(out) :: error
            call file%write_dataset(path, values, error)
            if (allocated(error)) return
            call file%write_attribute(path, 'units', 'm', error)
        end subroutine put
    end subroutine write_beam_overlap

    !> Store the current multipliers and energy audit as one output.
    subroutine writer_store(self, file, sys, error)
        !> The writer (begin done).
        class(coupled_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system.
        type(coupled_system_t), intent(in) :: sys
        !> Set on a size mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        type(coupled_energies_t) :: en
        real(wp) :: values(size(energy_names))
        integer :: k
        if (.not. allocated(self%values) .or. sys%op%n_rows /= self%n_rows) then
            call make_internal_error(error, 'results: coupling store', 'begin was not called for '// &
                                     'this system')
            return
        end if
        call file%append('/coupling/time', sys%fe%t, error)
        if (allocated(error)) return
        call file%append('/coupling/lambda', sys%lambda, error)
        if (allocated(error)) return
        en = coupled_energies(sys)
        values = energy_values(en)
        self%max_balance = max(self%max_balance, abs(en%balance))
        call file%append('/coupling/energy/time', sys%fe%t, error)
        if (allocated(error)) return
        do k = 1, size(energy_names)
            call file%append('/coupling/energy/'//trim(energy_names(k)), values(k), error)
            if (allocated(error)) return
        end do
        self%n_out = self%n_out + 1
    end subroutine writer_store

    !> The audit as the values of energy_names [J].
    pure function energy_values(en) result(values)
        type(coupled_energies_t), intent(in) :: en
        real(wp) :: values(size(energy_names))
        values = [en%fe_kinetic, en%fe_strain, en%fe_external_work, en%fe_damping, &
                  en%fe_coupling_work, en%dem_kinetic, en%dem_potential, en%dem_external_work, &
                  en%dem_drive_work, en%dem_contact_dissipation, en%dem_numerical_dissipation, &
                  en%dem_coupling_work, en%fe_external_work + en%fe_reaction_work + en%dem_external_work + &
                  en%dem_drive_work, en%coupling_work, en%balance, en%fe_reaction_work]
    end function energy_values

    !> Record the residuals and solver effort of the step just done; writes when the buffer
    !> is full.
    subroutine writer_record_step(self, file, sys, error)
        !> The writer (begin done).
        class(coupled_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> The coupled system after the step.
        type(coupled_system_t), intent(in) :: sys
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        real(wp) :: coord
        if (.not. allocated(self%values)) then
            call make_internal_error(error, 'results: coupling record_step', 'begin was not called')
            return
        end if
        if (self%n_buffered == stats_buffer) call flush_steps(self, file, error)
        if (allocated(error)) return
        k = self%n_buffered + 1
        coord = coordinate_residual(sys)
        associate (st => sys%stats)
            self%values(k, :) = [st%free_residual, st%position_residual, &
                                 st%velocity_residual, st%rotation_residual, coord, st%lambda_norm]
            self%sweeps(k) = st%sweeps
            self%corrections(k) = st%corrections
            self%max_position = max(self%max_position, st%position_residual)
            self%max_velocity = max(self%max_velocity, st%velocity_residual)
        end associate
        self%max_coordinate = max(self%max_coordinate, coord)
        self%n_buffered = k
        self%n_steps = self%n_steps + 1
    end subroutine writer_record_step

    !> Write the buffered per-step values.
    !> Write the buffered per-step values now (before a checkpoint: then nothing is buffered).
    subroutine writer_flush_buffer(self, file, error)
        !> The writer.
        class(coupled_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call flush_steps(self, file, error)
    end subroutine writer_flush_buffer

    !> Take over a results file that `begin` wrote for the same system (restart): sizes and
    !> buffers as `begin`, nothing written; the counters are then restored by the caller.
    subroutine writer_resume(self, sys)
        !> The writer.
        class(coupled_writer_t), intent(inout) :: self
        !> The coupled system.
        type(coupled_system_t), intent(in) :: sys
        self%n_rows = sys%op%n_rows
        self%n_out = 0
        self%n_buffered = 0
        self%n_steps = 0
        if (allocated(self%values)) deallocate (self%values, self%sweeps, self%corrections)
        allocate (self%values(stats_buffer, size(step_names)), self%sweeps(stats_buffer), &
                  self%corrections(stats_buffer))
    end subroutine writer_resume

    subroutine flush_steps(self, file, error)
        type(coupled_writer_t), intent(inout) :: self
        type(h5_file_t), intent(inout) :: file
        type(error_t), allocatable, intent(out) :: error
        integer :: k, j
        k = self%n_buffered
        do j = 1, size(step_names)
            call file%append_chunk('/coupling/'//trim(step_names(j)), self%values(:k, j), error)
            if (allocated(error)) return
        end do
        call file%append_chunk('/coupling/sweeps', self%sweeps(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/coupling/corrections', self%corrections(:k), error)
        if (allocated(error)) return
        self%n_buffered = 0
        ! Every batch of writes ends with a flush (a killed run keeps a readable file).
        call file%flush(error)
    end subroutine flush_steps

    !> Write the buffered values and the closing attributes of /coupling (steps, largest
    !> residuals over the steps, largest |balance| over the outputs).
    subroutine writer_finish(self, file, error)
        !> The writer.
        class(coupled_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call flush_steps(self, file, error)
        if (allocated(error)) return
        call file%write_attribute('/coupling', 'steps', self%n_steps, error)
        if (allocated(error)) return
        call file%write_attribute('/coupling', 'max_position_residual', self%max_position, &
                                  error)
        if (allocated(error)) return
        call file%write_attribute('/coupling', 'max_velocity_residual', self%max_velocity, &
                                  error)
        if (allocated(error)) return
        call file%write_attribute('/coupling', 'max_coordinate_residual', &
                                  self%max_coordinate, error)
        if (allocated(error)) return
        call file%write_attribute('/coupling', 'max_abs_balance', self%max_balance, error)
    end subroutine writer_finish
end module driver_results_coupled
