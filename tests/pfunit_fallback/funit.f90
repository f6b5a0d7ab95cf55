!> Stand-in for pFUnit 4.12, used only when pFUnit is not installed. Two modules:
!>
!> * `funit_fallback_runner`: the harness (test bookkeeping, assertion bodies, summary). The
!>   generated suites and driver use it inside BLOCKs; test code never sees it.
!> * `funit`: what a `.pf` file gets from `use funit`. It exports the same public names as
!>   pFUnit 4.12's `FUnit` module that user code can collide with (`run`, `initialize`,
!>   `finalize`, the `assert*` procedures, `SourceLocation`, `anyExceptions`, the fHamcrest
!>   matchers and their types, ...), so that a helper named like one of them fails to compile
!>   here as it does under pFUnit. The assertions MULTICOR uses are real; the other names are
!>   placeholders that stop the run if called. The fHamcrest types are those of 4.12
!>   (fHamcrest.F90 uses pf_IsNear, pf_IsRelativelyNear, pf_AnyOf, pf_AllOf, pf_Every,
!>   pf_StringContains/StartsWith/EndsWith, pf_IsArrayWithSize, pf_Matchable, each with its
!>   type public): `IsNear` and `IsRelativelyNear`, not the `IsNear_32`/`IsNear_64` and
!>   `IsRelativelyNear_32`/`_64` that replaced them in pFUnit PR #544 (April 2026, after 4.14),
!>   so that the fallback refuses no name 4.12 accepts.
!>
!> Assertions follow pFUnit's argument names, overloads and rules (src/funit/asserts): the real
!> `assertEqual`, `assertLessThan` and `assertGreaterThan` have Assert_Real.tmpl's two sets,
!> `(expected, actual, message, location)` and `(expected, actual, tolerance, message,
!> location)` (lhs, rhs for comparisons: `lhs < rhs + tolerance`, `lhs > rhs - tolerance`);
!> `assertRelativelyEqual` needs a tolerance and fails with 'Zero denominator detected in
!> AssertRelativelyEqual.' when an expected value is zero; `assertIsFinite` takes a scalar; the
!> integer `assertEqual` is `(expected, actual, message, location)` while the integer
!> `assertLessThan` and `assertGreaterThan` take the message by keyword only (pFUnit's
!> KeywordEnforcer dummy comes third, Assert_Integer.tmpl); the string `assertEqual` names its
!> second argument `found` and ignores leading and trailing blanks and tabs (pFUnit's default
!> TRIM_ALL); `assertTrue`/`assertFalse` take a scalar or a rank-1 array (all elements).
!>
!> Known differences, all narrower than pFUnit (a call the fallback accepts compiles under
!> pFUnit, not always the reverse; MULTICOR's tests use none of them): real64 and default
!> integers only; ranks 0 and 1 (pFUnit: 0 to MAX_ASSERT_RANK, 5 by default); no scalar
!> expected against an array actual, no integer or default-real expected against a real64
!> actual, no default-real tolerance (pFUnit's no_tol/with_tol sets have all of these); no
!> array `assertLessThan`/`assertGreaterThan`, integer or real; no `whitespace=` option for
!> strings. Each would take one more specific per kind and rank combination; they are left out.
!> A failed assertion prints file, line, expected and actual values, marks the running test as
!> failed, and the test returns.
!> `fallback_finish` prints 'N passed, N failed' and stops with a non-zero exit code when a
!> test failed. The state below is the test harness's own, not physics.
module funit_fallback_runner
    use, intrinsic :: iso_fortran_env, only: real64, error_unit, output_unit
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    implicit none
    private
    public :: fallback_run_test, fallback_finish, fallback_unsupported
    public :: SourceLocation, anyExceptions
    public :: assertEqual, assertTrue, assertFalse, assertLessThan, assertGreaterThan
    public :: assertRelativelyEqual, assertIsFinite

    integer, parameter :: dp = real64
    integer, parameter :: tab = 9, blank = 32
    integer :: n_passed = 0
    integer :: n_failed = 0
    logical :: current_failed = .false.
    character(len=:), allocatable :: current_name

    !> pFUnit's KeywordEnforcer: a dummy no caller can pass, placed before the optional
    !> arguments that pFUnit wants by keyword.
    type :: keyword_enforcer_t
    end type keyword_enforcer_t

    !> Where an assertion is (pFUnit's `SourceLocation(file, line)`).
    type :: SourceLocation
        character(len=256) :: fileName = '<unknown file>'
        integer :: lineNumber = -1
    end type SourceLocation

    abstract interface
        !> A test, set-up or tear-down procedure (no arguments).
        subroutine test_procedure()
        end subroutine test_procedure
    end interface

    interface assertTrue
        module procedure true_scalar, true_1d
    end interface assertTrue

    interface assertFalse
        module procedure false_scalar, false_1d
    end interface assertFalse

    ! pFUnit's real overloads come in two sets (Assert_Real.tmpl): without a tolerance
    ! (expected, actual, message, location) and with one (expected, actual, tolerance, message,
    ! location), so a message may come third or fourth by position
    interface assertEqual
        module procedure equal_real, equal_real_tol, equal_real_1d, equal_real_1d_tol
        module procedure equal_int, equal_int_1d, equal_string
    end interface assertEqual

    interface assertRelativelyEqual
        module procedure rel_equal_real, rel_equal_real_1d
    end interface assertRelativelyEqual

    interface assertLessThan
        module procedure less_real, less_real_tol, less_int
    end interface assertLessThan

    interface assertGreaterThan
        module procedure greater_real, greater_real_tol, greater_int
    end interface assertGreaterThan

    interface assertIsFinite
        module procedure finite_real
    end interface assertIsFinite

contains

    !> Runs one test as pFUnit's TestCase%runBare does: `set_up`, then, only if it raised
    !> nothing, `test` and `tear_down` (also after a failed test, never after a failed set-up).
    subroutine fallback_run_test(module_name, test_name, test, set_up, tear_down)
        !> the test module and test procedure names, for the report
        character(len=*), intent(in) :: module_name, test_name
        !> the @test procedure
        procedure(test_procedure) :: test
        !> the @before and @after procedures, if the module has them
        procedure(test_procedure), optional :: set_up, tear_down
        call fallback_start_test(module_name, test_name)
        if (present(set_up)) call set_up()
        if (.not. current_failed) then
            call test()
            if (present(tear_down)) call tear_down()
        end if
        call fallback_end_test()
    end subroutine fallback_run_test

    subroutine fallback_start_test(module_name, test_name)
        character(len=*), intent(in) :: module_name, test_name
        current_name = module_name//'::'//test_name
        current_failed = .false.
    end subroutine fallback_start_test

    subroutine fallback_end_test()
        if (current_failed) then
            n_failed = n_failed + 1
            write (output_unit, '(a)') 'FAILED  '//current_name
        else
            n_passed = n_passed + 1
            write (output_unit, '(a)') 'passed  '//current_name
        end if
        flush (output_unit)
    end subroutine fallback_end_test

    subroutine fallback_finish()
        write (output_unit, '(i0,a,i0,a)') n_passed, ' passed, ', n_failed, ' failed'
        if (n_failed > 0 .or. n_passed == 0) error stop 1
    end subroutine fallback_finish

    !> Stops the run: `name` is exported only to reserve it (pFUnit has it).
    subroutine fallback_unsupported(name)
        character(len=*), intent(in) :: name
        write (error_unit, '(a)') 'pFUnit fallback: '//name//' is not provided by the fallback'
        error stop 2
    end subroutine fallback_unsupported

    logical function anyExceptions()
        anyExceptions = current_failed
    end function anyExceptions

    subroutine fail(location, what, message)
        type(SourceLocation), intent(in), optional :: location
        character(len=*), intent(in) :: what
        character(len=*), intent(in), optional :: message
        type(SourceLocation) :: loc
        current_failed = .true.
        if (present(location)) loc = location
        write (error_unit, '(a,":",i0,": assertion failed in ",a,": ",a)') trim(loc%fileName), &
            loc%lineNumber, current_name, what
        if (present(message)) write (error_unit, '(4x,a)') message
        flush (error_unit)
    end subroutine fail

    !> pFUnit's no-tolerance real assertEqual: exact equality (tolerance 0).
    subroutine equal_real(expected, actual, message, location)
        real(dp), intent(in) :: expected, actual
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        call equal_real_tol(expected, actual, 0.0_dp, message, location)
    end subroutine equal_real

    !> |expected - actual| <= tolerance, exact equality first (Inf == Inf), NaN fails.
    subroutine equal_real_tol(expected, actual, tolerance, message, location)
        real(dp), intent(in) :: expected, actual
        real(dp), intent(in) :: tolerance
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=200) :: buf
        if (actual == expected) return
        if (.not. (abs(expected - actual) <= tolerance)) then
            write (buf, '(a,es24.16,a,es24.16,a,es10.3,a,es10.3)') 'expected ', expected, &
                ' actual ', actual, ' |diff| ', abs(expected - actual), ' > tolerance ', tolerance
            call fail(location, trim(buf), message)
        end if
    end subroutine equal_real_tol

    !> pFUnit's no-tolerance real assertEqual on arrays: exact equality (tolerance 0).
    subroutine equal_real_1d(expected, actual, message, location)
        real(dp), intent(in) :: expected(:), actual(:)
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        call equal_real_1d_tol(expected, actual, 0.0_dp, message, location)
    end subroutine equal_real_1d

    subroutine equal_real_1d_tol(expected, actual, tolerance, message, location)
        real(dp), intent(in) :: expected(:), actual(:)
        real(dp), intent(in) :: tolerance
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        integer :: i
        if (size(expected) /= size(actual)) then
            call fail(location, 'nonconforming arrays (sizes differ)', message)
            return
        end if
        ! as pFUnit: exact equality first (Inf == Inf), then |diff| <= tolerance (NaN fails)
        do i = 1, size(expected)
            if (actual(i) == expected(i)) cycle
            if (abs(actual(i) - expected(i)) <= tolerance) cycle
            call equal_real_tol(expected(i), actual(i), tolerance, message, location)
            write (error_unit, '(4x,a,i0)') 'at index ', i
            return
        end do
    end subroutine equal_real_1d_tol

    subroutine equal_int(expected, actual, message, location)
        integer, intent(in) :: expected, actual
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=100) :: buf
        if (expected /= actual) then
            write (buf, '(a,i0,a,i0)') 'expected ', expected, ' actual ', actual
            call fail(location, trim(buf), message)
        end if
    end subroutine equal_int

    subroutine equal_int_1d(expected, actual, message, location)
        integer, intent(in) :: expected(:), actual(:)
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        integer :: i
        if (size(expected) /= size(actual)) then
            call fail(location, 'nonconforming arrays (sizes differ)', message)
            return
        end if
        do i = 1, size(expected)
            if (expected(i) == actual(i)) cycle
            call equal_int(expected(i), actual(i), message, location)
            write (error_unit, '(4x,a,i0)') 'at index ', i
            return
        end do
    end subroutine equal_int_1d

    !> pFUnit's default (TRIM_ALL): leading and trailing blanks and tabs do not count, the rest
    !> must be identical (length included). The second argument is `found`, as in pFUnit.
    subroutine equal_string(expected, found, message, location)
        character(len=*), intent(in) :: expected, found
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=:), allocatable :: e, f
        e = trim_all(expected)
        f = trim_all(found)
        if (len(e) /= len(f)) then
            call fail(location, 'expected "'//e//'" found "'//f//'"', message)
        else if (e /= f) then
            call fail(location, 'expected "'//e//'" found "'//f//'"', message)
        end if
    end subroutine equal_string

    !> `s` without its leading and trailing blanks and tabs (pFUnit's trimAll).
    pure function trim_all(s) result(t)
        character(len=*), intent(in) :: s
        character(len=:), allocatable :: t
        integer :: first, last
        first = 1
        do while (first <= len(s))
            if (iachar(s(first:first)) /= blank .and. iachar(s(first:first)) /= tab) exit
            first = first + 1
        end do
        last = len(s)
        do while (last >= first)
            if (iachar(s(last:last)) /= blank .and. iachar(s(last:last)) /= tab) exit
            last = last - 1
        end do
        t = s(first:last)
    end function trim_all

    !> pFUnit's rule: no zero expected value (the relative error has no meaning there).
    subroutine rel_equal_real(expected, actual, tolerance, message, location)
        real(dp), intent(in) :: expected, actual
        real(dp), intent(in) :: tolerance
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=200) :: buf
        if (expected == 0.0_dp) then
            call fail(location, 'Zero denominator detected in AssertRelativelyEqual.', message)
            return
        end if
        if (.not. (abs(expected - actual) <= tolerance*abs(expected))) then
            write (buf, '(a,es24.16,a,es24.16,a,es10.3,a,es10.3)') 'expected ', expected, &
                ' actual ', actual, ' relative error ', abs(expected - actual)/abs(expected), &
                ' > tolerance ', tolerance
            call fail(location, trim(buf), message)
        end if
    end subroutine rel_equal_real

    subroutine rel_equal_real_1d(expected, actual, tolerance, message, location)
        real(dp), intent(in) :: expected(:), actual(:)
        real(dp), intent(in) :: tolerance
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        integer :: i
        if (size(expected) /= size(actual)) then
            call fail(location, 'nonconforming arrays (sizes differ)', message)
            return
        end if
        ! as pFUnit: any zero expected element fails before any comparison
        if (any(expected == 0.0_dp)) then
            call fail(location, 'Zero denominator detected in AssertRelativelyEqual.', message)
            return
        end if
        do i = 1, size(expected)
            if (abs(actual(i) - expected(i)) <= tolerance*abs(expected(i))) cycle
            call rel_equal_real(expected(i), actual(i), tolerance, message, location)
            write (error_unit, '(4x,a,i0)') 'at index ', i
            return
        end do
    end subroutine rel_equal_real_1d

    subroutine true_scalar(condition, message, location)
        logical, intent(in) :: condition
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        if (.not. condition) call fail(location, 'expected .true.', message)
    end subroutine true_scalar

    !> As pFUnit's assertTrue_1d_: fails unless all elements are true.
    subroutine true_1d(condition, message, location)
        logical, intent(in) :: condition(:)
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        if (.not. all(condition)) call fail(location, 'expected all elements .true.', message)
    end subroutine true_1d

    subroutine false_scalar(condition, message, location)
        logical, intent(in) :: condition
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        if (condition) call fail(location, 'expected .false.', message)
    end subroutine false_scalar

    !> As pFUnit's assertFalse_1d_ (assertTrue of .not. condition): fails unless all are false.
    subroutine false_1d(condition, message, location)
        logical, intent(in) :: condition(:)
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        if (any(condition)) call fail(location, 'expected all elements .false.', message)
    end subroutine false_1d

    !> pFUnit's no-tolerance real assertLessThan: lhs < rhs.
    subroutine less_real(lhs, rhs, message, location)
        real(dp), intent(in) :: lhs, rhs
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        call less_real_tol(lhs, rhs, 0.0_dp, message, location)
    end subroutine less_real

    !> As pFUnit's assert_less_than: lhs < rhs + tolerance.
    subroutine less_real_tol(lhs, rhs, tolerance, message, location)
        real(dp), intent(in) :: lhs, rhs
        real(dp), intent(in) :: tolerance
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=100) :: buf
        if (.not. (lhs < rhs + tolerance)) then
            write (buf, '(es24.16,a,es24.16)') lhs, ' is not less than ', rhs
            call fail(location, trim(buf), message)
        end if
    end subroutine less_real_tol

    !> `unused` is pFUnit's KeywordEnforcer: the message goes by keyword (integers only).
    subroutine less_int(lhs, rhs, unused, message, location)
        integer, intent(in) :: lhs, rhs
        type(keyword_enforcer_t), intent(in), optional :: unused
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=100) :: buf
        if (.not. (lhs < rhs)) then
            write (buf, '(i0,a,i0)') lhs, ' is not less than ', rhs
            call fail(location, trim(buf), message)
        end if
    end subroutine less_int

    !> pFUnit's no-tolerance real assertGreaterThan: lhs > rhs.
    subroutine greater_real(lhs, rhs, message, location)
        real(dp), intent(in) :: lhs, rhs
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        call greater_real_tol(lhs, rhs, 0.0_dp, message, location)
    end subroutine greater_real

    !> As pFUnit's assert_greater_than: lhs > rhs - tolerance.
    subroutine greater_real_tol(lhs, rhs, tolerance, message, location)
        real(dp), intent(in) :: lhs, rhs
        real(dp), intent(in) :: tolerance
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=100) :: buf
        if (.not. (lhs > rhs - tolerance)) then
            write (buf, '(es24.16,a,es24.16)') lhs, ' is not greater than ', rhs
            call fail(location, trim(buf), message)
        end if
    end subroutine greater_real_tol

    !> `unused` is pFUnit's KeywordEnforcer: the message goes by keyword (integers only).
    subroutine greater_int(lhs, rhs, unused, message, location)
        integer, intent(in) :: lhs, rhs
        type(keyword_enforcer_t), intent(in), optional :: unused
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        character(len=100) :: buf
        if (.not. (lhs > rhs)) then
            write (buf, '(i0,a,i0)') lhs, ' is not greater than ', rhs
            call fail(location, trim(buf), message)
        end if
    end subroutine greater_int

    subroutine finite_real(x, message, location)
        real(dp), intent(in) :: x
        character(len=*), intent(in), optional :: message
        type(SourceLocation), intent(in), optional :: location
        if (.not. ieee_is_finite(x)) call fail(location, 'value is not finite', message)
    end subroutine finite_real
end module funit_fallback_runner

!> What `use funit` gives a test module: pFUnit 4.12's public names (FUnit, its PF_Assert and
!> FUnit_Core parts, the fHamcrest matchers and the types and functions they export, such as
!> `is`, `not`, `true`, `false`). Names the fallback does not implement are
!> placeholders (stop the run if called): they are here so that a clash with user code is a
!> compile error as under pFUnit. `output_unit` is re-exported as pFUnit's FUnit does.
module funit
    use, intrinsic :: iso_fortran_env, only: output_unit
    use funit_fallback_runner, only: SourceLocation, anyExceptions, assertEqual, assertTrue, &
                                     assertFalse, assertLessThan, assertGreaterThan, &
                                     assertRelativelyEqual, assertIsFinite, fallback_unsupported
    implicit none
    private
    ! implemented (pFUnit names and arguments)
    public :: SourceLocation, anyExceptions, assertEqual, assertTrue, assertFalse
    public :: assertLessThan, assertGreaterThan, assertRelativelyEqual, assertIsFinite
    public :: output_unit
    ! FUnit
    public :: initialize, run, generic_run, finalize, stub, get_context, LoadTests_interface
    ! PF_Assert
    public :: assertFail, assertExceptionRaised, assertSameShape, assertAny, assertAll
    public :: assertNone, assertNotAll, assertNotEqual, assertLessThanOrEqual
    public :: assertGreaterThanOrEqual, assertApprox, assertIsNan
    public :: WhitespaceOptions, IGNORE_ALL, TRIM_ALL, KEEP_ALL, IGNORE_DIFFERENCES
    ! FUnit_Core
    public :: throw, catchNext, catch, Test, TestSuite, TestMethod, TestCase, TestResult
    public :: TestRunner, ParameterizedTestCase, Expectation, wasCalled, wasNotCalled
    public :: wasCalledOnce, Disable, BaseTestRunner, RemoteRunner, RobustRunner, TestListener
    public :: TestListenerVector, ListenerPointer, ResultPrinter, XmlPrinter, DebugListener
    public :: NameFilter, AbstractTestParameter, ParallelContext, SerialContext, Subject
    public :: Predicate, TestAnnotation, StringTestAnnotationMap, TimeoutAnnotation, TapListener
    ! fHamcrest
    public :: assert_that, equal_to, greater_than, greater_than_or_equal_to, less_than
    public :: less_than_or_equal_to, near, relatively_near, every_item, any_of, all_of
    public :: contains_string, starts_with, ends_with, array_with_size, empty_array
    public :: Is, IsNot, not, IsTrueOrFalse, true, false, AbstractMatcher, MatcherDescription
    public :: StringDescription, IsEqual, IsGreater, IsNear, IsRelativelyNear, AnyOf, AllOf
    public :: Every, StringContains, StringStartsWith, StringEndsWith, IsArrayWithSize, Matchable

    !> pFUnit's whitespace option type for string comparisons.
    type :: WhitespaceOptions
        integer :: value = 0
    end type WhitespaceOptions
    type(WhitespaceOptions), parameter :: TRIM_ALL = WhitespaceOptions(0)
    type(WhitespaceOptions), parameter :: IGNORE_ALL = WhitespaceOptions(1)
    type(WhitespaceOptions), parameter :: KEEP_ALL = WhitespaceOptions(2)
    type(WhitespaceOptions), parameter :: IGNORE_DIFFERENCES = WhitespaceOptions(3)

    !> Placeholders for pFUnit's test-object types.
    type :: Test
    end type Test
    type :: TestSuite
    end type TestSuite
    type, extends(Test) :: TestMethod
    end type TestMethod
    type :: TestCase
    end type TestCase
    type :: TestResult
    end type TestResult
    type :: TestRunner
    end type TestRunner
    type :: ParameterizedTestCase
    end type ParameterizedTestCase
    type :: Expectation
    end type Expectation
    type :: Disable
    end type Disable
    type :: BaseTestRunner
    end type BaseTestRunner
    type :: RemoteRunner
    end type RemoteRunner
    type :: RobustRunner
    end type RobustRunner
    type :: TestListener
    end type TestListener
    type :: TestListenerVector
    end type TestListenerVector
    type :: ListenerPointer
    end type ListenerPointer
    type :: ResultPrinter
    end type ResultPrinter
    type :: XmlPrinter
    end type XmlPrinter
    type :: DebugListener
    end type DebugListener
    type :: NameFilter
    end type NameFilter
    type :: AbstractTestParameter
    end type AbstractTestParameter
    type :: ParallelContext
    end type ParallelContext
    type :: SerialContext
    end type SerialContext
    type :: Subject
    end type Subject
    type :: Predicate
    end type Predicate
    type :: TestAnnotation
    end type TestAnnotation
    type :: StringTestAnnotationMap
    end type StringTestAnnotationMap
    type :: TimeoutAnnotation
    end type TimeoutAnnotation
    type :: TapListener
    end type TapListener
    type :: Is
    end type Is
    type :: IsNot
    end type IsNot
    type :: IsTrueOrFalse
    end type IsTrueOrFalse
    type :: AbstractMatcher
    end type AbstractMatcher
    type :: MatcherDescription
    end type MatcherDescription
    type :: StringDescription
    end type StringDescription
    type :: IsEqual
    end type IsEqual
    type :: IsGreater
    end type IsGreater
    type :: IsNear
    end type IsNear
    type :: IsRelativelyNear
    end type IsRelativelyNear
    type :: AnyOf
    end type AnyOf
    type :: AllOf
    end type AllOf
    type :: Every
    end type Every
    type :: StringContains
    end type StringContains
    type :: StringStartsWith
    end type StringStartsWith
    type :: StringEndsWith
    end type StringEndsWith
    type :: IsArrayWithSize
    end type IsArrayWithSize
    type :: Matchable
    end type Matchable

    abstract interface
        subroutine LoadTests_interface()
        end subroutine LoadTests_interface
    end interface

contains

    subroutine initialize()
        call fallback_unsupported('initialize')
    end subroutine initialize

    subroutine run()
        call fallback_unsupported('run')
    end subroutine run

    subroutine generic_run()
        call fallback_unsupported('generic_run')
    end subroutine generic_run

    subroutine finalize()
        call fallback_unsupported('finalize')
    end subroutine finalize

    subroutine stub()
        call fallback_unsupported('stub')
    end subroutine stub

    subroutine get_context()
        call fallback_unsupported('get_context')
    end subroutine get_context

    subroutine assertFail()
        call fallback_unsupported('assertFail')
    end subroutine assertFail

    subroutine assertExceptionRaised()
        call fallback_unsupported('assertExceptionRaised')
    end subroutine assertExceptionRaised

    subroutine assertSameShape()
        call fallback_unsupported('assertSameShape')
    end subroutine assertSameShape

    subroutine assertAny()
        call fallback_unsupported('assertAny')
    end subroutine assertAny

    subroutine assertAll()
        call fallback_unsupported('assertAll')
    end subroutine assertAll

    subroutine assertNone()
        call fallback_unsupported('assertNone')
    end subroutine assertNone

    subroutine assertNotAll()
        call fallback_unsupported('assertNotAll')
    end subroutine assertNotAll

    subroutine assertNotEqual()
        call fallback_unsupported('assertNotEqual')
    end subroutine assertNotEqual

    subroutine assertLessThanOrEqual()
        call fallback_unsupported('assertLessThanOrEqual')
    end subroutine assertLessThanOrEqual

    subroutine assertGreaterThanOrEqual()
        call fallback_unsupported('assertGreaterThanOrEqual')
    end subroutine assertGreaterThanOrEqual

    subroutine assertApprox()
        call fallback_unsupported('assertApprox')
    end subroutine assertApprox

    subroutine assertIsNan()
        call fallback_unsupported('assertIsNan')
    end subroutine assertIsNan

    subroutine throw()
        call fallback_unsupported('throw')
    end subroutine throw

    subroutine catchNext()
        call fallback_unsupported('catchNext')
    end subroutine catchNext

    subroutine catch()
        call fallback_unsupported('catch')
    end subroutine catch

    subroutine wasCalled()
        call fallback_unsupported('wasCalled')
    end subroutine wasCalled

    subroutine wasNotCalled()
        call fallback_unsupported('wasNotCalled')
    end subroutine wasNotCalled

    subroutine wasCalledOnce()
        call fallback_unsupported('wasCalledOnce')
    end subroutine wasCalledOnce

    subroutine not()
        call fallback_unsupported('not')
    end subroutine not

    subroutine true()
        call fallback_unsupported('true')
    end subroutine true

    subroutine false()
        call fallback_unsupported('false')
    end subroutine false

    subroutine assert_that()
        call fallback_unsupported('assert_that')
    end subroutine assert_that

    subroutine equal_to()
        call fallback_unsupported('equal_to')
    end subroutine equal_to

    subroutine greater_than()
        call fallback_unsupported('greater_than')
    end subroutine greater_than

    subroutine greater_than_or_equal_to()
        call fallback_unsupported('greater_than_or_equal_to')
    end subroutine greater_than_or_equal_to

    subroutine less_than()
        call fallback_unsupported('less_than')
    end subroutine less_than

    subroutine less_than_or_equal_to()
        call fallback_unsupported('less_than_or_equal_to')
    end subroutine less_than_or_equal_to

    subroutine near()
        call fallback_unsupported('near')
    end subroutine near

    subroutine relatively_near()
        call fallback_unsupported('relatively_near')
    end subroutine relatively_near

    subroutine every_item()
        call fallback_unsupported('every_item')
    end subroutine every_item

    subroutine any_of()
        call fallback_unsupported('any_of')
    end subroutine any_of

    subroutine all_of()
        call fallback_unsupported('all_of')
    end subroutine all_of

    subroutine contains_string()
        call fallback_unsupported('contains_string')
    end subroutine contains_string

    subroutine starts_with()
        call fallback_unsupported('starts_with')
    end subroutine starts_with

    subroutine ends_with()
        call fallback_unsupported('ends_with')
    end subroutine ends_with

    subroutine array_with_size()
        call fallback_unsupported('array_with_size')
    end subroutine array_with_size

    subroutine empty_array()
        call fallback_unsupported('empty_array')
    end subroutine empty_array
end module funit
