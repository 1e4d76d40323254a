#!/usr/bin/env bash
# Runs the README's quick start exactly as written: the ```sh block between
# <!-- quickstart:begin --> and <!-- quickstart:end --> of README.md, in a fresh working
# directory laid out like the repository root (a copy of examples/, `build` a link to the build
# directory, build/cli on PATH). Fails on any non-zero exit, on a missing output listed in
# <!-- quickstart:outputs ... --> (and <!-- quickstart:pictures ... --> in a build with VTK),
# and when the README's generated results differ from the run beyond their tolerance.
#   bash scripts/check_readme_quickstart.sh [BUILD_DIR]      (default ./build)
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 scripts/update_docs.py --check --only quickstart --build "${1:-build}"
