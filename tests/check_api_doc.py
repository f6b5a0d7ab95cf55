#!/usr/bin/env python3
"""Build the API documentation with FORD and fail on undocumented public entities.

Runs FORD on doc/ford.md (output in --output), then walks the parsed project: every module,
and in each module every public procedure with its arguments, public type with its
components and type-bound procedures, public variable and abstract interface must carry a
`!>` comment (STYLE: FORD comments on every public entity and argument). Any FORD warning
(e.g. a comment that FORD reads as metadata and drops) fails too.
Exit 0: documentation built, nothing missing; 1: something missing or FORD failed;
77: FORD is not installed (ctest reports the test as skipped).
Usage (ctest does this): check_api_doc.py --project doc/ford.md --output DIR [--fypp PROGRAM]
(FORD reads the .fypp sources through fypp: --fypp names the one the build uses.)
"""
import argparse
import contextlib
import io
import pathlib
import sys

try:
    import ford
    import ford.fortran_project
    from ford.sourceform import FortranVariable
except ImportError:
    print("skipped: FORD is not installed in this Python (pip install -r doc/requirements.txt)")
    sys.exit(77)


def documented(entity):
    if entity is None:
        return False
    if any(line.strip() for line in getattr(entity, "doc_list", []) or []):
        return True
    # An interface block for one procedure carries its comment on that procedure.
    return getattr(entity, "obj", "") == "interface" and documented(getattr(entity, "procedure", None))


def where(entity):
    return f"{getattr(entity, 'filename', '?')}: {getattr(entity, 'obj', 'entity')} '{entity.name}'"


def inherited_doc(dtype, name):
    """True when a parent type of dtype documents the binding `name`."""
    parent = getattr(dtype, "extends", None)
    while parent is not None and not isinstance(parent, str):
        for bound in getattr(parent, "boundprocs", []):
            if bound.name.lower() == name.lower() and documented(bound):
                return True
        parent = getattr(parent, "extends", None)
    return False


def missing_docs(project):
    missing = []

    def need(entity, label):
        if not documented(entity):
            missing.append(f"{label}: {where(entity)}")

    for module in project.modules:
        need(module, module.name)
        for proc in module.pub_procs.values():
            if getattr(proc, "module", None) is not None and proc.module is not module and \
                    getattr(proc, "parent", None) is not module:
                continue  # re-exported from another module: checked there
            need(proc, module.name)
            for arg in getattr(proc, "args", []) or []:
                if isinstance(arg, FortranVariable):
                    need(arg, f"{module.name}::{proc.name} argument")
        for dtype in module.pub_types.values():
            need(dtype, module.name)
            for comp in dtype.variables:
                need(comp, f"{module.name}::{dtype.name} component")
            for bound in dtype.boundprocs:
                if not documented(bound) and inherited_doc(dtype, bound.name):
                    continue  # overrides a binding documented in the parent type
                need(bound, f"{module.name}::{dtype.name} type-bound procedure")
        for var in module.pub_vars.values():
            need(var, module.name)
        for absint in module.pub_absints.values():
            need(absint, module.name)
    return missing


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--project", required=True, type=pathlib.Path)
    ap.add_argument("--output", required=True, type=pathlib.Path)
    ap.add_argument("--fypp", help="fypp program (default: the project file's preprocessor)")
    args = ap.parse_args()
    project_file = args.project.resolve()
    text = project_file.read_text(encoding="utf-8")
    proj_docs, settings = ford.load_settings(text, project_file.parent, project_file.name)
    cli = {"output_dir": str(args.output.resolve()), "quiet": True, "warn": False}
    if args.fypp:
        cli["preprocessor"] = args.fypp
    settings, proj_docs = ford.parse_arguments(cli, proj_docs, settings, project_file.parent)
    log = io.StringIO()
    with contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        status = ford.main(settings, proj_docs)
    out = log.getvalue()
    warnings = [line for line in out.splitlines() if "Warning" in line or "Error" in line]
    index = args.output / "index.html"
    ok = status == 0 and index.is_file()
    print(f"FORD {ford.__version__}: {'built ' + str(index) if ok else 'failed'}")
    for line in warnings:
        print(f"FORD: {line}")
    # The walk needs a fresh parse (the written project has been consumed by the output).
    project = ford.fortran_project.Project(settings)
    project.correlate()
    missing = missing_docs(project)
    for line in missing:
        print(f"undocumented public entity: {line}")
    n_modules = len(project.modules)
    print(f"{n_modules} modules, {len(missing)} undocumented public entities, {len(warnings)} FORD warnings")
    return 0 if ok and not missing and not warnings else 1


if __name__ == "__main__":
    sys.exit(main())
