#!/usr/bin/env bash
# Runs the commands whose figures docs/benchmarks.md quotes and writes their raw output to
# bench/results/, one CSV per command (or per table, where a table sweeps one option):
#
#   bench/results.sh [BUILD_DIR] [SET...]       (default: build; every set)
#
# SET is one of: bench targets cost dear churn stream thesis theta quality callgrind
# churn_callgrind restarts_callgrind flyover scheduler.
# A file is named after its command: the program, then each option without its dashes
# and joined to its value by '-' (tclod_bench --scene churn --frames 2400 writes
# tclod_bench_scene-churn_frames-2400.csv). Where a command is run several times its rows
# are prefixed by a column run (1, 2, ...), and by the swept option where there is one.
# flyover_sim prints a table, not CSV: its rows here are the key=value pairs of its summary
# line, and from its per-frame CSV the mean number of nodes drawn (mean_drawn; --scheduler)
# or, with --simulate-gpu, the frames whose unconstrained frame time reaches the target
# (reachable_frames) and avg_err over them.
#
# Needs bash and awk, and valgrind for the sets *callgrind. About fifteen minutes on two
# cores.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
build="${1:-build}"
shift || true
sets=("$@")
[ ${#sets[@]} -gt 0 ] || sets=(bench targets cost dear churn stream thesis theta quality callgrind
    churn_callgrind restarts_callgrind flyover scheduler)
bench="$build/bench/tclod_bench"
quality="$build/bench/tclod_quality"
flyover="$build/examples/flyover_sim"
for program in "$bench" "$quality" "$flyover"; do
    if [ ! -x "$program" ]; then
        echo "results.sh: $program not found; build with -DCMAKE_BUILD_TYPE=Release first" >&2
        exit 1
    fi
done
out=bench/results
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# name ARGS...: the file name of a command's results.
name() {
    local n="$1" a
    shift
    for a in "$@"; do
        case "$a" in
        --*) n="${n}_${a#--}" ;;
        *) n="${n}-${a}" ;;
        esac
    done
    printf '%s.csv' "$n"
}

# prefixed PREFIX HEADER_PREFIX FILE: a run's CSV on stdin, appended to FILE with each row
# prefixed (the header once, when FILE is empty).
prefixed() {
    local first=1
    [ ! -s "$3" ] || first=0
    awk -v p="$1" -v h="$2" -v first="$first" -F, \
        'NR == 1 { if (first) print h "," $0; next } { print p "," $0 }' >>"$3"
}

# repeated RUNS ARGS...: RUNS runs of tclod_bench ARGS, prefixed by run.
repeated() {
    local runs="$1" r file
    shift
    file="$out/$(name tclod_bench "$@")"
    : >"$file"
    for ((r = 1; r <= runs; ++r)); do
        "$bench" "$@" 2>/dev/null | prefixed "$r" run "$file"
    done
}

# summary_row KEYS: flyover_sim's output on stdin; the values of its summary line's keys KEYS
# (comma-separated) as one CSV row on stdout, empty where the line lacks a key.
summary_row() {
    awk -v keys="$1" '
        /^summary:/ { for (i = 2; i <= NF; ++i) { split($i, kv, "="); v[kv[1]] = kv[2] } }
        END {
            n = split(keys, k, ",")
            for (i = 1; i <= n; ++i) printf "%s%s", v[k[i]], (i < n ? "," : "\n")
        }'
}

# reachable CSV: frames whose unconstrained frame time reaches the target, and avg_err
# over them, from flyover_sim's per-frame CSV.
reachable() {
    awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
        $c["unconstrained_ms"] >= $c["target_ms"] {
            ++n; e = ($c["frame_ms"] - $c["target_ms"]) / $c["target_ms"]
            s += (e < 0 ? -e : e)
        }
        END { printf "%d,%.5f\n", n, (n ? s / n : 0) }' "$1"
}

run_bench() { "$bench" >"$out/$(name tclod_bench)" 2>/dev/null; }

# The performance targets: alternating runs, five of each.
run_targets() {
    local configs=(
        "--scene random --objects 10000 --solver greedy"
        "--scene random --objects 100000 --solver greedy --mode cold"
        "--scene random --objects 100000 --solver robin_hood"
    ) c r
    for c in "${configs[@]}"; do
        # shellcheck disable=SC2086 # c is a list of words
        : >"$out/$(name tclod_bench $c)"
    done
    for ((r = 1; r <= 5; ++r)); do
        for c in "${configs[@]}"; do
            # shellcheck disable=SC2086
            "$bench" $c 2>/dev/null | prefixed "$r" run "$out/$(name tclod_bench $c)"
        done
    done
}

# Selection cost against the frontier, and warm against cold on every family: one run of
# each.
run_cost() {
    local configs=(
        "--scene random --objects 10000 --solver greedy --frames 200"
        "--scene random --objects 100000 --solver greedy --frames 100"
        "--scene flyover --solver greedy"
        "--scene drift"
        "--solver greedy"
    ) c
    for c in "${configs[@]}"; do
        # shellcheck disable=SC2086 # c is a list of words
        "$bench" $c >"$out/$(name tclod_bench $c)" 2>/dev/null
    done
}

# A dear host: the batch and worker modes at 10^5 objects as every benefit spends N rounds
# of busy work (one run of each, prefixed by N).
run_dear() {
    local file n mode
    file="$out/$(name tclod_bench --scene random --objects 100000 --solver greedy --frames 60 \
        --benefit-work N)"
    : >"$file"
    for n in 0 25 50 100 200 400 800; do
        for mode in warm_floor warm_batch warm_parallel; do
            "$bench" --scene random --objects 100000 --solver greedy --frames 60 --mode "$mode" \
                --benefit-work "$n" 2>/dev/null | prefixed "$n" benefit_work "$file"
        done
    done
}

run_churn() {
    repeated 3 --scene churn
    repeated 3 --scene churn --frames 2400
}

# What streaming costs: three runs of each command (10^4 and 10^5 objects, and 10^4 under a
# memory budget that evicts), their rows and, one row per run, their summary lines.
run_stream() {
    local keys summary c r file
    keys="objects,flip_ns_median,warm_us_median,stream_us_median,stream_ratio"
    keys="$keys,resident_only_us_median,plan_us_median,requests_per_frame,evictions_per_frame"
    summary="$out/tclod_bench_scene-stream_summary.csv"
    echo "options,run,$keys" >"$summary"
    for c in "--objects 10000" "--objects 100000" "--objects 10000 --memory 0.001"; do
        # shellcheck disable=SC2086 # c is a list of words
        file="$out/$(name tclod_bench --scene stream $c)"
        : >"$file"
        for ((r = 1; r <= 3; ++r)); do
            # shellcheck disable=SC2086
            "$bench" --scene stream $c 2>"$tmp/err.txt" | prefixed "$r" run "$file"
            printf '%s,%s,%s\n' "$c" "$r" "$(summary_row "$keys" <"$tmp/err.txt")" >>"$summary"
        done
    done
}

run_thesis() { repeated 5 --scene thesis; }

run_theta() {
    local file theta r
    file="$out/$(name tclod_bench --scene thesis --mode split --theta X)"
    : >"$file"
    for theta in 0.1 0.3 1 3; do
        for ((r = 1; r <= 5; ++r)); do
            "$bench" --scene thesis --mode split --theta "$theta" 2>/dev/null |
                prefixed "$theta,$r" theta,run "$file"
        done
    done
}

run_quality() {
    "$quality" >"$out/$(name tclod_quality)" 2>/dev/null
    "$quality" --lookahead 2 >"$out/$(name tclod_quality --lookahead 2)" 2>/dev/null
}

need_valgrind() {
    command -v valgrind >/dev/null 2>&1 || {
        echo "results.sh: valgrind is not installed (Debian: apt-get install valgrind)" >&2
        exit 1
    }
}

# Instructions per solve: bench/callgrind.sh, the same count for the lookahead's rows, the
# thesis scene's flat solve and Robin Hood over the benchmark's 200 frames at 10^5 objects.
run_callgrind() {
    need_valgrind
    bench/callgrind.sh "$build" >"$out/callgrind.csv"
    local file="$out/callgrind_lookahead.csv" l c scene options mode ir
    echo "lookahead,scene,mode,objects,frames,instructions_per_solve,evaluations_per_solve" >"$file"
    for l in 0 2 8; do
        for c in "random|--objects 10000|cold" "random|--objects 10000|warm" \
            "flyover||cold" "flyover||warm"; do
            IFS='|' read -r scene options mode <<<"$c"
            # shellcheck disable=SC2086 # options is a list of words
            valgrind --tool=callgrind --toggle-collect='bench_solve*' \
                --callgrind-out-file="$tmp/callgrind.out" "$bench" --scene "$scene" $options \
                --frames 20 --solver greedy --mode "$mode" --lookahead "$l" \
                >"$tmp/row.csv" 2>/dev/null
            ir="$(awk '/^summary:/ { print $2 }' "$tmp/callgrind.out")"
            awk -F, -v ir="$ir" -v l="$l" 'NR == 2 {
                printf "%s,%s,%s,%s,%s,%.0f,%s\n", l, $1, $3, $4, $19, ir / $19, $15 }' \
                "$tmp/row.csv" >>"$file"
        done
    done
    # The thesis scene's split and flat solves, as callgrind.sh counts split (--quick: flat
    # times each of its 10 views once).
    file="$out/callgrind_scene-thesis_quick_frames-20_solver-mixed.csv"
    echo "mode,frames,instructions_per_solve,evaluations_per_solve,variables" >"$file"
    for mode in split flat; do
        valgrind --tool=callgrind --toggle-collect='bench_solve*' \
            --callgrind-out-file="$tmp/callgrind.out" "$bench" --scene thesis --quick \
            --frames 20 --solver mixed --mode "$mode" >"$tmp/row.csv" 2>/dev/null
        ir="$(awk '/^summary:/ { print $2 }' "$tmp/callgrind.out")"
        awk -F, -v ir="$ir" 'NR == 2 {
            printf "%s,%s,%.0f,%s,%s\n", $3, $19, ir / $19, $15, $20 }' "$tmp/row.csv" >>"$file"
    done
    # Robin Hood at 10^5 objects over the benchmark's 200 frames.
    file="$out/callgrind_scene-random_objects-100000_solver-robin_hood_mode-cold.csv"
    echo "frames,instructions_per_solve,evaluations_per_solve,instructions_per_evaluation" >"$file"
    valgrind --tool=callgrind --toggle-collect='bench_solve*' \
        --callgrind-out-file="$tmp/callgrind.out" "$bench" --scene random --objects 100000 \
        --solver robin_hood --mode cold >"$tmp/row.csv" 2>/dev/null
    ir="$(awk '/^summary:/ { print $2 }' "$tmp/callgrind.out")"
    awk -F, -v ir="$ir" 'NR == 2 {
        printf "%s,%.0f,%s,%.0f\n", $19, ir / $19, $15, ir / $19 / $15 }' \
        "$tmp/row.csv" >>"$file"
}

# The churn scene under callgrind's cache simulation (a last-level cache of 2 MB):
# instructions and last-level misses per select, with and without the edits.
run_churn_callgrind() {
    local file="$out/callgrind_scene-churn.csv" c mode frames
    need_valgrind
    echo "mode,frames,instructions_per_solve,ll_misses_per_solve" >"$file"
    for c in "warm|200" "warm_noedit|200" "warm|2400" "warm_noedit|2400"; do
        IFS='|' read -r mode frames <<<"$c"
        valgrind --tool=callgrind --toggle-collect='bench_solve*' --cache-sim=yes \
            --LL=2097152,16,64 --callgrind-out-file="$tmp/callgrind.out" "$bench" \
            --scene churn --frames "$frames" --mode "$mode" >/dev/null 2>&1
        awk -v m="$mode" -v f="$frames" '
            /^events:/ { for (i = 2; i <= NF; ++i) e[$i] = i }
            /^summary:/ {
                printf "%s,%s,%.0f,%.0f\n", m, f, $e["Ir"] / f,
                       ($e["ILmr"] + $e["DLmr"] + $e["DLmw"]) / f
            }' "$tmp/callgrind.out" >>"$file"
    done
}

# The greedy's search (restarts) on the random worlds: instructions per cold solve with one
# restart (the single T(n) pass) and with the default 32.
run_restarts_callgrind() {
    local file="$out/callgrind_restarts.csv" c objects frames restarts ir
    need_valgrind
    echo "restarts,objects,frames,instructions_per_solve,evaluations_per_solve,iterations_per_solve" \
        >"$file"
    for c in "1|1000|200" "32|1000|200" "1|10000|20" "32|10000|20"; do
        IFS='|' read -r restarts objects frames <<<"$c"
        valgrind --tool=callgrind --toggle-collect='bench_solve*' \
            --callgrind-out-file="$tmp/callgrind.out" "$bench" --scene random \
            --objects "$objects" --frames "$frames" --solver greedy --mode cold \
            --restarts "$restarts" >"$tmp/row.csv" 2>/dev/null
        ir="$(awk '/^summary:/ { print $2 }' "$tmp/callgrind.out")"
        awk -F, -v ir="$ir" -v r="$restarts" 'NR == 2 {
            printf "%s,%s,%s,%.0f,%s,%s\n", r, $4, $19, ir / $19, $15, $16 }' \
            "$tmp/row.csv" >>"$file"
    done
}

# Frame time against the target on the simulated GPU, 2400 frames.
run_flyover() {
    local file keys scene solver target c
    file="$out/$(name flyover_sim --simulate-gpu --frames 2400)"
    keys="frames,solver,mean_select_us,p99_select_us,mean_cost_ratio,violations,mean_ms"
    keys="$keys,stddev_ms,avg_err,p99_overshoot"
    echo "scene,gpu_c,target_ms,$keys,reachable_frames,avg_err_reachable" >"$file"
    for c in flyover:greedy flyover:robin_hood thesis:robin_hood thesis:mixed; do
        scene="${c%%:*}"
        solver="${c#*:}"
        for target in 12.5 25 50 100 200; do
            "$flyover" --scene "$scene" --solver "$solver" --simulate-gpu --target-ms "$target" \
                --frames 2400 --csv "$tmp/frames.csv" >"$tmp/out.txt"
            printf '%s,1,%s,%s,%s\n' "$scene" "$target" \
                "$(summary_row "$keys" <"$tmp/out.txt")" "$(reachable "$tmp/frames.csv")" >>"$file"
        done
    done
    for c in 0.95 1.05; do
        "$flyover" --solver greedy --simulate-gpu --target-ms 12.5 --gpu-c "$c" --frames 2400 \
            --csv "$tmp/frames.csv" >"$tmp/out.txt"
        printf 'flyover,%s,12.5,%s,%s\n' "$c" "$(summary_row "$keys" <"$tmp/out.txt")" \
            "$(reachable "$tmp/frames.csv")" >>"$file"
    done
}

# The scheduler against per-frame selection.
run_scheduler() {
    local file keys c
    file="$out/$(name flyover_sim --scheduler)"
    keys="frames,solver,mean_select_us,p99_select_us,mean_cost_ratio,violations"
    keys="$keys,changes_per_frame,pops_per_frame,draw_violations,morph_coverage"
    keys="$keys,select_us_per_frame,selections,unfinished,emergencies"
    echo "options,$keys,mean_drawn" >"$file"
    for c in "--frames 2400" "--frames 2400 --scheduler" \
        "--frames 2400 --scheduler --tau 0.25" "--frames 2400 --scheduler --tau 1" \
        "--frames 2400 --scheduler --morph 0" "--scene thesis --frames 1200" \
        "--scene thesis --frames 1200 --scheduler"; do
        # shellcheck disable=SC2086 # c is a list of words
        "$flyover" $c --csv "$tmp/frames.csv" >"$tmp/out.txt"
        printf '%s,%s,%s\n' "$c" "$(summary_row "$keys" <"$tmp/out.txt")" \
            "$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
                { s += $c["drawn"]; ++n } END { printf "%.0f", s / n }' "$tmp/frames.csv")" \
            >>"$file"
    done
}

for set in "${sets[@]}"; do
    case "$set" in
    bench | targets | cost | dear | churn | stream | thesis | theta | quality | callgrind \
        | churn_callgrind | restarts_callgrind | flyover | scheduler)
        echo "results.sh: $set" >&2
        "run_$set"
        ;;
    *)
        echo "results.sh: unknown set '$set'" >&2
        exit 1
        ;;
    esac
done
