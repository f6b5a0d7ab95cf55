!> The beam's part of the results file (layout in doc/output.md): its mesh (/fem/mesh), its
!> state at every stored output (/fem/{time, displacement, velocity, acceleration}), the
!> energy audit (/energy), the static solution (/static) and the modal results (/modal). The
!> file itself, its creation, restart and closing, is driver_results's, whose writer holds
!> this part (`results_writer_t%beam`) so that a checkpoint keeps its counters with the
!> file's.
!> Arrays per node are (3, n_nodes) in Fortran = (n_nodes, 3) in h5py, with the
!> DOFs u (x), w (y), theta (rotation about z); time series add a last Fortran dimension
!> (the first in h5py) per stored output.
module driver_results_beam
    use core_kinds, only: wp
    use core_constants, only: two_pi
    use core_error, only: error_t, make_internal_error
    use io_hdf5_file, only: h5_file_t
    implicit none
    private
    public :: beam_writer_t

    !> Writes the beam's datasets into the results file.
    type :: beam_writer_t
        !> Number of nodes (0 until the mesh or a first state is written).
        integer :: n_nodes = 0
        !> Whether the /fem state series exist.
        logical :: have_state = .false.
        !> Whether the /energy series exist.
        logical :: have_energy = .false.
        !> Total energy of the first energy record [J] (reference of the balance).
        real(wp) :: energy0 = 0.0_wp
    contains
        !> Write the mesh of the beam: node ids, coordinates, connectivity.
        procedure :: write_mesh => writer_write_mesh
        !> Append one stored state: time, displacements, velocities, accelerations.
        procedure :: append_state => writer_append_state
        !> Append one record of the energy audit.
        procedure :: append_energy => writer_append_energy
        !> Write the static solution: displacements and support reactions.
        procedure :: write_static => writer_write_static
        !> Write the modal results: frequencies and mode shapes.
        procedure :: write_modal => writer_write_modal
        !> Write the kind of each mode (axial share of its strain energy).
        procedure :: write_modal_kinds => writer_write_modal_kinds
    end type beam_writer_t

contains

    !> Write the FE mesh: /fem/mesh/{node_id, coordinates, connectivity}.
    subroutine writer_write_mesh(self, file, node_id, x, y, conn, error)
        !> The beam part of the results.
        class(beam_writer_t), intent(inout) :: self
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Deck ids of the nodes (n_nodes).
        integer, intent(in) :: node_id(:)
        !> Node x coordinates [m] (n_nodes).
        real(wp), intent(in) :: x(:)
        !> Node y coordinates [m] (n_nodes).
        real(wp), intent(in) :: y(:)
        !> Element connectivity (2, n_elements), node indices 1..n_nodes.
        integer, intent(in) :: conn(:, :)
        !> Set on a size mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: coordinates(:, :)
        call require_open(file, 'write_mesh', error)
        if (allocated(error)) return
        if (size(x) /= size(node_id) .or. size(y) /= size(node_id) .or. size(conn, 1) /= 2) then
            call make_internal_error(error, 'results: write_mesh', 'node_id, x, y must have the same '// &
                                     'size and conn must be (2, n_elements)')
            return
        end if
        call check_nodes(self, size(node_id), 'write_mesh', error)
        if (allocated(error)) return
        allocate (coordinates(2, size(x)))
        coordinates(1, :) = x
        coordinates(2, :) = y
        call file%create_group('/fem/mesh', error)
        if (allocated(error)) return
        call file%write_dataset('/fem/mesh/node_id', node_id, error)
        if (allocated(error)) return
        call file%write_dataset('/fem/mesh/coordinates', coordinates, error)
        if (allocated(error)) return
        call file%write_attribute('/fem/mesh/coordinates', 'units', 'm', error)
        if (allocated(error)) return
        call file%write_dataset('/fem/mesh/connectivity', conn, error)
        if (allocated(error)) return
        call file%write_attribute('/fem/mesh/connectivity', 'description', &
                                  'node indices (1-based positions in node_id) of the 2 ends of each element', error)
    end subroutine writer_write_mesh

    !> Append one output state: /fem/{time, displacement, velocity, acceleration}.
    subroutine writer_append_state(self, file, t, d, v, a, error)
        !> The beam part of the results.
        class(beam_writer_t), intent(inout) :: self
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Time [s].
        real(wp), intent(in) :: t
        !> Nodal displacements (3, n_nodes) [m, m, rad].
        real(wp), intent(in) :: d(:, :)
        !> Nodal velocities (3, n_nodes) [m/s, m/s, rad/s].
        real(wp), intent(in) :: v(:, :)
        !> Nodal accelerations (3, n_nodes) [m/s^2, m/s^2, rad/s^2].
        real(wp), intent(in) :: a(:, :)
        !> Set on a shape mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        call require_open(file, 'append_state', error)
        if (allocated(error)) return
        if (size(d, 1) /= 3 .or. any(shape(v) /= shape(d)) .or. any(shape(a) /= shape(d))) then
            call make_internal_error(error, 'results: append_state', 'd, v, a must all be (3, n_nodes)')
            return
        end if
        call check_nodes(self, size(d, 2), 'append_state', error)
        if (allocated(error)) return
        if (.not. self%have_state) then
            call new_series(file, '/fem/time', [integer ::], 's', error)
            if (allocated(error)) return
            call new_series(file, '/fem/displacement', shape(d), 'm, m, rad', error)
            if (allocated(error)) return
            call new_series(file, '/fem/velocity', shape(d), 'm/s, m/s, rad/s', error)
            if (allocated(error)) return
            call new_series(file, '/fem/acceleration', shape(d), 'm/s^2, m/s^2, rad/s^2', error)
            if (allocated(error)) return
            self%have_state = .true.
        end if
        call file%append('/fem/time', t, error)
        if (allocated(error)) return
        call file%append('/fem/displacement', d, error)
        if (allocated(error)) return
        call file%append('/fem/velocity', v, error)
        if (allocated(error)) return
        call file%append('/fem/acceleration', a, error)
    end subroutine writer_append_state

    !> Append one energy record: /energy/{time, kinetic, strain, external_work, damping,
    !> balance}, balance = kinetic + strain + damping - external_work - (same at the first
    !> record), i.e. zero for an exact energy-conserving integration.
    subroutine writer_append_energy(self, file, t, kinetic, strain, external_work, damping, error)
        !> The beam part of the results.
        class(beam_writer_t), intent(inout) :: self
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Time [s].
        real(wp), intent(in) :: t
        !> Kinetic energy [J].
        real(wp), intent(in) :: kinetic
        !> Strain energy [J].
        real(wp), intent(in) :: strain
        !> Work of the external loads since t = 0 [J].
        real(wp), intent(in) :: external_work
        !> Energy dissipated by damping since t = 0 [J].
        real(wp), intent(in) :: damping
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        real(wp) :: total
        call require_open(file, 'append_energy', error)
        if (allocated(error)) return
        total = kinetic + strain + damping - external_work
        if (.not. self%have_energy) then
            call new_series(file, '/energy/time', [integer ::], 's', error)
            if (allocated(error)) return
            call new_series(file, '/energy/kinetic', [integer ::], 'J', error)
            if (allocated(error)) return
            call new_series(file, '/energy/strain', [integer ::], 'J', error)
            if (allocated(error)) return
            call new_series(file, '/energy/external_work', [integer ::], 'J', error)
            if (allocated(error)) return
            call new_series(file, '/energy/damping', [integer ::], 'J', error)
            if (allocated(error)) return
            call new_series(file, '/energy/balance', [integer ::], 'J', error)
            if (allocated(error)) return
            self%energy0 = total
            self%have_energy = .true.
        end if
        call file%append('/energy/time', t, error)
        if (allocated(error)) return
        call file%append('/energy/kinetic', kinetic, error)
        if (allocated(error)) return
        call file%append('/energy/strain', strain, error)
        if (allocated(error)) return
        call file%append('/energy/external_work', external_work, error)
        if (allocated(error)) return
        call file%append('/energy/damping', damping, error)
        if (allocated(error)) return
        call file%append('/energy/balance', total - self%energy0, error)
    end subroutine writer_append_energy

    !> Write a static solution: /static/{displacement, reactions}.
    subroutine writer_write_static(self, file, d, reactions, error)
        !> The beam part of the results.
        class(beam_writer_t), intent(inout) :: self
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Nodal displacements (3, n_nodes) [m, m, rad].
        real(wp), intent(in) :: d(:, :)
        !> Support reactions (3, n_nodes) [N, N, N.m] (zero at free DOFs).
        real(wp), intent(in) :: reactions(:, :)
        !> Set on a shape mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        call require_open(file, 'write_static', error)
        if (allocated(error)) return
        if (size(d, 1) /= 3 .or. any(shape(reactions) /= shape(d))) then
            call make_internal_error(error, 'results: write_static', 'd and reactions must be (3, n_nodes)')
            return
        end if
        call check_nodes(self, size(d, 2), 'write_static', error)
        if (allocated(error)) return
        call file%write_dataset('/static/displacement', d, error)
        if (allocated(error)) return
        call file%write_attribute('/static/displacement', 'units', 'm, m, rad', error)
        if (allocated(error)) return
        call file%write_dataset('/static/reactions', reactions, error)
        if (allocated(error)) return
        call file%write_attribute('/static/reactions', 'units', 'N, N, N.m', error)
    end subroutine writer_write_static

    !> Write modal results: /modal/{omega, frequency, shapes}.
    subroutine writer_write_modal(self, file, omega, shapes, error)
        !> The beam part of the results.
        class(beam_writer_t), intent(inout) :: self
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Angular eigenfrequencies [rad/s] (n_modes).
        real(wp), intent(in) :: omega(:)
        !> Mode shapes (3, n_nodes, n_modes), normalised as the modal solver returns them.
        real(wp), intent(in) :: shapes(:, :, :)
        !> Set on a shape mismatch or a write failure.
        type(error_t), allocatable, intent(out) :: error
        call require_open(file, 'write_modal', error)
        if (allocated(error)) return
        if (size(shapes, 1) /= 3 .or. size(shapes, 3) /= size(omega)) then
            call make_internal_error(error, 'results: write_modal', 'shapes must be (3, n_nodes, '// &
                                     'n_modes) with n_modes = size(omega)')
            return
        end if
        call check_nodes(self, size(shapes, 2), 'write_modal', error)
        if (allocated(error)) return
        call file%write_dataset('/modal/omega', omega, error)
        if (allocated(error)) return
        call file%write_attribute('/modal/omega', 'units', 'rad/s', error)
        if (allocated(error)) return
        call file%write_dataset('/modal/frequency', omega/two_pi, error)
        if (allocated(error)) return
        call file%write_attribute('/modal/frequency', 'units', 'Hz', error)
        if (allocated(error)) return
        call file%write_dataset('/modal/shapes', shapes, error)
        if (allocated(error)) return
        call file%write_attribute('/modal/shapes', 'units', 'm, m, rad (arbitrary scale)', &
                                  error)
    end subroutine writer_write_modal

    !> Write the kind of each mode: /modal/axial_fraction (axial share of the strain energy,
    !> -1 for a rigid-body mode) with the attributes `kind` (one word per mode: axial,
    !> bending, mixed or rigid) and `threshold` (the share that makes a mode axial or bending).
    subroutine writer_write_modal_kinds(self, file, fraction, kinds, threshold, error)
        !> The beam part of the results.
        class(beam_writer_t), intent(inout) :: self
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Axial strain-energy share of each mode (n_modes).
        real(wp), intent(in) :: fraction(:)
        !> Kinds of the modes, space-separated, in mode order.
        character(len=*), intent(in) :: kinds
        !> Share above which a mode is axial (or, of bending energy, bending).
        real(wp), intent(in) :: threshold
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call require_open(file, 'write_modal_kinds', error)
        if (allocated(error)) return
        call file%write_dataset('/modal/axial_fraction', fraction, error)
        if (allocated(error)) return
        call file%write_attribute('/modal/axial_fraction', 'kind', kinds, error)
        if (allocated(error)) return
        call file%write_attribute('/modal/axial_fraction', 'threshold', threshold, error)
    end subroutine writer_write_modal_kinds

    !> Create an empty series and give it a 'units' attribute.
    subroutine new_series(file, path, record_shape, units, error)
        !> The results file, open.
        type(h5_file_t), intent(inout) :: file
        !> Series path.
        character(len=*), intent(in) :: path
        !> Shape of one record (Fortran order).
        integer, intent(in) :: record_shape(:)
        !> Units of the values.
        character(len=*), intent(in) :: units
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call file%create_series(path, record_shape, error)
        if (allocated(error)) return
        call file%write_attribute(path, 'units', units, error)
    end subroutine new_series

    !> Record the number of nodes, or check it against the one recorded.
    subroutine check_nodes(self, n, what, error)
        !> The writer.
        type(beam_writer_t), intent(inout) :: self
        !> Number of nodes of the data being written.
        integer, intent(in) :: n
        !> Name of the operation.
        character(len=*), intent(in) :: what
        !> Set when `n` differs from the number of nodes written before.
        type(error_t), allocatable, intent(out) :: error
        character(len=64) :: buf
        if (self%n_nodes == 0) then
            self%n_nodes = n
        else if (n /= self%n_nodes) then
            write (buf, '(i0,a,i0)') n, ' nodes instead of ', self%n_nodes
            call make_internal_error(error, 'results: '//what, trim(buf))
        end if
    end subroutine check_nodes

    !> Error unless the results file is open.
    subroutine require_open(file, what, error)
        !> The results file.
        type(h5_file_t), intent(in) :: file
        !> Name of the operation.
        character(len=*), intent(in) :: what
        !> Set when the file is not open.
        type(error_t), allocatable, intent(out) :: error
        if (.not. file%is_open()) then
            call make_internal_error(error, 'results: '//what, 'no results file is open')
        end if
    end subroutine require_open
end module driver_results_beam
