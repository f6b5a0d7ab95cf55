!> A family's state (core_state) in a group of a checkpoint (driver_checkpoint): each named
!> integer is an attribute of the group, each named array a dataset in it (an empty array is
!> not written, and reads back as the deck's empty array). The group is created by the first
!> dataset written into it, so that a state without arrays leaves no group (the solve method's
!> '/dem/block').
module driver_checkpoint_state
    use core_kinds, only: wp
    use core_error, only: error_t
    use core_state, only: state_sink_t, state_source_t
    use io_hdf5_file, only: h5_file_t
    use driver_checkpoint_values, only: get_r1, require_range, damaged
    implicit none
    private
    public :: h5_state_sink_t, h5_state_source_t

    !> A group of a checkpoint being written.
    type, extends(state_sink_t) :: h5_state_sink_t
        !> The checkpoint (open for writing).
        type(h5_file_t), pointer :: file => null()
        !> The group ('/fe').
        character(len=:), allocatable :: group
    contains
        procedure :: put_integer => sink_put_integer
        procedure :: put_reals => sink_put_reals
        procedure :: put_integers => sink_put_integers
    end type h5_state_sink_t

    !> A group of a checkpoint being read.
    type, extends(state_source_t) :: h5_state_source_t
        !> The checkpoint (open).
        type(h5_file_t), pointer :: file => null()
        !> The group ('/fe').
        character(len=:), allocatable :: group
    contains
        procedure :: is_empty => source_is_empty
        procedure :: has => source_has
        procedure :: get_integer => source_get_integer
        procedure :: get_reals => source_get_reals
        procedure :: get_integers => source_get_integers
        procedure :: require_range => source_require_range
        procedure :: damaged => source_damaged
    end type h5_state_source_t

contains

    !> The attribute `name` of the group.
    subroutine sink_put_integer(self, name, value, error)
        !> The group.
        class(h5_state_sink_t), intent(inout) :: self
        !> Name of the attribute.
        character(len=*), intent(in) :: name
        !> The value.
        integer, intent(in) :: value
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        call self%file%write_attribute(self%group, name, value, error)
    end subroutine sink_put_integer

    !> The dataset `name` of the group, unless `x` is empty.
    subroutine sink_put_reals(self, name, x, error)
        !> The group.
        class(h5_state_sink_t), intent(inout) :: self
        !> Name of the dataset.
        character(len=*), intent(in) :: name
        !> The values.
        real(wp), intent(in) :: x(:)
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        if (size(x) == 0) return
        call self%file%write_dataset(self%group//'/'//name, x, error)
    end subroutine sink_put_reals

    !> The dataset `name` of the group, unless `x` is empty.
    subroutine sink_put_integers(self, name, x, error)
        !> The group.
        class(h5_state_sink_t), intent(inout) :: self
        !> Name of the dataset.
        character(len=*), intent(in) :: name
        !> The values.
        integer, intent(in) :: x(:)
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        if (size(x) == 0) return
        call self%file%write_dataset(self%group//'/'//name, x, error)
    end subroutine sink_put_integers

    !> Whether the group is missing.
    function source_is_empty(self) result(empty)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> True when the checkpoint has no such group.
        logical :: empty
        empty = .not. self%file%exists(self%group)
    end function source_is_empty

    !> Whether the group has the dataset `name`.
    function source_has(self, name) result(found)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> Name of the dataset.
        character(len=*), intent(in) :: name
        !> True when it exists.
        logical :: found
        found = self%file%exists(self%group//'/'//name)
    end function source_has

    !> The attribute `name` of the group, in lo .. hi.
    subroutine source_get_integer(self, name, lo, hi, value, error)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> Name of the attribute.
        character(len=*), intent(in) :: name
        !> Smallest and largest value allowed.
        integer, intent(in) :: lo, hi
        !> The value.
        integer, intent(out) :: value
        !> Set on a read failure or a value outside lo .. hi (damaged).
        type(error_t), allocatable, intent(out) :: error
        call self%file%read_attribute(self%group, name, value, error)
        if (allocated(error)) return
        call require_range([value], lo, hi, self%group//'@'//name, error)
    end subroutine source_get_integer

    !> The real dataset `name` of the group (driver_checkpoint_values::get_r1).
    subroutine source_get_reals(self, name, x, error)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> Name of the dataset.
        character(len=*), intent(in) :: name
        !> The array of the deck's model, replaced by the values read.
        real(wp), allocatable, intent(inout) :: x(:)
        !> Set on a read failure, another size, a value not finite or a missing dataset.
        type(error_t), allocatable, intent(out) :: error
        call get_r1(self%file, self%group//'/'//name, x, error)
    end subroutine source_get_reals

    !> The integer dataset `name` of the group.
    subroutine source_get_integers(self, name, x, error)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> Name of the dataset.
        character(len=*), intent(in) :: name
        !> The values.
        integer, allocatable, intent(out) :: x(:)
        !> Set on a read failure.
        type(error_t), allocatable, intent(out) :: error
        call self%file%read_dataset(self%group//'/'//name, x, error)
    end subroutine source_get_integers

    !> Damaged unless lo <= values <= hi, naming the dataset `name` of the group.
    subroutine source_require_range(self, name, values, lo, hi, error)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> Name of the dataset read.
        character(len=*), intent(in) :: name
        !> Its values.
        integer, intent(in) :: values(:)
        !> Smallest and largest value allowed.
        integer, intent(in) :: lo, hi
        !> Set on a value outside lo .. hi.
        type(error_t), allocatable, intent(out) :: error
        call require_range(values, lo, hi, self%group//'/'//name, error)
    end subroutine source_require_range

    !> Damaged: the group, then `problem`.
    subroutine source_damaged(self, problem, error)
        !> The group.
        class(h5_state_source_t), intent(in) :: self
        !> What is inconsistent.
        character(len=*), intent(in) :: problem
        !> The error.
        type(error_t), allocatable, intent(out) :: error
        call damaged(error, self%group//': '//problem)
    end subroutine source_damaged
end module driver_checkpoint_state
