#!/usr/bin/env bash
# Installs what is missing, builds everything (benchmarks included, so they keep compiling),
# and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
