#!/usr/bin/env bash
# Instructions per solve, counted by callgrind: repeatable where wall-clock times are not
# (shared or throttled machines), for comparing one commit with another.
#
#   bench/callgrind.sh [BUILD_DIR] > instructions.csv
#
# BUILD_DIR (default: build) holds a Release build with the benchmarks. For each
# configuration below, tclod_bench runs under valgrind --tool=callgrind with collection
# switched on only inside bench_solve, the function that makes the timed call of every
# frame (warm-up frames are not counted), so the instruction count divided by the timed
# frames is the cost of one solve, callbacks included. Output, CSV on stdout:
#
#   scene,solver,mode,objects,frames,instructions_per_solve,evaluations_per_solve,
#   instructions_per_evaluation
#
# Needs bash, valgrind and awk. Takes a few minutes (valgrind runs about 50x slower).
set -euo pipefail

build="${1:-build}"
bench="$build/bench/tclod_bench"
if [ ! -x "$bench" ]; then
    echo "callgrind.sh: $bench not found; build with -DCMAKE_BUILD_TYPE=Release first" >&2
    exit 1
fi
command -v valgrind >/dev/null 2>&1 || {
    echo "callgrind.sh: valgrind is not installed (Debian: apt-get install valgrind)" >&2
    exit 1
}
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# scene, extra options, solver, mode. Small frame counts: instruction counts vary
# little from frame to frame, and the whole list stays within minutes under valgrind.
configs=(
    "random|--objects 10000 --frames 20|greedy|cold"
    "random|--objects 10000 --frames 20|greedy|warm"
    "random|--objects 10000 --frames 20|robin_hood|cold"
    "random|--objects 100000 --frames 20|robin_hood|cold"
    "random|--objects 10000 --frames 20|mixed|cold"
    "random|--objects 10000 --frames 20|threshold_tuned|cold"
    "random|--objects 10000 --frames 20|pq_stop|cold"
    "random|--objects 10000 --frames 20|flat|cold"
    "flyover|--frames 20|greedy|cold"
    "flyover|--frames 20|greedy|warm"
    "flyover|--frames 20|robin_hood|cold"
    "thesis|--quick --frames 20|mixed|split"
)

echo "scene,solver,mode,objects,frames,instructions_per_solve,evaluations_per_solve,instructions_per_evaluation"
for config in "${configs[@]}"; do
    IFS='|' read -r scene options solver mode <<<"$config"
    out="$tmp/callgrind.out"
    # shellcheck disable=SC2086 # options is a list of words
    valgrind --tool=callgrind --toggle-collect='bench_solve*' --callgrind-out-file="$out" \
        "$bench" --scene "$scene" $options --solver "$solver" --mode "$mode" \
        >"$tmp/row.csv" 2>"$tmp/valgrind.log" || {
        echo "callgrind.sh: $scene $solver $mode failed:" >&2
        cat "$tmp/valgrind.log" >&2
        exit 1
    }
    instructions="$(awk '/^summary:/ { print $2 }' "$out")"
    # The row's columns: objects (4), evaluations per frame (15), timed frames (19).
    awk -F, -v ir="$instructions" 'NR == 2 {
        per_solve = ir / $19
        printf "%s,%s,%s,%s,%s,%.0f,%s,%.0f\n", $1, $2, $3, $4, $19, per_solve, $15,
               ($15 > 0 ? per_solve / $15 : 0)
    }' "$tmp/row.csv"
done
