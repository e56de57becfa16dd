#!/usr/bin/env bash
# Flies tclod_tiles over every tileset of the corpus (docs/tiles.md, the corpus) and prints
# its table:
#
#   bench/tiles_corpus.sh [--build DIR] [--frames N] [--csv FILE] [--check] [DIR...]
#
# DIR: a directory holding tileset.json and, beside it, sizes.tsv (path<TAB>bytes) and
# SOURCE (its origin, licence and a line "producer: ..."). Without DIR, every directory
# of bench/data. For each it runs
#   1. at equal cost:    tclod_tiles --budget-ms sse16 --frames N (default 300)
#   2. streaming:        tclod_tiles --stream (its defaults: 2000 frames, half the bytes)
#   3. streaming, tight: the same with --memory-mb a quarter of the tileset's bytes
# and prints one row per tileset (the columns below), then one line
#   summary: tilesets=T equal_cost_ok=A stream_ok=B stream_quarter_ok=C
#            stream_memory_bound=D stream_quarter_memory_bound=E
# counting the tilesets that meet the goals of docs/tiles.md:
#   equal cost: violations=0 check_errors=0 benefit_vs_sse16 >= 1 and
#               cwsse_median <= sse16_cwsse_median;
#   streaming:  violations=0 nonresident_draws=0 mem_violations=0 check_errors=0,
#               t95_ms <= 0.7 x t95_baseline_ms, bytes_loaded <= bytes_loaded_baseline
#               and benefit_vs_sse16 >= 0.95;
#   memory bound: a streaming run that misses them while the median frame's
#               all-resident selection needs more bytes than the memory holds
#               (needed_bytes_median > memory_bytes): no loader can reach it.
# --csv FILE also writes every key of the three summary lines, a row per tileset and run.
# --check exits 1 when a run breaks a guarantee (violations, nonresident_draws,
# mem_violations or check_errors not 0) or, at equal cost, misses its goal: what CI
# checks on the committed corpus. Columns:
#   tileset tiles producer b_equal cwsse/sse16 b_stream t95/base bytes/base need/mem
#   b_quarter t95/base bytes/base need/mem
# (need/mem: needed_bytes_median / memory_bytes, a * after it marks a run whose goals are
# missed; > 1 is memory bound)
# (a ratio over a baseline of 0 prints as 0/0 when both are 0, as inf otherwise).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
build=build
frames=300
csv=
check=0
dirs=()
while [ $# -gt 0 ]; do
    case "$1" in
    --build) build="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --csv) csv="$2"; shift 2 ;;
    --check) check=1; shift ;;
    -h | --help) sed -n '2,38p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "tiles_corpus.sh: unknown option $1" >&2; exit 2 ;;
    *) dirs+=("${1%/}"); shift ;;
    esac
done
if [ ${#dirs[@]} -eq 0 ]; then
    for d in bench/data/*/; do
        [ -f "$d/tileset.json" ] && dirs+=("${d%/}")
    done
fi
tiles="$build/examples/tiles/tclod_tiles"
if [ ! -x "$tiles" ]; then
    echo "tiles_corpus.sh: $tiles not found (build with libcjson-dev installed)" >&2
    exit 1
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
[ -z "$csv" ] || : >"$csv"

# key=value pairs of a summary line into v[...]; ratio a/b as the table shows it
declare -A v
read_summary() {
    local kv
    v=()
    for kv in $(tail -n 1 "$1"); do
        case "$kv" in *=*) v["${kv%%=*}"]="${kv#*=}" ;; esac
    done
}
ratio() {
    awk -v a="$1" -v b="$2" 'BEGIN {
        if (b + 0 > 0) printf "%.3f", a / b; else if (a + 0 == 0) printf "0/0"; else printf "inf" }'
}
write_csv() { # tileset run: every key of v
    local k line
    [ -n "$csv" ] || return 0
    if [ ! -s "$csv" ]; then
        line="tileset,run"
        for k in $(printf '%s\n' "${!v[@]}" | sort); do line+=",$k"; done
        echo "$line" >"$csv"
    fi
    line="$1,$2"
    for k in $(head -n 1 "$csv" | tr ',' '\n' | tail -n +3); do line+=",${v[$k]:-}"; done
    echo "$line" >>"$csv"
}
guarantees_hold() {
    [ "${v[violations]:-1}" = 0 ] && [ "${v[check_errors]:-1}" = 0 ] &&
        [ "${v[nonresident_draws]:-0}" = 0 ] && [ "${v[mem_violations]:-0}" = 0 ]
}
stream_goals() {
    awk -v b="${v[benefit_vs_sse16]}" -v t="${v[t95_ms]}" -v tb="${v[t95_baseline_ms]}" \
        -v by="${v[bytes_loaded]}" -v bb="${v[bytes_loaded_baseline]}" \
        'BEGIN { exit !(t <= 0.7 * tb + 1e-9 && by <= bb && b >= 0.95) }'
}

row='%-26s %7s  %-28s %8s %11s | %8s %8s %10s %9s | %8s %8s %10s %9s\n'
printf "$row" tileset tiles producer b_equal cwsse/sse16 b_stream t95/base bytes/base need/mem \
    b_quarter t95/base bytes/base need/mem
n=0 eq_ok=0 st_ok=0 q_ok=0 st_bound=0 q_bound=0 failed=0
for d in "${dirs[@]}"; do
    name="$(basename "$d")"
    sizes=()
    [ -f "$d/sizes.tsv" ] && sizes=(--sizes "$d/sizes.tsv")
    producer="$( (sed -n 's/^producer: //p' "$d/SOURCE" 2>/dev/null || true) | head -n 1 | cut -c1-28)"
    n=$((n + 1))

    "$tiles" "${sizes[@]}" --budget-ms sse16 --frames "$frames" "$d/tileset.json" \
        >"$tmp/equal.txt" 2>"$tmp/equal.err" || { cat "$tmp/equal.err" >&2; exit 1; }
    read_summary "$tmp/equal.txt"
    write_csv "$name" equal_cost
    count="${v[tiles]}"
    b_equal="${v[benefit_vs_sse16]}"
    cw="$(ratio "${v[cwsse_median]}" "${v[sse16_cwsse_median]}")"
    ok=$(awk -v b="$b_equal" -v c="${v[cwsse_median]}" -v s="${v[sse16_cwsse_median]}" \
        'BEGIN { print (b >= 1.0 && c <= s * (1 + 1e-9)) ? 1 : 0 }')
    if guarantees_hold && [ "$ok" = 1 ]; then
        eq_ok=$((eq_ok + 1))
    else
        failed=1
        echo "tiles_corpus.sh: $name at equal cost: $(tail -n 1 "$tmp/equal.txt")" >&2
    fi
    mb="$(sed -n 's/^content: [0-9]* contents, [0-9.]* MB (\([0-9]*\) bytes).*/\1/p' "$tmp/equal.txt")"

    cols=()
    for run in stream quarter; do
        memory=()
        [ "$run" = quarter ] && memory=(--memory-mb "$(awk -v b="$mb" 'BEGIN { printf "%.9g", b / 4e6 }')")
        "$tiles" "${sizes[@]}" --stream "${memory[@]}" "$d/tileset.json" >"$tmp/$run.txt" \
            2>"$tmp/$run.err" || { cat "$tmp/$run.err" >&2; exit 1; }
        read_summary "$tmp/$run.txt"
        write_csv "$name" "$run"
        guarantees_hold || {
            failed=1
            echo "tiles_corpus.sh: $name --stream ($run): $(tail -n 1 "$tmp/$run.txt")" >&2
        }
        need="$(ratio "${v[needed_bytes_median]}" "${v[memory_bytes]}")"
        if guarantees_hold && stream_goals; then
            [ "$run" = stream ] && st_ok=$((st_ok + 1)) || q_ok=$((q_ok + 1))
        else
            if awk -v a="${v[needed_bytes_median]}" -v b="${v[memory_bytes]}" 'BEGIN { exit !(a > b) }'; then
                [ "$run" = stream ] && st_bound=$((st_bound + 1)) || q_bound=$((q_bound + 1))
            fi
            need="$need*"
        fi
        cols+=("${v[benefit_vs_sse16]}" "$(ratio "${v[t95_ms]}" "${v[t95_baseline_ms]}")"
            "$(ratio "${v[bytes_loaded]}" "${v[bytes_loaded_baseline]}")" "$need")
    done
    printf "$row" "$name" "$count" "$producer" "$b_equal" "$cw" "${cols[@]}"
done
echo "summary: tilesets=$n equal_cost_ok=$eq_ok stream_ok=$st_ok stream_quarter_ok=$q_ok" \
    "stream_memory_bound=$st_bound stream_quarter_memory_bound=$q_bound"
if [ "$check" = 1 ] && [ "$failed" = 1 ]; then
    exit 1
fi
exit 0
