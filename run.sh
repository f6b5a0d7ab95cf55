#!/usr/bin/env bash
# Run a MULTICOR deck and plot its results.
#   ./run.sh [deck.dat]       default: reference experiment 1 (input/bending_case1.dat)
#   ./run.sh --experiments    all reference experiments and their figures (doc/experiments.md)
# Installs what is missing, builds a Release build in build/, runs the deck, writes
# results/<deck name>/<deck name>.h5 and its plots, and prints where they are (a run of the
# deck stopped by a signal, Ctrl-C, is continued from its checkpoint). With
# --experiments: input/bending_case1.dat, bending_case2.dat and bending_stack.dat into
# results/experiments/<case>/, the interface experiment (input/interface_shear.dat and its
# variants of friction, cohesion and band width, postproc/run_interface_experiment.py) into
# results/experiments/interface/, then the figures (PNG and PDF) and a summary of the
# measured figures in results/experiments/ (postproc/plot_experiments.py).
set -euo pipefail
source "$(cd "$(dirname "$0")" && pwd)/scripts/bootstrap.sh"

experiments=0
if [ "${1:-}" = "--experiments" ]; then
    experiments=1
    shift
    [ $# -eq 0 ] || die "--experiments takes no deck"
fi
deck=${1:-$MULTICOR_ROOT/input/bending_case1.dat}
# Experiment 1 is plotted at t = 5 ms (doc/experiments.md); other decks at their last output.
plot_time=()
[ $# -gt 0 ] || plot_time=(--time 5e-3)
if [ $experiments -eq 0 ]; then
    [ -f "$deck" ] || die "no such deck: $deck"
    deck=$(realpath "$deck")
fi
cd "$MULTICOR_ROOT"

ensure_system_deps
ensure_venv
configure_and_build build Release

# run_deck <deck> <folder>: runs the deck into the folder. A run of it stopped there by a
# signal (Ctrl-C: its partial file and checkpoint) is continued; when it cannot be (the deck
# changed since: multicor says why), the deck runs afresh, which multicor refuses while that
# stopped run could still be continued (its message says what to do).
run_deck() {
    local deck="$1" out="$2" name rc=0
    name=$(basename "$deck")
    name=${name%.*}
    if [ -f "$out/checkpoint.h5" ] && [ -f "$out/$name.h5.partial" ]; then
        say "continuing the run stopped in $out (to run $deck afresh, remove that folder first)"
        build/src/multicor "$deck" --output "$out" --restart "$out/checkpoint.h5" || rc=$?
        [ $rc -eq 0 ] && return 0
        [ $rc -eq 1 ] || exit $rc
        say "the stopped run cannot be continued (above): running $deck afresh"
    else
        say "running $deck"
    fi
    build/src/multicor "$deck" --output "$out"
}

if [ $experiments -eq 1 ]; then
    out="$MULTICOR_ROOT/results/experiments"
    for name in bending_case1 bending_case2 bending_stack; do
        run_deck "$MULTICOR_ROOT/input/$name.dat" "$out/$name"
    done
    say "running the interface experiment (input/interface_shear.dat and its variants)"
    .venv/bin/python postproc/run_interface_experiment.py --exe build/src/multicor --out "$out/interface"
    say "plotting the experiments"
    .venv/bin/python postproc/plot_experiments.py --results "$out"
    say "figures in $out"
    exit 0
fi

name=$(basename "$deck")
name=${name%.*}
# absolute, so that the commands the run prints (continue with --restart, --end) work from
# any folder, not only from the repository's root where this script runs the deck
out="$MULTICOR_ROOT/results/$name"
run_deck "$deck" "$out"
say "plotting"
.venv/bin/python postproc/plot_results.py "$out/$name.h5" --out "$out" "${plot_time[@]}"
say "results in $out"
