#!/usr/bin/env bash
# The discovery demo: installs what is missing, builds, "measures" 21 sine tests of the paper's
# cantilever whose tip joint hides a cubic stiffness and Coulomb friction (time integration,
# 1 % noise on every channel), then runs `jointid discover` from the linear joint alone.
# Output: out/discovery_demo/data/*.csv (the records) and out/discovery_demo/report/ (the
# report, discovery.json and the plots). Extra arguments go to `jointid discover`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh -DJOINTID_BUILD_BENCH=OFF
demo=examples/discovery_demo
out=out/discovery_demo
rm -rf "$out/data"
./build/cli/jointid simulate "$demo/hidden.toml" --force 7:uy --freq 2,2.5,3,3.5,4,4.5,5 \
  --amplitude 20,50,100 --steps-per-period 1024 --samples-per-period 256 --periods 8 \
  --noise 0.01 --seed 1 -o "$out/data" > /dev/null
./build/cli/jointid discover "$demo/start.toml" "$out"/data/*.csv -o "$out/report" "$@"
echo "report: $out/report/report.md"
