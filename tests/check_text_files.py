#!/usr/bin/env python3
"""The project's text files hold no control character other than the line feed (and the tab
in decks, where the syntax allows it: tests/data has decks with tabs on purpose): a tab or
BEL in a Markdown formula is the trace of a backslash eaten by an escape (\\t of \\text, \\a
of \\alpha), and a stray byte in a deck or a source is invisible in an editor. Fortran lines
(.f90, .fypp, .pf; fypp directives aside) hold at most 132 characters, gfortran's default and
the project's hard limit: fprettify's format test leaves comment lines alone. pFUnit tests
(.pf) are ASCII: pFUnit's preprocessor (bin/funit/pFUnitParser.py) opens them in the locale's
encoding, which a Python before 3.7 under the C locale takes as ASCII.
Usage (ctest does this): check_text_files.py ROOT. Exit 1 with file:line:column of each."""
import pathlib
import re
import sys

SUFFIXES = {".md", ".f90", ".fypp", ".pf", ".py", ".dat", ".geo", ".msh", ".cmake", ".txt",
            ".sh", ".toml", ".cfg", ".slurm", ".csv"}
FOLDERS = ["doc", "input", "src", "tests", "bench", "postproc", "scripts", ".ci"]
CONTROL = re.compile(r"[\x00-\x09\x0b-\x1f\x7f]")
DECK_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")
FORTRAN = {".f90", ".fypp", ".pf"}
MAX_FORTRAN = 132


def files(root):
    yield from (root / n for n in ["README.md", "CMakeLists.txt", "run.sh", "test.sh"]
                if (root / n).is_file())
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*")):
            if path.is_file() and (path.suffix in SUFFIXES or path.parent.name == ".ci"):
                yield path


def main():
    root = pathlib.Path(sys.argv[1])
    bad = checked = 0
    for path in files(root):
        checked += 1
        text = path.read_bytes().decode("utf-8", errors="replace")
        for number, line in enumerate(text.split("\n"), start=1):
            for m in (DECK_CONTROL if path.suffix == ".dat" else CONTROL).finditer(line):
                bad += 1
                print(f"{path.relative_to(root)}:{number}:{m.start() + 1}: control character "
                      f"0x{ord(m.group()):02x}")
            if path.suffix in FORTRAN and len(line) > MAX_FORTRAN and not line.lstrip().startswith("#:"):
                bad += 1
                print(f"{path.relative_to(root)}:{number}: {len(line)} characters, more than {MAX_FORTRAN}")
            if path.suffix == ".pf" and not line.isascii():
                bad += 1
                column = next(i for i, c in enumerate(line) if not c.isascii()) + 1
                print(f"{path.relative_to(root)}:{number}:{column}: not ASCII (pFUnit's preprocessor reads "
                      "a .pf file in the locale's encoding)")
    print(f"{checked} files checked, {bad} control characters, long Fortran lines or non-ASCII .pf lines")
    return 1 if bad or not checked else 0


if __name__ == "__main__":
    sys.exit(main())
