!> The beam (/fem/mesh) in the XDMF file (driver_results_xdmf): a polyline grid "beam" of the
!> nodes (reference coordinates) with their ids and, per analysis, the displacement (x, y;
!> ParaView adds z = 0, so that Warp By Vector applies) and rotation with the reactions
!> (static), the mode shapes (modal), or the displacement, rotation, velocity, angular velocity
!> and acceleration of each stored state (dynamic).
module driver_xdmf_beam
    use core_error, only: error_t
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t, xdmf_item_t, xdmf_whole, xdmf_slab
    use driver_xdmf_series, only: xdmf_series_t
    use driver_xdmf_part, only: xdmf_part_t, shape_of, require_records
    implicit none
    private
    public :: beam_static_xdmf_t, beam_modal_xdmf_t, beam_dynamic_xdmf_t

    !> The beam's mesh, common to every analysis.
    type, abstract, extends(xdmf_part_t) :: beam_xdmf_t
        !> Nodes.
        integer :: nodes = 0
        !> Elements.
        integer :: elements = 0
    contains
        procedure :: name => beam_name
        procedure :: survey => beam_survey
        procedure :: write_grid => beam_write_grid
        !> The fields of the analysis at state (mode) k.
        procedure(fields_iface), deferred :: write_fields
    end type beam_xdmf_t

    abstract interface
        !> Write the fields of the beam at state (mode) k into the open grid.
        subroutine fields_iface(self, x, series, k)
            import :: beam_xdmf_t, xdmf_file_t, xdmf_series_t
            !> The beam (surveyed).
            class(beam_xdmf_t), intent(in) :: self
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
            !> The stored states.
            class(xdmf_series_t), intent(in) :: series
            !> State (mode).
            integer, intent(in) :: k
        end subroutine fields_iface
    end interface

    !> The beam of a static analysis: displacement, rotation, reaction force and moment.
    type, extends(beam_xdmf_t) :: beam_static_xdmf_t
    contains
        procedure :: analysis => static_analysis
        procedure :: write_fields => static_fields
    end type beam_static_xdmf_t

    !> The beam of a modal analysis: the shape and rotation of each mode.
    type, extends(beam_xdmf_t) :: beam_modal_xdmf_t
    contains
        procedure :: analysis => modal_analysis
        procedure :: states_dataset => modal_states
        procedure :: write_fields => modal_fields
    end type beam_modal_xdmf_t

    !> The beam of a dynamic analysis: displacement, rotation, velocity, angular velocity and
    !> acceleration of each stored state.
    type, extends(beam_xdmf_t) :: beam_dynamic_xdmf_t
    contains
        procedure :: analysis => dynamic_analysis
        procedure :: states_dataset => dynamic_states
        procedure :: check_records => dynamic_records
        procedure :: write_fields => dynamic_fields
    end type beam_dynamic_xdmf_t

contains

    !> 'beam'.
    function beam_name(self) result(name)
        !> The part.
        class(beam_xdmf_t), intent(in) :: self
        !> Name of the part.
        character(len=:), allocatable :: name
        name = 'beam'
    end function beam_name

    !> Whether the results file has a beam (/fem/mesh), and its nodes and elements.
    subroutine beam_survey(self, file, found, error)
        !> The part.
        class(beam_xdmf_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Whether the file has a beam.
        logical, intent(out) :: found
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:)
        found = file%exists('/fem/mesh/coordinates')
        if (.not. found) return
        call shape_of(file, '/fem/mesh/coordinates', d, error)
        if (allocated(error)) return
        self%nodes = d(1)
        call shape_of(file, '/fem/mesh/connectivity', d, error)
        if (allocated(error)) return
        self%elements = d(1)
    end subroutine beam_survey

    !> The beam's nodes as a polyline grid with their ids and the fields of state (mode) k.
    subroutine beam_write_grid(self, x, series, k)
        !> The part (surveyed).
        class(beam_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states.
        class(xdmf_series_t), intent(in) :: series
        !> State (mode).
        integer, intent(in) :: k
        integer :: n
        n = self%nodes
        call series%begin_state(x, self%name(), k)
        call x%topology('Polyline', self%elements, &
                        xdmf_whole('/fem/mesh/connectivity', [self%elements, 2], is_integer=.true.), base_offset=1)
        call x%geometry('XY', xdmf_whole('/fem/mesh/coordinates', [n, 2]))
        call x%attribute('node_id', 'Scalar', 'Node', xdmf_whole('/fem/mesh/node_id', [n], is_integer=.true.))
        call self%write_fields(x, series, k)
        call x%end_grid()
    end subroutine beam_write_grid

    !> 'static'.
    function static_analysis(self) result(name)
        !> The part.
        class(beam_static_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'static'
    end function static_analysis

    !> Displacement, rotation, reaction force and moment (/static).
    subroutine static_fields(self, x, series, k)
        !> The part (surveyed).
        class(beam_static_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states (one).
        class(xdmf_series_t), intent(in) :: series
        !> State (one).
        integer, intent(in) :: k
        integer :: n
        n = self%nodes
        call x%attribute('displacement', 'Vector', 'Node', xdmf_slab('/static/displacement', [n, 3], [0, 0], [n, 2]))
        call x%attribute('rotation', 'Scalar', 'Node', xdmf_slab('/static/displacement', [n, 3], [0, 2], [n, 1]))
        call x%attribute('reaction', 'Vector', 'Node', xdmf_slab('/static/reactions', [n, 3], [0, 0], [n, 2]))
        call x%attribute('reaction_moment', 'Scalar', 'Node', xdmf_slab('/static/reactions', [n, 3], [0, 2], [n, 1]))
    end subroutine static_fields

    !> 'modal'.
    function modal_analysis(self) result(name)
        !> The part.
        class(beam_modal_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'modal'
    end function modal_analysis

    !> The beam's eigenvalues.
    function modal_states(self) result(path)
        !> The part.
        class(beam_modal_xdmf_t), intent(in) :: self
        !> Dataset path.
        character(len=:), allocatable :: path
        path = '/modal/omega'
    end function modal_states

    !> Shape and rotation of mode k.
    subroutine modal_fields(self, x, series, k)
        !> The part (surveyed).
        class(beam_modal_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The modes.
        class(xdmf_series_t), intent(in) :: series
        !> Mode.
        integer, intent(in) :: k
        call x%attribute('mode_shape', 'Vector', 'Node', record('/modal/shapes', series%n_states, self%nodes, k, 0, 2))
        call x%attribute('mode_rotation', 'Scalar', 'Node', record('/modal/shapes', series%n_states, self%nodes, k, 2, 1))
    end subroutine modal_fields

    !> 'dynamic'.
    function dynamic_analysis(self) result(name)
        !> The part.
        class(beam_dynamic_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'dynamic'
    end function dynamic_analysis

    !> The beam's stored times.
    function dynamic_states(self) result(path)
        !> The part.
        class(beam_dynamic_xdmf_t), intent(in) :: self
        !> Dataset path.
        character(len=:), allocatable :: path
        path = '/fem/time'
    end function dynamic_states

    !> Error unless /fem/displacement holds the stored states.
    subroutine dynamic_records(self, file, n, error)
        !> The part.
        class(beam_dynamic_xdmf_t), intent(in) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Stored states.
        integer, intent(in) :: n
        !> Set on a read failure or another number of records.
        type(error_t), allocatable, intent(out) :: error
        call require_records(file, '/fem/displacement', n, error)
    end subroutine dynamic_records

    !> Displacement, rotation, velocity, angular velocity and acceleration of state k.
    subroutine dynamic_fields(self, x, series, k)
        !> The part (surveyed).
        class(beam_dynamic_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states.
        class(xdmf_series_t), intent(in) :: series
        !> State.
        integer, intent(in) :: k
        integer :: n, r
        n = self%nodes
        r = series%n_states
        call x%attribute('displacement', 'Vector', 'Node', record('/fem/displacement', r, n, k, 0, 2))
        call x%attribute('rotation', 'Scalar', 'Node', record('/fem/displacement', r, n, k, 2, 1))
        call x%attribute('velocity', 'Vector', 'Node', record('/fem/velocity', r, n, k, 0, 2))
        call x%attribute('angular_velocity', 'Scalar', 'Node', record('/fem/velocity', r, n, k, 2, 1))
        call x%attribute('acceleration', 'Vector', 'Node', record('/fem/acceleration', r, n, k, 0, 2))
    end subroutine dynamic_fields

    !> Columns c .. c + m - 1 of record k of a (records, n, 3) series.
    function record(dataset, records, n, k, c, m) result(item)
        !> Dataset path.
        character(len=*), intent(in) :: dataset
        !> Records of the series.
        integer, intent(in) :: records
        !> Nodes.
        integer, intent(in) :: n
        !> Record (1-based).
        integer, intent(in) :: k
        !> First column (0-based).
        integer, intent(in) :: c
        !> Number of columns.
        integer, intent(in) :: m
        !> The hyperslab.
        type(xdmf_item_t) :: item
        item = xdmf_slab(dataset, [records, n, 3], [k - 1, 0, c], [1, n, m])
    end function record
end module driver_xdmf_beam
