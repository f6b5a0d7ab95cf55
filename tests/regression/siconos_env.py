"""The system Python that runs Siconos 4.4 for the regression tests (Debian's python3-siconos
and python3-h5py, which the project's .venv does not see): MULTICOR_SICONOS_PYTHON, default
/usr/bin/python3, run without the virtual environment's variables."""
import os
import pathlib
import shutil
import subprocess


def siconos_python(imports="siconos.numerics, h5py"):
    """(interpreter, env) when it imports `imports`; else prints why and exits: 1 on Debian,
    where scripts/bootstrap.sh installs Siconos (a missing package is a failure), 77 (ctest's
    skip) elsewhere."""
    python = os.environ.get("MULTICOR_SICONOS_PYTHON", "/usr/bin/python3")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    if shutil.which(python) is None:
        reason = f"no {python}"
    else:
        proc = subprocess.run([python, "-c", f"import {imports}"], capture_output=True, text=True, env=env)
        if proc.returncode == 0:
            return python, env
        reason = f"{python} cannot import {imports}: " + (proc.stderr.strip().splitlines() or ["?"])[-1]
    if shutil.which("dpkg-query") or pathlib.Path("/etc/debian_version").exists():
        print(f"FAILED Siconos: {reason}. On Debian: apt-get install -y python3-siconos python3-h5py "
              "(scripts/bootstrap.sh installs them)")
        raise SystemExit(1)
    print(f"skipped: {reason} (Siconos 4.4 with h5py; set MULTICOR_SICONOS_PYTHON)")
    raise SystemExit(77)
