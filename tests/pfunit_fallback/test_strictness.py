#!/usr/bin/env python3
"""The pFUnit fallback refuses what real pFUnit 4.12 refuses.

Each case is a small .pf module. Generation-time cases must make pf2f90.py fail with the
expected message; compile-time cases must generate, then fail to compile against the
fallback's funit module with the expected compiler message; run-time cases must compile
and the test executable must fail with the expected output. A correct module must
generate, compile and pass, so that the refusals are not caused by a broken set-up, and so
must each ACCEPT case: what pFUnit 4.12 accepts, the fallback must not refuse.

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
    return (f"module {name}\n    use funit\n    use, intrinsic :: iso_fortran_env, only: real64\n"
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
    # pFUnit's suite function declares `suite` and `t` only: a module may export other names
    ('strict_suite_names', module('strict_suite_names', "        @assertEqual(1, method)",
                                  ).replace('contains\n', '    integer, public :: method = 1, '
                                            'fallback_start_test = 2, fallback_end_test = 3, '
                                            'fallback_run_test = 4\ncontains\n')),
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

    def compile(self):
        fc = [self.args.fc, '-ffree-line-length-none', f'-I{self.args.moddir}']
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

    print(f'{len(failures)} failed')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
