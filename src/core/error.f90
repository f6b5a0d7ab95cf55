!> Error values threaded through every fallible call (errors are values, not stops).
!>
!> A fallible routine takes `type(error_t), allocatable, intent(out) :: error`; it allocates
!> the error on failure and returns. Callers propagate with `if (allocated(error)) return`.
!> Only the main program stops, with a non-zero exit code.
!>
!> Each error has a kind, as stdlib's linalg state does: `error_input` (the default) for what
!> the user can fix (deck, model, data, disk space), worded as such; `error_internal` for a
!> failed internal consistency check (a bug: sizes that the code itself computed disagree, a
!> routine called out of order), built by `make_internal_error` and worded so that nobody
!> looks for the cause in the deck.
!>
!> A message shows every control character and every byte that is not UTF-8 as its value
!> (`<0x00>`, core_utf8::printable): a junk file echoed in a message (a mesh's line) prints
!> as text instead of sending raw bytes to the terminal.
module core_error
    use core_strings, only: shorten
    use core_utf8, only: printable
    implicit none
    private
    public :: error_t, make_error, make_input_error, make_internal_error
    public :: error_input, error_internal

    !> Kind of an error the user can fix: input, model, data, environment.
    integer, parameter :: error_input = 1
    !> Kind of an error that reveals a bug: an internal consistency check failed.
    integer, parameter :: error_internal = 2

    !> A user-facing error: what went wrong and where (file, line, keyword when known).
    type :: error_t
        !> error_input or error_internal.
        integer :: kind = error_input
        !> Complete message, ready to print.
        character(len=:), allocatable :: message
        !> File the error refers to ('' when none).
        character(len=:), allocatable :: file
        !> Line in that file (0 when none).
        integer :: line = 0
        !> Keyword the error refers to ('' when none).
        character(len=:), allocatable :: keyword
    end type error_t

contains

    !> Build a plain error with a message.
    subroutine make_error(error, message)
        !> The error to allocate.
        type(error_t), allocatable, intent(out) :: error
        !> What went wrong and what to do about it.
        character(len=*), intent(in) :: message
        allocate (error)
        error%message = printable(message)
        error%file = ''
        error%keyword = ''
    end subroutine make_error

    !> Build an internal error: `internal error in <where>: <message> (a bug in MULTICOR, not
    !> a problem of the input: please report it with the deck)`.
    subroutine make_internal_error(error, where, message)
        !> The error to allocate.
        type(error_t), allocatable, intent(out) :: error
        !> Routine or component whose check failed.
        character(len=*), intent(in) :: where
        !> The consistency condition that does not hold.
        character(len=*), intent(in) :: message
        allocate (error)
        error%kind = error_internal
        error%message = printable('internal error in '//where//': '//message//' (a bug in MULTICOR, '// &
                                  'not a problem of the input: please report it with the deck)')
        error%file = ''
        error%keyword = ''
    end subroutine make_internal_error

    !> Build an input error that names file, line and keyword:
    !> `file:line: keyword 'kw': message`.
    subroutine make_input_error(error, file, line, keyword, message)
        !> The error to allocate.
        type(error_t), allocatable, intent(out) :: error
        !> Input file name.
        character(len=*), intent(in) :: file
        !> Line number in the file (0 if the error concerns the whole file).
        integer, intent(in) :: line
        !> Keyword concerned ('' if none).
        character(len=*), intent(in) :: keyword
        !> What is wrong and what is expected.
        character(len=*), intent(in) :: message
        character(len=32) :: buf
        allocate (error)
        error%file = file
        error%line = line
        error%keyword = keyword
        if (line > 0) then
            write (buf, '(i0)') line
            error%message = file//':'//trim(buf)//': '
        else
            error%message = file//': '
        end if
        if (len(keyword) > 0) error%message = error%message//"keyword '"//shorten(keyword)//"': "
        error%message = printable(error%message//message)
    end subroutine make_input_error
end module core_error
