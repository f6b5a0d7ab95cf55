!> Where a family of behaviour (a time integrator, a contact solve method) puts the state it
!> keeps between steps, and where it takes it back from, by name and without knowing the file:
!> a checkpoint (driver_checkpoint) provides both, writing named integers as attributes and
!> named arrays as datasets of one group. Each kind of the family exports and imports its own
!> state through its bindings, so that a new kind with state adds its bindings, not a branch in
!> the checkpoint.
module core_state
    use core_kinds, only: wp
    use core_error, only: error_t
    implicit none
    private
    public :: state_sink_t, state_source_t

    !> Where a state is put: named integers and named arrays (an empty array is not stored).
    type, abstract :: state_sink_t
    contains
        !> Store one integer.
        procedure(put_integer_iface), deferred :: put_integer
        !> Store an array of reals.
        procedure(put_reals_iface), deferred :: put_reals
        !> Store an array of integers.
        procedure(put_integers_iface), deferred :: put_integers
    end type state_sink_t

    !> Where a state is taken back from, with the checks whose messages name what is read.
    type, abstract :: state_source_t
    contains
        !> Whether nothing is stored.
        procedure(empty_iface), deferred :: is_empty
        !> Whether the array `name` is stored.
        procedure(has_iface), deferred :: has
        !> Read one integer, which must lie in a range.
        procedure(get_integer_iface), deferred :: get_integer
        !> Read an array of reals, all finite, of the size of the array it replaces.
        procedure(get_reals_iface), deferred :: get_reals
        !> Read an array of integers.
        procedure(get_integers_iface), deferred :: get_integers
        !> Error unless every value of the array `name` lies in a range.
        procedure(require_range_iface), deferred :: require_range
        !> The error of a stored state that is inconsistent.
        procedure(damaged_iface), deferred :: damaged
    end type state_source_t

    abstract interface
        !> Store the integer `value` as `name`.
        subroutine put_integer_iface(self, name, value, error)
            import :: state_sink_t, error_t
            !> The sink.
            class(state_sink_t), intent(inout) :: self
            !> Name of the value.
            character(len=*), intent(in) :: name
            !> The value.
            integer, intent(in) :: value
            !> Set on a write failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine put_integer_iface

        !> Store the reals `x` as `name` (nothing when empty).
        subroutine put_reals_iface(self, name, x, error)
            import :: state_sink_t, error_t, wp
            !> The sink.
            class(state_sink_t), intent(inout) :: self
            !> Name of the array.
            character(len=*), intent(in) :: name
            !> The values.
            real(wp), intent(in) :: x(:)
            !> Set on a write failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine put_reals_iface

        !> Store the integers `x` as `name` (nothing when empty).
        subroutine put_integers_iface(self, name, x, error)
            import :: state_sink_t, error_t
            !> The sink.
            class(state_sink_t), intent(inout) :: self
            !> Name of the array.
            character(len=*), intent(in) :: name
            !> The values.
            integer, intent(in) :: x(:)
            !> Set on a write failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine put_integers_iface

        !> Whether nothing is stored.
        function empty_iface(self) result(empty)
            import :: state_source_t
            !> The source.
            class(state_source_t), intent(in) :: self
            !> True when no value or array is stored.
            logical :: empty
        end function empty_iface

        !> Whether the array `name` is stored.
        function has_iface(self, name) result(found)
            import :: state_source_t
            !> The source.
            class(state_source_t), intent(in) :: self
            !> Name of the array.
            character(len=*), intent(in) :: name
            !> True when stored.
            logical :: found
        end function has_iface

        !> Read the integer `name`, an error unless it lies in lo .. hi.
        subroutine get_integer_iface(self, name, lo, hi, value, error)
            import :: state_source_t, error_t
            !> The source.
            class(state_source_t), intent(in) :: self
            !> Name of the value.
            character(len=*), intent(in) :: name
            !> Smallest and largest value allowed.
            integer, intent(in) :: lo, hi
            !> The value.
            integer, intent(out) :: value
            !> Set on a read failure or a value outside lo .. hi.
            type(error_t), allocatable, intent(out) :: error
        end subroutine get_integer_iface

        !> Read the reals `name` into `x`. When not stored, `x` stays as it is and must be
        !> unallocated or empty; when `x` is allocated, the array read must have its size.
        subroutine get_reals_iface(self, name, x, error)
            import :: state_source_t, error_t, wp
            !> The source.
            class(state_source_t), intent(in) :: self
            !> Name of the array.
            character(len=*), intent(in) :: name
            !> The array of the model built from the deck, replaced by the values read.
            real(wp), allocatable, intent(inout) :: x(:)
            !> Set on a read failure, another size, a value not finite, or no array stored for
            !> an `x` that is not empty.
            type(error_t), allocatable, intent(out) :: error
        end subroutine get_reals_iface

        !> Read the integers `name`.
        subroutine get_integers_iface(self, name, x, error)
            import :: state_source_t, error_t
            !> The source.
            class(state_source_t), intent(in) :: self
            !> Name of the array.
            character(len=*), intent(in) :: name
            !> The values.
            integer, allocatable, intent(out) :: x(:)
            !> Set on a read failure.
            type(error_t), allocatable, intent(out) :: error
        end subroutine get_integers_iface

        !> Error unless lo <= values <= hi, naming the array `name`.
        subroutine require_range_iface(self, name, values, lo, hi, error)
            import :: state_source_t, error_t
            !> The source.
            class(state_source_t), intent(in) :: self
            !> Name of the array read.
            character(len=*), intent(in) :: name
            !> Its values.
            integer, intent(in) :: values(:)
            !> Smallest and largest value allowed.
            integer, intent(in) :: lo, hi
            !> Set on a value outside lo .. hi.
            type(error_t), allocatable, intent(out) :: error
        end subroutine require_range_iface

        !> Set `error`: the stored state is inconsistent, as `problem` says.
        subroutine damaged_iface(self, problem, error)
            import :: state_source_t, error_t
            !> The source.
            class(state_source_t), intent(in) :: self
            !> What is inconsistent ('key_i1 and key_i2 differ in size').
            character(len=*), intent(in) :: problem
            !> The error.
            type(error_t), allocatable, intent(out) :: error
        end subroutine damaged_iface
    end interface
end module core_state
