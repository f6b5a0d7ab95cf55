#!/usr/bin/env bash
# Run every MULTICOR test suite: Fortran unit tests (pFUnit or its fallback), malformed-deck
# errors, regression runs of the executable, and the Python post-processing tests (which run
# beside the CTest suites of the Debug build).
# Installs what is missing and builds a Debug build with run-time checks in build-debug/,
# where everything runs but the long suites (ctest label long: the long-horizon unit suites,
# thousands of coupled steps each, ~20x faster without the run-time checks, and every
# combination of the solver's settings on every particle deck), which run on the Release
# build in build/ (the one run.sh uses), with the malformed-deck tests (label baddeck) again,
# so that the messages do not depend on the build type, and the check that the Release sweep
# inlines its local solver (label build). The Debug build also compiles the benchmark programs
# of bench/ (not part of `all`), so that a change of an interface they call cannot leave them
# broken (tests/CMakeLists.txt, bench_bonded_command_line). Exit code is non-zero on any failure.
set -uo pipefail
source "$(cd "$(dirname "$0")" && pwd)/scripts/bootstrap.sh"
cd "$MULTICOR_ROOT"

ensure_system_deps
ensure_venv
MULTICOR_BUILD_TARGET="all bench" configure_and_build build-debug Debug

status=0
# The Python tests run on one core while the CTest suites run beside them: pytest alone left
# a core idle for about 100 s of a 12-minute run. Their output is printed at the end. The
# Release phase starts when the Debug suites end, whether pytest has ended or not (it uses no
# build): waiting for it first would leave a core idle whenever it outlasts them.
say "Python tests (postproc) and CTest suites, side by side"
pytest_log=build-debug/pytest.log
.venv/bin/python -m pytest -q postproc/tests >"$pytest_log" 2>&1 &
pytest_pid=$!
ctest --test-dir build-debug --output-on-failure -j "$(nproc)" -LE long || status=1
say "Long suites, malformed decks and the inlined sweep on the Release build (build/)"
# in a subshell: a failed build stops this phase (its log is printed), not the wait for pytest
if (MULTICOR_BUILD_TARGET="multicor long_tests" configure_and_build build Release); then
    ctest --test-dir build --output-on-failure -j "$(nproc)" -L 'baddeck|long|build' || status=1
else
    status=1
fi
pytest_status=0
wait "$pytest_pid" || pytest_status=1
say "Python tests (postproc)"
cat "$pytest_log"
[ $pytest_status -eq 0 ] || status=1
exit $status
