#!/usr/bin/env bash
# The payload example (examples/frame_payload/README.md), end to end: installs what is missing,
# builds, then "measures" the rig of examples/frame_payload/frame.toml by time integration with
# 1 % noise on every channel — a low-level multisine and multisine tests at six levels, plus
# one validation level not used — fits the substructure to the low-level test (modal-fit),
# discovers the mount's joint from a linear start, and compares the discovered model with the
# validation record. Output under out/frame_payload/. Extra arguments go to `jointid discover`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh -DJOINTID_BUILD_BENCH=OFF
J=./build/cli/jointid
ex=examples/frame_payload
out=out/frame_payload
rm -rf "$out"
mkdir -p "$out"
# 1. The low-level test: 1 N RMS multisine, 4-150 Hz, period 4 s; the joint stays stuck.
$J simulate "$ex/frame.toml" --force 4:uy --excitation multisine --band 4:150 --rms 1 \
  --period 4 --duration 36 --sample-rate 1024 --channels x --outputs 5:uy,10:uy --noise 0.01 \
  -o "$out/low" > /dev/null
# 2. The substructure from it.
$J modal-fit "$out/low/multisine_4-150Hz_1N.csv" --band 6:120 -o "$out/modal_fit"
# 3. Multisine tests at six levels (10-26 Hz, period 1 s), and a validation level (30 N).
for r in 5 10 15 20 40 80 30; do
  dir=tests
  [ "$r" = 30 ] && dir=validation
  $J simulate "$ex/frame.toml" --force 4:uy --excitation multisine --band 10:26 --rms "$r" \
    --period 1 --duration 16 --sample-rate 1024 --channels x --outputs 5:uy,10:uy \
    --noise 0.01 --seed "$r" -o "$out/$dir" > /dev/null
done
# 4. Discovery from the fitted substructure and a linear mount.
cp "$ex/start.toml" "$out/start.toml"
$J discover "$out/start.toml" "$out"/tests/*.csv --band 10:26 -o "$out/discovery" "$@"
# 5. The model discovery ended at, against the validation record (a level it was not given).
$J compare "$out/discovery/model.toml" "$out"/validation/*.csv --band 10:26 -o "$out/compare"
echo "report: $out/discovery/report.md; validation: $out/compare/compare.json"
