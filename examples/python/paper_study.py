#!/usr/bin/env python3
"""The paper's cantilever study from Python (docs/paper_study.md; the C++ original is
examples/paper_cantilever/main.cpp).

A 6-element cantilever with a non-linear joint between its tip and ground, models I (k, c, c2,
k3) and II (k, c, fc, k3), sine-test cases I-IV. The "measured" records come from time
integration of the finite element model with the joint (exact stick-slip for friction); the
joint is identified from them alone, from the fundamental and from harmonics 1-3, and compared
with the exact values and the paper's.

    PYTHONPATH=build/python python3 examples/python/paper_study.py [--quick] [--output DIR]

--quick: case I of each model only (the test `python_example_paper_study`). Written like a
notebook: each `# %%` cell is a step; a figure is drawn when matplotlib is installed.
"""

# %% 0. Set-up: the arguments, the model file.
import argparse
import pathlib
import sys
import time
import tomllib

import numpy as np

import jointid

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--quick", action="store_true", help="case I of each model only")
parser.add_argument("--output", type=pathlib.Path, default=pathlib.Path("out/python_paper_study"))
parser.add_argument("--steps", type=int, default=2048, help="time steps per period")
args = parser.parse_args()
args.output.mkdir(parents=True, exist_ok=True)
model_file = here.parent / "paper_cantilever" / "cantilever.toml"
started = time.monotonic()

# %% 1. The substructure: the cantilever of the model file, and its first modes.
with open(model_file, "rb") as f:
    cantilever = tomllib.load(f)
modes = jointid.read_model(model_file).modes(3)
print("Substructure: {} DOFs, modes {} Hz".format(
    len(modes.dofs), ", ".join(f"{f:.4f}" for f in modes.frequencies_hz)))

# %% 2. The paper's models (exact values) and cases (frequencies in Hz x forces in N), and its
#       own results (its Tables 2 and 3, per case).
MODELS = {
    "I": dict(terms=["k", "c", "c2", "k3"], exact=[4800.0, 20.0, 500.0, 1.6e8],
              paper=[[4799.6, 20.003, 499.95, 1.6003e8], [4800.0, 20.063, 499.68, 1.5998e8],
                     [4800.0, 20.000, 500.00, 1.6000e8], [4800.0, 20.000, 499.99, 1.5998e8]]),
    "II": dict(terms=["k", "c", "fc", "k3"], exact=[4800.0, 20.0, 3.0, 1.6e8],
               paper=[[4707.3, 20.040, 2.9806, 1.6226e8], [4740.2, 20.068, 2.9192, 1.6146e8],
                      [4754.2, 20.631, 2.9205, 1.6108e8], [4821.8, 20.054, 2.9784, 1.5940e8]]),
}
CASES = {
    "I": ([1.0 + 0.4 * i for i in range(10)], [80.0]),
    "II": ([17.0 + 0.4 * i for i in range(10)], [80.0]),
    "III": ([3.0], [10.0 * (i + 1) for i in range(10)]),
    "IV": ([19.0], [10.0 * (i + 1) for i in range(10)]),
}
cases = ["I"] if args.quick else list(CASES)


def model_with(name):
    """The cantilever with the joint of model `name` at its exact values (a model from dicts)."""
    d = dict(cantilever)
    m = MODELS[name]
    d["joints"] = [dict(cantilever["joints"][0], terms=m["terms"],
                        values=dict(zip(m["terms"], m["exact"])))]
    return jointid.read_model(d, directory=model_file.parent)


# %% 3. Measure every case by time integration, identify from the records, print the tables.
worst = {}
errors = {}  # (model, case, harmonics) -> relative errors of the terms
for name, m in MODELS.items():
    model = model_with(name)
    print(f"\nModel {name}: g = " + " + ".join(m["terms"]))
    for c in cases:
        freqs, forces = CASES[c]
        records = jointid.simulate_sine(model, force="7:uy", freq_hz=freqs, amplitude=forces,
                                        method="time", periods=4, steps_per_period=args.steps)
        for harmonics in ([1], [1, 2, 3]):
            result = jointid.identify(model, records, harmonics=harmonics)
            values = [result.values["tip"][t] for t in m["terms"]]
            rel = [(v - e) / e for v, e in zip(values, m["exact"])]
            errors[name, c, len(harmonics)] = rel
            print(f"  case {c:<3} harmonics {'1' if len(harmonics) == 1 else '1-3':<4}"
                  f"{'term':>6} {'exact':>12} {'paper':>12} {'paper err':>10} {'jointid':>15}"
                  f" {'our err':>9}")
            paper = m["paper"][list(CASES).index(c)]
            for t, e, p, v, r in zip(m["terms"], m["exact"], paper, values, rel):
                print(f"  {'':20}{t:>6} {e:12.6g} {p:12.6g} {100 * (p - e) / e:9.3f}% "
                      f"{v:15.8g} {100 * r:8.4f}%")
            for w in result.warnings:
                print(f"  {'':20}warning: {w}")
            if len(harmonics) == 1:
                worst[name] = max(worst.get(name, 0.0), max(abs(r) for r in rel))

# %% 4. The accuracy of the paper's method as implemented: model I within 0.05 %, model II
#       (friction, which sticks in some tests) within 1 %, from the fundamental.
ok = True
for name, limit in (("I", 5e-4), ("II", 1e-2)):
    good = worst[name] <= limit
    ok = ok and good
    print(f"check: model {name} worst relative error {100 * worst[name]:.4f} % "
          f"(limit {100 * limit:.2f} %) {'ok' if good else 'FAILED'}")

# %% 5. A picture: every term's error by case and model (when matplotlib is installed).
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
    print("no figure: matplotlib is not installed (Debian: python3-matplotlib)")
if plt is not None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for ax, (name, m) in zip(axes, MODELS.items()):
        x = np.arange(len(m["terms"]))
        width = 0.8 / (2 * len(cases))
        for i, (c, h) in enumerate((c, h) for c in cases for h in (1, 3)):
            rel = np.abs(errors[name, c, h]) * 100
            ax.bar(x + (i - len(cases) + 0.5) * width, np.maximum(rel, 1e-6), width,
                   label=f"case {c}, harmonics {'1' if h == 1 else '1-3'}")
        ax.set_xticks(x, m["terms"])
        ax.set_yscale("log")
        ax.set_ylabel("|relative error| (%)")
        ax.set_title(f"Model {name}: identified vs exact")
        ax.legend(fontsize=7)
    png = args.output / "paper_study_errors.png"
    fig.savefig(png, dpi=100)
    print(f"wrote {png}")

print(f"time: {time.monotonic() - started:.1f} s")
sys.exit(0 if ok else 2)
