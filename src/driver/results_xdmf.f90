!> `<deck>.xdmf` next to the results file: what the HDF5 file holds, described by reference
!> (io_xdmf: whole datasets and hyperslabs, no data copied) for ParaView's "XDMF Reader".
!>
!> The description is read from the results file itself (its root attribute `analysis`, the
!> groups it has and the shapes of their datasets), so that it is the same for every kind of
!> run and after a restart (doc/output.md, "XDMF file"):
!> - a beam (/fem/mesh): a polyline grid "beam" of the nodes (reference coordinates) with the
!>   displacement (x, y; ParaView adds z = 0, so that Warp By Vector applies), the rotation,
!>   and the velocity and acceleration when stored; the node ids;
!> - a 2D continuum (/continuum/mesh): its mesh "continuum" with displacement, velocity, the
!>   static reactions, the centre stresses as the scalars sigma_xx, sigma_yy, sigma_xy, their
!>   sigma_zz and von Mises stress (von_mises; when stored: a file of an earlier build, continued
!>   by a restart, lacks them) and each element's material;
!> - disks (/dem/position): a point grid "disks" (the centres) with radius, material, velocity,
!>   rotation and angular velocity; walls (/dem/walls/position): segments "walls";
!> - static: one grid; modal: a temporal collection per part with one grid per mode, at the
!>   mode number as its time (ParaView's time steps through the modes); dynamic: a temporal
!>   collection per part ("beam", "continuum", "disks", "walls") over the same stored times.
!>   ParaView shows several parts as the blocks of one data set, named after the parts at every
!>   time (a spatial collection per time would name them "beam[k]" with the state k, which
!>   changes with the time and breaks a block selection).
module driver_results_xdmf
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t, xdmf_item_t, xdmf_whole, xdmf_slab
    use fem_element_registry, only: element_slot_t, new_element
    implicit none
    private
    public :: write_results_xdmf

    !> What the results file holds: which parts, and the shapes (XDMF order) of their data.
    type :: survey_t
        !> The analysis ('static', 'modal', 'dynamic').
        character(len=:), allocatable :: analysis
        !> Parts present.
        logical :: beam = .false., continuum = .false., disks = .false., walls = .false.
        !> Beam nodes and elements.
        integer :: beam_nodes = 0, beam_elements = 0
        !> Continuum nodes and elements.
        integer :: mesh_nodes = 0, mesh_elements = 0
        !> Shape of /continuum/mesh/topology.
        integer, allocatable :: topology_dims(:)
        !> XDMF topology of the continuum ('Triangle', 'Quadrilateral', 'Mixed').
        character(len=:), allocatable :: topology
        !> The continuum's /continuum/mesh/material and /continuum/static/reactions are stored
        !> (a file of an earlier build, continued by a restart, may lack them).
        logical :: mesh_material = .false., static_reactions = .false.
        !> The continuum's sigma_zz and von Mises stress are stored (static: stress_zz and von_mises
        !> of /continuum/static; dynamic: the series /continuum/stress_zz and von_mises, which a
        !> file of an earlier build, continued by a restart, lacks).
        logical :: stress_measures = .false.
        !> Disks and walls.
        integer :: n_disks = 0, n_walls = 0
        !> Stored states (dynamic) or modes (modal).
        integer :: n_states = 0
        !> Their times [s] (dynamic) or mode numbers (modal).
        real(wp), allocatable :: times(:)
    end type survey_t

    abstract interface
        !> The grid of one part at state (mode) k (0: static).
        subroutine grid_iface(x, s, k, part)
            import :: xdmf_file_t, survey_t
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
            !> What the results file holds.
            type(survey_t), intent(in) :: s
            !> State or mode (0: static).
            integer, intent(in) :: k
            !> Name of the part.
            character(len=*), intent(in) :: part
        end subroutine grid_iface
    end interface

contains

    !> Write the XDMF file `path` describing the open results file `file`.
    !>
    !> The results file is read first, whole (`survey`); what follows writes the XDMF file alone.
    subroutine write_results_xdmf(file, path, h5_name, error, results_read)
        !> The results file (open; every output written).
        type(h5_file_t), intent(in) :: file
        !> XDMF file to write.
        character(len=*), intent(in) :: path
        !> Name of the HDF5 file as seen from the XDMF file's folder (its final name).
        character(len=*), intent(in) :: h5_name
        !> Set on a read failure, an inconsistent file, or when the XDMF file cannot be written.
        type(error_t), allocatable, intent(out) :: error
        !> Whether the results file was read and found consistent: an error is then one of the
        !> XDMF file itself (it cannot be created or written: a full disk, a quota, a file size
        !> limit), which says nothing against the results file.
        logical, intent(out) :: results_read
        type(survey_t) :: s
        type(xdmf_file_t) :: x
        integer :: k
        results_read = .false.
        call survey(file, s, error)
        if (allocated(error)) return
        results_read = .true.
        call x%open(path, h5_name, error)
        if (allocated(error)) return
        if (s%beam) call part(beam_grid, 'beam')
        if (s%continuum) call part(continuum_grid, 'continuum')
        if (s%disks) call part(disks_grid, 'disks')
        if (s%walls) call part(walls_grid, 'walls')
        call x%close(error)
    contains
        !> One part: a grid (static), or a temporal collection named after the part with one
        !> grid per stored state (mode).
        subroutine part(grid, name)
            procedure(grid_iface) :: grid
            character(len=*), intent(in) :: name
            if (s%analysis == 'static') then
                call grid(x, s, 0, name)
                return
            end if
            call x%begin_collection(name, 'Temporal')
            do k = 1, s%n_states
                call grid(x, s, k, name)
            end do
            call x%end_grid()
        end subroutine part
    end subroutine write_results_xdmf

    !> Parts, sizes and stored times (mode numbers) of the results file; an error when a
    !> series has fewer records than the times.
    subroutine survey(file, s, error)
        type(h5_file_t), intent(in) :: file
        type(survey_t), intent(out) :: s
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:), kinds(:)
        integer :: k
        type(element_slot_t) :: slot
        call file%read_attribute('/', 'analysis', s%analysis, error)
        if (allocated(error)) return
        s%beam = file%exists('/fem/mesh/coordinates')
        s%continuum = file%exists('/continuum/mesh/coordinates')
        s%disks = file%exists('/dem/position')
        s%walls = file%exists('/dem/walls/position')
        if (s%beam) then
            call shape_of(file, '/fem/mesh/coordinates', d, error)
            if (allocated(error)) return
            s%beam_nodes = d(1)
            call shape_of(file, '/fem/mesh/connectivity', d, error)
            if (allocated(error)) return
            s%beam_elements = d(1)
        end if
        if (s%continuum) then
            call shape_of(file, '/continuum/mesh/coordinates', d, error)
            if (allocated(error)) return
            s%mesh_nodes = d(1)
            call shape_of(file, '/continuum/mesh/kind', d, error)
            if (allocated(error)) return
            s%mesh_elements = d(1)
            s%mesh_material = file%exists('/continuum/mesh/material')
            s%static_reactions = file%exists('/continuum/static/reactions')
            if (s%analysis == 'static') then
                s%stress_measures = file%exists('/continuum/static/stress_zz') .and. &
                                    file%exists('/continuum/static/von_mises')
            else
                s%stress_measures = file%exists('/continuum/stress_zz') .and. file%exists('/continuum/von_mises')
            end if
            call shape_of(file, '/continuum/mesh/topology', s%topology_dims, error)
            if (allocated(error)) return
            if (size(s%topology_dims) == 1) then
                s%topology = 'Mixed'
            else
                ! One kind of element: its topology, from the kind id of the first element.
                call file%read_dataset('/continuum/mesh/kind', kinds, error)
                if (allocated(error)) return
                if (size(kinds) > 0) call new_element(kinds(1), slot)
                if (.not. allocated(slot%element)) then
                    call make_error(error, 'XDMF file: /continuum/mesh/kind holds no known element kind')
                    return
                end if
                s%topology = slot%element%xdmf_topology()
            end if
        end if
        if (s%disks) then
            call shape_of(file, '/dem/particles/radius', d, error)
            if (allocated(error)) return
            s%n_disks = d(1)
        end if
        if (s%walls) then
            call shape_of(file, '/dem/walls/material', d, error)
            if (allocated(error)) return
            s%n_walls = d(1)
        end if
        select case (s%analysis)
        case ('static')
            s%n_states = 1
        case ('modal')
            if (s%beam) call shape_of(file, '/modal/omega', d, error)
            if (s%continuum) call shape_of(file, '/continuum/modal/omega', d, error)
            if (allocated(error)) return
            s%n_states = d(1)
            s%times = [(real(k, wp), k=1, s%n_states)]
        case default
            if (s%beam) then
                call file%read_dataset('/fem/time', s%times, error)
            else if (s%continuum) then
                call file%read_dataset('/continuum/time', s%times, error)
            else
                call file%read_dataset('/dem/time', s%times, error)
            end if
            if (allocated(error)) return
            s%n_states = size(s%times)
            if (s%beam) call check_records(file, '/fem/displacement', s%n_states, error)
            if (s%continuum .and. .not. allocated(error)) &
                call check_records(file, '/continuum/displacement', s%n_states, error)
            if (s%stress_measures .and. .not. allocated(error)) &
                call check_records(file, '/continuum/stress_zz', s%n_states, error)
            if (s%stress_measures .and. .not. allocated(error)) &
                call check_records(file, '/continuum/von_mises', s%n_states, error)
            if (s%disks .and. .not. allocated(error)) call check_records(file, '/dem/position', s%n_states, error)
            if (s%walls .and. .not. allocated(error)) call check_records(file, '/dem/walls/position', s%n_states, error)
        end select
    end subroutine survey

    !> The beam's nodes as a polyline grid with the fields of state (mode) k (0: static).
    subroutine beam_grid(x, s, k, part)
        type(xdmf_file_t), intent(inout) :: x
        type(survey_t), intent(in) :: s
        integer, intent(in) :: k
        !> Name of the part.
        character(len=*), intent(in) :: part
        integer :: n
        n = s%beam_nodes
        call begin_part(x, s, part, k)
        call x%topology('Polyline', s%beam_elements, &
                        xdmf_whole('/fem/mesh/connectivity', [s%beam_elements, 2], is_integer=.true.), base_offset=1)
        call x%geometry('XY', xdmf_whole('/fem/mesh/coordinates', [n, 2]))
        call x%attribute('node_id', 'Scalar', 'Node', xdmf_whole('/fem/mesh/node_id', [n], is_integer=.true.))
        select case (s%analysis)
        case ('static')
            call x%attribute('displacement', 'Vector', 'Node', xdmf_slab('/static/displacement', [n, 3], [0, 0], [n, 2]))
            call x%attribute('rotation', 'Scalar', 'Node', xdmf_slab('/static/displacement', [n, 3], [0, 2], [n, 1]))
            call x%attribute('reaction', 'Vector', 'Node', xdmf_slab('/static/reactions', [n, 3], [0, 0], [n, 2]))
            call x%attribute('reaction_moment', 'Scalar', 'Node', xdmf_slab('/static/reactions', [n, 3], [0, 2], [n, 1]))
        case ('modal')
            call x%attribute('mode_shape', 'Vector', 'Node', record('/modal/shapes', s%n_states, n, 0, 2))
            call x%attribute('mode_rotation', 'Scalar', 'Node', record('/modal/shapes', s%n_states, n, 2, 1))
        case default
            call x%attribute('displacement', 'Vector', 'Node', record('/fem/displacement', s%n_states, n, 0, 2))
            call x%attribute('rotation', 'Scalar', 'Node', record('/fem/displacement', s%n_states, n, 2, 1))
            call x%attribute('velocity', 'Vector', 'Node', record('/fem/velocity', s%n_states, n, 0, 2))
            call x%attribute('angular_velocity', 'Scalar', 'Node', record('/fem/velocity', s%n_states, n, 2, 1))
            call x%attribute('acceleration', 'Vector', 'Node', record('/fem/acceleration', s%n_states, n, 0, 2))
        end select
        call x%end_grid()
    contains
        !> Columns c .. c + m - 1 of record k of a (records, n, 3) series.
        function record(dataset, records, n, c, m) result(item)
            character(len=*), intent(in) :: dataset
            integer, intent(in) :: records, n, c, m
            type(xdmf_item_t) :: item
            item = xdmf_slab(dataset, [records, n, 3], [k - 1, 0, c], [1, n, m])
        end function record
    end subroutine beam_grid

    !> The continuum's mesh with the fields of state (mode) k (0: static).
    subroutine continuum_grid(x, s, k, part)
        type(xdmf_file_t), intent(inout) :: x
        type(survey_t), intent(in) :: s
        integer, intent(in) :: k
        !> Name of the part.
        character(len=*), intent(in) :: part
        ! the stress components as three scalars (a 3-vector would be coloured by its
        ! "Magnitude", which is no stress measure)
        character(len=*), parameter :: stress_names(3) = ['sigma_xx', 'sigma_yy', 'sigma_xy']
        integer :: n, e, c
        n = s%mesh_nodes
        e = s%mesh_elements
        call begin_part(x, s, part, k)
        call x%topology(s%topology, e, xdmf_whole('/continuum/mesh/topology', s%topology_dims, is_integer=.true.))
        call x%geometry('XY', xdmf_whole('/continuum/mesh/coordinates', [n, 2]))
        if (s%mesh_material) &
            call x%attribute('material', 'Scalar', 'Cell', xdmf_whole('/continuum/mesh/material', [e], is_integer=.true.))
        select case (s%analysis)
        case ('static')
            call x%attribute('displacement', 'Vector', 'Node', xdmf_whole('/continuum/static/displacement', [n, 2]))
            if (s%static_reactions) &
                call x%attribute('reaction', 'Vector', 'Node', xdmf_whole('/continuum/static/reactions', [n, 2]))
            do c = 1, 3
                call x%attribute(stress_names(c), 'Scalar', 'Cell', &
                                 xdmf_slab('/continuum/static/stress', [e, 3], [0, c - 1], [e, 1]))
            end do
            if (s%stress_measures) then
                call x%attribute('sigma_zz', 'Scalar', 'Cell', xdmf_whole('/continuum/static/stress_zz', [e]))
                call x%attribute('von_mises', 'Scalar', 'Cell', xdmf_whole('/continuum/static/von_mises', [e]))
            end if
        case ('modal')
            call x%attribute('mode_shape', 'Vector', 'Node', &
                             xdmf_slab('/continuum/modal/shapes', [s%n_states, n, 2], [k - 1, 0, 0], [1, n, 2]))
        case default
            call x%attribute('displacement', 'Vector', 'Node', &
                             xdmf_slab('/continuum/displacement', [s%n_states, n, 2], [k - 1, 0, 0], [1, n, 2]))
            call x%attribute('velocity', 'Vector', 'Node', &
                             xdmf_slab('/continuum/velocity', [s%n_states, n, 2], [k - 1, 0, 0], [1, n, 2]))
            do c = 1, 3
                call x%attribute(stress_names(c), 'Scalar', 'Cell', &
                                 xdmf_slab('/continuum/stress', [s%n_states, e, 3], [k - 1, 0, c - 1], [1, e, 1]))
            end do
            if (s%stress_measures) then
                call x%attribute('sigma_zz', 'Scalar', 'Cell', &
                                 xdmf_slab('/continuum/stress_zz', [s%n_states, e], [k - 1, 0], [1, e]))
                call x%attribute('von_mises', 'Scalar', 'Cell', &
                                 xdmf_slab('/continuum/von_mises', [s%n_states, e], [k - 1, 0], [1, e]))
            end if
        end select
        call x%end_grid()
    end subroutine continuum_grid

    !> The disks of state k as points (their centres) with radius, material, velocity,
    !> rotation and angular velocity (ParaView: Glyph, 2D disk or sphere, scaled by "radius",
    !> factor 2 for the diameter).
    subroutine disks_grid(x, s, k, part)
        type(xdmf_file_t), intent(inout) :: x
        type(survey_t), intent(in) :: s
        integer, intent(in) :: k
        !> Name of the part.
        character(len=*), intent(in) :: part
        integer :: n, r
        n = s%n_disks
        r = s%n_states
        call begin_part(x, s, part, k)
        call x%topology('Polyvertex', n)
        call x%geometry('XY', xdmf_slab('/dem/position', [r, n, 3], [k - 1, 0, 0], [1, n, 2]))
        call x%attribute('radius', 'Scalar', 'Node', xdmf_whole('/dem/particles/radius', [n]))
        call x%attribute('material', 'Scalar', 'Node', xdmf_whole('/dem/particles/material', [n], is_integer=.true.))
        call x%attribute('velocity', 'Vector', 'Node', xdmf_slab('/dem/velocity', [r, n, 3], [k - 1, 0, 0], [1, n, 2]))
        call x%attribute('rotation', 'Scalar', 'Node', xdmf_slab('/dem/position', [r, n, 3], [k - 1, 0, 2], [1, n, 1]))
        call x%attribute('angular_velocity', 'Scalar', 'Node', &
                         xdmf_slab('/dem/velocity', [r, n, 3], [k - 1, 0, 2], [1, n, 1]))
        call x%end_grid()
    end subroutine disks_grid

    !> The walls of state k as segments (x1 y1 x2 y2 of each wall: two points), with their
    !> material.
    subroutine walls_grid(x, s, k, part)
        type(xdmf_file_t), intent(inout) :: x
        type(survey_t), intent(in) :: s
        integer, intent(in) :: k
        !> Name of the part.
        character(len=*), intent(in) :: part
        integer :: n
        n = s%n_walls
        call begin_part(x, s, part, k)
        call x%topology('Polyline', n)
        call x%geometry('XY', xdmf_slab('/dem/walls/position', [s%n_states, n, 4], [k - 1, 0, 0], [1, n, 4]))
        call x%attribute('material', 'Scalar', 'Cell', xdmf_whole('/dem/walls/material', [n], is_integer=.true.))
        call x%end_grid()
    end subroutine walls_grid

    !> Open a part's uniform grid: named after the part (static), the mode or the state, at
    !> its time (the mode number in a modal analysis).
    subroutine begin_part(x, s, part, k)
        type(xdmf_file_t), intent(inout) :: x
        type(survey_t), intent(in) :: s
        character(len=*), intent(in) :: part
        integer, intent(in) :: k
        if (k == 0) then
            call x%begin_grid(part)
        else if (s%analysis == 'modal') then
            call x%begin_grid('mode '//to_str(k), s%times(k))
        else
            call x%begin_grid('state '//to_str(k - 1), s%times(k))
        end if
    end subroutine begin_part

    !> Shape of a dataset in XDMF (h5py) order.
    subroutine shape_of(file, path, dims, error)
        type(h5_file_t), intent(in) :: file
        character(len=*), intent(in) :: path
        integer, allocatable, intent(out) :: dims(:)
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: f(:)
        call file%dataset_shape(path, f, error)
        if (allocated(error)) return
        dims = f(size(f):1:-1)
    end subroutine shape_of

    !> Error unless the series `path` has `n` records (the stored times).
    subroutine check_records(file, path, n, error)
        type(h5_file_t), intent(in) :: file
        character(len=*), intent(in) :: path
        integer, intent(in) :: n
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:)
        call shape_of(file, path, d, error)
        if (allocated(error)) return
        if (d(1) /= n) call make_error(error, 'XDMF file: '//path//' holds '//to_str(d(1))//' records, the stored '// &
                                       'times '//to_str(n))
    end subroutine check_records
end module driver_results_xdmf
