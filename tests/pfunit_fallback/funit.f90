!> Minimal stand-in for pFUnit's `funit` module, used only when pFUnit is not installed.
!>
!> Provides the assertions MULTICOR's `.pf` tests use. A failed assertion prints file, line,
!> expected and actual values, marks the running test as failed, and the test returns
!> (as in pFUnit). `funit_finish` prints 'N passed, N failed' and stops with a non-zero
!> exit code when any test failed. The state below is the test harness's own, not physics.
module funit
    use, intrinsic :: iso_fortran_env, only: real64, error_unit, output_unit
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    implicit none
    private
    public :: funit_start_test, funit_end_test, funit_finish, funit_any_failure
    public :: funit_assert_equal, funit_assert_true, funit_assert_false, funit_assert_less_than
    public :: funit_assert_greater_than, funit_assert_relatively_equal, funit_assert_is_finite

    integer, parameter :: dp = real64
    integer :: n_passed = 0
    integer :: n_failed = 0
    logical :: current_failed = .false.
    character(len=:), allocatable :: current_name

    interface funit_assert_equal
        module procedure equal_real, equal_real_1d, equal_int, equal_int_1d, equal_string
    end interface funit_assert_equal

    interface funit_assert_relatively_equal
        module procedure rel_equal_real, rel_equal_real_1d
    end interface funit_assert_relatively_equal

    interface funit_assert_less_than
        module procedure less_real, less_int
    end interface funit_assert_less_than

    interface funit_assert_greater_than
        module procedure greater_real, greater_int
    end interface funit_assert_greater_than

    interface funit_assert_is_finite
        module procedure finite_real, finite_real_1d
    end interface funit_assert_is_finite

contains

    subroutine funit_start_test(module_name, test_name)
        character(len=*), intent(in) :: module_name, test_name
        current_name = module_name//'::'//test_name
        current_failed = .false.
    end subroutine funit_start_test

    subroutine funit_end_test()
        if (current_failed) then
            n_failed = n_failed + 1
            write (output_unit, '(a)') 'FAILED  '//current_name
        else
            n_passed = n_passed + 1
            write (output_unit, '(a)') 'passed  '//current_name
        end if
        flush (output_unit)
    end subroutine funit_end_test

    subroutine funit_finish()
        write (output_unit, '(i0,a,i0,a)') n_passed, ' passed, ', n_failed, ' failed'
        if (n_failed > 0 .or. n_passed == 0) error stop 1
    end subroutine funit_finish

    logical function funit_any_failure()
        funit_any_failure = current_failed
    end function funit_any_failure

    subroutine fail(file, line, what, message)
        character(len=*), intent(in) :: file, what
        integer, intent(in) :: line
        character(len=*), intent(in), optional :: message
        current_failed = .true.
        write (error_unit, '(a,":",i0,": assertion failed in ",a,": ",a)') file, line, &
            current_name, what
        if (present(message)) write (error_unit, '(4x,a)') message
        flush (error_unit)
    end subroutine fail

    subroutine equal_real(expected, actual, tolerance, message, file, line)
        real(dp), intent(in) :: expected, actual
        real(dp), intent(in), optional :: tolerance
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        real(dp) :: tol
        character(len=200) :: buf
        tol = 0.0_dp
        if (present(tolerance)) tol = tolerance
        if (.not. (abs(expected - actual) <= tol)) then
            write (buf, '(a,es24.16,a,es24.16,a,es10.3,a,es10.3)') 'expected ', expected, &
                ' actual ', actual, ' |diff| ', abs(expected - actual), ' > tolerance ', tol
            call fail(file, line, trim(buf), message)
        end if
    end subroutine equal_real

    subroutine equal_real_1d(expected, actual, tolerance, message, file, line)
        real(dp), intent(in) :: expected(:), actual(:)
        real(dp), intent(in), optional :: tolerance
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        integer :: i
        if (size(expected) /= size(actual)) then
            call fail(file, line, 'array sizes differ', message)
            return
        end if
        do i = 1, size(expected)
            call equal_real(expected(i), actual(i), tolerance, message, file, line)
            if (current_failed) then
                write (error_unit, '(4x,a,i0)') 'at index ', i
                return
            end if
        end do
    end subroutine equal_real_1d

    subroutine equal_int(expected, actual, message, file, line)
        integer, intent(in) :: expected, actual
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        character(len=100) :: buf
        if (expected /= actual) then
            write (buf, '(a,i0,a,i0)') 'expected ', expected, ' actual ', actual
            call fail(file, line, trim(buf), message)
        end if
    end subroutine equal_int

    subroutine equal_int_1d(expected, actual, message, file, line)
        integer, intent(in) :: expected(:), actual(:)
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        integer :: i
        if (size(expected) /= size(actual)) then
            call fail(file, line, 'array sizes differ', message)
            return
        end if
        do i = 1, size(expected)
            call equal_int(expected(i), actual(i), message, file, line)
            if (current_failed) return
        end do
    end subroutine equal_int_1d

    subroutine equal_string(expected, actual, message, file, line)
        character(len=*), intent(in) :: expected, actual
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        if (expected /= actual) call fail(file, line, 'expected "'//expected//'" actual "'//actual//'"', message)
    end subroutine equal_string

    subroutine rel_equal_real(expected, actual, tolerance, message, file, line)
        real(dp), intent(in) :: expected, actual
        real(dp), intent(in), optional :: tolerance
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        real(dp) :: tol
        character(len=200) :: buf
        tol = 0.0_dp
        if (present(tolerance)) tol = tolerance
        if (.not. (abs(expected - actual) <= tol*abs(expected))) then
            write (buf, '(a,es24.16,a,es24.16,a,es10.3,a,es10.3)') 'expected ', expected, &
                ' actual ', actual, ' relative error ', abs(expected - actual)/abs(expected), &
                ' > tolerance ', tol
            call fail(file, line, trim(buf), message)
        end if
    end subroutine rel_equal_real

    subroutine rel_equal_real_1d(expected, actual, tolerance, message, file, line)
        real(dp), intent(in) :: expected(:), actual(:)
        real(dp), intent(in), optional :: tolerance
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        integer :: i
        if (size(expected) /= size(actual)) then
            call fail(file, line, 'array sizes differ', message)
            return
        end if
        do i = 1, size(expected)
            call rel_equal_real(expected(i), actual(i), tolerance, message, file, line)
            if (current_failed) then
                write (error_unit, '(4x,a,i0)') 'at index ', i
                return
            end if
        end do
    end subroutine rel_equal_real_1d

    subroutine funit_assert_true(condition, message, file, line)
        logical, intent(in) :: condition
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        if (.not. condition) call fail(file, line, 'expected .true.', message)
    end subroutine funit_assert_true

    subroutine funit_assert_false(condition, message, file, line)
        logical, intent(in) :: condition
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        if (condition) call fail(file, line, 'expected .false.', message)
    end subroutine funit_assert_false

    subroutine less_real(a, b, message, file, line)
        real(dp), intent(in) :: a, b
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        character(len=100) :: buf
        if (.not. (a < b)) then
            write (buf, '(es24.16,a,es24.16)') a, ' is not less than ', b
            call fail(file, line, trim(buf), message)
        end if
    end subroutine less_real

    subroutine less_int(a, b, message, file, line)
        integer, intent(in) :: a, b
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        character(len=100) :: buf
        if (.not. (a < b)) then
            write (buf, '(i0,a,i0)') a, ' is not less than ', b
            call fail(file, line, trim(buf), message)
        end if
    end subroutine less_int

    subroutine greater_real(a, b, message, file, line)
        real(dp), intent(in) :: a, b
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        character(len=100) :: buf
        if (.not. (a > b)) then
            write (buf, '(es24.16,a,es24.16)') a, ' is not greater than ', b
            call fail(file, line, trim(buf), message)
        end if
    end subroutine greater_real

    subroutine greater_int(a, b, message, file, line)
        integer, intent(in) :: a, b
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        character(len=100) :: buf
        if (.not. (a > b)) then
            write (buf, '(i0,a,i0)') a, ' is not greater than ', b
            call fail(file, line, trim(buf), message)
        end if
    end subroutine greater_int

    subroutine finite_real(x, message, file, line)
        real(dp), intent(in) :: x
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        if (.not. ieee_is_finite(x)) call fail(file, line, 'value is not finite', message)
    end subroutine finite_real

    subroutine finite_real_1d(x, message, file, line)
        real(dp), intent(in) :: x(:)
        character(len=*), intent(in), optional :: message
        character(len=*), intent(in) :: file
        integer, intent(in) :: line
        if (.not. all(ieee_is_finite(x))) call fail(file, line, 'array has non-finite values', message)
    end subroutine finite_real_1d
end module funit
