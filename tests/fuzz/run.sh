#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang, AddressSanitizer,
# UndefinedBehaviorSanitizer and assertions, and fuzzes each for SECONDS
# starting from its committed corpus (tests/fuzz/README.md).
#
#   tests/fuzz/run.sh [SECONDS [WORK_DIR [TARGET...]]]
#
# SECONDS defaults to 60 per target (CI runs 40); WORK_DIR (default: a new
# temporary directory) receives the build, the growing corpora and any crash
# reproducer. TARGETs default to every target (select schedule calib learn stream, and
# tileset, the 3D Tiles reader of examples/tiles, when cJSON is found). Prints
# each target's executions, executions per second and corpus size; exits
# non-zero on the first crash, leak, sanitizer report, failed assertion or
# broken guarantee.
# Needs clang and its libFuzzer runtime (Debian: libclang-rt-14-dev).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
seconds="${1:-60}"
work="${2:-$(mktemp -d)}"
shift $(($# > 2 ? 2 : $#))
targets=("$@")
default_targets=$((${#targets[@]} == 0))
if ((default_targets)); then
    targets=(select schedule calib learn stream)
fi
jobs="$(nproc 2>/dev/null || echo 2)"
mkdir -p "$work"

# RelWithDebInfo without its -DNDEBUG: the library's assertions stay on, so
# that an input breaking an internal invariant (a NaN heap key, a non-root
# dropped) is a finding even when the guarantees the targets check still hold.
env CC=clang CXX=clang++ cmake -S "$root" -B "$work/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g" -DTCLOD_FUZZ=ON -DTCLOD_SANITIZE=address,undefined \
    -DTCLOD_BUILD_EXAMPLES=ON -DTCLOD_BUILD_BENCH=OFF >"$work/configure.log"
# the examples are configured for the tileset target alone (tests/tiles adds it
# when cJSON is found); no other example is built
build_targets="$(cmake --build "$work/build" --target help)"
if ((default_targets)) && grep -qx '\.\.\. fuzz_tileset' <<<"$build_targets"; then
    targets+=(tileset)
fi
cmake --build "$work/build" -j "$jobs" --target "${targets[@]/#/fuzz_}" >"$work/build.log"

export ASAN_OPTIONS=detect_leaks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
for t in "${targets[@]}"; do
    corpus="$work/corpus-$t"
    mkdir -p "$corpus"
    cp "$root/tests/fuzz/corpus/$t/"* "$corpus/"
    echo "fuzz_$t: ${seconds} s from $(ls "$corpus" | wc -l) committed inputs"
    # -max_len keeps inputs at the size of scenes the targets build; a unit
    # slower than 10 s is a hang.
    if ! (cd "$work" && "$work/build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" \
        -max_len=2048 -timeout=10 -print_final_stats=1 -artifact_prefix="$work/fuzz_$t-" \
        "$corpus" >"$work/fuzz_$t.log" 2>&1); then
        grep -E -A12 'guarantee broken|ERROR: |runtime error' "$work/fuzz_$t.log" | head -40 >&2 || true
        echo "fuzz_$t failed; reproducer and log in $work" >&2
        exit 1
    fi
    awk -v t="fuzz_$t" -v n="$(ls "$corpus" | wc -l)" '
        /stat::number_of_executed_units/ { runs = $2 }
        /stat::average_exec_per_sec/ { rate = $2 }
        END { printf "%s: %d executions, %d/s, corpus %d inputs\n", t, runs, rate, n }' \
        "$work/fuzz_$t.log"
done
