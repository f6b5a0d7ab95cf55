#!/usr/bin/env python3
"""The Release build's sweep calls no local solver: gfortran must have inlined
bipotential_local_solve_scaled (dem_bipotential) into the sweeps of dem_nlgs at link time.

The local solver runs once per contact and sweep; called instead of inlined, it costs 16 % of
the 200-disk deposit's time (0.492 against 0.414 ms per step, doc/performance.md). gfortran
decides the inlining by a size limit (src/CMakeLists.txt), so the solver growing by a few
lines loses it silently, with the same results: only the machine code tells. This script
disassembles the executable (objdump) and fails when a procedure of dem_nlgs calls the local
solver, naming the callers. It also fails when the disassembly shows no procedure of
dem_nlgs at all (a renamed module would otherwise pass unchecked).

    check_inlined.py OBJDUMP EXECUTABLE
"""
import re
import subprocess
import sys

SOLVER = "__dem_bipotential_MOD_bipotential_local_solve_scaled"
SWEEPS = "__dem_nlgs_MOD_"


def main():
    objdump, exe = sys.argv[1], sys.argv[2]
    header = re.compile(r"^[0-9a-f]+ <([^>]+)>:$")
    callers, nlgs_seen, caller = set(), 0, None
    proc = subprocess.Popen([objdump, "-d", "--no-show-raw-insn", exe], stdout=subprocess.PIPE,
                            text=True, errors="replace")
    for line in proc.stdout:
        m = header.match(line)
        if m:
            caller = m.group(1)
            nlgs_seen += caller.startswith(SWEEPS)
        elif caller and caller.startswith(SWEEPS) and "call" in line and f"<{SOLVER}" in line:
            callers.add(caller)
    if proc.wait() != 0:
        sys.exit(f"{objdump} -d {exe} failed")
    if nlgs_seen == 0:
        sys.exit(f"no procedure {SWEEPS}* in {exe}: cannot check the inlining")
    if callers:
        sys.exit(f"the local solver {SOLVER} is called, not inlined, by: {', '.join(sorted(callers))}\n"
                 "raise max-inline-insns-auto for dem/nlgs.f90 and dem/bipotential.f90 in src/CMakeLists.txt")
    print(f"{SOLVER} inlined into the {nlgs_seen} procedures of dem_nlgs in {exe}")


if __name__ == "__main__":
    main()
