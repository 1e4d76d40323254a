#!/usr/bin/env bash
# Distributed modal analysis of a large substructure on a cluster (see docs/scaling.md).
#
#   scripts/cluster_modes.sh HOSTFILE RANKS_PER_NODE MODEL.toml OUTDIR [COUNT]
#
# HOSTFILE lists one node per line (Open MPI syntax: "node17 slots=2"). RANKS_PER_NODE is 1
# (one rank per node: the whole node's memory and cores for one MUMPS process, its BLAS
# threaded over the cores) or the number of sockets (one rank per socket, each pinned to its
# socket and its memory). Every node needs the same jointid build at the same path and the
# model file; only rank 0 writes OUTDIR. Under SLURM use `srun` with the same layout instead.
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,12p' "$0"
  exit 2
fi
hostfile=$1 per_node=$2 model=$3 out=$4 count=${5:-20}
root=$(cd "$(dirname "$0")/.." && pwd)
jointid=${JOINTID:-$root/build/cli/jointid}
nodes=$(grep -cv '^\s*\(#\|$\)' "$hostfile")
ranks=$((nodes * per_node))
cores=$(nproc) # assumed the same on every node
threads=$((cores / per_node))
if [ "$per_node" -eq 1 ]; then
  layout=(--map-by ppr:1:node --bind-to none)
else
  layout=(--map-by "ppr:1:socket:PE=$threads" --bind-to core)
fi
echo "cluster_modes: $ranks ranks on $nodes nodes, $threads BLAS threads each"
# MUMPS (options of SLEPc's ST, prefix st_): 30 % more working space than its estimate, since
# a failed factorisation costs the whole run; -eps_view prints what was solved (rank 0).
export PETSC_OPTIONS="${PETSC_OPTIONS:-} -st_mat_mumps_icntl_14 30 -st_mat_mumps_icntl_4 1"
mpirun --hostfile "$hostfile" -np "$ranks" "${layout[@]}" \
  -x OPENBLAS_NUM_THREADS="$threads" -x OMP_NUM_THREADS="$threads" -x PETSC_OPTIONS \
  "$jointid" modes "$model" --engine slepc --count "$count" --pictures 0 -o "$out"
