#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang in ./build-fuzz (every library instrumented
# with -fsanitize=fuzzer-no-link,address,undefined) and runs each for SECONDS (default 600), one
# after another, on one core. Not part of the normal test run; see docs/fuzzing.md.
#   scripts/run_fuzzers.sh [seconds] [target...]    (targets: fuzz_model_file fuzz_gmsh ...)
# Each target grows its corpus in build-fuzz/corpus/<target> (seeded from fuzz/corpus/<target>);
# a crash, sanitizer finding, leak, timeout (10 s) or out-of-memory (2 GB) stops it and leaves
# the input as build-fuzz/findings/<target>/crash-* (or timeout-*, oom-*, leak-*), and the
# script exits non-zero after the remaining targets have run. Logs: build-fuzz/logs/<target>.log.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
seconds=${1:-600}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(fuzz_model_file fuzz_gmsh fuzz_record_csv fuzz_uff58 fuzz_matrix_market fuzz_frf_csv
    fuzz_tests)
fi
command -v clang++ >/dev/null || { echo "clang++ not found (Debian: apt-get install clang)" >&2; exit 1; }

CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" -DJOINTID_BUILD_FUZZERS=ON -DJOINTID_BUILD_TESTS=OFF \
  -DJOINTID_BUILD_BENCH=OFF -DJOINTID_WITH_VTK=OFF -DJOINTID_WITH_SLEPC=OFF >/dev/null
cmake --build build-fuzz -j "${JOBS:-2}" --target "${targets[@]}"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
for target in "${targets[@]}"; do
  name=${target#fuzz_}
  corpus=build-fuzz/corpus/$target
  findings=build-fuzz/findings/$target
  mkdir -p "$corpus" "$findings" build-fuzz/logs
  dict=()
  [ -f "fuzz/$name.dict" ] && dict=(-dict="fuzz/$name.dict")
  echo "== $target: ${seconds} s (log: build-fuzz/logs/$target.log)"
  "build-fuzz/fuzz/$target" "$corpus" "fuzz/corpus/$target" "${dict[@]}" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
    -print_final_stats=1 -artifact_prefix="$findings/" >"build-fuzz/logs/$target.log" 2>&1 &
  pid=$!
  if ! wait "$pid"; then
    echo "   FOUND something: see build-fuzz/logs/$target.log and $findings/" >&2
    status=1
  fi
  rm -rf "/dev/shm/jointid_fuzz.$pid" # the target's input directory, left behind by a crash
  grep -E '^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)' \
    "build-fuzz/logs/$target.log" | sed 's/^/   /' || true
  echo "   corpus: $(find "$corpus" -type f | wc -l) inputs"
done
exit $status
