!> Values of a checkpoint (driver_checkpoint): arrays written when they hold something, and
!> every value read back checked before a run uses it (reals finite, integers in their
!> ranges); anything else is refused as 'the checkpoint is damaged', naming the value.
module driver_checkpoint_values
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use core_strings, only: to_str
    use io_hdf5_file, only: h5_file_t
    implicit none
    private
    public :: put_r1, put_part, get_r1, read_int_attr_1d, read_finite_attribute
    public :: require_finite, require_range, damaged, real_text

contains

    !> Write a real array if it is allocated and not empty.
    subroutine put_r1(file, path, x, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Path of the dataset ('/fe/u').
        character(len=*), intent(in) :: path
        !> The array.
        real(wp), allocatable, intent(in) :: x(:)
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        if (.not. allocated(x)) return
        if (size(x) == 0) return
        call file%write_dataset(path, x, error)
    end subroutine put_r1

    !> Write a real array if it is not empty.
    subroutine put_part(file, path, x, error)
        !> Checkpoint being written.
        type(h5_file_t), intent(inout) :: file
        !> Path of the dataset ('/dem/x').
        character(len=*), intent(in) :: path
        !> The array.
        real(wp), intent(in) :: x(:)
        !> Set on a write failure.
        type(error_t), allocatable, intent(out) :: error
        if (size(x) == 0) return
        call file%write_dataset(path, x, error)
    end subroutine put_part

    !> Read a real array written by put_r1 (left as it is when absent; it must then be
    !> unallocated or empty).
    subroutine get_r1(file, path, x, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Path of the dataset ('/fe/u').
        character(len=*), intent(in) :: path
        !> The array of the deck's model, replaced by the values read (of its size).
        real(wp), allocatable, intent(inout) :: x(:)
        !> Set on a read failure, another size, a value not finite, or a dataset missing for
        !> an array that is not empty.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: v(:)
        if (.not. file%exists(path)) then
            if (allocated(x)) then
                if (size(x) > 0) call make_error(error, 'checkpoint: no dataset '//path)
            end if
            return
        end if
        call file%read_dataset(path, v, error)
        if (allocated(error)) return
        if (allocated(x)) then
            if (size(x) /= size(v)) then
                call make_error(error, 'checkpoint: '//path//': size differs from the deck''s model')
                return
            end if
        end if
        call require_finite(v, path, error)
        if (allocated(error)) return
        call move_alloc(v, x)
    end subroutine get_r1

    !> Read an integer attribute array (the file API has 1-D attributes of reals only: the
    !> integers are written as reals, exact below 2**53).
    subroutine read_int_attr_1d(file, object, name, values, error)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group or dataset, and name of the attribute.
        character(len=*), intent(in) :: object, name
        !> The values.
        integer, allocatable, intent(out) :: values(:)
        !> Set on a read failure, or a value that is not a 32-bit integer.
        type(error_t), allocatable, intent(out) :: error
        real(wp), allocatable :: r(:)
        integer :: k
        call file%read_attribute(object, name, r, error)
        if (allocated(error)) return
        do k = 1, size(r)
            if (ieee_is_finite(r(k))) then
                if (r(k) == aint(r(k)) .and. abs(r(k)) <= real(huge(0), wp)) cycle
            end if
            call damaged(error, object//'@'//name//' value '//to_str(k)//' is '//real_text(r(k))// &
                         ', not a 32-bit integer')
            return
        end do
        values = nint(r)
    end subroutine read_int_attr_1d

    !> Read a real attribute array of n values, all finite (else the checkpoint is damaged).
    subroutine read_finite_attribute(file, object, name, values, n, error, names)
        !> Checkpoint being read.
        type(h5_file_t), intent(inout) :: file
        !> Group or dataset, and name of the attribute.
        character(len=*), intent(in) :: object, name
        !> The values.
        real(wp), allocatable, intent(out) :: values(:)
        !> Number of values expected.
        integer, intent(in) :: n
        !> Set on a read failure, another number of values, or a value not finite.
        type(error_t), allocatable, intent(out) :: error
        !> What each value is (for the message).
        character(len=*), intent(in), optional :: names(:)
        call file%read_attribute(object, name, values, error)
        if (allocated(error)) return
        if (size(values) /= n) then
            call damaged(error, object//'@'//name//': '//to_str(size(values))//' values, not '//to_str(n))
            return
        end if
        call require_finite(values, object//'@'//name, error, names)
    end subroutine read_finite_attribute

    !> Refuse a value read from a checkpoint that is not finite, naming it.
    subroutine require_finite(values, what, error, names)
        !> The values.
        real(wp), intent(in) :: values(:)
        !> Where they come from ('/fe@scalars', '/dem/x').
        character(len=*), intent(in) :: what
        !> Set on the first value that is NaN or infinite.
        type(error_t), allocatable, intent(out) :: error
        !> What each value is (for the message).
        character(len=*), intent(in), optional :: names(:)
        integer :: k
        do k = 1, size(values)
            if (ieee_is_finite(values(k))) cycle
            if (present(names)) then
                call damaged(error, what//' value '//to_str(k)//' ('//trim(names(k))//') is '// &
                             real_text(values(k)))
            else if (size(values) == 1) then
                call damaged(error, what//' is '//real_text(values(k)))
            else
                call damaged(error, what//' value '//to_str(k)//' is '//real_text(values(k)))
            end if
            return
        end do
    end subroutine require_finite

    !> Refuse integers read from a checkpoint outside [lo, hi], naming the first.
    subroutine require_range(values, lo, hi, what, error, first)
        !> The values.
        integer, intent(in) :: values(:)
        !> Allowed range.
        integer, intent(in) :: lo, hi
        !> Where they come from ('/dem/contacts/status').
        character(len=*), intent(in) :: what
        !> Set on the first value out of range.
        type(error_t), allocatable, intent(out) :: error
        !> Index of values(1) in the message (default 1).
        integer, intent(in), optional :: first
        integer :: k, k0
        k0 = 0
        if (present(first)) k0 = first - 1
        do k = 1, size(values)
            if (values(k) >= lo .and. values(k) <= hi) cycle
            if (size(values) == 1 .and. .not. present(first)) then
                call damaged(error, what//' is '//to_str(values(k))//', outside '//to_str(lo)//'..'//to_str(hi))
            else
                call damaged(error, what//' value '//to_str(k + k0)//' is '//to_str(values(k))//', outside '// &
                             to_str(lo)//'..'//to_str(hi))
            end if
            return
        end do
    end subroutine require_range

    !> The error for a damaged checkpoint: 'checkpoint: <problem>: the checkpoint is damaged'.
    subroutine damaged(error, problem)
        !> Set.
        type(error_t), allocatable, intent(out) :: error
        !> What is wrong, naming the value.
        character(len=*), intent(in) :: problem
        call make_error(error, 'checkpoint: '//problem//': the checkpoint is damaged')
    end subroutine damaged

    !> A real for messages: 'NaN', 'Infinity', '-Infinity' or 4 significant digits.
    function real_text(x) result(text)
        !> The value.
        real(wp), intent(in) :: x
        character(len=:), allocatable :: text
        character(len=24) :: buf
        if (ieee_is_nan(x)) then
            text = 'NaN'
        else if (.not. ieee_is_finite(x)) then
            text = merge('Infinity ', '-Infinity', x > 0.0_wp)
            text = trim(text)
        else
            write (buf, '(es11.3e3)') x
            text = trim(adjustl(buf))
        end if
    end function real_text
end module driver_checkpoint_values
