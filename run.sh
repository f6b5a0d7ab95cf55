#!/usr/bin/env bash
# Run a MULTICOR deck and plot its results.
#   ./run.sh [deck.dat]       default: the reference deck (input/cantilever.dat for now)
# Installs what is missing, builds a Release build in build/, runs the deck, writes
# results/<deck name>/<deck name>.h5 and its plots, and prints where they are.
set -euo pipefail
source "$(cd "$(dirname "$0")" && pwd)/scripts/bootstrap.sh"

deck=${1:-$MULTICOR_ROOT/input/cantilever.dat}
[ -f "$deck" ] || die "no such deck: $deck"
deck=$(realpath "$deck")
cd "$MULTICOR_ROOT"
name=$(basename "$deck")
name=${name%.*}
out="results/$name"

ensure_system_deps
ensure_venv
configure_and_build build Release

say "running $deck"
build/src/multicor "$deck" --output "$out"
say "plotting"
.venv/bin/python postproc/plot_results.py "$out/$name.h5" --out "$out"
say "results in $MULTICOR_ROOT/$out"
