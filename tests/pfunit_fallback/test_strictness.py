#!/usr/bin/env python3
"""The pFUnit fallback refuses what real pFUnit 4.12 refuses, and accepts what it accepts.

Each case is a small .pf module or a test procedure of one. Generation-time cases must make
pf2f90.py fail with the expected message; compile-time cases must generate, then fail to
compile against the fallback's funit module with the expected compiler message at their own
lines; run-time cases must compile and their test must fail with the expected output. A
correct module must generate, compile and pass, so that the refusals are not caused by a
broken set-up, and so must each ACCEPT case: what pFUnit 4.12 accepts, the fallback must not
refuse. Each PAIRS case is an assertion form pFUnit 4.12 accepts (a kind, rank or option of
its generated overloads, src/funit/asserts/Assert_Real.tmpl, Assert_Integer.tmpl,
Assert_Logical.tmpl, AssertString.F90, AssertBasic.F90 in Goddard-Fortran-Ecosystem/pFUnit):
written once so that it holds (the test must pass) and once so that it does not (the test must
fail, naming the .pf file and the line of the assertion).

Cases that differ only inside a test procedure (their `unit`s) are compiled together, as the
@test procedures of one module per kind of check (one that must compile and run, one that must
not compile, one under a floating-point trap): each unrestricted `use funit` costs about 0.2 s
of compile time, and one module per case took 70 s of CPU time (170 s alone on the loaded 2-core
test machine, past ctest's 240 s under -j2), the batches 11 s (20 s). A batch is no weaker
than separate modules: each test must give its own verdict (its own 'passed'/'FAILED' line, its
failure at its own line, its compiler error at one of its own lines) and the batch's counts
must add up. Cases that change the module itself (its name, uses, declarations, @before/@after)
stay modules of their own. The audit's cross check with pFUnit's own preprocessor (README.md,
"Unit tests and pFUnit") ran every case alone, through pFUnit and through the fallback.

Usage: test_strictness.py --fc gfortran --moddir <funit .mod dir> --lib <libfunit.a>
                          --work <scratch dir>
"""
import argparse
import collections
import pathlib
import re
import shutil
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
PF2F90 = HERE / 'pf2f90.py'
USES = ("    use funit\n    use, intrinsic :: iso_fortran_env, only: int8, int16, int64, real32, real64, "
        "real128\n    implicit none\n")


def module(name, body, helpers='', spec=''):
    """A .pf test module `name` with one test whose body is `body`; `spec`: declarations of the
    module (before `contains`), `helpers`: procedures after the test."""
    return (f"module {name}\n{USES}{spec}contains\n    @test\n    subroutine test_one()\n{body}\n"
            f"    end subroutine test_one\n{helpers}end module {name}\n")


# A case that differs from module(name, body) only by its body, its module declarations
# (`spec`) and its procedures (`helpers`): it can be one @test procedure of a batch module.
# `pattern`: what its failure must print (None: it must pass).
Unit = collections.namedtuple('Unit', 'name body pattern spec helpers')


def unit(name, body, pattern=None, spec='', helpers=''):
    return Unit(name, body, pattern, spec, helpers)


def alone(u):
    """The unit as a module of its own (the form pFUnit's cross check runs)."""
    return module(u.name, u.body, u.helpers, u.spec)


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
    # pFUnit 4.12 copies a continued directive unchanged and the compiler rejects the '@'
    # (checked with its preprocessor as of 4.12; joining the lines of a directive came after
    # 4.14, pFUnit issue #537)
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
    ('strict_before_args', module('strict_before_args', "        @assertTrue(.true.)",
                                  "    @before(x)\n    subroutine set_up()\n    end subroutine set_up\n"),
     r'not a pFUnit 4\.12 directive form'),
    ('strict_before_line', module('strict_before_line', "        @assertTrue(.true.)",
                                  "    @before\n    recursive subroutine set_up()\n"
                                  "    end subroutine set_up\n"),
     r'must be followed by its subroutine statement'),
    ('strict_module_name', module('other_name', "        @assertTrue(.true.)"),
     r'must be named like the file'),
]

# pFUnit 4.12 accepts these modules (each must generate, compile and pass)
ACCEPT = [
    # pFUnit's suite function declares `suite` and `t` only: a module may export other names
    ('strict_suite_names', module('strict_suite_names', "        @assertEqual(1, method)",
                                  spec='    integer, public :: method = 1, fallback_run_suite = 2, '
                                  'fallback_finish = 3, fallback_start_test = 4\n')),
    # a module exporting a type TestMethod: pFUnit's suite function calls FUnit's generic
    # TestMethod(...) next to `use <module>`, and gfortran 12 accepts it (pFUnit's preprocessor
    # as of 4.12 with a stand-in FUnit written from pFUnit's TestMethod.F90)
    ('strict_suite_testmethod', module('strict_suite_testmethod', "        @assertTrue(.true.)",
                                       spec='    type, public :: TestMethod\n    end type TestMethod\n')
     .replace('    use funit\n', '    use funit, only: SourceLocation, anyExceptions, assertTrue\n')),
    # pFUnitParser.py compares module and file names ignoring case ("do not match (ignoring
    # case)", since 4.7.0)
    ('strict_module_case', module('Strict_Module_Case', "        @assertTrue(.true.)")),
]

# pFUnit 4.12 accepts these test bodies (each must pass)
ACCEPT_BODIES = [
    # Assert_Real.tmpl: a no-tolerance overload (expected, actual, message, location) and a
    # tolerance one (expected, actual, tolerance, message, location), for every comparison
    unit('strict_real_message', "        real(real64) :: x\n"
         "        x = 2.0_real64\n"
         "        @assertEqual(2.0_real64, x, 'x is two')\n"
         "        @assertEqual([x, x], [x, x], 'arrays')\n"
         "        @assertEqual(2.0_real64, x, 0.0_real64, 'within 0')\n"
         "        @assertEqual([x], [x], 0.0_real64, 'within 0')"),
    unit('strict_real_compare', "        real(real64) :: x\n"
         "        x = 2.0_real64\n"
         "        @assertLessThan(1.0_real64, x, '1 < x')\n"
         "        @assertGreaterThan(x, 1.0_real64, 'x > 1')\n"
         "        @assertLessThan(x, 2.0_real64, 1.0e-12_real64)\n"
         "        @assertGreaterThan(x, 2.0_real64, 1.0e-12_real64, 'x > 2 - tol')"),
    # a comment past column 132 (pFUnit copies the line)
    unit('strict_tail_comment', "        integer :: n\n        n = 1  ! " + 'c' * 140
         + "\n        @assertEqual(1, n)"),
    # pFUnit matches an @assert at the start of a line only: one inside a literal is text
    unit('strict_literal_at', "        character(len=*), parameter :: s = "
         "'see @assertTrue; !'\n        @assertEqual(18, len(s))"),
    # ... also in a literal continued on the next line (pFUnit copies a line starting with '&')
    unit('strict_literal_continued', "        character(len=*), "
         "parameter :: s = 'abc &\n            &@assertTrue(x)'\n"
         "        @assertEqual(18, len(s))"),
    # Lines past gfortran's default 132 columns: tests/CMakeLists.txt compiles every suite with
    # -ffree-line-length-none, with pFUnit as with the fallback (this test compiles with it
    # too), so pFUnit 4.12 accepts them (its preprocessor with a stand-in FUnit, same flag):
    # code past column 132, a '!' in a literal past it, 131 characters in 221 bytes (gfortran
    # counts bytes), and an assert whose generated line '  call assertTrue(..., &' is longer
    unit('strict_long_line', "        call sleep(0)" + ' ' * 120 + '; continue'),
    unit('strict_long_quoted_bang', "        print *, 'a!b', " + "1 + " * 30 + "1"),
    unit('strict_long_bytes', "    character(len=*), parameter :: s = '" + '\u00e9' * 90
         + "'\n        @assertTrue(.true.)"),
    unit('strict_long_assert', "        @assertTrue(" + '.true. .and. ' * 10 + ".true.)"),
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

# pFUnit 4.12 refuses these at compile time: each must generate, then not compile, with a
# compiler error matching its pattern at one of its own lines
COMPILE = [
    unit('strict_helper_run', "        call run(1)", r"Procedure .run. at \(1\) is already defined",
         helpers="    subroutine run(n)\n        integer, intent(in) :: n\n"
         "        if (n < 0) stop\n    end subroutine run\n"),
    unit('strict_helper_assert', "        call assertEqual()",
         r"Cannot change attributes of USE-associated symbol assertequal",
         helpers="    subroutine assertEqual()\n    end subroutine assertEqual\n"),
    unit('strict_relative_no_tol', "        @assertRelativelyEqual(1.0_real64, 1.0_real64)",
     r"no specific subroutine for the generic .assertrelativelyequal."),
    # pFUnit's integer comparisons put a KeywordEnforcer third: the message goes by keyword
    unit('strict_int_message', "        @assertLessThan(1, 2, '1 < 2')",
     r"no specific subroutine for the generic .assertlessthan."),
    unit('strict_int_message_gt', "        @assertGreaterThan(2, 1, '2 > 1')",
     r"no specific subroutine for the generic .assertgreaterthan."),
    # pFUnit's string assertEqual calls its second argument `found`
    unit('strict_string_keyword', "        @assertEqual('a', actual='a')",
     r"no specific subroutine for the generic .assertequal."),
    # fHamcrest's `true` is public in pFUnit's FUnit module
    unit('strict_helper_true', "        @assertTrue(true())", r"(already defined|USE-associated)",
         helpers="    logical function true()\n        true = .true.\n    end function true\n"),
    # Kinds and ranks pFUnit 4.12 does not combine (Assert_Real.tmpl's no_tol/with_tol lists,
    # after tools/overload_template.py drops duplicates and the kinds gfortran lacks): expected
    # of another real kind than default real or the actual's, an array expected against a
    # scalar or another rank, a tolerance of another kind, an integer tolerance, rank 6
    unit('strict_kind_real64_real32', "        @assertEqual(1.0_real64, 1.0_real32)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_kind_real64_real128', "        @assertEqual(1.0_real64, 1.0_real128)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_rank_array_scalar', "        @assertEqual([1.0_real64], 1.0_real64)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_rank_mixed', "        real(real64) :: a(1, 1)\n        a = 1\n"
                                 "        @assertEqual([1.0_real64], a)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_tol_kind', "        @assertEqual(1.0_real32, 1.0_real32, 0.1_real64)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_tol_real128', "        @assertEqual(1.0_real64, 1.0_real64, 0.1_real128)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_tol_integer', "        @assertEqual(1.0_real64, 1.0_real64, 0)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_rank6', "        real(real64) :: a(1, 1, 1, 1, 1, 1)\n        a = 1\n"
                            "        @assertEqual(a, a)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_less_rank6', "        integer :: a(1, 1, 1, 1, 1, 1)\n        a = 1\n"
                                 "        @assertLessThan(0, a)",
     r"no specific subroutine for the generic .assertlessthan."),
    # the scalar may be the expected value or lhs only ("Rank 0 is also conformable" lists the
    # expected/lhs at rank 0, never the actual/rhs)
    unit('strict_lhs_array_rhs_scalar', "        @assertGreaterThan([4, 5], 3)",
     r"no specific subroutine for the generic .assertgreaterthan."),
    unit('strict_real_lhs_array', "        @assertLessThan([1.0_real64], 2.0_real64, 0.5_real64)",
     r"no specific subroutine for the generic .assertlessthan."),
    # Assert_Integer.tmpl: expected of the actual's kind or default only; no real expected for
    # an integer actual, no tolerance
    unit('strict_int_kinds', "        @assertEqual(1_int64, 1)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_int_kinds_8_16', "        @assertEqual(1_int8, 1_int16)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_real_int_actual', "        @assertEqual(1.0_real64, 1)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_int_tolerance', "        @assertEqual(1, 1, 1)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_relative_int', "        @assertRelativelyEqual(1, 1, 0.1)",
     r"no specific subroutine for the generic .assertrelativelyequal."),
    # Assert_Logical.tmpl puts a KeywordEnforcer third: the message goes by keyword
    unit('strict_logical_message', "        @assertEqual(.true., .true., 'msg')",
     r"no specific subroutine for the generic .assertequal."),
    # AssertString.F90: no array expected against a scalar; whitespace is a WhitespaceOptions,
    # whose component has no default (StringUtilities.F90)
    unit('strict_string_1d0d', "        @assertEqual(['a'], 'a')",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_whitespace_int', "        @assertEqual('a', 'a', whitespace=1)",
     r"no specific subroutine for the generic .assertequal."),
    unit('strict_whitespace_default', "        @assertEqual('a', 'a', whitespace=WhitespaceOptions())",
     r"No initializer for component .value."),
    # AssertBasic.F90: assertIsFinite takes a scalar
    unit('strict_finite_array', "        @assertIsFinite([1.0_real64])",
     r"no specific subroutine for the generic .assertisfinite."),
]

COMPILE += [unit(f'strict_type_{t.lower()}', "        @assertTrue(.true.)",
                 rf'Derived type definition of .{t.lower()}. at \(1\) has already been defined',
                 spec=f'    type :: {t}\n    end type {t}\n') for t in MATCHER_TYPES]

# Modules pFUnit 4.12 refuses at compile time: names its generated suite function
# `<module>_suite` declares (`suite`, `t`) or uses (the types TestSuite and Test) or the name of
# the wrapper module it generates, `Wrap<module>`, exported by the test module (each checked
# with pFUnit's preprocessor as of 4.12 and a stand-in FUnit; they compile under neither)
COMPILE_MODULES = [
    ('strict_suite_suite', module('strict_suite_suite', "        @assertTrue(.true.)",
                                  spec='    integer, public :: suite = 1\n'),
     r"Name .suite. at \(1\) is an ambiguous reference"),
    ('strict_suite_t', module('strict_suite_t', "        @assertTrue(.true.)",
                              spec='    integer, public :: t = 1\n'),
     r"Symbol .t. at \(1\) conflicts with symbol from module"),
    ('strict_suite_type', module('strict_suite_type', "        @assertTrue(.true.)",
                                 spec='    type, public :: TestSuite\n    end type TestSuite\n')
     .replace('    use funit\n', '    use funit, only: SourceLocation, anyExceptions, assertTrue\n'),
     r"Type name .testsuite. at \(1\) is ambiguous"),
    ('strict_suite_wrap', module('strict_suite_wrap', "        @assertTrue(.true.)",
                                 spec='    integer, public :: Wrapstrict_suite_wrap = 1\n'),
     r"is also the name of the current program unit"),
]

# (unit: its test must fail, the output matching the pattern)
RUN_BODIES = [
    unit('strict_relative_zero', "        @assertRelativelyEqual(0.0_real64, 0.0_real64, "
         "tolerance=1.0e-12_real64)", r'Zero denominator detected in AssertRelativelyEqual\.'),
    unit('strict_relative_zero_1d', "        @assertRelativelyEqual([1.0_real64, 0.0_real64], "
         "[1.0_real64, 0.0_real64], tolerance=1.0e-12_real64)",
         r'Zero denominator detected in AssertRelativelyEqual\.'),
    # pFUnit's assert_less_than with a tolerance: lhs < rhs + tolerance
    unit('strict_less_tol', "        @assertLessThan(2.0_real64, 1.5_real64, 0.5_real64)",
         r'is not less than'),
    # TRIM_ALL ignores the ends only: inner blanks count
    unit('strict_string_inner', "        @assertEqual('a b', 'a  b')", r'expected "a b" found "a  b"'),
    # same rank, other shape: pFUnit's conformable() fails ('Arrays not conformable')
    unit('strict_shape_real', "        real(real64) :: a(2, 3), b(3, 2)\n"
         "        a = 1\n        b = 1\n        @assertEqual(a, b, 1.0_real64)",
         r'Arrays not conformable: expected shape \[2, 3\] actual shape \[3, 2\]'),
    unit('strict_shape_int', "        @assertLessThan([1, 2], [3, 4, 5])", r'Arrays not conformable'),
    unit('strict_shape_string', "        @assertEqual(['a', 'b'], ['a'])", r'Arrays not conformable'),
    # AssertRelativelyEqual takes expected as 0*actual + expected: an Inf actual makes it NaN,
    # which fails even with an infinite tolerance
    unit('strict_relative_inf', "        use, intrinsic :: ieee_arithmetic\n"
         "        real(real64) :: f\n        f = ieee_value(f, ieee_positive_inf)\n"
         "        @assertRelativelyEqual(1.0_real64, f, f)", r'relative error'),
    # a whitespace value outside pFUnit's four
    unit('strict_whitespace_unknown', "        @assertEqual('a', 'a', whitespace=WhitespaceOptions(7))",
         r'Unknown case for handling Whitespace'),
]

# (name, .pf text, regex the run output must match): modules with @before/@after
RUN_MODULES = [
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
]

# (unit: pattern the run output must match, or None: must pass), compiled with the Debug unit
# tests' trap on invalid operations: pFUnit's array assert_equal (WHERE/ELSEWHERE) computes
# Inf - Inf for equal infinities, which traps; its scalar one returns on equality first and
# passes. In this order: the trap stops the batch, so the test that must pass comes first.
INF = "        use, intrinsic :: ieee_arithmetic\n        real(real64) :: f\n        f = ieee_value(f, ieee_positive_inf)\n"
TRAP = [
    unit('trap_inf_scalar', INF + "        @assertEqual(f, f)"),
    unit('trap_inf_array', INF + "        @assertEqual([f], [f])", r'Floating-point exception'),
]

def run(cmd, cwd):
    """Exit code and output, standard output and error joined in the order written (the harness
    flushes both after each message)."""
    p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return p.returncode, p.stdout


class Build:
    """A .pf file in a folder of its own under --work, generated, compiled and run as
    tests/CMakeLists.txt does (pf2f90.py module and driver, -ffree-line-length-none)."""

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

    def compile(self, flags=(), link=True):
        fc = [self.args.fc, '-ffree-line-length-none', f'-I{self.args.moddir}', *flags]
        rc, out = run(fc + ['-c', f'{self.name}.F90'], self.dir)
        if rc == 0 and link:
            rc, out2 = run(fc + ['-c', 'driver.f90'], self.dir)
            out += out2
            if rc == 0:
                rc, out2 = run(fc + ['-o', 'suite', f'{self.name}.o', 'driver.o', self.args.lib],
                               self.dir)
                out += out2
        return rc, out

    def execute(self):
        return run([str(self.dir / 'suite')], self.dir)

    def build_and_run(self, flags=()):
        """(stage reached: 'generate', 'compile' or 'run', exit code, output)"""
        rc, out = self.generate()
        if rc != 0:
            return 'generate', rc, out
        rc, out = self.compile(flags)
        if rc != 0:
            return 'compile', rc, out
        rc, out = self.execute()
        return 'run', rc, out


class Batch(Build):
    """Units as the @test procedures of one module `name`, each procedure named after its unit,
    its declarations before `contains` and its helpers after its procedure."""

    def __init__(self, args, name, units):
        assert len({u.name for u in units}) == len(units), 'unit names must differ'
        lines = [f'module {name}'] + USES.splitlines()
        self.units = units
        self.lines = {u.name: set() for u in units}   # the .pf lines of each unit
        self.last = {}                                # the line of its body's last statement

        def add(u, text):
            for line in text.splitlines():
                lines.append(line)
                self.lines[u.name].add(len(lines))

        for u in units:
            add(u, u.spec)
        lines.append('contains')
        for u in units:
            add(u, f'    @test\n    subroutine {u.name}()\n{u.body}')
            self.last[u.name] = len(lines)
            add(u, f'    end subroutine {u.name}\n{u.helpers}')
        lines.append(f'end module {name}')
        super().__init__(args, name, '\n'.join(lines) + '\n')


# the harness's line after each test: 'passed  <module>_suite.<test>' or 'FAILED  ...'
STATUS = re.compile(r'(passed|FAILED)  \w+_suite\.(\w+)$')
# gfortran's message header, 'file:line:column:' on a line of its own
DIAGNOSTIC = re.compile(r'^\S+?:(\d+):\d+(?:-\d+)?:$', re.MULTILINE)


def verdicts(out):
    """{test: (status, its output)} from a suite's output: a test's output runs from the status
    line before it to its own; key None: what follows the last status line."""
    tests, section = {}, []
    for line in out.splitlines():
        section.append(line)
        m = STATUS.match(line)
        if m:
            tests[m.group(2)] = (m.group(1), '\n'.join(section))
            section = []
    tests[None] = ('', '\n'.join(section))
    return tests


def diagnostics(out):
    """[(line, message)] of a gfortran run's messages."""
    heads = list(DIAGNOSTIC.finditer(out))
    ends = [h.start() for h in heads[1:]] + [len(out)]
    return [(int(h.group(1)), out[h.start():end]) for h, end in zip(heads, ends)]


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

    for name, text in [('strict_good', GOOD)] + ACCEPT:
        stage, rc, out = Build(args, name, text).build_and_run()
        expect(stage == 'run' and rc == 0 and '1 passed, 0 failed' in out, name,
               'generates, compiles, passes', out)

    for name, text, pattern in GENERATION:
        rc, out = Build(args, name, text).generate()
        expect(rc == 1 and re.search(pattern, out), name, f'pf2f90 refuses ({pattern})', out)

    # Every body that must compile, in one module: the ACCEPT bodies and the PAIRS that hold
    # must pass, the PAIRS that do not and the RUN bodies must fail at their last line
    units = list(ACCEPT_BODIES)
    for name, decls, holds, fails, pattern in PAIRS:
        units.append(unit(f'{name}_ok', '\n'.join(x for x in (decls, holds) if x)))
        units.append(unit(f'{name}_ko', '\n'.join(x for x in (decls, fails) if x), pattern))
    units += RUN_BODIES
    batch = Batch(args, 'strict_run_batch', units)
    stage, rc, out = batch.build_and_run()
    tests = verdicts(out) if stage == 'run' else {}
    for u in units:
        status, text = tests.get(u.name, (None, out if stage != 'run' else ''))
        if u.pattern is None:
            expect(status == 'passed', u.name, 'passes', text)
        else:
            line = batch.last[u.name]
            where = rf'{batch.name}\.pf:{line}: assertion failed'
            expect(status == 'FAILED' and re.search(where, text) is not None
                   and re.search(u.pattern, text) is not None, u.name,
                   f'fails at {batch.name}.pf:{line} ({u.pattern})', text)
    n_pass = sum(u.pattern is None for u in units)
    summary = f'{n_pass} passed, {len(units) - n_pass} failed'
    expect(stage == 'run' and rc != 0 and summary in out and len(tests) == len(units) + 1,
           batch.name, f'reports {summary}', out)

    # Every compile-time refusal of a unit, in one module: an error at one of its lines each
    batch = Batch(args, 'strict_compile_batch', COMPILE)
    rc, out = batch.generate()
    if rc == 0:
        rc, out = batch.compile(link=False)
        messages = diagnostics(out)
    else:
        messages = []
    for u in COMPILE:
        own = '\n'.join(text for line, text in messages if line in batch.lines[u.name])
        expect(rc != 0 and re.search(r'^Error: ', own, re.MULTILINE) is not None
               and re.search(u.pattern, own, re.IGNORECASE) is not None, u.name,
               f'generates, then does not compile ({u.pattern})', own or out)

    for name, text, pattern in COMPILE_MODULES:
        b = Build(args, name, text)
        rc, out = b.generate()
        ok = rc == 0
        if ok:
            rc, out = b.compile(link=False)
            ok = rc != 0 and re.search(pattern, out, re.IGNORECASE) is not None
        expect(ok, name, f'generates, then does not compile ({pattern})', out)

    for name, text, pattern in RUN_MODULES:
        stage, rc, out = Build(args, name, text).build_and_run()
        expect(stage == 'run' and rc != 0 and re.search(pattern, out) is not None, name,
               f'compiles, then fails at run time ({pattern})', out)

    # The trap stops the run: the test that must pass runs first, the trapped one reports nothing
    batch = Batch(args, 'strict_trap_batch', TRAP)
    stage, rc, out = batch.build_and_run(['-ffpe-trap=invalid'])
    tests = verdicts(out) if stage == 'run' else {None: ('', out)}
    for u in TRAP:
        if u.pattern is None:
            expect(tests.get(u.name, (None,))[0] == 'passed', u.name,
                   'passes with -ffpe-trap=invalid', out)
        else:
            expect(stage == 'run' and rc != 0 and u.name not in tests
                   and re.search(u.pattern, tests[None][1]) is not None, u.name,
                   f'compiles, then stops on a trap ({u.pattern})', out)

    print(f'{len(failures)} failed')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
