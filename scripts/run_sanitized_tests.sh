#!/usr/bin/env bash
# Builds the whole test suite (VTK and SLEPc included) with AddressSanitizer and
# UndefinedBehaviorSanitizer in ./build-sanitize (-O2 -g, jointid's assertions on, Eigen's off,
# no benchmarks) and runs it. Any finding aborts its test. CI runs the VTK-free build this way
# (scripts/run_tests_novtk.sh --sanitize); this script adds the VTK and SLEPc code. Run after
# scripts/run_tests.sh (which installs the packages); extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
export root
# The sanitizer settings (scripts/sanitizer_env.sh) are exported for the build as well: it runs
# the test programs (gtest_discover_tests lists their tests), and cli_tests runs `jointid`.
# shellcheck source=scripts/sanitizer_env.sh
source scripts/sanitizer_env.sh
cmake -S . -B build-sanitize "${sanitize_cmake_args[@]}" -DJOINTID_BUILD_TESTS=ON \
  -DJOINTID_BUILD_BENCH=OFF >/dev/null
cmake --build build-sanitize -j "$(nproc)"
# Tests that draw through VTK and Mesa under xvfb-run, and those that run under MPI: Mesa's
# driver and Open MPI's components, loaded with dlopen and closed before exit, leave blocks that
# LeakSanitizer reports from an "<unknown module>" (the library is gone, so no suppression can
# name it). These run with leak detection off; ASan's memory errors and UBSan stay on. Every
# other test runs with leak detection.
drawing='^(report_vtk_png|report_vtk_demo|CliTest\..*|fem_slepc_np[12])$'
ctest --test-dir build-sanitize --output-on-failure --timeout 1800 -j "$(nproc)" \
  -E "$drawing" "$@"
ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" \
  ctest --test-dir build-sanitize --output-on-failure --timeout 1800 -j "$(nproc)" \
  -R "$drawing" "$@"
