#!/usr/bin/env bash
# Installs what is missing, builds, and runs the paper's cantilever study (models I and II,
# cases I-IV), printing the paper's tables beside ours. Extra arguments go to the study.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh -DJOINTID_BUILD_BENCH=OFF
mkdir -p out
./build/examples/paper_cantilever/paper_cantilever --json out/paper_study.json "$@"
echo "results: out/paper_study.json"
