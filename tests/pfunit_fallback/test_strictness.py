#!/usr/bin/env python3
"""The pFUnit fallback refuses what real pFUnit 4.12 refuses.

Each case is a small .pf module. Generation-time cases must make pf2f90.py fail with the
expected message; compile-time cases must generate, then fail to compile against the
fallback's funit module with the expected compiler message; run-time cases must compile
and the test executable must fail with the expected output. A correct module must
generate, compile and pass, so that the refusals are not caused by a broken set-up, and so
must each ACCEPT case: what pFUnit 4.12 accepts, the fallback must not refuse. Each PAIRS case
is an assertion form pFUnit 4.12 accepts (a kind, rank or option of its generated overloads,
src/funit/asserts/Assert_Real.tmpl, Assert_Integer.tmpl, Assert_Logical.tmpl, AssertString.F90,
AssertBasic.F90 in Goddard-Fortran-Ecosystem/pFUnit): written once so that it holds (the suite
must pass) and once so that it does not (the suite must fail, naming the .pf file and the line
of the assertion).

Usage: test_strictness.py --fc gfortran --moddir <funit .mod dir> --lib <libfunit.a>
                          --work <scratch dir>
"""
import argparse
import pathlib
import re
import shutil
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
PF2F90 = HERE / 'pf2f90.py'


def module(name, body, helpers=''):
    """A .pf test module `name` with one test whose body is `body`."""
    return (f"module {name}\n    use funit\n    use, intrinsic :: iso_fortran_env, only: int8, int16, "
            f"int64, real32, real64, real128\n"
            f"    implicit none\ncontains\n    @test\n    subroutine test_one()\n{body}\n"
            f"    end subroutine test_one\n{helpers}end module {name}\n")


GOOD = module('strict_good', "        real(real64) :: x\n        x = 2.0_real64\n"
              "        @assertEqual(2.0_real64, x, tolerance=0.0_real64)\n"
              "        @assertRelativelyEqual(2.0_real64, x, tolerance=1.0e-15_real64)\n"
              "        @assertTrue(x > 1.0_real64, message='x > 1')\n"
              # pFUnit accepts these too: logical arrays, the integer comparisons with the
              # message by keyword, strings compared without leading/trailing blanks and tabs
              "        @assertTrue([x > 1.0_real64, x < 3.0_real64])\n"
              "        @assertFalse([x < 1.0_real64, x > 3.0_real64])\n"
              "        @assertLessThan(1, 2, message='1 < 2')\n"
              "        @assertGreaterThan(2, 1, message='2 > 1')\n"
              "        @assertEqual('abc', '  abc ' // achar(9))")

# (name, .pf text, regex the pf2f90 error must match)
GENERATION = [
    ('strict_comment', module('strict_comment', "        @assertTrue(.true.) ! why"),
     r'not a pFUnit 4\.12 directive form'),
    ('strict_continued', module('strict_continued', "        @assertEqual(1, &\n            1)"),
     r'not a pFUnit 4\.12 directive form'),
    ('strict_operands', module('strict_operands', "        @assertEqual(1)"),
     r'needs at least 2 arguments'),
    ('strict_typo', module('strict_typo', "        @asertTrue(.true.)"),
     r'not a pFUnit 4\.12 directive form'),
    ('strict_not_alone', module('strict_not_alone', "        if (.true.) @assertTrue(.true.)"),
     r'must stand alone'),
    ('strict_long_name', module('strict_long_name', "        @assertTrue(.true.)").replace(
        'test_one', 't' * 64), r'longer than 63'),
    ('strict_long_line', module('strict_long_line', "        call sleep(0)" + ' ' * 120 + '; continue'),
     r'more than gfortran'),
    # gfortran counts bytes: 131 characters, 221 bytes
    # a '!' inside a character literal starts no comment: the code past 132 counts
    ('strict_long_quoted_bang', module('strict_long_quoted_bang', "        print *, 'a!b', "
                                       + "1 + " * 30 + "1"), r'more than gfortran'),
    ('strict_long_bytes', module('strict_long_bytes', "    character(len=*), parameter :: s = '"
                                 + '\u00e9' * 90 + "'\n        @assertTrue(.true.)"),
     r'more than gfortran'),
    ('strict_long_assert', module('strict_long_assert', "        @assertTrue(" + '.true. .and. ' * 10
                                  + ".true.)"), r'would generate a 1[0-9][0-9]-character line'),
    ('strict_before_args', module('strict_before_args', "        @assertTrue(.true.)",
                                  "    @before(x)\n    subroutine set_up()\n    end subroutine set_up\n"),
     r'not a pFUnit 4\.12 directive form'),
    ('strict_before_line', module('strict_before_line', "        @assertTrue(.true.)",
                                  "    @before\n    recursive subroutine set_up()\n"
                                  "    end subroutine set_up\n"),
     r'must be followed by its subroutine statement'),
    ('strict_module_name', module('other_name', "        @assertTrue(.true.)"),
     r'must be named exactly like the file'),
    ('strict_module_case', module('Strict_Module_Case', "        @assertTrue(.true.)"),
     r'must be named exactly like the file'),
]

# pFUnit 4.12 accepts these (each must generate, compile and pass)
ACCEPT = [
    # Assert_Real.tmpl: a no-tolerance overload (expected, actual, message, location) and a
    # tolerance one (expected, actual, tolerance, message, location), for every comparison
    ('strict_real_message', module('strict_real_message', "        real(real64) :: x\n"
                                   "        x = 2.0_real64\n"
                                   "        @assertEqual(2.0_real64, x, 'x is two')\n"
                                   "        @assertEqual([x, x], [x, x], 'arrays')\n"
                                   "        @assertEqual(2.0_real64, x, 0.0_real64, 'within 0')\n"
                                   "        @assertEqual([x], [x], 0.0_real64, 'within 0')")),
    ('strict_real_compare', module('strict_real_compare', "        real(real64) :: x\n"
                                   "        x = 2.0_real64\n"
                                   "        @assertLessThan(1.0_real64, x, '1 < x')\n"
                                   "        @assertGreaterThan(x, 1.0_real64, 'x > 1')\n"
                                   "        @assertLessThan(x, 2.0_real64, 1.0e-12_real64)\n"
                                   "        @assertGreaterThan(x, 2.0_real64, 1.0e-12_real64, 'x > 2 - tol')")),
    # gfortran (default 132) ignores what a comment puts past column 132; pFUnit copies the line
    ('strict_tail_comment', module('strict_tail_comment', "        integer :: n\n        n = 1  ! "
                                   + 'c' * 140 + "\n        @assertEqual(1, n)")),
    # pFUnit matches an @assert at the start of a line only: one inside a literal is text
    ('strict_literal_at', module('strict_literal_at', "        character(len=*), parameter :: s = "
                                 "'see @assertTrue; !'\n        @assertEqual(18, len(s))")),
    # ... also in a literal continued on the next line (pFUnit copies a line starting with '&')
    ('strict_literal_continued', module('strict_literal_continued', "        character(len=*), "
                                        "parameter :: s = 'abc &\n            &@assertTrue(x)'\n"
                                        "        @assertEqual(18, len(s))")),
    # pFUnit's suite function declares `suite` and `t` only: a module may export other names
    ('strict_suite_names', module('strict_suite_names', "        @assertEqual(1, method)",
                                  ).replace('contains\n', '    integer, public :: method = 1, '
                                            'fallback_start_test = 2, fallback_end_test = 3, '
                                            'fallback_run_test = 4\ncontains\n')),
]

# (name, declarations, assertion that holds, assertion that fails, regex the failure must match).
# Tolerances: pFUnit's assert_equal passes an element when |actual - expected| <= tolerance
# (Assert_Real.tmpl); without a tolerance it uses 0, exact equality. Each case's values are chosen
# exactly representable (or their difference known) so that the tolerance decides.
PAIRS = [
    # no_tol (integer default, real kind(actual)): the integer is converted to real64; 3 and
    # 3 + spacing(3) are exact, no tolerance means exact equality
    ('pair_int_real64', "        real(real64) :: x\n        x = 3.0_real64",
     "        @assertEqual(3, x)",
     "        @assertEqual(3, x + spacing(x))", r'expected 3\.0+ actual 3\.0+4'),
    # no_tol (real default, real64): the default real 0.1 is converted to real64 and differs from
    # 0.1_real64 by 1.49e-9 (real32's 0.1 is 0.100000001490116...): exact comparison fails ...
    ('pair_default_real64', "        real(real64) :: x, y\n        x = 0.5_real64\n        y = 0.1_real64",
     "        @assertEqual(0.5, x)",
     "        @assertEqual(0.1, y)", r'\|diff\| 0\.149'),
    # ... with_tol (real default, real64, tolerance default real): 1.0e-8 > 1.49e-9 passes,
    # 1.0e-9 < 1.49e-9 fails
    ('pair_default_tol', "        real(real64) :: x\n        x = 0.1_real64",
     "        @assertEqual(0.1, x, 1.0e-8)",
     "        @assertEqual(0.1, x, 1.0e-9)", r'> tolerance'),
    # real32 throughout: |1.5 - 1.0| = 0.5 exactly; <= tolerance, so 0.5 passes, 0.25 fails
    ('pair_real32', "        real(real32) :: y\n        y = 1.5_real32",
     "        @assertEqual(1.0_real32, y, 0.5_real32)",
     "        @assertEqual(1.0_real32, y, 0.25)", r'> tolerance'),
    # real128: z = 1 + 1.0e-31 is resolved (epsilon 1.9e-34, lost in real64): within 1.0e-30,
    # not within 1.0e-32, so the comparison is made in real128
    ('pair_real128', "        real(real128) :: z\n        z = 1.0_real128 + 1.0e-31_real128",
     "        @assertEqual(1, z, 1.0e-30_real128)",
     "        @assertEqual(1.0_real128, z, 1.0e-32_real128)", r'> tolerance'),
    # scalar expected against an array actual ("Rank 0 is also conformable"), exact values;
    # the first failing element is reported
    ('pair_scalar_array', "        real(real64) :: v(2)\n        v = [2.0_real64, 2.5_real64]",
     "        @assertEqual(2.0_real64, v(1:1))",
     "        @assertEqual(2.0_real64, v)", r'at index \[2\]'),
    # rank 2, real64 tolerance: one element off by 1.0e-10 (rounded to about 1.00000008e-10),
    # within 1.0e-9, not within 1.0e-11
    ('pair_rank2', "        real(real64) :: a(2, 3), b(2, 3)\n        a = 1\n        b = a\n"
                   "        b(2, 3) = 1 + 1.0e-10_real64",
     "        @assertEqual(a, b, 1.0e-9_real64)",
     "        @assertEqual(a, b, 1.0e-11_real64)", r'at index \[2, 3\]'),
    # rank 5 (pFUnit's MAX_ASSERT_RANK), exact
    ('pair_rank5', "        real(real64) :: c(1, 2, 1, 2, 1)\n        c = 0",
     "        @assertEqual(0, c)",
     "        c(1, 2, 1, 2, 1) = 1\n        @assertEqual(0.0, c)", r'at index \[1, 2, 1, 2, 1\]'),
    # Inf == Inf passes (exact equality first); NaN fails whatever the tolerance
    ('pair_inf_nan', "        use, intrinsic :: ieee_arithmetic\n        real(real64) :: f, n\n"
                     "        f = ieee_value(f, ieee_positive_inf)\n        n = ieee_value(n, ieee_quiet_nan)",
     "        @assertEqual(f, [f, f])",
     "        @assertEqual(n, n, huge(n))", r'NaN'),
    # integer kinds (Assert_Integer.tmpl 'useful'): a default-integer expected against int8,
    # exact
    ('pair_int8', "        integer(int8) :: k\n        k = 7_int8",
     "        @assertEqual(7, k)",
     "        @assertEqual(8, k)", r'expected 8 actual 7'),
    # int64 rank 2 against a scalar, exact
    ('pair_int64_2d', "        integer(int64) :: m(2, 2)\n        m = 5\n        m(1, 2) = 6",
     "        @assertEqual(5_int64, m(:, 1))",
     "        @assertEqual(5, m)", r'at index \[1, 2\]'),
    # int16 arrays compared (strict <), message by keyword
    ('pair_int_less', "        integer(int16) :: j(2)\n        j = [2_int16, 3_int16]",
     "        @assertLessThan([1_int16, 2_int16], j, message='lt')",
     "        @assertLessThan([1_int16, 3_int16], j, message='lt')", r'3 is not less than 3 at index \[2\]'),
    # a scalar lhs against an array rhs (not the reverse, see strict_lhs_array_rhs_scalar)
    ('pair_int_greater', "        integer :: i(3)\n        i = [4, 5, 6]",
     "        @assertGreaterThan(7, i)",
     "        @assertGreaterThan(6, i)", r'6 is not greater than 6 at index \[3\]'),
    # real array comparisons: lhs < rhs + tolerance with a scalar lhs (no tolerance: strict)
    ('pair_real_less', "        real(real64) :: r(2)\n        r = [1.0_real64, 2.0_real64]",
     "        @assertLessThan(0.5_real64, r)",
     "        @assertLessThan(1, r)", r'is not less than'),
    # lhs > rhs - tolerance: 1 > 1.5 - 0.75 holds; 1 > 1.5 - 0.5 = 1 does not (strict), values exact
    ('pair_real_greater', "        real(real32) :: q(1)\n        q = 1.0_real32",
     "        @assertGreaterThan(q, [1.5_real32], 0.75)",
     "        @assertGreaterThan(q, [1.5_real32], 0.5)", r'is not greater than'),
    # relative: |actual - expected| <= tolerance*|expected|; both errors are 0.005 (to real32
    # rounding), within 0.01, not within 0.001
    ('pair_relative', "        real(real32) :: y(2)\n        y = [100.5_real32, 201.0_real32]",
     "        @assertRelativelyEqual([100.0, 200.0], y, 0.01)",
     "        @assertRelativelyEqual([100.0, 200.0], y, 0.001)", r'relative error'),
    # logical assertEqual (Assert_Logical.tmpl), a scalar expected spread over the array
    ('pair_logical', "        logical :: l(2)\n        l = [.true., .false.]",
     "        @assertEqual([.true., .false.], l)",
     "        @assertEqual(.true., l, message='logical')", r'at index \[2\]'),
    # whitespace= (AssertString.F90, StringUtilities.F90): any run of blanks and tabs equals
    # any other run under IGNORE_DIFFERENCES, but not none
    ('pair_ws_differences', "",
     "        @assertEqual('a b', 'a ' // achar(9) // ' b', whitespace=IGNORE_DIFFERENCES)",
     "        @assertEqual('a b', 'ab', whitespace=IGNORE_DIFFERENCES)", r'expected "a b" found "ab"'),
    ('pair_ws_ignore_all', "",
     "        @assertEqual('ab', ' a  b ', whitespace=IGNORE_ALL)",
     "        @assertEqual('ab', ' a  c ', whitespace=IGNORE_ALL)", r'found "a  c"'),
    ('pair_ws_keep_all', "",
     "        @assertEqual(' a', ' a', whitespace=KEEP_ALL)",
     "        @assertEqual(' a', 'a', whitespace=KEEP_ALL)", r'expected " a" found "a"'),
    ('pair_ws_trim_all', "",
     "        @assertEqual('a', ' a ', 'msg', whitespace=TRIM_ALL)",
     "        @assertEqual('a', ' a b', 'msg', whitespace=TRIM_ALL)", r'found "a b"'),
    # string arrays (AssertString.F90 0d1d and 1d1d)
    ('pair_string_arrays', "",
     "        @assertEqual('x', ['x ', ' x'])",
     "        @assertEqual(['ab', 'cd'], ['ab', 'ce'])", r'expected "cd" found "ce"'),
    # assertIsFinite for real32 and real128 (AssertBasic.F90)
    ('pair_finite', "        use, intrinsic :: ieee_arithmetic\n        real(real128) :: z\n"
                    "        z = ieee_value(z, ieee_positive_inf)",
     "        @assertIsFinite(1.0_real32)",
     "        @assertIsFinite(z)", r'not finite'),
]

# fHamcrest's matcher types, public in pFUnit 4.12's FUnit (IsNear/IsRelativelyNear were split
# into IsNear_32/_64 and IsRelativelyNear_32/_64 only after 4.14, pFUnit PR #544)
MATCHER_TYPES = ['Every', 'AnyOf', 'AllOf', 'IsNear', 'IsRelativelyNear', 'StringContains',
                 'StringStartsWith', 'StringEndsWith', 'IsArrayWithSize', 'Matchable']

# (name, .pf text, regex the compiler output must match)
COMPILE = [
    ('strict_helper_run', module('strict_helper_run', "        call run(1)",
                                 "    subroutine run(n)\n        integer, intent(in) :: n\n"
                                 "        if (n < 0) stop\n    end subroutine run\n"),
     r"Procedure .run. at \(1\) is already defined"),
    ('strict_helper_assert', module('strict_helper_assert', "        call assertEqual()",
                                    "    subroutine assertEqual()\n    end subroutine assertEqual\n"),
     r"Cannot change attributes of USE-associated symbol assertequal"),
    ('strict_relative_no_tol', module('strict_relative_no_tol',
                                      "        @assertRelativelyEqual(1.0_real64, 1.0_real64)"),
     r"no specific subroutine for the generic .assertrelativelyequal."),
    # pFUnit's suite function names TestMethod (its constructor) next to `use <module>`
    ('strict_suite_testmethod', module('strict_suite_testmethod', "        @assertTrue(.true.)")
     .replace('    use funit\n', '    use funit, only: SourceLocation, anyExceptions, assertTrue\n')
     .replace('contains\n', '    type, public :: TestMethod\n    end type TestMethod\ncontains\n'),
     r"(ambiguous|TestMethod)"),
    # pFUnit's integer comparisons put a KeywordEnforcer third: the message goes by keyword
    ('strict_int_message', module('strict_int_message', "        @assertLessThan(1, 2, '1 < 2')"),
     r"no specific subroutine for the generic .assertlessthan."),
    ('strict_int_message_gt', module('strict_int_message_gt',
                                     "        @assertGreaterThan(2, 1, '2 > 1')"),
     r"no specific subroutine for the generic .assertgreaterthan."),
    # pFUnit's string assertEqual calls its second argument `found`
    ('strict_string_keyword', module('strict_string_keyword',
                                     "        @assertEqual('a', actual='a')"),
     r"no specific subroutine for the generic .assertequal."),
    # fHamcrest's `true` is public in pFUnit's FUnit module
    ('strict_helper_true', module('strict_helper_true', "        @assertTrue(true())",
                                  "    logical function true()\n        true = .true.\n"
                                  "    end function true\n"),
     r"(already defined|USE-associated)"),
    # Kinds and ranks pFUnit 4.12 does not combine (Assert_Real.tmpl's no_tol/with_tol lists,
    # after tools/overload_template.py drops duplicates and the kinds gfortran lacks): expected
    # of another real kind than default real or the actual's, an array expected against a
    # scalar or another rank, a tolerance of another kind, an integer tolerance, rank 6
    ('strict_kind_real64_real32', module('strict_kind_real64_real32',
                                         "        @assertEqual(1.0_real64, 1.0_real32)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_kind_real64_real128', module('strict_kind_real64_real128',
                                          "        @assertEqual(1.0_real64, 1.0_real128)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_rank_array_scalar', module('strict_rank_array_scalar',
                                        "        @assertEqual([1.0_real64], 1.0_real64)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_rank_mixed', module('strict_rank_mixed', "        real(real64) :: a(1, 1)\n        a = 1\n"
                                 "        @assertEqual([1.0_real64], a)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_tol_kind', module('strict_tol_kind', "        @assertEqual(1.0_real32, 1.0_real32, 0.1_real64)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_tol_real128', module('strict_tol_real128',
                                  "        @assertEqual(1.0_real64, 1.0_real64, 0.1_real128)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_tol_integer', module('strict_tol_integer', "        @assertEqual(1.0_real64, 1.0_real64, 0)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_rank6', module('strict_rank6', "        real(real64) :: a(1, 1, 1, 1, 1, 1)\n        a = 1\n"
                            "        @assertEqual(a, a)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_less_rank6', module('strict_less_rank6', "        integer :: a(1, 1, 1, 1, 1, 1)\n        a = 1\n"
                                 "        @assertLessThan(0, a)"),
     r"no specific subroutine for the generic .assertlessthan."),
    # the scalar may be the expected value or lhs only ("Rank 0 is also conformable" lists the
    # expected/lhs at rank 0, never the actual/rhs)
    ('strict_lhs_array_rhs_scalar', module('strict_lhs_array_rhs_scalar',
                                           "        @assertGreaterThan([4, 5], 3)"),
     r"no specific subroutine for the generic .assertgreaterthan."),
    ('strict_real_lhs_array', module('strict_real_lhs_array',
                                     "        @assertLessThan([1.0_real64], 2.0_real64, 0.5_real64)"),
     r"no specific subroutine for the generic .assertlessthan."),
    # Assert_Integer.tmpl: expected of the actual's kind or default only; no real expected for
    # an integer actual, no tolerance
    ('strict_int_kinds', module('strict_int_kinds', "        @assertEqual(1_int64, 1)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_int_kinds_8_16', module('strict_int_kinds_8_16', "        @assertEqual(1_int8, 1_int16)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_real_int_actual', module('strict_real_int_actual', "        @assertEqual(1.0_real64, 1)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_int_tolerance', module('strict_int_tolerance', "        @assertEqual(1, 1, 1)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_relative_int', module('strict_relative_int', "        @assertRelativelyEqual(1, 1, 0.1)"),
     r"no specific subroutine for the generic .assertrelativelyequal."),
    # Assert_Logical.tmpl puts a KeywordEnforcer third: the message goes by keyword
    ('strict_logical_message', module('strict_logical_message',
                                      "        @assertEqual(.true., .true., 'msg')"),
     r"no specific subroutine for the generic .assertequal."),
    # AssertString.F90: no array expected against a scalar; whitespace is a WhitespaceOptions,
    # whose component has no default (StringUtilities.F90)
    ('strict_string_1d0d', module('strict_string_1d0d', "        @assertEqual(['a'], 'a')"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_whitespace_int', module('strict_whitespace_int', "        @assertEqual('a', 'a', whitespace=1)"),
     r"no specific subroutine for the generic .assertequal."),
    ('strict_whitespace_default', module('strict_whitespace_default',
                                         "        @assertEqual('a', 'a', whitespace=WhitespaceOptions())"),
     r"No initializer for component .value."),
    # AssertBasic.F90: assertIsFinite takes a scalar
    ('strict_finite_array', module('strict_finite_array', "        @assertIsFinite([1.0_real64])"),
     r"no specific subroutine for the generic .assertisfinite."),
]

COMPILE += [(f'strict_type_{t.lower()}', module(f'strict_type_{t.lower()}', "        @assertTrue(.true.)")
             .replace('\ncontains\n', f'\n    type :: {t}\n    end type {t}\ncontains\n'), rf'Derived type definition of .{t.lower()}. at \(1\) has already been defined')
            for t in MATCHER_TYPES]

# (name, .pf text, regex the run output must match)
RUN = [
    ('strict_relative_zero', module('strict_relative_zero',
                                    "        @assertRelativelyEqual(0.0_real64, 0.0_real64, "
                                    "tolerance=1.0e-12_real64)"),
     r'Zero denominator detected in AssertRelativelyEqual\.'),
    ('strict_relative_zero_1d', module('strict_relative_zero_1d',
                                       "        @assertRelativelyEqual([1.0_real64, 0.0_real64], "
                                       "[1.0_real64, 0.0_real64], tolerance=1.0e-12_real64)"),
     r'Zero denominator detected in AssertRelativelyEqual\.'),
    # pFUnit's TestCase%runBare: no tear-down after a failed set-up (the error stop would cut
    # the summary line; stdout and stderr are joined, hence the order-free look-aheads)
    ('strict_before_fails', module('strict_before_fails', "        @assertTrue(.true.)",
                                   "    @before\n    subroutine set_up()\n"
                                   "        @assertTrue(.false., message='set-up fails')\n"
                                   "    end subroutine set_up\n"
                                   "    @after\n    subroutine tear_down()\n"
                                   "        error stop 3\n    end subroutine tear_down\n"),
     r'(?=[\s\S]*set-up fails)(?=[\s\S]*0 passed, 1 failed)'),
    # ... but a tear-down after a failed test
    ('strict_after_runs', module('strict_after_runs', "        @assertTrue(.false., message='test fails')",
                                 "    @after\n    subroutine tear_down()\n"
                                 "        @assertTrue(.false., message='tear-down ran')\n"
                                 "    end subroutine tear_down\n"),
     r'(?=[\s\S]*test fails[\s\S]*tear-down ran)(?=[\s\S]*0 passed, 1 failed)'),
    # pFUnit's assert_less_than with a tolerance: lhs < rhs + tolerance
    ('strict_less_tol', module('strict_less_tol', "        @assertLessThan(2.0_real64, 1.5_real64, 0.5_real64)"),
     r'is not less than'),
    # TRIM_ALL ignores the ends only: inner blanks count
    ('strict_string_inner', module('strict_string_inner', "        @assertEqual('a b', 'a  b')"),
     r'expected "a b" found "a  b"'),
    # same rank, other shape: pFUnit's conformable() fails ('Arrays not conformable')
    ('strict_shape_real', module('strict_shape_real', "        real(real64) :: a(2, 3), b(3, 2)\n"
                                 "        a = 1\n        b = 1\n        @assertEqual(a, b, 1.0_real64)"),
     r'Arrays not conformable: expected shape \[2, 3\] actual shape \[3, 2\]'),
    ('strict_shape_int', module('strict_shape_int', "        @assertLessThan([1, 2], [3, 4, 5])"),
     r'Arrays not conformable'),
    ('strict_shape_string', module('strict_shape_string', "        @assertEqual(['a', 'b'], ['a'])"),
     r'Arrays not conformable'),
    # AssertRelativelyEqual takes expected as 0*actual + expected: an Inf actual makes it NaN,
    # which fails even with an infinite tolerance
    ('strict_relative_inf', module('strict_relative_inf', "        use, intrinsic :: ieee_arithmetic\n"
                                   "        real(real64) :: f\n        f = ieee_value(f, ieee_positive_inf)\n"
                                   "        @assertRelativelyEqual(1.0_real64, f, f)"),
     r'relative error'),
    # a whitespace value outside pFUnit's four
    ('strict_whitespace_unknown', module('strict_whitespace_unknown',
                                         "        @assertEqual('a', 'a', whitespace=WhitespaceOptions(7))"),
     r'Unknown case for handling Whitespace'),
]

# (name, .pf text, regex the run output must match, or None: must pass), compiled with the Debug
# unit tests' trap on invalid operations: pFUnit's array assert_equal (WHERE/ELSEWHERE) computes
# Inf - Inf for equal infinities, which traps; its scalar one returns on equality first and passes
INF = "        use, intrinsic :: ieee_arithmetic\n        real(real64) :: f\n        f = ieee_value(f, ieee_positive_inf)\n"
TRAP = [
    ('trap_inf_scalar', module('trap_inf_scalar', INF + "        @assertEqual(f, f)"), None),
    ('trap_inf_array', module('trap_inf_array', INF + "        @assertEqual([f], [f])"),
     r'Floating-point exception'),
]


def run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


class Case:
    def __init__(self, args, name, text):
        self.args = args
        self.dir = pathlib.Path(args.work) / name
        shutil.rmtree(self.dir, ignore_errors=True)
        self.dir.mkdir(parents=True)
        self.name = name
        self.pf = self.dir / f'{name}.pf'
        self.pf.write_text(text, encoding='utf-8')

    def generate(self):
        rc, out = run([sys.executable, str(PF2F90), 'module', str(self.pf),
                       str(self.dir / f'{self.name}.F90')], self.dir)
        if rc == 0:
            rc, out2 = run([sys.executable, str(PF2F90), 'driver', str(self.dir / 'driver.f90'),
                            str(self.pf)], self.dir)
            out += out2
        return rc, out

    def compile(self, flags=()):
        fc = [self.args.fc, '-ffree-line-length-none', f'-I{self.args.moddir}', *flags]
        rc, out = run(fc + ['-c', f'{self.name}.F90'], self.dir)
        if rc == 0:
            rc, out2 = run(fc + ['-c', 'driver.f90'], self.dir)
            out += out2
        if rc == 0:
            rc, out2 = run(fc + ['-o', 'suite', f'{self.name}.o', 'driver.o', self.args.lib],
                           self.dir)
            out += out2
        return rc, out

    def execute(self):
        return run([str(self.dir / 'suite')], self.dir)


def main():
    parser = argparse.ArgumentParser()
    for opt in ('--fc', '--moddir', '--lib', '--work'):
        parser.add_argument(opt, required=True)
    args = parser.parse_args()
    failures = []

    def expect(cond, name, what, out):
        print(('ok      ' if cond else 'FAILED  ') + f'{name}: {what}')
        if not cond:
            failures.append(name)
            print('    ' + out.replace('\n', '\n    '))

    c = Case(args, 'strict_good', GOOD)
    rc, out = c.generate()
    if rc == 0:
        rc, out = c.compile()
    if rc == 0:
        rc, out = c.execute()
    expect(rc == 0 and '1 passed, 0 failed' in out, 'strict_good', 'generates, compiles, passes', out)

    for name, text, pattern in GENERATION:
        rc, out = Case(args, name, text).generate()
        expect(rc == 1 and re.search(pattern, out), name, f'pf2f90 refuses ({pattern})', out)

    for name, text in ACCEPT:
        c = Case(args, name, text)
        rc, out = c.generate()
        if rc == 0:
            rc, out = c.compile()
        if rc == 0:
            rc, out = c.execute()
        expect(rc == 0 and '1 passed, 0 failed' in out, name, 'generates, compiles, passes', out)

    for name, decls, holds, fails, pattern in PAIRS:
        for suffix, assertion in (('ok', holds), ('ko', fails)):
            case = f'{name}_{suffix}'
            body = '\n'.join(x for x in (decls, assertion) if x)
            c = Case(args, case, module(case, body))
            rc, out = c.generate()
            if rc == 0:
                rc, out = c.compile()
            if rc != 0:
                expect(False, case, 'generates and compiles', out)
                continue
            rc, out = c.execute()
            if suffix == 'ok':
                expect(rc == 0 and '1 passed, 0 failed' in out, case, 'passes', out)
            else:
                # the failing assertion is the body's last line: module() puts the body at line 8
                line = 7 + body.count('\n') + 1
                where = rf'{case}\.pf:{line}: assertion failed'
                expect(rc != 0 and re.search(where, out) is not None and re.search(pattern, out) is not None,
                       case, f'fails at {case}.pf:{line} ({pattern})', out)

    for name, text, pattern in COMPILE:
        c = Case(args, name, text)
        rc, out = c.generate()
        ok = rc == 0
        if ok:
            rc, out = c.compile()
            ok = rc != 0 and re.search(pattern, out, re.IGNORECASE) is not None
        expect(ok, name, f'generates, then does not compile ({pattern})', out)

    for name, text, pattern in RUN:
        c = Case(args, name, text)
        rc, out = c.generate()
        if rc == 0:
            rc, out = c.compile()
            ok = rc == 0
            if ok:
                rc, out = c.execute()
                ok = rc != 0 and re.search(pattern, out) is not None
        else:
            ok = False
        expect(ok, name, f'compiles, then fails at run time ({pattern})', out)

    for name, text, pattern in TRAP:
        c = Case(args, name, text)
        rc, out = c.generate()
        if rc == 0:
            rc, out = c.compile(['-ffpe-trap=invalid'])
            ok = rc == 0
            if ok:
                rc, out = c.execute()
                if pattern is None:
                    ok = rc == 0 and '1 passed, 0 failed' in out
                else:
                    ok = rc != 0 and re.search(pattern, out) is not None and 'passed' not in out
        else:
            ok = False
        expect(ok, name, 'passes with -ffpe-trap=invalid' if pattern is None
               else f'compiles, then stops on a trap ({pattern})', out)

    print(f'{len(failures)} failed')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
