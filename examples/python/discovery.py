#!/usr/bin/env python3
"""Model discovery from Python: the discovery demo (scripts/run_discovery_demo.sh) as a script.

The paper's cantilever whose tip joint hides a cubic stiffness and Coulomb friction beside its
linear stiffness and damping (examples/discovery_demo/hidden.toml) is "measured" by sine tests
(time integration, 1 % noise on every channel). Discovery starts from the linear joint alone,
its values unknown (start.toml), and adds what the tests say is missing.

    PYTHONPATH=build/python python3 examples/python/discovery.py [--quick] [--output DIR]

--quick: 6 tests instead of 21, coarser time steps, at most 2 steps (the test
`python_example_discovery`). Written like a notebook: each `# %%` cell is a step; figures are
drawn when matplotlib is installed.
"""

# %% 0. Set-up.
import argparse
import json
import pathlib
import sys
import time
import tomllib

import numpy as np

import jointid

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--quick", action="store_true", help="fewer tests and steps")
parser.add_argument("--output", type=pathlib.Path, default=pathlib.Path("out/python_discovery"))
args = parser.parse_args()
args.output.mkdir(parents=True, exist_ok=True)
demo = here.parent / "discovery_demo"
started = time.monotonic()

# %% 1. "Measure" the hidden structure: sine tests at three force levels, 1 % noise.
hidden = jointid.read_model(demo / "hidden.toml")
print("hidden joint:", hidden.joints[0]["values"])
if args.quick:
    freqs, forces, steps, samples, max_steps = [2.5, 3.5, 4.5], [20.0, 100.0], 512, 128, 2
else:
    freqs, forces, steps, samples, max_steps = [2, 2.5, 3, 3.5, 4, 4.5, 5], [20, 50, 100], 1024, 256, 6
records = jointid.simulate_sine(hidden, force="7:uy", freq_hz=freqs, amplitude=forces,
                                method="time", periods=8, steps_per_period=steps,
                                samples_per_period=samples, noise=0.01, seed=1)
print(f"{len(records)} records of {len(records[0])} samples, channels {records[0].channel_names}")

# %% 2. Discover from the linear joint, its values unknown.
start = jointid.read_model(demo / "start.toml")
print("starting joint:", start.joints[0])
result = jointid.discover(start, records, max_steps=max_steps)
for finding in result.findings:
    print(finding)
print(f"\n{'step':<5} {'added':<10} {'effect':<26} {'value':>12} {'gap before':>11} {'gap after':>10}")
for i, s in enumerate(result.steps, 1):
    print(f"{i:<5} {s['term'] + ' at ' + s['joint']:<10} {s['effect']:<26} {s['value']:>12.5g} "
          f"{s['gap_before']:>11.4g} {s['gap_after']:>10.4g}")
print(f"\nStopped: {result.stop_reason}.")
with open(args.output / "discovery.json", "w") as f:
    json.dump(result.to_dict(), f, indent=2)
print(f"wrote {args.output / 'discovery.json'}")

# %% 3. Did it find what was hidden? The cubic stiffness first (it explains the most), then the
#       friction, and the gap down by two orders of magnitude.
added = [s["term"] for s in result.steps]
ok = added[:2] == ["k3", "fc"] and result.gap[-1] < result.gap[0] / 100
print(f"check: the steps add k3, then fc ({added}) and the gap falls 100-fold or more "
      f"({result.gap[0]:.4g} -> {result.gap[-1]:.4g}): {'ok' if ok else 'FAILED'}")

# %% 4. The final model: the starting model's dicts with the joints discovery ended with; its
#       steady state at the last test, by harmonic balance.
with open(demo / "start.toml", "rb") as f:
    final_dict = tomllib.load(f)
final_dict["joints"] = result.final_joints
final = jointid.read_model(final_dict, directory=demo)
print("final joint:", final.joints[0]["values"], f"(substructure damping x {result.damping_scale:g})")
simulated = jointid.simulate_sine(final, force="7:uy", freq_hz=freqs[-1], amplitude=forces[-1],
                                  method="hb", periods=1, steps_per_period=samples)[0]

# %% 5. Pictures: the gap after each step; the last test, measured and by the final model.
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
    print("no figures: matplotlib is not installed (Debian: python3-matplotlib)")
if plt is not None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    labels = ["start"] + [s["term"] for s in result.steps]
    left.semilogy(range(len(result.gap)), result.gap, "o-", label="gap")
    if result.noise_gap is not None:
        left.axhline(result.noise_gap, color="gray", ls="--", label="noise level")
    left.set_xticks(range(len(labels)), labels)
    left.set_xlabel("model (term added)")
    left.set_ylabel("gap (relative)")
    left.set_title("Discovery: the gap after each step")
    left.legend()
    r = records[-1]
    period = 1.0 / r.excitation_hz
    last = r.t >= r.t[-1] - period  # the last period
    right.plot(r.t[last] - r.t[last][0], r["x@7:uy"][last] * 1e3, label="measured (1 % noise)")
    right.plot(simulated.t, simulated["x@7:uy"] * 1e3, "--", label="final model (harmonic balance)")
    right.set_xlabel("t within the period (s)")
    right.set_ylabel("tip displacement x@7:uy (mm)")
    right.set_title(f"{r.source}: the last period")
    right.legend()
    png = args.output / "discovery.png"
    fig.savefig(png, dpi=100)
    print(f"wrote {png}")

print(f"time: {time.monotonic() - started:.1f} s")
sys.exit(0 if ok else 2)
