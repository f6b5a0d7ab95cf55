#!/usr/bin/env python3
"""Check the package layering of src/ and that every `use` has `only:` (STYLE.md 2 and 16).

Usage: check_layering.py SRC_DIR

Every .f90, .fypp and .f90.in file under SRC_DIR belongs to the package of its first folder
(core, io, fem, dem, coupling, driver). Each `use` (and each submodule's parent) must name a
module of a package it may use:

    core     -> core
    io       -> core, io
    fem      -> core, fem
    dem      -> core, dem
    coupling -> core, fem, dem, coupling
    driver   -> every package

i.e. arrows point down, io, fem and dem never use each other, coupling never uses io or
driver. Intrinsic modules (`use, intrinsic ::`) may be used anywhere; the other modules that
src/ does not define are allowed only where listed in EXTERNAL (HDF5 only in io). Every `use`
statement, intrinsic ones included, must have `only:`. Prints each violation as
file:line: message and exits with 1 when there is any, 0 otherwise. Python 3 standard
library only.
"""
import pathlib
import re
import sys

ALLOWED = {
    'core': {'core'},
    'io': {'core', 'io'},
    'fem': {'core', 'fem'},
    'dem': {'core', 'dem'},
    'coupling': {'core', 'fem', 'dem', 'coupling'},
    'driver': {'core', 'io', 'fem', 'dem', 'coupling', 'driver'},
}
# Non-intrinsic modules that src/ does not define, and the packages that may use them.
EXTERNAL = {
    'hdf5': {'io'},
    'h5lt': {'io'},
    'h5ds': {'io'},
    'omp_lib': set(ALLOWED),
}
SUFFIXES = ('.f90', '.fypp', '.f90.in')

MODULE_RE = re.compile(r'^\s*module\s+(?!procedure\b|subroutine\b|function\b)(\w+)\s*$', re.I)
SUBMODULE_RE = re.compile(r'^\s*submodule\s*\(\s*(\w+)(?::\w+)?\s*\)\s*(\w+)', re.I)
USE_RE = re.compile(r'^\s*use\b\s*(?:,\s*(intrinsic|non_intrinsic)\s*)?(?:::)?\s*(\w+)\s*(,\s*only\s*:)?', re.I)


def logical_lines(path):
    """Yield (first line number, text) of each statement: comments (a `!` outside quotes)
    removed, OpenMP conditional lines (`!$ `) kept, `&` continuation lines joined."""
    text, start = '', None
    for number, raw in enumerate(path.read_text(encoding='utf-8', errors='replace').splitlines(), 1):
        stripped = raw.lstrip()
        if stripped.startswith('!$') and stripped[2:3] in (' ', '&'):
            # OpenMP conditional compilation (`!$ use omp_lib, ...`): a statement with OpenMP
            raw = '  ' + stripped[2:]
        kept, quote = [], None
        for ch in raw:
            if quote:
                kept.append(ch)
                if ch == quote:
                    quote = None
            elif ch in '"\'':
                quote = ch
                kept.append(ch)
            elif ch == '!':
                break
            else:
                kept.append(ch)
        line = ''.join(kept).strip()
        if start is None:
            start = number
        if text and line.startswith('&'):
            line = line[1:]
        if line.endswith('&'):
            text += line[:-1] + ' '
            continue
        yield start, text + line
        text, start = '', None


def source_files(src):
    return sorted(p for p in src.rglob('*') if p.is_file() and p.name.endswith(SUFFIXES))


def check(src):
    """The violations found under src, as 'file:line: message'."""
    files = source_files(src)
    package_of_module = {}
    uses = []
    problems = []
    for path in files:
        rel = path.relative_to(src)
        package = rel.parts[0] if len(rel.parts) > 1 else ''
        if package not in ALLOWED:
            problems.append(f'{rel}: not in a package folder ({", ".join(sorted(ALLOWED))})')
            continue
        for line, text in logical_lines(path):
            m = MODULE_RE.match(text)
            if m:
                package_of_module[m.group(1).lower()] = package
            m = SUBMODULE_RE.match(text)
            if m:
                uses.append((rel, line, package, m.group(1).lower(), True, False))
            m = USE_RE.match(text)
            if m:
                intrinsic = (m.group(1) or '').lower() == 'intrinsic'
                uses.append((rel, line, package, m.group(2).lower(), bool(m.group(3)), intrinsic))
    for rel, line, package, module, has_only, intrinsic in uses:
        where = f'{rel}:{line}'
        if not has_only:
            problems.append(f'{where}: use {module} without only:')
        if intrinsic:
            continue
        if module in package_of_module:
            target = package_of_module[module]
            if target not in ALLOWED[package]:
                problems.append(f'{where}: {package} uses {module} of package {target} '
                                f'({package} may use {", ".join(sorted(ALLOWED[package]))})')
        elif module in EXTERNAL:
            if package not in EXTERNAL[module]:
                problems.append(f'{where}: {package} uses the external module {module} '
                                f'(allowed in {", ".join(sorted(EXTERNAL[module]))})')
        else:
            problems.append(f'{where}: use {module}: a module that src/ does not define and that is '
                            'neither intrinsic nor a known external one')
    return files, uses, problems


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2])
        return 2
    src = pathlib.Path(argv[1])
    files, uses, problems = check(src)
    if not files:
        print(f'{src}: no Fortran sources')
        return 1
    for problem in problems:
        print(problem)
    print(f'{len(files)} files, {len(uses)} use statements: {len(problems)} violations')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
