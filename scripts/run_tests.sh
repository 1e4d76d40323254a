#!/usr/bin/env bash
# Installs what is missing, builds everything (benchmarks included, so they keep compiling),
# and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Explicit: another script may have left the options off in the cache.
bash scripts/build.sh -DJOINTID_BUILD_TESTS=ON -DJOINTID_BUILD_BENCH=ON
ctest --test-dir build --output-on-failure -j "$(nproc)"
