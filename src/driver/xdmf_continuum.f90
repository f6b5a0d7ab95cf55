!> The 2D continuum (/continuum/mesh) in the XDMF file (driver_results_xdmf): its mesh
!> "continuum" with each element's material and, per analysis, the displacement, the static
!> reactions and the centre stresses (static), the mode shapes (modal), or the displacement,
!> velocity and centre stresses of each stored state (dynamic). The stresses are the scalars
!> sigma_xx, sigma_yy, sigma_xy, with sigma_zz and the von Mises stress (von_mises) when stored:
!> a file of an earlier build, continued by a restart, lacks them, as it may lack the
!> materials and the static reactions.
module driver_xdmf_continuum
    use core_error, only: error_t, make_error
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t, xdmf_whole, xdmf_slab
    use fem_element_registry, only: element_slot_t, new_element
    use driver_xdmf_series, only: xdmf_series_t
    use driver_xdmf_part, only: xdmf_part_t, shape_of, require_records
    implicit none
    private
    public :: continuum_static_xdmf_t, continuum_modal_xdmf_t, continuum_dynamic_xdmf_t

    ! the stress components as three scalars (a 3-vector would be coloured by its
    ! "Magnitude", which is no stress measure)
    character(len=*), parameter :: stress_names(3) = ['sigma_xx', 'sigma_yy', 'sigma_xy']

    !> The continuum's mesh, common to every analysis.
    type, abstract, extends(xdmf_part_t) :: continuum_xdmf_t
        !> Nodes.
        integer :: nodes = 0
        !> Elements.
        integer :: elements = 0
        !> Shape of /continuum/mesh/topology (XDMF order).
        integer, allocatable :: topology_dims(:)
        !> XDMF topology ('Triangle', 'Quadrilateral', 'Mixed').
        character(len=:), allocatable :: topology
        !> Whether /continuum/mesh/material is stored.
        logical :: material = .false.
    contains
        procedure :: name => continuum_name
        procedure :: survey => continuum_survey
        procedure :: write_grid => continuum_write_grid
        !> The fields of the analysis at state (mode) k.
        procedure(fields_iface), deferred :: write_fields
    end type continuum_xdmf_t

    abstract interface
        !> Write the fields of the continuum at state (mode) k into the open grid.
        subroutine fields_iface(self, x, series, k)
            import :: continuum_xdmf_t, xdmf_file_t, xdmf_series_t
            !> The continuum (surveyed).
            class(continuum_xdmf_t), intent(in) :: self
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
            !> The stored states.
            class(xdmf_series_t), intent(in) :: series
            !> State (mode).
            integer, intent(in) :: k
        end subroutine fields_iface
    end interface

    !> The continuum of a static analysis (/continuum/static).
    type, extends(continuum_xdmf_t) :: continuum_static_xdmf_t
        !> Whether the reactions are stored.
        logical :: reactions = .false.
        !> Whether sigma_zz and the von Mises stress are stored.
        logical :: stress_measures = .false.
    contains
        procedure :: analysis => static_analysis
        procedure :: survey => static_survey
        procedure :: write_fields => static_fields
    end type continuum_static_xdmf_t

    !> The continuum of a modal analysis (/continuum/modal).
    type, extends(continuum_xdmf_t) :: continuum_modal_xdmf_t
    contains
        procedure :: analysis => modal_analysis
        procedure :: states_dataset => modal_states
        procedure :: write_fields => modal_fields
    end type continuum_modal_xdmf_t

    !> The continuum of a dynamic analysis (the series of /continuum).
    type, extends(continuum_xdmf_t) :: continuum_dynamic_xdmf_t
        !> Whether the series of sigma_zz and the von Mises stress are stored.
        logical :: stress_measures = .false.
    contains
        procedure :: analysis => dynamic_analysis
        procedure :: survey => dynamic_survey
        procedure :: states_dataset => dynamic_states
        procedure :: check_records => dynamic_records
        procedure :: write_fields => dynamic_fields
    end type continuum_dynamic_xdmf_t

contains

    !> 'continuum'.
    function continuum_name(self) result(name)
        !> The part.
        class(continuum_xdmf_t), intent(in) :: self
        !> Name of the part.
        character(len=:), allocatable :: name
        name = 'continuum'
    end function continuum_name

    !> Whether the results file has a continuum (/continuum/mesh), and its nodes, elements,
    !> topology and materials.
    subroutine continuum_survey(self, file, found, error)
        !> The part.
        class(continuum_xdmf_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Whether the file has a continuum.
        logical, intent(out) :: found
        !> Set on a read failure or an unknown element kind.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:), kinds(:)
        type(element_slot_t) :: slot
        found = file%exists('/continuum/mesh/coordinates')
        if (.not. found) return
        call shape_of(file, '/continuum/mesh/coordinates', d, error)
        if (allocated(error)) return
        self%nodes = d(1)
        call shape_of(file, '/continuum/mesh/kind', d, error)
        if (allocated(error)) return
        self%elements = d(1)
        self%material = file%exists('/continuum/mesh/material')
        call shape_of(file, '/continuum/mesh/topology', self%topology_dims, error)
        if (allocated(error)) return
        if (size(self%topology_dims) == 1) then
            self%topology = 'Mixed'
        else
            ! One kind of element: its topology, from the kind id of the first element.
            call file%read_dataset('/continuum/mesh/kind', kinds, error)
            if (allocated(error)) return
            if (size(kinds) > 0) call new_element(kinds(1), slot)
            if (.not. allocated(slot%element)) then
                call make_error(error, 'XDMF file: /continuum/mesh/kind holds no known element kind')
                return
            end if
            self%topology = slot%element%xdmf_topology()
        end if
    end subroutine continuum_survey

    !> The continuum's mesh with its materials and the fields of state (mode) k.
    subroutine continuum_write_grid(self, x, series, k)
        !> The part (surveyed).
        class(continuum_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states.
        class(xdmf_series_t), intent(in) :: series
        !> State (mode).
        integer, intent(in) :: k
        call series%begin_state(x, self%name(), k)
        call x%topology(self%topology, self%elements, &
                        xdmf_whole('/continuum/mesh/topology', self%topology_dims, is_integer=.true.))
        call x%geometry('XY', xdmf_whole('/continuum/mesh/coordinates', [self%nodes, 2]))
        if (self%material) call x%attribute('material', 'Scalar', 'Cell', &
                                            xdmf_whole('/continuum/mesh/material', [self%elements], is_integer=.true.))
        call self%write_fields(x, series, k)
        call x%end_grid()
    end subroutine continuum_write_grid

    !> 'static'.
    function static_analysis(self) result(name)
        !> The part.
        class(continuum_static_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'static'
    end function static_analysis

    !> The mesh, and whether the reactions and the stress measures are stored.
    subroutine static_survey(self, file, found, error)
        !> The part.
        class(continuum_static_xdmf_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Whether the file has a continuum.
        logical, intent(out) :: found
        !> Set on a read failure or an unknown element kind.
        type(error_t), allocatable, intent(out) :: error
        call continuum_survey(self, file, found, error)
        if (allocated(error) .or. .not. found) return
        self%reactions = file%exists('/continuum/static/reactions')
        self%stress_measures = file%exists('/continuum/static/stress_zz') .and. &
                               file%exists('/continuum/static/von_mises')
    end subroutine static_survey

    !> Displacement, reactions and stresses (/continuum/static).
    subroutine static_fields(self, x, series, k)
        !> The part (surveyed).
        class(continuum_static_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states (one).
        class(xdmf_series_t), intent(in) :: series
        !> State (one).
        integer, intent(in) :: k
        integer :: n, e, c
        n = self%nodes
        e = self%elements
        call x%attribute('displacement', 'Vector', 'Node', xdmf_whole('/continuum/static/displacement', [n, 2]))
        if (self%reactions) &
            call x%attribute('reaction', 'Vector', 'Node', xdmf_whole('/continuum/static/reactions', [n, 2]))
        do c = 1, 3
            call x%attribute(stress_names(c), 'Scalar', 'Cell', &
                             xdmf_slab('/continuum/static/stress', [e, 3], [0, c - 1], [e, 1]))
        end do
        if (self%stress_measures) then
            call x%attribute('sigma_zz', 'Scalar', 'Cell', xdmf_whole('/continuum/static/stress_zz', [e]))
            call x%attribute('von_mises', 'Scalar', 'Cell', xdmf_whole('/continuum/static/von_mises', [e]))
        end if
    end subroutine static_fields

    !> 'modal'.
    function modal_analysis(self) result(name)
        !> The part.
        class(continuum_modal_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'modal'
    end function modal_analysis

    !> The continuum's eigenvalues.
    function modal_states(self) result(path)
        !> The part.
        class(continuum_modal_xdmf_t), intent(in) :: self
        !> Dataset path.
        character(len=:), allocatable :: path
        path = '/continuum/modal/omega'
    end function modal_states

    !> The shape of mode k.
    subroutine modal_fields(self, x, series, k)
        !> The part (surveyed).
        class(continuum_modal_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The modes.
        class(xdmf_series_t), intent(in) :: series
        !> Mode.
        integer, intent(in) :: k
        integer :: n
        n = self%nodes
        call x%attribute('mode_shape', 'Vector', 'Node', &
                         xdmf_slab('/continuum/modal/shapes', [series%n_states, n, 2], [k - 1, 0, 0], [1, n, 2]))
    end subroutine modal_fields

    !> 'dynamic'.
    function dynamic_analysis(self) result(name)
        !> The part.
        class(continuum_dynamic_xdmf_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'dynamic'
    end function dynamic_analysis

    !> The mesh, and whether the series of the stress measures are stored.
    subroutine dynamic_survey(self, file, found, error)
        !> The part.
        class(continuum_dynamic_xdmf_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Whether the file has a continuum.
        logical, intent(out) :: found
        !> Set on a read failure or an unknown element kind.
        type(error_t), allocatable, intent(out) :: error
        call continuum_survey(self, file, found, error)
        if (allocated(error) .or. .not. found) return
        self%stress_measures = file%exists('/continuum/stress_zz') .and. file%exists('/continuum/von_mises')
    end subroutine dynamic_survey

    !> The continuum's stored times.
    function dynamic_states(self) result(path)
        !> The part.
        class(continuum_dynamic_xdmf_t), intent(in) :: self
        !> Dataset path.
        character(len=:), allocatable :: path
        path = '/continuum/time'
    end function dynamic_states

    !> Error unless the displacement (and the stress measures, when stored) hold the stored
    !> states.
    subroutine dynamic_records(self, file, n, error)
        !> The part.
        class(continuum_dynamic_xdmf_t), intent(in) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Stored states.
        integer, intent(in) :: n
        !> Set on a read failure or another number of records.
        type(error_t), allocatable, intent(out) :: error
        call require_records(file, '/continuum/displacement', n, error)
        if (allocated(error) .or. .not. self%stress_measures) return
        call require_records(file, '/continuum/stress_zz', n, error)
        if (allocated(error)) return
        call require_records(file, '/continuum/von_mises', n, error)
    end subroutine dynamic_records

    !> Displacement, velocity and stresses of state k.
    subroutine dynamic_fields(self, x, series, k)
        !> The part (surveyed).
        class(continuum_dynamic_xdmf_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> The stored states.
        class(xdmf_series_t), intent(in) :: series
        !> State.
        integer, intent(in) :: k
        integer :: n, e, r, c
        n = self%nodes
        e = self%elements
        r = series%n_states
        call x%attribute('displacement', 'Vector', 'Node', &
                         xdmf_slab('/continuum/displacement', [r, n, 2], [k - 1, 0, 0], [1, n, 2]))
        call x%attribute('velocity', 'Vector', 'Node', &
                         xdmf_slab('/continuum/velocity', [r, n, 2], [k - 1, 0, 0], [1, n, 2]))
        do c = 1, 3
            call x%attribute(stress_names(c), 'Scalar', 'Cell', &
                             xdmf_slab('/continuum/stress', [r, e, 3], [k - 1, 0, c - 1], [1, e, 1]))
        end do
        if (self%stress_measures) then
            call x%attribute('sigma_zz', 'Scalar', 'Cell', &
                             xdmf_slab('/continuum/stress_zz', [r, e], [k - 1, 0], [1, e]))
            call x%attribute('von_mises', 'Scalar', 'Cell', &
                             xdmf_slab('/continuum/von_mises', [r, e], [k - 1, 0], [1, e]))
        end if
    end subroutine dynamic_fields
end module driver_xdmf_continuum
