#!/usr/bin/env bash
# The build without VTK and without the SLEPc engine (what a headless node without PETSc gets):
# configures ./build-novtk with -DJOINTID_WITH_VTK=OFF -DJOINTID_WITH_SLEPC=OFF (no benchmarks),
# builds it and runs its tests: everything but the VTK files and pictures, plus the checks that
# `modes`, `discover` and `--engine slepc` say what this build lacks. Extra arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build-novtk -DCMAKE_BUILD_TYPE=Release -DJOINTID_WITH_VTK=OFF \
  -DJOINTID_WITH_SLEPC=OFF -DJOINTID_BUILD_TESTS=ON -DJOINTID_BUILD_BENCH=OFF "$@" >/dev/null
cmake --build build-novtk -j "$(nproc)"
ctest --test-dir build-novtk --output-on-failure -j "$(nproc)"
