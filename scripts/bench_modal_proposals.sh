#!/usr/bin/env bash
# Measurements behind the proposals for fem/modal.cpp and fem/assembly in
# docs/benchmarks_modal.md: bench_modal_scale's `proto` engine (a copy of the library's
# shift-invert operator with CHOLMOD ordering, Spectra ncv and index type exposed), on the
# lattices of scripts/bench_modal_scale.sh. Prints one JSON line per
# run to stdout (and to WORK/proposals.jsonl).
#
#   scripts/bench_modal_proposals.sh [--build DIR] [--work DIR] [--openblas DIR]
#                                    [--quiet-load L] [--max-wait S]
#
# --openblas DIR: a folder holding OpenBLAS's libblas.so.3, used through LD_LIBRARY_PATH for
# the "optimised BLAS" runs without touching the system's BLAS alternative, e.g.
#   apt-get download libopenblas0-pthread && dpkg -x libopenblas0-pthread_*.deb ob
#   --openblas $PWD/ob/usr/lib/x86_64-linux-gnu/openblas-pthread
# Without it those runs are skipped.
set -uo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build-bench"
work="${TMPDIR:-/tmp}/jointid_modal_proposals"
openblas=""
quiet_load=0.6
max_wait=900
MEM_LIMIT_KB=${MEM_LIMIT_KB:-20971520}
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --openblas) openblas="$2"; shift 2 ;;
    --quiet-load) quiet_load="$2"; shift 2 ;;
    --max-wait) max_wait="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "bench_modal_proposals.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
bench="$build/bench/bench_modal_scale"
[[ -x "$bench" ]] || { echo "bench_modal_proposals.sh: build $bench first" >&2; exit 2; }
mkdir -p "$work"
out="$work/proposals.jsonl"
: > "$out"

load1() { cut -d' ' -f1 /proc/loadavg; }
wait_quiet() {
  local waited=0
  while awk -v l="$(load1)" -v q="$quiet_load" 'BEGIN { exit !(l >= q) }'; do
    (( waited >= max_wait )) && { echo "  still loaded ($(load1)); running anyway" >&2; return; }
    sleep 15
    waited=$((waited + 15))
  done
}

# measure LABEL BLAS ARGS...: BLAS is "reference" or "openblas".
measure() {
  local label=$1 blas=$2
  shift 2
  if [[ "$blas" == openblas && -z "$openblas" ]]; then
    echo "skip $label (no --openblas)" >&2
    return
  fi
  wait_quiet
  local before line rc
  before=$(load1)
  echo "[$(date +%T)] $label: $*" >&2
  if [[ "$blas" == openblas ]]; then
    line=$( (ulimit -v "$MEM_LIMIT_KB"; LD_LIBRARY_PATH="$openblas" OPENBLAS_NUM_THREADS=2 \
      timeout 1800 "$bench" "$@") 2> "$work/last.err")
  else
    line=$( (ulimit -v "$MEM_LIMIT_KB"; timeout 1800 "$bench" "$@") 2> "$work/last.err")
  fi
  rc=$?
  /usr/bin/python3 - "$label" "$blas" "$rc" "$before" "$(load1)" "$line" "$work/last.err" \
    "$*" <<'EOF' | tee -a "$out"
import json, sys
label, blas, rc, before, after, line, err, args = sys.argv[1:]
rec = {"label": label, "blas": blas, "args": args, "rc": int(rc),
       "load_before": float(before), "load_after": float(after)}
try:
    r = json.loads(line)
    r.pop("eigenvalues", None)
    r["frequencies_hz"] = [round(f, 6) for f in r.get("frequencies_hz", [])[:3]]
    rec["result"] = r
except ValueError:
    rec["stderr_tail"] = open(err).read().splitlines()[-2:]
print(json.dumps(rec))
EOF
}

# Where the eigen time goes (factorisation vs Lanczos solves), reference BLAS vs OpenBLAS.
measure proto_1e5 reference 1e5 --engine proto
measure proto_1e5 openblas 1e5 --engine proto
measure library_1e5 openblas 1e5 --engine sparse
# CHOLMOD ordering, Spectra subspace size, 64-bit indices.
measure proto_1e5_nesdis openblas 1e5 --engine proto --ordering nesdis
measure proto_1e5_amd openblas 1e5 --engine proto --ordering amd
measure proto_1e5_ncv60 openblas 1e5 --engine proto --ncv 60
measure proto_1e5_ncv80 openblas 1e5 --engine proto --ncv 80
measure proto_1e5_long openblas 1e5 --engine proto --index long
# 1e6: the cube's factor (analysis only: it does not fit), and a flat lattice of 1e6 DOFs.
measure analysis_1e6_metis reference 1e6 --engine proto --analyze-only --index long
measure analysis_1e6_nesdis reference 1e6 --engine proto --analyze-only --index long --ordering nesdis
measure analysis_slab reference 205x205x5 --engine proto --analyze-only --index long
measure library_slab_1e6 reference 205x205x5 --engine sparse
measure library_slab_1e6 openblas 205x205x5 --engine sparse
measure proto_slab_1e6 openblas 205x205x5 --engine proto
# The dense engine, small lattices (its cost grows as n^3).
measure dense_1296 reference 6x6x7 --engine dense
measure dense_3072 reference 8x8x9 --engine dense
measure sparse_3072 reference 8x8x9 --engine sparse
echo "wrote $out" >&2
