#!/usr/bin/env bash
# Writes every figure in README.md and docs/ that a jointid program prints, from a run
# (scripts/update_docs.py; docs/index.md, "How the figures stay current"). Needs a build in
# ./build (scripts/build.sh) with the example programs.
#   bash scripts/update_docs.sh                      all groups (the studies take minutes)
#   bash scripts/update_docs.sh --only quickstart,paper,commands    the cheap ones
#   bash scripts/update_docs.sh --check [--only ...] compare the pages with a new run; exit 1
#                                                    if a figure differs beyond its tolerance
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 scripts/update_docs.py "$@"
