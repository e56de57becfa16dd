#!/usr/bin/env bash
# Regenerates the data and the figures of docs/benchmarks.md from a Release build:
#
#   bench/figures.sh [BUILD_DIR]          (default: build)
#
# Writes docs/figures/data/*.csv (tclod_bench, tclod_quality, and flyover_sim with its
# simulated GPU for the greedy and Robin Hood solvers) and then draws
# docs/figures/*.png with bench/plots.gp. Needs bash and gnuplot (gnuplot-nox). The
# full benchmark takes several minutes; run it on a quiet machine.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
build="${1:-build}"
data=docs/figures/data
for program in "$build/bench/tclod_bench" "$build/bench/tclod_quality" \
    "$build/examples/flyover_sim"; do
    if [ ! -x "$program" ]; then
        echo "figures.sh: $program not found; build with -DCMAKE_BUILD_TYPE=Release first" >&2
        exit 1
    fi
done
command -v gnuplot >/dev/null 2>&1 || {
    echo "figures.sh: gnuplot is not installed (Debian: apt-get install gnuplot-nox)" >&2
    exit 1
}
mkdir -p "$data"
set -x
"$build/bench/tclod_bench" >"$data/bench.csv"
"$build/bench/tclod_quality" >"$data/quality.csv"
"$build/examples/flyover_sim" --simulate-gpu --frames 2400 --solver greedy \
    --csv "$data/frame_time_greedy.csv" >/dev/null
"$build/examples/flyover_sim" --simulate-gpu --frames 2400 --solver robin_hood \
    --csv "$data/frame_time_robin_hood.csv" >/dev/null
gnuplot -e "data='$data'; out='docs/figures'" bench/plots.gp
