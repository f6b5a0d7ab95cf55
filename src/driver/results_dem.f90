!> Discrete-element results in the run's HDF5 file (layout in doc/output.md, group /dem):
!> disk properties, the state of the disks (and of the walls) at every stored output, the
!> contact network at the stored outputs in compressed-row form, the energy audit at the
!> stored outputs, and the solver statistics of EVERY time step (buffered in memory and
!> written in chunks).
!>
!> Per-disk arrays are (3, n) in Fortran = (n, 3) in h5py with columns x, y, rot; series add
!> a first h5py axis per stored output. Contacts of output k are the entries
!> offset[k]:offset[k+1] (h5py, 0-based) of the concatenated lists i, j, normal, rn, rt,
!> status: disk i touches body j (j > 0: disk j, j < 0: wall -j), the unit normal goes from
!> j to i, and (rn, rt) is the mean contact force on i over the step (impulse / h) per unit
!> thickness, in the frame (n, t = (-n_y, n_x)); j receives the opposite force.
module driver_results_dem
    use core_kinds, only: wp
    use core_error, only: error_t, make_error, make_internal_error
    use core_strings, only: to_str
    use core_version, only: multicor_name, multicor_version
    use io_hdf5_file, only: h5_file_t
    use dem_nlgs, only: nlgs_stats_t, nlgs_criterion_name, nlgs_start_name, block_kept, block_given_up_unconverged, &
                        block_given_up_reverted
    use dem_moreau_jean, only: dem_system_t, energies_balance
    use dem_local_problem, only: local_problem_t, local_problem_siconos_error
    implicit none
    private
    public :: dem_writer_t, write_fclib_local

    !> Steps of solver statistics kept in memory before they are written.
    integer, parameter :: stats_buffer = 4096
    !> Meaning of the contact status codes (stored as an attribute).
    character(len=*), parameter :: status_codes = &
                                   '0 = open (no force), 1 = stick (inside the Coulomb cone), 2 = slip (on the cone), '// &
                                   '3 = cohesive (intact bond), 4 = broken (bond broken for good)'

    !> Writes the discrete-element part of a results file.
    type :: dem_writer_t
        !> Number of disks and walls.
        integer :: n_particles = 0, n_walls = 0
        !> Store the contact network.
        logical :: store_contacts = .true.
        !> Outputs stored so far.
        integer :: n_out = 0
        !> Contacts stored so far (all outputs).
        integer :: n_contacts_stored = 0
        !> Time steps whose statistics are buffered, and steps recorded in all.
        integer :: n_buffered = 0, n_steps = 0
        !> Bond ruptures written so far.
        integer :: n_ruptures = 0
        !> Steps recorded so far whose bonded block was given up (nlgs_stats_t%block_given_up),
        !> for either reason, ...
        integer :: n_block_given_up = 0
        !> ... and those of them given up unconverged at the cap with a bond outside its cone
        !> (block_given_up_unconverged; the others by the energy guard).
        integer :: n_block_given_up_unconverged = 0
        !> Steps recorded so far whose block was given up unconverged at the cap and taken back,
        !> the plain sweeps ending worse (block_given_up_reverted; not in n_block_given_up).
        integer :: n_block_given_up_reverted = 0
        !> Buffered statistics per step: sweeps, contacts in the list, active contacts,
        !> converged (1) or not (0), why the bonded block was given up (nlgs_stats_t%block_given_up,
        !> 0 when it was not), contact solves (nlgs_stats_t%solves).
        integer, allocatable :: sweeps(:), contacts(:), active(:), blocked(:), converged(:), given_up(:), solves(:)
        !> Buffered convergence norms and Signorini-Coulomb residuals per step.
        real(wp), allocatable :: norm(:), residual(:)
        !> Buffered Siconos errors per step (dem_nlgs, nlgs_siconos_error).
        real(wp), allocatable :: siconos(:)
    contains
        !> Write disk and wall properties, settings, and create every series.
        procedure :: begin => writer_begin
        !> Store the current state (an output): disks, walls, energies, contacts.
        procedure :: store => writer_store
        !> Record the solver statistics of the step just done.
        procedure :: record_step => writer_record_step
        !> Write what is buffered and the closing attributes.
        procedure :: finish => writer_finish
        !> Write the buffered statistics now (before a checkpoint).
        procedure :: flush_buffer => writer_flush_buffer
        !> Take over a results file written by `begin` (restart; counters set by the caller).
        procedure :: resume => writer_resume
    end type dem_writer_t

contains

    !> Write /dem/particles, /dem/walls/material, the settings as attributes of /dem and
    !> /dem/solver, and create the empty series.
    subroutine writer_begin(self, file, sys, material_id, store_contacts, error)
        !> The writer.
        class(dem_writer_t), intent(inout) :: self
        !> A results file open for writing.
        type(h5_file_t), intent(inout) :: file
        !> The system (mj_init done).
        type(dem_system_t), intent(in) :: sys
        !> Deck id of each material index.
        integer, intent(in) :: material_id(:)
        !> Store the contact network at the outputs.
        logical, intent(in) :: store_contacts
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: n
        n = sys%particles%n
        self%n_particles = n
        self%n_walls = sys%walls%n
        self%store_contacts = store_contacts
        self%n_out = 0
        self%n_contacts_stored = 0
        self%n_buffered = 0
        self%n_steps = 0
        self%n_ruptures = 0
        self%n_block_given_up = 0
        self%n_block_given_up_unconverged = 0
        self%n_block_given_up_reverted = 0
        allocate (self%sweeps(stats_buffer), self%contacts(stats_buffer), &
                  self%active(stats_buffer), self%blocked(stats_buffer), self%converged(stats_buffer), &
                  self%given_up(stats_buffer), self%solves(stats_buffer), self%norm(stats_buffer), &
                  self%residual(stats_buffer), self%siconos(stats_buffer))
        call properties(error)
        if (allocated(error)) return
        call settings(error)
        if (allocated(error)) return
        call series(error)
    contains
        subroutine properties(error)
            type(error_t), allocatable, intent(out) :: error
            call dataset('/dem/particles/radius', sys%particles%radius(1:n), 'm', error)
            if (allocated(error)) return
            call dataset('/dem/particles/mass', sys%particles%mass(1:n), 'kg/m', error)
            if (allocated(error)) return
            call dataset('/dem/particles/inertia', sys%particles%inertia(1:n), 'kg m', error)
            if (allocated(error)) return
            call file%write_dataset('/dem/particles/material', &
                                    material_id(sys%particles%mat(1:n)), error)
            if (allocated(error) .or. sys%walls%n == 0) return
            call file%write_dataset('/dem/walls/material', &
                                    material_id(sys%walls%mat(1:sys%walls%n)), error)
        end subroutine properties

        subroutine settings(error)
            type(error_t), allocatable, intent(out) :: error
            call file%write_attribute('/dem', 'n_particles', n, error)
            if (allocated(error)) return
            call file%write_attribute('/dem', 'n_walls', sys%walls%n, error)
            if (allocated(error)) return
            call file%write_attribute('/dem', 'time_step', sys%scheme%h, error)
            if (allocated(error)) return
            call file%write_attribute('/dem', 'theta', sys%scheme%theta, error)
            if (allocated(error)) return
            call file%write_attribute('/dem', 'contact_scheme', sys%scheme%activation%name(), error)
            if (allocated(error)) return
            call file%write_attribute('/dem', 'alert', sys%scheme%alert, error)
            if (allocated(error)) return
            call file%write_attribute('/dem', 'gravity', sys%particles%gravity, error)
            if (allocated(error)) return
            call file%create_group('/dem/solver', error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'tolerance', sys%solver%tol, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'max_sweeps', sys%solver%max_sweeps, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'relaxation', sys%solver%relaxation, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'criterion', nlgs_criterion_name(sys%solver), error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'method', sys%method%name(sys%solver), error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'cold_start', nlgs_start_name(sys%solver), error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'sweep_order', trim(merge('alternating', 'forward    ', &
                                                                               sys%solver%symmetric)), error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'anderson', sys%solver%anderson, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'anderson_after', sys%solver%anderson_after, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'anderson_sweeps', sys%solver%anderson_sweeps, error)
            if (allocated(error)) return
            ! the closing attributes (`finish`), created now with their types so that the end of
            ! the run overwrites them in place (a kill while the file is closed leaves it readable:
            ! doc/output.md, restart)
            call file%write_attribute('/dem/solver', 'steps', 0, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'unconverged_steps', 0, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'block_given_up_steps', 0, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'block_given_up_unconverged_steps', 0, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'block_given_up_reverted_steps', 0, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'detection_seconds', 0.0_wp, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'solver_seconds', 0.0_wp, error)
            if (allocated(error)) return
            call file%write_attribute('/dem/solver', 'bond_ruptures', 0, error)
        end subroutine settings

        subroutine series(error)
            type(error_t), allocatable, intent(out) :: error
            !&<
            character(len=*), parameter :: energies(7) = [character(len=13) :: 'kinetic', &
                'potential', 'external_work', 'drive_work', 'dissipated', 'numerical', 'balance']
            character(len=*), parameter :: stats_int(7) = [character(len=14) :: 'sweeps', &
                'contacts', 'active', 'blocked', 'converged', 'block_given_up', 'solves']
            character(len=*), parameter :: bond_ints(4) = [character(len=4) :: 'i', 'j', 'step', 'mode']
            !&>
            integer :: k
            call real_series('/dem/time', [integer ::], 's', error)
            if (allocated(error)) return
            call real_series('/dem/position', [3, n], 'm, m, rad', error)
            if (allocated(error)) return
            call real_series('/dem/velocity', [3, n], 'm/s, m/s, rad/s', error)
            if (allocated(error)) return
            if (sys%walls%n > 0) then
                call real_series('/dem/walls/position', [4, sys%walls%n], 'm', error)
                if (allocated(error)) return
            end if
            call real_series('/dem/energy/time', [integer ::], 's', error)
            if (allocated(error)) return
            do k = 1, size(energies)
                call real_series('/dem/energy/'//trim(energies(k)), [integer ::], 'J/m', error)
                if (allocated(error)) return
            end do
            do k = 1, size(stats_int)
                call file%create_int_series('/dem/solver/'//trim(stats_int(k)), error)
                if (allocated(error)) return
            end do
            call real_series('/dem/solver/error', [integer ::], '', error)
            if (allocated(error)) return
            call real_series('/dem/solver/residual', [integer ::], '', error)
            if (allocated(error)) return
            call real_series('/dem/solver/siconos_error', [integer ::], '', error)
            if (allocated(error)) return
            do k = 1, size(bond_ints)
                call file%create_int_series('/dem/bonds/'//trim(bond_ints(k)), error)
                if (allocated(error)) return
            end do
            call real_series('/dem/bonds/time', [integer ::], 's', error)
            if (allocated(error) .or. .not. self%store_contacts) return
            call file%create_int_series('/dem/contacts/offset', error)
            if (allocated(error)) return
            call file%append_chunk('/dem/contacts/offset', [0], error)
            if (allocated(error)) return
            call file%create_int_series('/dem/contacts/i', error)
            if (allocated(error)) return
            call file%create_int_series('/dem/contacts/j', error)
            if (allocated(error)) return
            call file%create_int_series('/dem/contacts/status', error)
            if (allocated(error)) return
            call file%write_attribute('/dem/contacts/status', 'codes', status_codes, error)
            if (allocated(error)) return
            call real_series('/dem/contacts/normal', [2], '', error)
            if (allocated(error)) return
            call real_series('/dem/contacts/rn', [integer ::], 'N/m', error)
            if (allocated(error)) return
            call real_series('/dem/contacts/rt', [integer ::], 'N/m', error)
            if (allocated(error)) return
            call real_series('/dem/contacts/m', [integer ::], 'N.m/m', error)
        end subroutine series

        subroutine dataset(path, values, units, error)
            character(len=*), intent(in) :: path, units
            real(wp), intent(in) :: values(:)
            type(error_t), allocatable, intent(out) :: error
            call file%write_dataset(path, values, error)
            if (allocated(error)) return
            call file%write_attribute(path, 'units', units, error)
        end subroutine dataset

        subroutine real_series(path, record_shape, units, error)
            character(len=*), intent(in) :: path, units
            integer, intent(in) :: record_shape(:)
            type(error_t), allocatable, intent(out) :: error
            call file%create_series(path, record_shape, error)
            if (allocated(error) .or. len(units) == 0) return
            call file%write_attribute(path, 'units', units, error)
        end subroutine real_series
    end subroutine writer_begin

    !> Store the current state as one output: time, positions and velocities of the disks,
    !> positions of the walls, energies, and the contact network.
    subroutine writer_store(self, file, sys, error)
        !> The writer (begin done).
        class(dem_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Set on a size mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: state(:, :)
        integer :: n
        n = sys%particles%n
        if (n /= self%n_particles .or. .not. allocated(self%sweeps)) then
            call make_internal_error(error, 'results: DEM store', 'begin was not called for this system')
            return
        end if
        call file%append('/dem/time', sys%time, error)
        if (allocated(error)) return
        allocate (state(3, n))
        state(1, :) = sys%particles%x(1:n)
        state(2, :) = sys%particles%y(1:n)
        state(3, :) = sys%particles%rot(1:n)
        call file%append('/dem/position', state, error)
        if (allocated(error)) return
        state(1, :) = sys%particles%vx(1:n)
        state(2, :) = sys%particles%vy(1:n)
        state(3, :) = sys%particles%w(1:n)
        call file%append('/dem/velocity', state, error)
        if (allocated(error)) return
        if (sys%walls%n > 0) then
            associate (w => sys%walls)
                call file%append('/dem/walls/position', reshape([w%x1(1:w%n), w%y1(1:w%n), &
                                                                 w%x2(1:w%n), w%y2(1:w%n)], [4, w%n], order=[2, 1]), error)
            end associate
            if (allocated(error)) return
        end if
        call store_energies(file, sys, error)
        if (allocated(error)) return
        if (self%store_contacts) call store_contacts(self, file, sys, error)
        if (allocated(error)) return
        call store_ruptures(self, file, sys, error)
        if (allocated(error)) return
        self%n_out = self%n_out + 1
    end subroutine writer_store

    !> Append the energy record of the current state.
    subroutine store_energies(file, sys, error)
        type(h5_file_t), intent(inout) :: file
        type(dem_system_t), intent(in) :: sys
        type(error_t), allocatable, intent(out) :: error
        associate (e => sys%energies)
            call file%append('/dem/energy/time', sys%time, error)
            if (allocated(error)) return
            call file%append('/dem/energy/kinetic', e%kinetic, error)
            if (allocated(error)) return
            call file%append('/dem/energy/potential', e%potential, error)
            if (allocated(error)) return
            call file%append('/dem/energy/external_work', e%external_work, error)
            if (allocated(error)) return
            call file%append('/dem/energy/drive_work', e%drive_work, error)
            if (allocated(error)) return
            call file%append('/dem/energy/dissipated', e%contact_dissipation, error)
            if (allocated(error)) return
            call file%append('/dem/energy/numerical', e%numerical_dissipation, error)
            if (allocated(error)) return
            call file%append('/dem/energy/balance', energies_balance(e), error)
        end associate
    end subroutine store_energies

    !> Append the contacts of the current list and the offset of the next output.
    subroutine store_contacts(self, file, sys, error)
        type(dem_writer_t), intent(inout) :: self
        type(h5_file_t), intent(inout) :: file
        type(dem_system_t), intent(in) :: sys
        type(error_t), allocatable, intent(out) :: error
        integer :: m
        m = sys%contacts%n
        if (m > huge(0) - self%n_contacts_stored) then
            call make_error(error, 'results: more than 2**31 - 1 contacts stored: store fewer '// &
                            'outputs ([output] interval) or no contacts ([output] contacts = no)')
            return
        end if
        if (m > 0) then
            associate (cs => sys%contacts)
                call file%append_chunk('/dem/contacts/i', cs%i2(1:m), error)
                if (allocated(error)) return
                call file%append_chunk('/dem/contacts/j', cs%i1(1:m), error)
                if (allocated(error)) return
                call file%append_chunk('/dem/contacts/status', cs%status(1:m), error)
                if (allocated(error)) return
                call file%append_chunk('/dem/contacts/normal', cs%nrm(:, 1:m), error)
                if (allocated(error)) return
                call file%append_chunk('/dem/contacts/rn', cs%r(1, 1:m)/sys%scheme%h, error)
                if (allocated(error)) return
                call file%append_chunk('/dem/contacts/rt', cs%r(2, 1:m)/sys%scheme%h, error)
                if (allocated(error)) return
                call file%append_chunk('/dem/contacts/m', cs%r(3, 1:m)/sys%scheme%h, error)
                if (allocated(error)) return
            end associate
        end if
        self%n_contacts_stored = self%n_contacts_stored + m
        call file%append_chunk('/dem/contacts/offset', [self%n_contacts_stored], error)
    end subroutine store_contacts

    !> Record the statistics of the last solve (one time step); written every
    !> `stats_buffer` steps and by `finish`.
    subroutine writer_record_step(self, file, stats, error)
        !> The writer (begin done).
        class(dem_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> Statistics of the step.
        type(nlgs_stats_t), intent(in) :: stats
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        if (.not. allocated(self%sweeps)) then
            call make_internal_error(error, 'results: DEM record_step', 'begin was not called')
            return
        end if
        if (self%n_buffered == stats_buffer) call flush_stats(self, file, error)
        if (allocated(error)) return
        k = self%n_buffered + 1
        self%sweeps(k) = stats%sweeps
        self%contacts(k) = stats%n_contacts
        self%active(k) = stats%n_active
        self%blocked(k) = stats%n_blocked
        self%converged(k) = merge(1, 0, stats%converged)
        self%given_up(k) = stats%block_given_up
        self%solves(k) = stats%solves
        if (stats%block_given_up /= block_kept .and. stats%block_given_up /= block_given_up_reverted) &
            self%n_block_given_up = self%n_block_given_up + 1
        if (stats%block_given_up == block_given_up_reverted) &
            self%n_block_given_up_reverted = self%n_block_given_up_reverted + 1
        if (stats%block_given_up == block_given_up_unconverged) &
            self%n_block_given_up_unconverged = self%n_block_given_up_unconverged + 1
        self%norm(k) = stats%error
        self%residual(k) = stats%residual
        self%siconos(k) = stats%siconos_error
        self%n_buffered = k
        self%n_steps = self%n_steps + 1
    end subroutine writer_record_step

    !> Write the buffered solver statistics now (before a checkpoint: then nothing is
    !> buffered).
    subroutine writer_flush_buffer(self, file, error)
        !> The writer.
        class(dem_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call flush_stats(self, file, error)
    end subroutine writer_flush_buffer

    !> Take over a results file that `begin` wrote for the same system (restart): sizes and
    !> buffers as `begin`, nothing written; the counters are then restored by the caller.
    subroutine writer_resume(self, sys, store_contacts)
        !> The writer.
        class(dem_writer_t), intent(inout) :: self
        !> The system.
        type(dem_system_t), intent(in) :: sys
        !> Store the contact network at the outputs.
        logical, intent(in) :: store_contacts
        self%n_particles = sys%particles%n
        self%n_walls = sys%walls%n
        self%store_contacts = store_contacts
        self%n_out = 0
        self%n_contacts_stored = 0
        self%n_buffered = 0
        self%n_steps = 0
        self%n_ruptures = 0
        self%n_block_given_up = 0
        self%n_block_given_up_unconverged = 0
        self%n_block_given_up_reverted = 0
        if (allocated(self%sweeps)) deallocate (self%sweeps, self%contacts, self%active, self%blocked, &
                                                self%converged, self%norm, self%residual)
        if (allocated(self%siconos)) deallocate (self%siconos)
        if (allocated(self%given_up)) deallocate (self%given_up)
        if (allocated(self%solves)) deallocate (self%solves)
        allocate (self%sweeps(stats_buffer), self%contacts(stats_buffer), &
                  self%active(stats_buffer), self%blocked(stats_buffer), self%converged(stats_buffer), &
                  self%given_up(stats_buffer), self%solves(stats_buffer), self%norm(stats_buffer), &
                  self%residual(stats_buffer), &
                  self%siconos(stats_buffer))
    end subroutine writer_resume

    !> Write the buffered solver statistics.
    subroutine flush_stats(self, file, error)
        type(dem_writer_t), intent(inout) :: self
        type(h5_file_t), intent(inout) :: file
        type(error_t), allocatable, intent(out) :: error
        integer :: k
        k = self%n_buffered
        call file%append_chunk('/dem/solver/sweeps', self%sweeps(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/contacts', self%contacts(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/active', self%active(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/blocked', self%blocked(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/converged', self%converged(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/block_given_up', self%given_up(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/solves', self%solves(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/error', self%norm(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/residual', self%residual(:k), error)
        if (allocated(error)) return
        call file%append_chunk('/dem/solver/siconos_error', self%siconos(:k), error)
        if (allocated(error)) return
        self%n_buffered = 0
        ! Every batch of writes ends with a flush (a killed run keeps a readable file).
        call file%flush(error)
    end subroutine flush_stats

    !> Write the buffered statistics and the closing attributes of /dem/solver (steps,
    !> unconverged steps, steps whose bonded block was given up, for either reason and
    !> unconverged at its cap, time spent in detection and in the solver).
    subroutine writer_finish(self, file, sys, unconverged, error)
        !> The writer.
        class(dem_writer_t), intent(inout) :: self
        !> The results file.
        type(h5_file_t), intent(inout) :: file
        !> The system at the end of the run.
        type(dem_system_t), intent(in) :: sys
        !> Number of steps whose solve did not converge.
        integer, intent(in) :: unconverged
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call flush_stats(self, file, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'steps', self%n_steps, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'unconverged_steps', unconverged, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'block_given_up_steps', self%n_block_given_up, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'block_given_up_unconverged_steps', self%n_block_given_up_unconverged, &
                                  error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'block_given_up_reverted_steps', self%n_block_given_up_reverted, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'detection_seconds', sys%time_detection, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'solver_seconds', sys%time_solver, error)
        if (allocated(error)) return
        call store_ruptures(self, file, sys, error)
        if (allocated(error)) return
        call file%write_attribute('/dem/solver', 'bond_ruptures', sys%ruptures%n, error)
    end subroutine writer_finish

    !> Append the bond ruptures logged since the last call to /dem/bonds, so that a run
    !> stopped early (signal, guard, kill after a flush) keeps the ruptures of its outputs.
    subroutine store_ruptures(self, file, sys, error)
        type(dem_writer_t), intent(inout) :: self
        type(h5_file_t), intent(inout) :: file
        type(dem_system_t), intent(in) :: sys
        type(error_t), allocatable, intent(out) :: error
        integer :: a, b
        a = self%n_ruptures + 1
        b = sys%ruptures%n
        if (b < a) return
        associate (rl => sys%ruptures)
            ! as the contacts: i is the second body (a disk), j the first (a disk, or -wall)
            call file%append_chunk('/dem/bonds/i', rl%i2(a:b), error)
            if (allocated(error)) return
            call file%append_chunk('/dem/bonds/j', rl%i1(a:b), error)
            if (allocated(error)) return
            ! steps <= huge(0) (driver_config caps the step count)
            call file%append_chunk('/dem/bonds/step', int(rl%step(a:b)), error)
            if (allocated(error)) return
            call file%append_chunk('/dem/bonds/time', rl%time(a:b), error)
            if (allocated(error)) return
            call file%append_chunk('/dem/bonds/mode', rl%mode(a:b), error)
            if (allocated(error)) return
        end associate
        self%n_ruptures = b
    end subroutine store_ruptures

    !> Write a local contact problem to a new HDF5 file in FCLIB's layout (fclib.c,
    !> fclib_write_local and fclib_write_solution): /fclib_local/spacedim, /fclib_local/W
    !> (compressed sparse columns, nz = -1, 0-based: nzmax, m, n, nz, p, i, x),
    !> /fclib_local/vectors/q and mu, /fclib_local/info (title, description, math_info:
    !> fixed-length strings), /solution/r and u; MULTICOR's extra data, which FCLIB readers
    !> ignore, in /multicor: cohesion (r_cohe h), rolling (moment lengths), i1 and i2 (bodies),
    !> and the attributes step, time, unknowns, siconos_error (the error of the exported
    !> problem, local_problem_siconos_error) and solver_siconos_error (the run's, as stored in
    !> /dem/solver/siconos_error; doc/theory.md, "Siconos error").
    subroutine write_fclib_local(path, title, lp, step, time, siconos_error, error)
        !> File name (created, or truncated).
        character(len=*), intent(in) :: path
        !> Title of the run ([run] title; empty: none given).
        character(len=*), intent(in) :: title
        !> The problem.
        type(local_problem_t), intent(in) :: lp
        !> Step number.
        integer, intent(in) :: step
        !> Time at the end of the step [s].
        real(wp), intent(in) :: time
        !> Siconos error of the solution found by the solver, as the run stores it.
        real(wp), intent(in) :: siconos_error
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        type(h5_file_t) :: file
        type(error_t), allocatable :: close_error
        integer :: m
        m = lp%dim*lp%n
        call file%create(path, error)
        if (allocated(error)) return
        call body(error)
        call file%close(close_error)
        if (.not. allocated(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    contains
        subroutine body(error)
            type(error_t), allocatable, intent(out) :: error
            call file%create_group('/fclib_local', error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/spacedim', [lp%dim], error)
            if (allocated(error)) return
            call file%create_group('/fclib_local/W', error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/nzmax', [size(lp%values)], error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/m', [m], error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/n', [m], error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/nz', [-1], error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/p', lp%colptr, error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/i', lp%rowind, error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/W/x', lp%values, error)
            if (allocated(error)) return
            call file%create_group('/fclib_local/vectors', error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/vectors/q', lp%q, error)
            if (allocated(error)) return
            call file%write_dataset('/fclib_local/vectors/mu', lp%mu, error)
            if (allocated(error)) return
            call write_info(error)
            if (allocated(error)) return
            call file%create_group('/solution', error)
            if (allocated(error)) return
            call file%write_dataset('/solution/r', lp%r, error)
            if (allocated(error)) return
            call file%write_dataset('/solution/u', lp%u, error)
            if (allocated(error)) return
            call file%create_group('/multicor', error)
            if (allocated(error)) return
            call file%write_dataset('/multicor/cohesion', lp%cohesion, error)
            if (allocated(error)) return
            call file%write_dataset('/multicor/rolling', lp%rolling, error)
            if (allocated(error)) return
            call file%write_dataset('/multicor/i1', lp%i1, error)
            if (allocated(error)) return
            call file%write_dataset('/multicor/i2', lp%i2, error)
            if (allocated(error)) return
            call file%write_attribute('/multicor', 'step', step, error)
            if (allocated(error)) return
            call file%write_attribute('/multicor', 'time', time, error)
            if (allocated(error)) return
            call file%write_attribute('/multicor', 'siconos_error', local_problem_siconos_error(lp), error)
            if (allocated(error)) return
            call file%write_attribute('/multicor', 'solver_siconos_error', siconos_error, error)
            if (allocated(error)) return
            if (lp%dim == 3) then
                call file%write_attribute('/multicor', 'unknowns', 'per contact (r_n + r_cohe h, r_t, M); cone '// &
                                          '|r_t| <= mu r_n, |M| <= e r_n with e = rolling', error)
            else
                call file%write_attribute('/multicor', 'unknowns', 'per contact (r_n + r_cohe h, r_t); cone '// &
                                          '|r_t| <= mu r_n', error)
            end if
        end subroutine body

        !> /fclib_local/info, FCLIB's description of the problem for other solvers.
        subroutine write_info(error)
            type(error_t), allocatable, intent(out) :: error
            character(len=:), allocatable :: text
            text = trim(title)
            if (len(text) == 0) text = multicor_name//' run'
            call file%write_dataset('/fclib_local/info/title', text//', step '//to_str(step), error)
            if (allocated(error)) return
            text = multicor_name//' '//multicor_version//': local contact problem of step '//to_str(step)// &
                   ' (t = '//to_str(time)//' s) between 2D disks and walls, u = W r + q with W = H^T M^-1 H, '// &
                   to_str(lp%n)//' contacts; per contact (normal, tangential'
            if (lp%dim == 3) text = text//', moment'
            text = text//'); r_n includes the cohesion impulse r_cohe h (/multicor/cohesion); '// &
                   '/solution is the one found by '//multicor_name//', its Siconos error in /multicor'
            call file%write_dataset('/fclib_local/info/description', text, error)
            if (allocated(error)) return
            text = 'W symmetric positive semi-definite (singular when the contacts are hyperstatic); '// &
                   'cone |r_t| <= mu r_n'
            if (lp%dim == 3) text = text//' and |M| <= e r_n with e = /multicor/rolling (the third '// &
                                    'component is a moment: not the circular cone of FCLIB''s 3D problems)'
            call file%write_dataset('/fclib_local/info/math_info', text, error)
        end subroutine write_info
    end subroutine write_fclib_local
end module driver_results_dem
