#!/usr/bin/env python3
"""Fallback for pFUnit: turn pFUnit 4 ``.pf`` test modules into plain Fortran.

Used only when CMake does not find a real pFUnit. It accepts a subset of what pFUnit 4.12's
preprocessor (``funitproc``, ``bin/funit/pFUnitParser.py``) accepts, and refuses at
generation time what real pFUnit would refuse, at generation or at compile time:

* directives are matched with pFUnit's own patterns: ``@test`` (no options), ``@before``
  and ``@after`` alone on their line; ``@assert<Variant>(...)`` alone on its line, ending
  with ``)``: no trailing comment and no ``&`` continuation (pFUnit 4.12 copies such a line
  unchanged and the compiler rejects the ``@``; joining the continuation lines of a
  directive came after 4.14, pFUnit issue #537); at least as many comma-separated arguments
  as pFUnit requires for the variant;
* the line after ``@before``/``@after`` (comments aside) must be the ``subroutine``
  statement, as pFUnit reads it;
* test procedure names <= 63 characters (Fortran), module name = file name, case aside
  (pFUnitParser.py compares them with ``.lower()``: "do not match (ignoring case)"; its
  registry calls ``<file name>_suite``, and Fortran ignores case) and <= 57 characters (pFUnit
  generates ``<module>_suite`` and ``Wrap<module>``).

No line-length rule: tests/CMakeLists.txt compiles every suite with ``-ffree-line-length-none``,
with pFUnit as with the fallback, so a long line compiles under both.

Supported asserts: ``@assertEqual``, ``@assertTrue``, ``@assertFalse``, ``@assertLessThan``,
``@assertGreaterThan``, ``@assertRelativelyEqual`` (tolerance required, as in pFUnit),
``@assertIsFinite`` (scalar). The generated code calls the same procedures with the same
``location=SourceLocation(file, line)`` argument as pFUnit; the fallback's ``funit`` module
(funit.fypp) exports pFUnit's public names, so a helper named like one of them (``run``...)
fails to compile as under pFUnit. After the module come the statements pFUnit writes: the
module ``Wrap<module>`` (it uses ``funit`` and the test module and exports nothing) and the
function ``<module>_suite``, which uses ``funit``, the test module and the wrapper
unrestricted, declares ``suite`` and ``t``, builds each test with the generic
``TestMethod(name, procedure, setUp=, tearDown=)`` and adds it with ``suite%addTest``; so a
name clashes (or, as a module's own ``TestMethod`` type with gfortran 12, does not) exactly as
under pFUnit. The driver runs each suite as pFUnit's ``TestCase%runBare`` runs a test
(``fallback_run_suite``): the ``@before`` procedure, then, only if it raised nothing, the test
and the ``@after`` procedure (also after a failed test, never after a failed set-up).

Checked against pFUnit (README.md, "Unit tests and pFUnit", has the details): an audit of
commit 17faccf ran pFUnit's own preprocessor (``pFUnitParser.py`` at pFUnit's commit 05504b8,
after 4.14, and a "4.12-approx" copy without its two later changes: the joining of continued
directives and a special case for ``@assertExceptionRaised``) on the 65 ``.pf`` files: the
same 587 tests as this script, same names, same order, from 3 265 assertion directives; its
output compiled against a stand-in FUnit written from pFUnit's sources (1 133 specific
assertions) and every suite passed; of 29 241 assertion call forms, both modules accepted the
same 1 134; and test_strictness.py's cases, each alone, behave through it as the test says.

Line numbers are preserved (annotations become blank lines, asserts stay on their line),
so compiler messages and failure reports point into the ``.pf`` file.

Usage:
    pf2f90.py module  <in.pf> <out.F90>
    pf2f90.py driver  <out.f90> <in.pf> [<in.pf> ...]
    pf2f90.py check   <in.pf> [<in.pf> ...]
"""
import os
import re
import sys

# pFUnit 4.12 pFUnitParser.py: minimum operand count per @assert variant.
PFUNIT_ASSERT_OPERANDS = {
    'fail': 0, 'equal': 2, 'notequal': 2, 'true': 1, 'false': 1, 'lessthan': 2,
    'lessthanorequal': 2, 'greaterthan': 2, 'greaterthanorequal': 2, 'relativelyequal': 2,
    'isinfinite': 1, 'isfinite': 1, 'isnan': 1, 'ismemberof': 2, 'contains': 2, 'any': 1,
    'all': 1, 'notall': 1, 'none': 1, 'ispermutationof': 2, 'exceptionraised': 0,
    'sameshape': 2, 'that': 2, '_that': 2,
}
# The variants the fallback implements (funit.fypp).
SUPPORTED = {'equal', 'true', 'false', 'lessthan', 'greaterthan', 'relativelyequal', 'isfinite'}

# pFUnit's patterns (same regular expressions, anchored with re.match).
ASSERT = re.compile(r'\s*@assert(' + '|'.join(PFUNIT_ASSERT_OPERANDS) + r')\s*\((.*)\)\s*$',
                    re.IGNORECASE)
AT_TEST = re.compile(r'\s*@test(\s*(\(.*\))?\s*$)', re.IGNORECASE)
AT_BEFORE = re.compile(r'\s*@before\s*$', re.IGNORECASE)
AT_AFTER = re.compile(r'\s*@after\s*$', re.IGNORECASE)
SUBROUTINE = re.compile(r'\s*subroutine\s+(\w*)\s*(\([\w\s,]*\))?\s*(!.*)*$', re.IGNORECASE)
MODULE = re.compile(r'\s*module\s+(\w*)\s*$', re.IGNORECASE)
COMMENT = re.compile(r'\s*(!.*|)$')

MAX_NAME = 63          # Fortran 2008 name length
MAX_MODULE = MAX_NAME - len('_suite')


class PfError(Exception):
    pass


def fortran_string(text):
    return "'" + text.replace("'", "''") + "'"


def code_outside_literals(line, quote=None):
    """`line` before its comment, with the contents of its character literals blanked
    (a literal may hold '@assert' or '!': pFUnit copies such a line unchanged and it
    compiles), and the quote of a literal continued on the next line ('...&' at the end), else
    None. `quote`: the literal this line continues (its leading blanks and '&' skipped)."""
    out = []
    if quote:
        line = line.lstrip()
        line = line[1:] if line.startswith('&') else line
    for c in line:
        if quote:
            if c == quote:
                quote = None
            out.append(c if quote is None else ' ')
        elif c in "'\"":
            quote = c
            out.append(c)
        elif c == '!':
            break
        else:
            out.append(c)
    continued = quote if quote and line.rstrip().endswith('&') else None
    return ''.join(out), continued


def check_arguments(args, where):
    """Balanced parentheses and no '!' outside character literals."""
    depth, quote = 0, None
    for c in args:
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == '!':
            raise PfError(f"{where}: comment inside an @assert line (pFUnit would pass it into "
                          "the generated call)")
        elif c == '(':
            depth += 1
        elif c == ')':
            depth -= 1
            if depth < 0:
                raise PfError(f"{where}: unbalanced parentheses in @assert arguments")
    if depth != 0 or quote:
        raise PfError(f"{where}: unbalanced parentheses or quotes in @assert arguments")


def parse(path):
    """Return (module name, tests, befores, afters, translated lines)."""
    with open(path, encoding='utf-8') as f:
        lines = f.read().splitlines()
    base = os.path.basename(path)
    stem = os.path.splitext(base)[0]
    module = None
    tests, befores, afters = [], [], []
    looking_for_test = False
    expect_sub = None      # 'before'/'after': next non-comment line must be the subroutine
    out = []
    literal = None         # quote of a character literal continued from the line before
    for number, line in enumerate(lines, start=1):
        where = f"{base}:{number}"
        if COMMENT.match(line):
            out.append(line)
            continue
        if expect_sub:
            s = SUBROUTINE.match(line)
            if not s or not s.group(1):
                raise PfError(f"{where}: @{expect_sub} must be followed by its subroutine "
                              "statement (pFUnit: 'Improper format in declaration of test "
                              "procedure')")
            (befores if expect_sub == 'before' else afters).append(s.group(1))
            expect_sub = None
            out.append(line)
            continue
        if line.lstrip().startswith('@'):
            a = ASSERT.match(line)
            if a:
                variant, args = a.group(1), a.group(2)
                n = args.count(',') + (1 if args.strip() else 0)
                if n < PFUNIT_ASSERT_OPERANDS[variant.lower()]:
                    raise PfError(f"{where}: @assert{variant} needs at least "
                                  f"{PFUNIT_ASSERT_OPERANDS[variant.lower()]} arguments")
                if variant.lower() not in SUPPORTED:
                    raise PfError(f"{where}: @assert{variant} is not supported by the fallback")
                check_arguments(args, where)
                indent = line[:len(line) - len(line.lstrip())]
                out.append(f"{indent}call assert{variant}({args}, location=SourceLocation("
                           f"{fortran_string(base)}, {number})); if (anyExceptions()) return")
                continue
            if AT_TEST.match(line):
                if line.strip().lower() != '@test':
                    raise PfError(f"{where}: @test options are not supported by the fallback")
                looking_for_test = True
            elif AT_BEFORE.match(line):
                expect_sub = 'before'
            elif AT_AFTER.match(line):
                expect_sub = 'after'
            else:
                raise PfError(f"{where}: not a pFUnit 4.12 directive form (pFUnit would copy "
                              f"it unchanged and the compiler would reject it): {line.strip()}")
            out.append('')
            continue
        code, literal = code_outside_literals(line, literal)
        if '@assert' in code.lower():
            # pFUnit copies the line unchanged; the compiler would reject the '@'
            raise PfError(f"{where}: an @assert must stand alone on its line")
        m = MODULE.match(line)
        if m and m.group(1).lower() != 'procedure':
            module = m.group(1)   # as pFUnit: the last 'module <name>' line wins
        if looking_for_test:
            s = SUBROUTINE.match(line)
            if s:
                tests.append(s.group(1))
                looking_for_test = False
        out.append(line)
    if expect_sub:
        raise PfError(f"{base}: @{expect_sub} at the end of the file")
    if looking_for_test:
        raise PfError(f"{base}: @test not followed by a subroutine statement")
    if module is None:
        raise PfError(f"{base}: no module found")
    if module.lower() != stem.lower():
        # pFUnit >= 4.7 (pFUnitParser.py): "module name (...) and file name (...) do not match
        # (ignoring case)"; its registry calls <file name>_suite, and Fortran ignores case
        raise PfError(f"{base}: module '{module}' must be named like the file ('{stem}', case "
                      f"aside): pFUnit's registry calls {stem}_suite")
    if len(module) > MAX_MODULE:
        raise PfError(f"{base}: module name longer than {MAX_MODULE} characters (pFUnit "
                      f"generates '{module}_suite')")
    for t in tests + befores + afters:
        if len(t) > MAX_NAME:
            raise PfError(f"{base}: procedure name '{t}' is longer than {MAX_NAME} characters")
    if not tests:
        raise PfError(f"{base}: no @test procedure found")
    if len(befores) > 1 or len(afters) > 1:
        raise PfError(f"{base}: at most one @before and one @after per module")
    return module, tests, befores, afters, out


def suite_lines(module, tests, befores, afters):
    """What pFUnit 4.12's preprocessor appends to a test module without a test case type: the
    empty wrapper module `Wrap<module>` and the suite function `<module>_suite`, statement for
    statement (pFUnitParser.py, printHeader and printMakeSuite), so that the names they use
    resolve, or clash with the test module's, as under pFUnit."""
    text = ["", f"module Wrap{module}", "    use funit", f"    use {module}", "    implicit none",
            "    private", "contains", f"end module Wrap{module}", "",
            f"function {module}_suite() result(suite)", "    use funit", f"    use {module}",
            f"    use Wrap{module}", "    implicit none", "    type(TestSuite) :: suite",
            "    class(Test), allocatable :: t",
            f"    suite = TestSuite('{module}_suite')"]
    extra = ''
    if befores:
        extra += f", setUp={befores[0]}"
    if afters:
        extra += f", tearDown={afters[0]}"
    for name in tests:
        text += ["    if (allocated(t)) deallocate (t)",
                 f"    allocate (t, source=TestMethod('{name}', {name}{extra}))",
                 "    call suite%addTest(t)"]
    text.append(f"end function {module}_suite")
    return text


def write_module(src, dst):
    module, tests, befores, afters, out = parse(src)
    with open(dst, 'w', encoding='utf-8') as f:
        f.write('\n'.join(out + [''] + suite_lines(module, tests, befores, afters)) + '\n')


def write_driver(dst, sources):
    modules = [parse(src)[0] for src in sources]
    text = ["! Generated by pf2f90.py (pFUnit fallback). Do not edit.", "program funit_driver",
            "    use funit_fallback_runner, only: TestSuite, fallback_run_suite, fallback_finish",
            "    implicit none", "    interface"]
    for m in modules:
        text += [f"        function {m}_suite() result(suite)", "            import :: TestSuite",
                 "            type(TestSuite) :: suite", f"        end function {m}_suite"]
    text.append("    end interface")
    text += [f"    call fallback_run_suite({m}_suite())" for m in modules]
    text += ["    call fallback_finish()", "end program funit_driver"]
    with open(dst, 'w', encoding='utf-8') as f:
        f.write('\n'.join(text) + '\n')


def main(argv):
    try:
        if len(argv) == 4 and argv[1] == 'module':
            write_module(argv[2], argv[3])
        elif len(argv) >= 4 and argv[1] == 'driver':
            write_driver(argv[2], argv[3:])
        elif len(argv) >= 3 and argv[1] == 'check':
            for src in argv[2:]:
                parse(src)
        else:
            print(__doc__, file=sys.stderr)
            return 2
    except PfError as exc:
        print(f"pf2f90: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
