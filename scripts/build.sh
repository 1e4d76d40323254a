#!/usr/bin/env bash
# Configures and builds jointid (Release) in ./build. Usage: scripts/build.sh [extra cmake args]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
# shellcheck source=scripts/compiler_cache.sh
source scripts/compiler_cache.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${cache_cmake_args[@]}" "$@" >/dev/null
cmake --build build -j "$(nproc)"
