#!/usr/bin/env bash
# The command-line run behind docs/benchmarks.md's "the command itself": `jointid discover` on a
# stepped-sine table of 492 rows (12 force levels from 0.1 to 1.5 N evenly in ratio × 41
# frequencies from 66 to 86 Hz) of the bolted beam's stand-in (tests/support/bolted_beam.hpp:
# a 0.4 m steel cantilever, 0.3 % modal damping, a joint at its tip with k, c and a hidden
# softening k3 and cubic damping c3), made by `jointid simulate --method hb --table` with 1 %
# noise on the time samples. Prints the wall and CPU time of the discovery (without pictures,
# then with them when xvfb-run is there) and what it found; then, with SEEDS="2 3 …" (default
# none), the same table with each of those noise seeds (the path a discovery screens can differ
# between them, and its time with it), without pictures, its time, result and screened path.
# Uses an existing build: JOINTID=path/to/jointid (default build/cli/jointid). Output under
# out/bench_discover_table/.
set -euo pipefail
cd "$(dirname "$0")/.."
J=${JOINTID:-build/cli/jointid}
out=out/bench_discover_table
rm -rf "$out"
mkdir -p "$out"
model() { # $1: the joint's terms and values
  cat <<EOF
[model]
dimension = 2

[[materials]]
name = "steel"
E = 210e9
rho = 7850.0
nu = 0.3

[[sections]]
name = "bar"
A = 3.6e-4     # m^2: 30 mm x 12 mm
Iz = 4.32e-9   # m^4: 0.03 * 0.012^3 / 12

[mesh]
nodes = [[1, 0.0, 0.0], [2, 0.04, 0.0], [3, 0.08, 0.0], [4, 0.12, 0.0], [5, 0.16, 0.0],
         [6, 0.2, 0.0], [7, 0.24, 0.0], [8, 0.28, 0.0], [9, 0.32, 0.0], [10, 0.36, 0.0],
         [11, 0.4, 0.0]]
elements = [[1, 1, 2], [2, 2, 3], [3, 3, 4], [4, 4, 5], [5, 5, 6], [6, 6, 7], [7, 7, 8],
            [8, 8, 9], [9, 9, 10], [10, 10, 11]]

[[element_sets]]
elements = "all"
type = "beam"
material = "steel"
section = "bar"

[[supports]]
node = 1
fix = ["ux", "uy", "rz"]

[damping]
modal = 0.003

[[joints]]
name = "bolt"
node = 11
dof = "uy"
$1
EOF
}
model 'terms = ["k", "c", "k3", "c3"]
values = { k = 2e4, c = 2.0, k3 = -3e9, c3 = 10.0 }' > "$out/truth.toml"
model 'terms = ["k", "c"]' > "$out/start.toml"
freqs=$(python3 -c 'print(",".join("%.4g" % (66 + 20 * i / 40) for i in range(41)))')
levels=$(python3 -c 'print(",".join("%.4g" % (0.1 * 15 ** (i / 11)) for i in range(12)))')
"$J" simulate "$out/truth.toml" --force 11:uy --freq "$freqs" --amplitude "$levels" --method hb \
  --table --channels a --noise 0.01 -o "$out/table" > /dev/null
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/time -f "discover --no-plot: %e s wall, %U s user, %S s system" \
  "$J" discover "$out/start.toml" "$out/table/stepped_sine.csv" -o "$out/discovery" --no-plot \
  2> >(grep -v '^jointid: warning' >&2) > /dev/null
grep '^\*\*Result' "$out/discovery/report.md"
if command -v xvfb-run > /dev/null; then
  /usr/bin/time -f "discover with pictures (xvfb-run): %e s wall, %U s user, %S s system" \
    xvfb-run -a "$J" discover "$out/start.toml" "$out/table/stepped_sine.csv" \
    -o "$out/discovery_pictures" 2> >(grep -v '^jointid: warning' >&2) > /dev/null
fi
for seed in ${SEEDS:-}; do
  "$J" simulate "$out/truth.toml" --force 11:uy --freq "$freqs" --amplitude "$levels" \
    --method hb --table --channels a --noise 0.01 --seed "$seed" -o "$out/table_$seed" > /dev/null
  echo "seed $seed, load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
  /usr/bin/time -f "discover --no-plot: %e s wall, %U s user, %S s system" \
    "$J" discover "$out/start.toml" "$out/table_$seed/stepped_sine.csv" \
    -o "$out/discovery_$seed" --no-plot 2> >(grep -v '^jointid: warning' >&2) > /dev/null
  grep '^\*\*Result' "$out/discovery_$seed/report.md"
  grep -o 'own noise, the path ([^)]*) ends at a criterion of [^ ]*' "$out/discovery_$seed/report.md" ||
    true
done
