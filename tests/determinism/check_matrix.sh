#!/usr/bin/env bash
# Builds tests/determinism/test_determinism across compilers, optimisation
# levels, instruction sets and library kinds, and checks that every build
# prints the same hash per configuration and passes its golden hashes
# (docs/api.md, "Determinism").
#
#   tests/determinism/check_matrix.sh [--quick] [WORK_DIR]
#
# The full matrix is gcc and clang x -O0, -O2, -O3 x without and with
# -march=x86-64-v3 x static and shared: 24 builds. --quick builds 6 of them
# that between them cover every value of every axis (the CI's choice). The
# -march=x86-64-v3 builds are skipped, and said so, on a machine whose CPU
# cannot run them. -O0 builds keep assertions; the others define NDEBUG.
# WORK_DIR (default: a new temporary directory) holds the builds and the
# printed hashes. Exits non-zero when a build fails, a golden hash differs or
# two builds disagree.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
quick=0
if [ "${1:-}" = --quick ]; then
    quick=1
    shift
fi
work="${1:-$(mktemp -d)}"
mkdir -p "$work"
jobs="$(nproc 2>/dev/null || echo 2)"

# x86-64-v3 = AVX2, BMI1/2, F16C, FMA, LZCNT, MOVBE, XSAVE on top of v2.
v3_runs=0
if [ "$(uname -m)" = x86_64 ] && grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo &&
    grep -qw bmi2 /proc/cpuinfo && grep -qw movbe /proc/cpuinfo; then
    v3_runs=1
fi

combos=()
if [ "$quick" = 1 ]; then
    combos=(
        "gcc -O0 - static"
        "gcc -O2 v3 shared"
        "gcc -O3 - shared"
        "clang -O0 v3 shared"
        "clang -O2 - static"
        "clang -O3 v3 static"
    )
else
    for cc in gcc clang; do
        for opt in -O0 -O2 -O3; do
            for arch in - v3; do
                for kind in static shared; do
                    combos+=("$cc $opt $arch $kind")
                done
            done
        done
    done
fi

reference=""
ran=0
skipped=0
failed=0
printf '%-8s %-4s %-16s %-7s %s\n' compiler opt arch library result
for combo in "${combos[@]}"; do
    read -r cc opt arch kind <<<"$combo"
    flags="$opt"
    arch_name=default
    if [ "$arch" = v3 ]; then
        if [ "$v3_runs" = 0 ]; then
            printf '%-8s %-4s %-16s %-7s %s\n' "$cc" "$opt" x86-64-v3 "$kind" \
                "skipped (this CPU cannot run x86-64-v3 code)"
            skipped=$((skipped + 1))
            continue
        fi
        flags="$flags -march=x86-64-v3"
        arch_name=x86-64-v3
    fi
    if [ "$opt" != -O0 ]; then
        flags="$flags -DNDEBUG"
    fi
    shared=OFF
    if [ "$kind" = shared ]; then
        shared=ON
    fi
    dir="$work/$cc$opt-$arch_name-$kind"
    log="$dir.log"
    if ! env CC="$cc" cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=None \
        -DCMAKE_C_FLAGS="$flags" -DBUILD_SHARED_LIBS="$shared" -DTCLOD_BUILD_EXAMPLES=OFF \
        -DTCLOD_BUILD_BENCH=OFF >"$log" 2>&1 ||
        ! cmake --build "$dir" -j "$jobs" --target test_determinism >>"$log" 2>&1; then
        printf '%-8s %-4s %-16s %-7s %s\n' "$cc" "$opt" "$arch_name" "$kind" "BUILD FAILED ($log)"
        failed=$((failed + 1))
        continue
    fi
    exe="$dir/tests/test_determinism"
    "$exe" --print >"$dir.hashes"
    if [ -z "$reference" ]; then
        reference="$dir.hashes"
    fi
    result=ok
    if ! "$exe" >>"$log" 2>&1; then
        result="GOLDEN MISMATCH ($log)"
        failed=$((failed + 1))
    elif ! cmp -s "$reference" "$dir.hashes"; then
        result="DIFFERS from $(basename "$reference" .hashes)"
        failed=$((failed + 1))
    fi
    ran=$((ran + 1))
    printf '%-8s %-4s %-16s %-7s %s\n' "$cc" "$opt" "$arch_name" "$kind" "$result"
done

echo
if [ -n "$reference" ]; then
    echo "hashes ($(basename "$reference" .hashes)):"
    sed 's/^/  /' "$reference"
fi
echo "determinism matrix: $ran built and compared, $skipped skipped, $failed failed"
[ "$failed" = 0 ] && [ "$ran" -gt 0 ]
