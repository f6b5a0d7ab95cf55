!> The states an XDMF file (driver_results_xdmf) steps through, one family per analysis: a
!> static run has one state and a grid per part named after the part; a modal run a temporal
!> collection per part with one grid per mode, at the mode number as its time (ParaView's time
!> steps through the modes); a dynamic run a temporal collection per part over the stored
!> times. The parts (driver_xdmf_part) open their grids through `begin_state` and so need not
!> know the analysis.
module driver_xdmf_series
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t
    implicit none
    private
    public :: xdmf_series_t, new_series

    !> The stored states (modes) of an analysis and how a part's grids are named and nested.
    type, abstract :: xdmf_series_t
        !> Number of stored states (modes); one in a static analysis.
        integer :: n_states = 0
        !> Their times [s] (dynamic) or mode numbers (modal); unallocated when static.
        real(wp), allocatable :: times(:)
    contains
        !> The analysis, as the results file's root attribute `analysis` names it.
        procedure(analysis_iface), deferred :: analysis
        !> Count (and read the times of) the stored states from the results file.
        procedure(survey_iface), deferred :: survey
        !> Open what holds the grids of one part.
        procedure(part_iface), deferred :: begin_part
        !> Close what `begin_part` opened.
        procedure(end_iface), deferred :: end_part
        !> Open the grid of one part at state (mode) k.
        procedure(state_iface), deferred :: begin_state
    end type xdmf_series_t

    abstract interface
        !> The analysis of the series ('static', 'modal', 'dynamic').
        function analysis_iface(self) result(name)
            import :: xdmf_series_t
            !> The series.
            class(xdmf_series_t), intent(in) :: self
            !> Name of the analysis.
            character(len=:), allocatable :: name
        end function analysis_iface

        !> Count the stored states from the dataset `path` of the results file.
        subroutine survey_iface(self, file, path, error)
            import :: xdmf_series_t, h5_file_t, error_t
            !> The series.
            class(xdmf_series_t), intent(inout) :: self
            !> The results file (open).
            type(h5_file_t), intent(in) :: file
            !> The dataset of the states: the times or the eigenvalues ('' when no part has one).
            character(len=*), intent(in) :: path
            !> Set on a read failure or when no dataset holds the states.
            type(error_t), allocatable, intent(out) :: error
        end subroutine survey_iface

        !> Open what holds the grids of the part `name`.
        subroutine part_iface(self, x, name)
            import :: xdmf_series_t, xdmf_file_t
            !> The series.
            class(xdmf_series_t), intent(in) :: self
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
            !> Name of the part.
            character(len=*), intent(in) :: name
        end subroutine part_iface

        !> Close what `begin_part` opened.
        subroutine end_iface(self, x)
            import :: xdmf_series_t, xdmf_file_t
            !> The series.
            class(xdmf_series_t), intent(in) :: self
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
        end subroutine end_iface

        !> Open the uniform grid of the part `name` at state (mode) k.
        subroutine state_iface(self, x, name, k)
            import :: xdmf_series_t, xdmf_file_t
            !> The series.
            class(xdmf_series_t), intent(in) :: self
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
            !> Name of the part.
            character(len=*), intent(in) :: name
            !> State (mode), 1 .. n_states.
            integer, intent(in) :: k
        end subroutine state_iface
    end interface

    !> A static analysis: one grid per part, named after the part.
    type, extends(xdmf_series_t) :: static_series_t
    contains
        procedure :: analysis => static_analysis
        procedure :: survey => static_survey
        procedure :: begin_part => static_begin_part
        procedure :: end_part => static_end_part
        procedure :: begin_state => static_begin_state
    end type static_series_t

    !> States in time: a temporal collection per part, named after the part.
    type, abstract, extends(xdmf_series_t) :: temporal_series_t
    contains
        procedure :: begin_part => temporal_begin_part
        procedure :: end_part => temporal_end_part
    end type temporal_series_t

    !> A modal analysis: one grid per mode ('mode k'), at the mode number as its time.
    type, extends(temporal_series_t) :: modal_series_t
    contains
        procedure :: analysis => modal_analysis
        procedure :: survey => modal_survey
        procedure :: begin_state => modal_begin_state
    end type modal_series_t

    !> A dynamic analysis: one grid per stored state ('state k', from 0), at its time.
    type, extends(temporal_series_t) :: dynamic_series_t
    contains
        procedure :: analysis => dynamic_analysis
        procedure :: survey => dynamic_survey
        procedure :: begin_state => dynamic_begin_state
    end type dynamic_series_t

contains

    !> The series of the analysis named by the results file ('static', 'modal'; any other:
    !> dynamic).
    subroutine new_series(analysis, series)
        !> The results file's root attribute `analysis`.
        character(len=*), intent(in) :: analysis
        !> The series, not surveyed yet.
        class(xdmf_series_t), allocatable, intent(out) :: series
        select case (analysis)
        case ('static')
            allocate (static_series_t :: series)
        case ('modal')
            allocate (modal_series_t :: series)
        case default
            allocate (dynamic_series_t :: series)
        end select
    end subroutine new_series

    !> 'static'.
    function static_analysis(self) result(name)
        !> The series.
        class(static_series_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'static'
    end function static_analysis

    !> One state.
    subroutine static_survey(self, file, path, error)
        !> The series.
        class(static_series_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Unused (a static run has one state).
        character(len=*), intent(in) :: path
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
        self%n_states = 1
    end subroutine static_survey

    !> Nothing: the part has a single grid.
    subroutine static_begin_part(self, x, name)
        !> The series.
        class(static_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> Name of the part.
        character(len=*), intent(in) :: name
    end subroutine static_begin_part

    !> Nothing: the part has a single grid.
    subroutine static_end_part(self, x)
        !> The series.
        class(static_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
    end subroutine static_end_part

    !> The grid named after the part, without a time.
    subroutine static_begin_state(self, x, name, k)
        !> The series.
        class(static_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> Name of the part.
        character(len=*), intent(in) :: name
        !> Unused (one state).
        integer, intent(in) :: k
        call x%begin_grid(name)
    end subroutine static_begin_state

    !> A temporal collection named after the part.
    subroutine temporal_begin_part(self, x, name)
        !> The series.
        class(temporal_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> Name of the part.
        character(len=*), intent(in) :: name
        call x%begin_collection(name, 'Temporal')
    end subroutine temporal_begin_part

    !> Close the temporal collection.
    subroutine temporal_end_part(self, x)
        !> The series.
        class(temporal_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        call x%end_grid()
    end subroutine temporal_end_part

    !> 'modal'.
    function modal_analysis(self) result(name)
        !> The series.
        class(modal_series_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'modal'
    end function modal_analysis

    !> As many modes as the eigenvalues `path` holds, numbered 1, 2, ... as their times.
    subroutine modal_survey(self, file, path, error)
        !> The series.
        class(modal_series_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> The eigenvalues (angular frequencies) of a part.
        character(len=*), intent(in) :: path
        !> Set on a read failure or when no part has eigenvalues.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:)
        integer :: k
        if (len(path) == 0) then
            call make_error(error, 'XDMF file: the results file holds no part with modes')
            return
        end if
        call file%dataset_shape(path, d, error)
        if (allocated(error)) return
        self%n_states = d(size(d))
        self%times = [(real(k, wp), k=1, self%n_states)]
    end subroutine modal_survey

    !> The grid 'mode k' at the time k.
    subroutine modal_begin_state(self, x, name, k)
        !> The series.
        class(modal_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> Name of the part (the collection's).
        character(len=*), intent(in) :: name
        !> Mode.
        integer, intent(in) :: k
        call x%begin_grid('mode '//to_str(k), self%times(k))
    end subroutine modal_begin_state

    !> 'dynamic'.
    function dynamic_analysis(self) result(name)
        !> The series.
        class(dynamic_series_t), intent(in) :: self
        !> Name of the analysis.
        character(len=:), allocatable :: name
        name = 'dynamic'
    end function dynamic_analysis

    !> The stored times `path`.
    subroutine dynamic_survey(self, file, path, error)
        !> The series.
        class(dynamic_series_t), intent(inout) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> The stored times of a part.
        character(len=*), intent(in) :: path
        !> Set on a read failure or when no part has stored times.
        type(error_t), allocatable, intent(out) :: error
        if (len(path) == 0) then
            call make_error(error, 'XDMF file: the results file holds no part with stored times')
            return
        end if
        call file%read_dataset(path, self%times, error)
        if (allocated(error)) return
        self%n_states = size(self%times)
    end subroutine dynamic_survey

    !> The grid 'state k - 1' at its time.
    subroutine dynamic_begin_state(self, x, name, k)
        !> The series.
        class(dynamic_series_t), intent(in) :: self
        !> The XDMF file.
        type(xdmf_file_t), intent(inout) :: x
        !> Name of the part (the collection's).
        character(len=*), intent(in) :: name
        !> Stored state.
        integer, intent(in) :: k
        call x%begin_grid('state '//to_str(k - 1), self%times(k))
    end subroutine dynamic_begin_state
end module driver_xdmf_series
