# Shared set-up for run.sh and test.sh (sourced, not executed).
# Installs what is missing on Debian/Ubuntu (as root), or prints the exact command (not root);
# creates .venv from postproc/requirements.txt; configures and builds with CMake + Ninja.

MULTICOR_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# slurm-wlm and munge serve only the Slurm sweep tests (they skip without them), paraview and
# python3-paraview only the XDMF test of the continuum (meshio stands in without pvpython): a
# user who is not root and lacks only these gets a note, not an error. python3-siconos and
# python3-h5py (Siconos 4.4 for the system python3) are required: the FCLIB cross-check
# (tests/regression/test_fclib_siconos.py) fails without them on Debian; python3-siconos also
# runs bench/siconos_deposit.py and its comparison test. strace is required too: the tests of
# kills and signals at chosen system calls (restart, lock, I/O errors) inject them with it, and
# fail without it.
MULTICOR_APT_OPTIONAL="slurm-wlm munge paraview python3-paraview"
MULTICOR_APT_PACKAGES="gfortran cmake ninja-build libhdf5-dev hdf5-tools libopenblas-dev liblapack-dev libsuitesparse-dev gmsh python3 python3-venv python3-pip slurm-wlm munge paraview python3-paraview python3-siconos python3-h5py strace"

say() { printf '[multicor] %s\n' "$*"; }
die() { printf '[multicor] error: %s\n' "$*" >&2; exit 1; }

# Which of the required Debian packages are missing (empty when all are there).
missing_apt_packages() {
    local missing="" pkg
    if ! command -v dpkg-query >/dev/null 2>&1; then
        # Not a Debian system: check the tools themselves.
        for tool in gfortran cmake ninja h5fc gmsh python3; do
            command -v "$tool" >/dev/null 2>&1 || missing="$missing $tool"
        done
        echo "$missing"
        return
    fi
    for pkg in $MULTICOR_APT_PACKAGES; do
        case "$pkg" in
            python3|python3-venv|python3-pip)
                # A working python3 with venv (e.g. pyenv) is as good as the Debian packages.
                python3 -c 'import venv, ensurepip' >/dev/null 2>&1 && continue ;;
            cmake)
                command -v cmake >/dev/null 2>&1 && continue ;;
        esac
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' \
            || missing="$missing $pkg"
    done
    echo "$missing"
}

ensure_system_deps() {
    local missing
    missing=$(missing_apt_packages)
    [ -z "${missing// /}" ] && return 0
    if [ "$(id -u)" -ne 0 ]; then
        local required="" pkg
        for pkg in $missing; do
            case " $MULTICOR_APT_OPTIONAL " in *" $pkg "*) ;; *) required="$required $pkg" ;; esac
        done
        if [ -z "$required" ]; then
            say "note: without$missing the tests that need them skip (as root: apt-get install$missing)"
            return 0
        fi
        printf '[multicor] missing system packages:%s\n' "$missing" >&2
        printf '[multicor] install them with:\n    sudo apt-get update && sudo apt-get install -y%s\n' "$missing" >&2
        exit 1
    fi
    if ! command -v apt-get >/dev/null 2>&1; then
        die "missing:$missing, and no apt-get here: install them with your package manager"
    fi
    say "installing:$missing"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq || die "apt-get update failed"
    # shellcheck disable=SC2086
    apt-get install -y -qq --no-install-recommends $missing >/dev/null || die "apt-get install failed"
}

ensure_cmake_version() {
    local v
    v=$(cmake --version | head -n 1 | awk '{print $3}')
    if ! printf '3.20\n%s\n' "$v" | sort -V -C; then
        die "CMake >= 3.20 is required (found $v): pip install cmake, or use a newer distribution"
    fi
}

# Python virtual environment for postproc/ (numpy, h5py, matplotlib, pytest) and the API
# documentation (doc/requirements.txt: FORD), pinned.
ensure_venv() {
    local req="$MULTICOR_ROOT/postproc/requirements.txt" venv="$MULTICOR_ROOT/.venv"
    local doc_req="$MULTICOR_ROOT/doc/requirements.txt"
    local stamp="$venv/.requirements.sha256" sum
    sum=$(cat "$req" "$doc_req" | sha256sum | awk '{print $1}')
    if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$sum" ]; then
        return 0
    fi
    say "setting up the Python environment in .venv"
    python3 -m venv "$venv" || die "python3 -m venv failed (Debian: apt-get install python3-venv)"
    "$venv/bin/python" -m pip install -q --upgrade pip >/dev/null || die "pip upgrade failed"
    "$venv/bin/python" -m pip install -q -r "$req" || die "pip install -r postproc/requirements.txt failed"
    "$venv/bin/python" -m pip install -q -r "$doc_req" || die "pip install -r doc/requirements.txt failed"
    echo "$sum" > "$stamp"
}

# configure_and_build <build dir> <build type> [extra cmake args...]
# Configures <build dir> once, then builds every target, or only the targets listed in
# $MULTICOR_BUILD_TARGET when that is set (e.g. MULTICOR_BUILD_TARGET=multicor for the
# executable alone).
configure_and_build() {
    local dir="$1" type="$2"
    shift 2
    ensure_cmake_version
    mkdir -p "$dir"
    if [ ! -f "$dir/build.ninja" ]; then
        say "configuring $type build in $dir"
        cmake -S "$MULTICOR_ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE="$type" \
            -DPython3_EXECUTABLE="$MULTICOR_ROOT/.venv/bin/python" "$@" >"$dir/configure.log" 2>&1 \
            || { cat "$dir/configure.log" >&2; die "CMake configuration failed (log: $dir/configure.log)"; }
    fi
    local target=()
    # shellcheck disable=SC2206
    [ -n "${MULTICOR_BUILD_TARGET:-}" ] && target=(--target $MULTICOR_BUILD_TARGET)
    say "building ($type${MULTICOR_BUILD_TARGET:+, target $MULTICOR_BUILD_TARGET})"
    cmake --build "$dir" -j "$(nproc)" "${target[@]}" >"$dir/build.log" 2>&1 \
        || { tail -n 60 "$dir/build.log" >&2; die "build failed (log: $dir/build.log)"; }
}
