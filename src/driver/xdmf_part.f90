!> One part of a run (a beam, a 2D continuum, the disks, the walls) as the XDMF file
!> (driver_results_xdmf) describes it: each kind of part of each analysis is a type that finds
!> itself in the results file, reads the sizes of its data, checks its series and writes its
!> grid at a state. A new model kind adds its types and registers them in
!> driver_results_xdmf; nothing else changes.
module driver_xdmf_part
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    use io_xdmf, only: xdmf_file_t
    use driver_xdmf_series, only: xdmf_series_t
    implicit none
    private
    public :: xdmf_part_t, xdmf_part_slot_t, shape_of, require_records

    !> A part of the results file and its XDMF description.
    type, abstract :: xdmf_part_t
    contains
        !> Name of the part (its temporal collection, or its grid when static).
        procedure(name_iface), deferred :: name
        !> The analysis whose results the part describes (xdmf_series_t%analysis).
        procedure(name_iface), deferred :: analysis
        !> Whether the part is in the results file, and the sizes of its data.
        procedure(survey_iface), deferred :: survey
        !> The dataset counting the states of the part ('' when none: static).
        procedure :: states_dataset => no_states_dataset
        !> Error unless every series of the part holds the stored states.
        procedure :: check_records => no_records
        !> The grid of the part at state (mode) k.
        procedure(grid_iface), deferred :: write_grid
    end type xdmf_part_t

    !> A part in a list of parts.
    type :: xdmf_part_slot_t
        !> The part.
        class(xdmf_part_t), allocatable :: part
    end type xdmf_part_slot_t

    abstract interface
        !> A name of the part.
        function name_iface(self) result(name)
            import :: xdmf_part_t
            !> The part.
            class(xdmf_part_t), intent(in) :: self
            !> The name.
            character(len=:), allocatable :: name
        end function name_iface

        !> Whether the part is in the results file; if so, the sizes of its data.
        subroutine survey_iface(self, file, found, error)
            import :: xdmf_part_t, h5_file_t, error_t
            !> The part.
            class(xdmf_part_t), intent(inout) :: self
            !> The results file (open).
            type(h5_file_t), intent(in) :: file
            !> Whether the part is in the file.
            logical, intent(out) :: found
            !> Set on a read failure or an inconsistent file.
            type(error_t), allocatable, intent(out) :: error
        end subroutine survey_iface

        !> Write the grid of the part at state (mode) k.
        subroutine grid_iface(self, x, series, k)
            import :: xdmf_part_t, xdmf_file_t, xdmf_series_t
            !> The part (surveyed).
            class(xdmf_part_t), intent(in) :: self
            !> The XDMF file.
            type(xdmf_file_t), intent(inout) :: x
            !> The stored states.
            class(xdmf_series_t), intent(in) :: series
            !> State (mode), 1 .. series%n_states.
            integer, intent(in) :: k
        end subroutine grid_iface
    end interface

contains

    !> No dataset counts the states (a static part).
    function no_states_dataset(self) result(path)
        !> The part.
        class(xdmf_part_t), intent(in) :: self
        !> ''.
        character(len=:), allocatable :: path
        path = ''
    end function no_states_dataset

    !> No series to check (a static part).
    subroutine no_records(self, file, n, error)
        !> The part.
        class(xdmf_part_t), intent(in) :: self
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Stored states.
        integer, intent(in) :: n
        !> Never set.
        type(error_t), allocatable, intent(out) :: error
    end subroutine no_records

    !> Shape of a dataset in XDMF (h5py) order.
    subroutine shape_of(file, path, dims, error)
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Dataset path.
        character(len=*), intent(in) :: path
        !> Its shape, XDMF order.
        integer, allocatable, intent(out) :: dims(:)
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: f(:)
        call file%dataset_shape(path, f, error)
        if (allocated(error)) return
        dims = f(size(f):1:-1)
    end subroutine shape_of

    !> Error unless the series `path` has `n` records (the stored times).
    subroutine require_records(file, path, n, error)
        !> The results file (open).
        type(h5_file_t), intent(in) :: file
        !> Dataset path of the series.
        character(len=*), intent(in) :: path
        !> Stored states.
        integer, intent(in) :: n
        !> Set on a read failure or another number of records.
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: d(:)
        call shape_of(file, path, d, error)
        if (allocated(error)) return
        if (d(1) /= n) call make_error(error, 'XDMF file: '//path//' holds '//to_str(d(1))//' records, the stored '// &
                                       'times '//to_str(n))
    end subroutine require_records
end module driver_xdmf_part
