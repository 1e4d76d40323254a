#!/usr/bin/env bash
# Builds the test suite with AddressSanitizer and UndefinedBehaviorSanitizer in ./build-sanitize
# (-O2 -g, jointid's assertions on, Eigen's off, benchmarks off) and runs it. Any finding aborts its test. Run after
# scripts/run_tests.sh (which installs the packages); extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
# The build runs the test programs too (gtest_discover_tests lists their tests), so the
# sanitizer settings hold for it as well as for ctest, and for the `jointid` runs of cli_tests.
# LeakSanitizer: the suppressions name only system libraries (VTK, Mesa, X11, fontconfig), which
# are not instrumented; see scripts/lsan.supp.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# -O2 rather than -O1: Eigen's expression templates are 10-30x slower when not inlined, which
# made the discovery tests take 150-600 s each; ASan and UBSan see the same accesses either way.
# Eigen's own index assertions are off (EIGEN_NO_DEBUG): ASan checks the accesses themselves.
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g -DEIGEN_NO_DEBUG" \
  -DJOINTID_SANITIZE=address,undefined -DJOINTID_BUILD_TESTS=ON -DJOINTID_BUILD_BENCH=OFF \
  >/dev/null
cmake --build build-sanitize -j "$(nproc)"
# Tests that draw through VTK and Mesa under xvfb-run: Mesa's driver, loaded with dlopen and
# closed before exit, leaves blocks that LeakSanitizer reports from an "<unknown module>" (the
# library is gone, so no suppression can name it). These run with leak detection off; ASan's
# memory errors and UBSan stay on. Every other test runs with leak detection.
drawing='^(io_vtk_png|io_vtk_demo|CliTest\..*)$'
ctest --test-dir build-sanitize --output-on-failure --timeout 1800 -j "$(nproc)" \
  -E "$drawing" "$@"
ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" \
  ctest --test-dir build-sanitize --output-on-failure --timeout 1800 -j "$(nproc)" \
  -R "$drawing" "$@"
