#!/usr/bin/env python3
"""Writes, or checks, every figure in README.md and docs/ that a jointid program prints.

Such figures sit in regions of the Markdown pages, between two comments:

    <!-- generated:NAME begin [rtol=R] [atol=A] -->
    ... text written by this script from a run ...
    <!-- generated:NAME end -->

Each NAME has a renderer below that turns the outputs of a run into the region's text (the
commands it shows are the ones it ran). The runs come in groups; a run happens in a fresh
working directory holding a copy of examples/ and a link `build` to the build directory, so the
commands are run exactly as the pages show them, from the repository root.

  update_docs.py [--only G1,G2] [--build DIR]           run, rewrite the regions, copy pictures
  update_docs.py --check [--only G1,G2] [--build DIR]   run, compare with the pages; exit 1 if
                                                        a region differs

--check compares a region's words exactly and its numbers within a tolerance: two numbers agree
when they differ by at most max(rtol·|x|, atol, one unit of the last digit printed), rtol and
atol from the region's begin comment (default 0: the last printed digit). Regions named
`run-<group>` (date, commit, machine, time of the runs) are written, never checked: times
depend on the machine. Each update appends the time of each group's run to
docs/generated_runs.tsv; a `run-<group>` region states the range over the runs logged on the
machine of the latest one.

Groups (--only; default all): quickstart, paper, commands (cheap: the test suite checks them),
three-joints, polyethylene, design-study (minutes each: generated only).
Python 3 standard library only.
"""

import argparse
import datetime
import json
import math
import os
import platform
import re
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RUN_LOG = ROOT / "docs" / "generated_runs.tsv"
PAGES = [ROOT / "README.md"] + sorted((ROOT / "docs").rglob("*.md"))
BEGIN = re.compile(r"<!-- generated:([a-z0-9-]+) begin((?: [a-z]+=[^ ]+)*) -->\n")
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")

CHEAP = ["quickstart", "paper", "commands"]
EXPENSIVE = ["three-joints", "polyethylene", "design-study"]


class Failure(Exception):
    pass


# --------------------------------------------------------------------------------------------
# Running programs


class Runner:
    """Runs commands in a working directory laid out like the repository root."""

    def __init__(self, build: Path, check: bool):
        self.build = build
        self.check = check
        self.work = Path(tempfile.mkdtemp(prefix="jointid-docs-"))
        shutil.copytree(ROOT / "examples", self.work / "examples")
        (self.work / "build").symlink_to(build)
        self.env = dict(os.environ)
        self.env["PATH"] = f"{self.work / 'build' / 'cli'}:{self.env.get('PATH', '')}"
        self.env["LC_ALL"] = "C"  # the shell's globs (out/tests/*.csv) in one order everywhere
        self.times = {}  # group -> [wall s, cpu s]
        self.vtk = "JOINTID_WITH_VTK:BOOL=OFF" not in read(build / "CMakeCache.txt", "")

    def close(self):
        shutil.rmtree(self.work, ignore_errors=True)

    def run(self, group: str, command) -> str:
        """Runs a command (argv, or a line of shell) in the working directory with bash, as a
        user would type it; returns its stdout."""
        shown = command if isinstance(command, str) else sh_join(command)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.monotonic()
        p = subprocess.run(["bash", "-euo", "pipefail", "-c", shown], cwd=self.work, env=self.env,
                           capture_output=True, text=True)
        wall = time.monotonic() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        t = self.times.setdefault(group, [0.0, 0.0])
        t[0] += wall
        t[1] += cpu
        if p.returncode != 0:
            raise Failure(f"exit status {p.returncode} from\n{shown}\n--- stderr:\n{p.stderr}"
                          f"--- stdout:\n{p.stdout}")
        return p.stdout

    def path(self, relative: str) -> Path:
        return self.work / relative


def read(path: Path, default=None) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        if default is None:
            raise
        return default


def load_json(path: Path):
    return json.loads(read(path))


# --------------------------------------------------------------------------------------------
# Number formatting


def g(x: float, digits: int = 4) -> str:
    """x with `digits` significant digits, as C's %g."""
    return f"{x:.{digits}g}"


def pct(x: float, digits: int = 2) -> str:
    return f"{100 * x:.{digits}g} %"


def sci(x: float, digits: int = 4) -> str:
    """Large or small numbers as 1.234e+08, others as %g."""
    return g(x, digits)


def ci(pair, digits: int = 4) -> str:
    return f"[{g(pair[0], digits)}, {g(pair[1], digits)}]"


def code(text: str, lang: str = "") -> str:
    return f"```{lang}\n{text.rstrip()}\n```"


def sh_join(argv) -> str:
    """argv as a shell line; words with a * stay unquoted (globs)."""
    return " ".join(w if "*" in w else shlex.quote(w) for w in argv)


def command_block(commands) -> str:
    """Commands (argv lists, or lines of shell) as a sh block, long lines continued."""
    lines = []
    for argv in commands:
        if isinstance(argv, str):
            lines.append(argv)
            continue
        quoted = [w if "*" in w else shlex.quote(w) for w in argv]
        words = []  # an option stays on the line of its value
        for w in quoted:
            if words and words[-1].startswith("-") and " " not in words[-1] and \
                    not w.startswith("-"):
                words[-1] += " " + w
            else:
                words.append(w)
        line, out = "", []
        for w in words:
            if line and len(line) + 1 + len(w) > 92:
                out.append(line + " \\")
                line = "        " + w
            else:
                line = f"{line} {w}" if line else w
        out.append(line)
        lines.extend(out)
    return code("\n".join(lines), "sh")


def printed_lines(stdout: str) -> str:
    """A program's output without the lines naming the files it wrote."""
    return "\n".join(l for l in stdout.splitlines() if not l.startswith("wrote ")).strip()


# --------------------------------------------------------------------------------------------
# Group: quickstart (the README's quick start, run as written)


def quickstart_commands(readme: str):
    m = re.search(r"<!-- quickstart:begin -->\s*```sh\n(.*?)```\s*<!-- quickstart:end -->",
                  readme, re.S)
    if not m:
        raise Failure("README.md: no ```sh block between <!-- quickstart:begin --> and "
                      "<!-- quickstart:end -->")
    return m.group(1)


def quickstart_files(readme: str, key: str):
    m = re.search(rf"<!-- quickstart:{key} ([^>]*?) -->", readme)
    return m.group(1).split() if m else []


def run_quickstart(r: Runner, out: dict):
    readme = read(ROOT / "README.md")
    r.run("quickstart", quickstart_commands(readme))
    expected = quickstart_files(readme, "outputs")
    if r.vtk:
        expected += quickstart_files(readme, "pictures")
    if not expected:
        raise Failure("README.md: no <!-- quickstart:outputs FILE... --> comment")
    missing = [f for f in expected if not r.path(f).is_file()]
    if missing:
        raise Failure("the README's quick start ran but did not write " + ", ".join(missing))
    out["linear"] = load_json(r.path("out/quickstart/linear.json"))
    out["discovery"] = load_json(r.path("out/quickstart/report/discovery.json"))
    if not r.check:
        target = ROOT / "docs" / "discovery_demo"
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(r.path("out/quickstart/report"), target)


def term_line(t) -> str:
    unit = f" {t['unit']}" if t.get("unit") else ""
    return f"{t['term']} = {g(t['value'])}{unit} {ci(t['ci95'])}"


def render_quickstart_identify(out) -> str:
    j = out["linear"]
    rows = ["| term | value | 95 % interval |", "|---|---:|---|"]
    for joint in j["joints"]:
        for t in joint["terms"]:
            rows.append(f"| {t['term']} of '{joint['name']}' | {g(t['value'])} | {ci(t['ci95'])} |")
    words = (f"{j['equations']} equations, relative residual {g(j['residual_relative'], 3)}, "
             f"χ² per degree of freedom {g(j['chi2_per_dof'], 3)} (about 1 when a model explains "
             "the data to their noise).")
    warnings = "".join(f"\n- warning: {w}" for w in j["warnings"])
    return "\n".join(rows) + "\n\n" + words + ("\n" + warnings if warnings else "")


def render_quickstart_discover(out) -> str:
    d = out["discovery"]
    start = d["start"]
    rows = ["| step | added | value [95 % interval] | gap after |", "|---|---|---|---:|"]
    linear = ", ".join(f"{t['term']} = {g(t['value'])}" for j in start["joints"] for t in j["terms"])
    rows.append(f"| start | {linear} | | {g(d['gap'][0])} |")
    for i, s in enumerate(d["steps"], 1):
        rows.append(f"| {i} | {s['term']} at '{s['joint']}', {s['effect']} | "
                    f"{g(s['value'])} {ci(s['ci95'])} | {g(s['gap_after'])} |")
    final = "; ".join(f"{t['term']} = {g(t['value'])} {t['unit']}"
                      for j in d["final_model"]["joints"] for t in j["terms"])
    level = "at" if d["at_noise_level"] else "not at"
    text = "\n".join(rows)
    text += (f"\n\nThe gap shrank {g(d['gap'][0] / d['gap'][-1], 3)}× and is {level} the noise "
             f"level (noise {g(d['noise_gap'])}, the simulation's own error "
             f"{g(d['simulation_gap'])}; χ² per value {g(d['chi2_per_value'], 3)}). "
             f"Final model: {final}.")
    return text


# --------------------------------------------------------------------------------------------
# Group: paper (the paper's cantilever study, scripts/run_paper_study.sh)

PAPER_ARGV = ["./build/examples/paper_cantilever/paper_cantilever", "--json",
              "out/paper_study.json"]
PAPER_NAMES = {"I": ["k", "c", "c2", "k3"], "II": ["k", "c", "fc", "k3"]}
PAPER_EXACT = {"I": [4800.0, 20.0, 500.0, 1.6e8], "II": [4800.0, 20.0, 3.0, 1.6e8]}
PAPER_OWN_WORST = {"I": ("0.32 %", "c, case II"), "II": ("3.2 %", "c, case III")}


def run_paper(r: Runner, out: dict):
    r.path("out").mkdir(exist_ok=True)  # as scripts/run_paper_study.sh does
    out["paper_text"] = r.run("paper", PAPER_ARGV)
    out["paper"] = load_json(r.path("out/paper_study.json"))


def paper_worst(results, model: str, harmonics: str, cases):
    worst = (0.0, "", "")
    for case in cases:
        terms = results[model][case][harmonics]["joints"][0]["terms"]
        for t, exact in zip(terms, PAPER_EXACT[model]):
            e = abs(t["value"] / exact - 1.0)
            if e > worst[0]:
                worst = (e, t["term"], case)
    return worst


def render_paper_summary(out) -> str:
    p = out["paper"]
    cases = ["I", "II", "III", "IV"]
    rows = ["| model | the paper (its Tables 2, 3) | jointid, fundamental | jointid, harmonics 1–3 |",
            "|---|---|---|---|"]
    for model in ["I", "II"]:
        cells = []
        for h in ["harmonic_1", "harmonics_1_3"]:
            e, term, case = paper_worst(p["models"], model, h, cases)
            cells.append(f"{100 * e:.2g} % ({term}, case {case})")
        own = PAPER_OWN_WORST[model]
        rows.append(f"| {model} | {own[0]} ({own[1]}) | {cells[0]} | {cells[1]} |")
    sticks = []
    for case in cases:
        for w in p["models"]["II"][case]["harmonic_1"]["warnings"]:
            m = re.search(r"sticks for ([0-9.e+-]+) %", w)
            if m:
                sticks.append((float(m.group(1)), case))
    text = "\n".join(rows)
    if sticks:
        lo, hi = min(s[0] for s in sticks), max(s[0] for s in sticks)
        where = sorted({s[1] for s in sticks}, key=cases.index)
        text += (f"\n\nWorst relative error over the four terms and the four cases. In model II "
                 f"the tip sticks for {g(lo, 3)}–{g(hi, 3)} % of the period in "
                 f"{len(sticks)} tests (cases {', '.join(where)}); without the tests of case I "
                 "that stick, its worst error with harmonics 1–3 is ")
        d = p["stick_slip_diagnosis"]["joints"][0]["terms"]
        e = max(abs(t["value"] / x - 1.0) for t, x in zip(d, PAPER_EXACT["II"]))
        text += f"{100 * e:.2g} %."
    return text


def render_paper_output(out) -> str:
    return code(out["paper_text"].strip())


def render_paper_modes(out) -> str:
    f = out["paper"]["substructure_modes_hz"]
    return (f"The substructure's first modes (without the joint) are {f[0]:.4f} Hz, {f[1]:.4f} Hz "
            f"and {f[2]:.4f} Hz.")


# --------------------------------------------------------------------------------------------
# Group: commands (the examples of docs/commands/ and docs/formats/)

RESPONSE_ARGV = ["jointid", "response", "examples/response/hardening_tip.toml", "--force", "7:uy",
                 "--amplitude", "10,40,80", "--freq-range", "15:30", "-o", "out/response"]
DESIGN_ARGV = ["jointid", "design", "examples/paper_cantilever/cantilever.toml", "--force",
               "7:uy", "--freq", "1:0.2:30", "--amplitude", "10:10:80", "-n", "10", "-o",
               "out/design"]
RANDOM_ARGV = ["jointid", "simulate", "examples/paper_cantilever/cantilever.toml", "--force",
               "7:uy", "--excitation", "random", "--band", "2:40", "--rms", "40", "--duration",
               "60", "--sample-rate", "256", "--channels", "x,a", "-o", "out/random"]
NO_K3 = "sed 's/k3 = 1.6e8/k3 = 0.0/' examples/paper_cantilever/cantilever.toml > out/no_k3.toml"
COMPARE_ARGV = ["jointid", "compare", "out/no_k3.toml", "out/random/random_2-40Hz_40N_seed1.csv",
                "--band", "2:40", "-o", "out/compare"]
COMPARE_SAME_ARGV = ["jointid", "compare", "examples/paper_cantilever/cantilever.toml",
                     "out/random/random_2-40Hz_40N_seed1.csv", "--band", "2:40", "-o",
                     "out/compare_same"]
# modal-fit: a low-level random test of the cantilever without its joint, fitted.
MODAL_BEAM = ("sed '/^\\[\\[joints\\]\\]/,$d' examples/paper_cantilever/cantilever.toml "
              "> out/beam.toml")
MODAL_SIM = ["jointid", "simulate", "out/beam.toml", "--force", "7:uy", "--excitation", "random",
             "--band", "2:80", "--rms", "20", "--duration", "128", "--sample-rate", "256",
             "--route", "full", "--substeps", "8", "--channels", "v", "--outputs", "3:uy,5:uy",
             "--noise", "0.01", "-o", "out/low_level"]
MODAL_FIT = ["jointid", "modal-fit", "out/low_level/random_2-80Hz_20N_seed1.csv", "--band",
             "10:70", "--segment", "4096", "-o", "out/modal_fit"]
TABLE_SIM = ["jointid", "simulate", "examples/paper_cantilever/cantilever.toml", "--force", "7:uy",
             "--freq", "2,3,4,5,6", "--amplitude", "10,80", "--steps-per-period", "512"]
TABLE_RECORDS = TABLE_SIM + ["-o", "out/records"]
TABLE_TABLE = TABLE_SIM + ["--table", "-o", "out/table"]
TABLE_ID_RECORDS = ["jointid", "identify", "examples/paper_cantilever/cantilever.toml",
                    "out/records/*.csv", "-o", "out/from_records.json"]
TABLE_ID_TABLE = ["jointid", "identify", "examples/paper_cantilever/cantilever.toml",
                  "out/table/stepped_sine.csv", "-o", "out/from_table.json"]
NOISE_SIM = ["jointid", "simulate", "examples/paper_cantilever/cantilever.toml", "--force", "7:uy",
             "--freq", "1,1.4,1.8,2.2", "--amplitude", "80", "--noise", "0.01", "-o",
             "out/noisy"]
NOISE_ID = ["jointid", "identify", "examples/paper_cantilever/cantilever.toml",
            "out/noisy/*.csv", "-o", "out/noisy.json"]
MODES_ARGV = ["jointid", "modes", "examples/portal_frame/portal.toml", "-o", "out/portal"]
FRF_ARGV = ["jointid", "frf", "examples/paper_cantilever/cantilever.toml", "--drive", "7:uy",
            "--response", "7:uy,4:uy,7:rz", "--freq-range", "0:60", "-o", "out/frf"]
SINE_ARGV = ["jointid", "simulate", "examples/paper_cantilever/cantilever.toml", "--force", "7:uy",
             "--freq", "1,1.4,1.8,2.2,2.6,3", "--amplitude", "80", "-o", "out/tests"]
IDENTIFY_ARGV = ["jointid", "identify", "examples/paper_cantilever/cantilever.toml",
                 "out/tests/*.csv", "-o", "out/result.json"]
TJ_DESIGN_ARGV = ["jointid", "design", "examples/three_joints/frame.toml", "--force", "corner:ux",
                  "--freq", "2:1:60", "--amplitude", "1000,3000,10000,30000", "-n", "12",
                  "--harmonics", "1,2,3", "-o", "out/three_joints_design"]


def no_plot(r: Runner, argv):
    """Pictures only where they are copied into docs/ (update mode of a build with VTK)."""
    return argv if (r.vtk and not r.check) else argv + ["--no-plot"]


def run_commands(r: Runner, out: dict):
    modes = MODES_ARGV if (r.vtk and not r.check) else MODES_ARGV + ["--pictures", "0"]
    out["modes"] = r.run("commands", modes)
    out["modes_json"] = load_json(r.path("out/portal/modes.json"))
    out["frf"] = r.run("commands", no_plot(r, FRF_ARGV))
    out["frf_csv"] = read(r.path("out/frf/frf.csv"))
    out["frf_uff"] = read(r.path("out/frf/frf.uff"))
    out["simulate"] = r.run("commands", SINE_ARGV)
    out["record"] = read(r.path("out/tests/sine_f3Hz_F80N.csv"))
    out["identify"] = r.run("commands", IDENTIFY_ARGV)
    out["response"] = r.run("commands", no_plot(r, RESPONSE_ARGV))
    out["design"] = r.run("commands", DESIGN_ARGV)
    out["design_json"] = load_json(r.path("out/design/design.json"))
    out["response_json"] = load_json(r.path("out/response/response.json"))
    r.run("commands", RANDOM_ARGV)
    r.run("commands", NO_K3)
    out["compare"] = r.run("commands", no_plot(r, COMPARE_ARGV))
    out["compare_json"] = load_json(r.path("out/compare/compare.json"))
    out["compare_same"] = r.run("commands", COMPARE_SAME_ARGV + ["--no-plot"])
    for argv in (TABLE_RECORDS, TABLE_TABLE, TABLE_ID_RECORDS, TABLE_ID_TABLE):
        r.run("commands", argv)
    out["table_csv"] = read(r.path("out/table/stepped_sine.csv"))
    out["from_records"] = load_json(r.path("out/from_records.json"))
    out["from_table"] = load_json(r.path("out/from_table.json"))
    r.run("commands", NOISE_SIM)
    r.run("commands", NOISE_ID)
    out["noisy"] = load_json(r.path("out/noisy.json"))
    r.run("commands", MODAL_BEAM)
    r.run("commands", MODAL_SIM)
    out["modal_fit"] = r.run("commands", no_plot(r, MODAL_FIT))
    out["modal_fit_toml"] = read(r.path("out/modal_fit/substructure.toml"))
    out["modal_fit_json"] = load_json(r.path("out/modal_fit/modal_fit.json"))
    out["tj_design"] = r.run("commands", TJ_DESIGN_ARGV)
    out["tj_design_json"] = load_json(r.path("out/three_joints_design/design.json"))
    if not r.check and r.vtk:
        shutil.copyfile(r.path("out/portal/modes.png"), ROOT / "docs" / "portal_modes.png")
        shutil.copyfile(r.path("out/response/response.png"),
                        ROOT / "docs" / "response_hardening_tip.png")
        shutil.copyfile(r.path("out/compare/compare.png"), ROOT / "docs" / "compare_missing_k3.png")
        shutil.copyfile(r.path("out/modal_fit/stabilisation.png"),
                        ROOT / "docs" / "modal_fit_stabilisation.png")
        shutil.copyfile(r.path("out/modal_fit/fit.png"), ROOT / "docs" / "modal_fit_fit.png")


def head(text: str, lines: int) -> str:
    return "\n".join(text.splitlines()[:lines])


def render_modes_example(out) -> str:
    return command_block([MODES_ARGV]) + "\n\nprints\n\n" + code(printed_lines(out["modes"]))


def render_frf_example(out) -> str:
    return (command_block([FRF_ARGV]) + "\n\nprints\n\n" + code(printed_lines(out["frf"])) +
            "\n\nand `out/frf/frf.csv` begins\n\n" + code(head(out["frf_csv"], 7)))


def render_frf_uff(out) -> str:
    return code(head(out["frf_uff"], 16) + "\n...")


def render_simulate_example(out) -> str:
    return (command_block([SINE_ARGV]) + "\n\nprints\n\n" + code(out["simulate"].strip()) +
            "\n\nand `out/tests/sine_f3Hz_F80N.csv` begins\n\n" + code(head(out["record"], 12)))


def render_identify_example(out) -> str:
    return (command_block([SINE_ARGV, IDENTIFY_ARGV]) + "\n\n`identify` prints\n\n" +
            code(out["identify"].strip()))


def render_record_head(out) -> str:
    return code(head(out["record"], 12) + "\n...")


def excerpt(value, items: int = 2):
    """A JSON value with lists cut to their first items ("..." marks the cut; lists of up to three
    numbers, such as intervals and complex amplitudes, are kept) and numbers to 6 significant
    digits."""
    if isinstance(value, dict):
        return {k: excerpt(v, items) for k, v in value.items()}
    if isinstance(value, list):
        if len(value) <= 3 and not any(isinstance(v, (dict, list)) for v in value):
            return [excerpt(v, items) for v in value]  # an interval, a complex number
        cut = [excerpt(v, items) for v in value[:items]]
        return cut + ["..."] if len(value) > items else cut
    if isinstance(value, float):
        return float(f"{value:.6g}")
    return value


def compact_json(value, indent: str = "") -> str:
    """JSON with objects one key a line and lists of plain values on one line."""
    inner = indent + "  "
    if isinstance(value, dict):
        if not value:
            return "{}"
        body = ",\n".join(f"{inner}{json.dumps(k)}: {compact_json(v, inner)}"
                           for k, v in value.items())
        return "{\n" + body + "\n" + indent + "}"
    if isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
        return "[\n" + ",\n".join(inner + compact_json(v, inner) for v in value) + "\n" + indent + "]"
    return json.dumps(value, ensure_ascii=False)


def json_block(value, items: int = 2) -> str:
    return code(compact_json(excerpt(value, items)), "json")


def render_json_identify(out) -> str:
    return json_block(out["noisy"], 2)


def render_json_modes(out) -> str:
    return json_block(out["modes_json"], 3)


def render_json_response(out) -> str:
    return json_block(out["response_json"], 2)


def render_json_design(out) -> str:
    return json_block(out["design_json"], 2)


def render_json_compare(out) -> str:
    return json_block(out["compare_json"], 3)


def render_json_modal_fit(out) -> str:
    return json_block(out["modal_fit_json"], 2)


def render_json_discover(out) -> str:
    return json_block(out["discovery"], 1)


def render_response_example(out) -> str:
    return command_block([RESPONSE_ARGV]) + "\n\nprints\n\n" + code(
        printed_lines(out["response"]))


def render_design_example(out) -> str:
    return command_block([DESIGN_ARGV]) + "\n\nprints\n\n" + code(printed_lines(out["design"]))


def render_compare_example(out) -> str:
    shown = command_block([RANDOM_ARGV, "# the same model without its cubic stiffness:", NO_K3,
                           COMPARE_ARGV])
    same = printed_lines(out["compare_same"]).splitlines()
    return (shown + "\n\nprints\n\n" + code(printed_lines(out["compare"])) +
            "\n\nThe same record against the model that made it prints\n\n" +
            command_block([COMPARE_SAME_ARGV]) + "\n\n" + code("\n".join(same[:3])))


def render_modal_fit_example(out) -> str:
    toml = out["modal_fit_toml"].splitlines()
    first = next(i for i, l in enumerate(toml) if l.startswith("[modal]"))
    return (command_block([MODAL_BEAM, MODAL_SIM, MODAL_FIT]) + "\n\nprints\n\n" +
            code(printed_lines(out["modal_fit"])) + "\n\nand `out/modal_fit/substructure.toml` "
            "holds\n\n" + code("\n".join(toml[first:])))


def render_stepped_sine(out) -> str:
    rec, tab = out["from_records"], out["from_table"]
    names = [t["term"] for t in rec["joints"][0]["terms"]]
    exact = {"k": 4800.0, "c": 20.0, "c2": 500.0, "k3": 1.6e8}
    head = "| route | " + " | ".join(f"{n} ({g(exact[n])})" for n in names) + " |"
    rows = [head, "|---" * (len(names) + 1) + "|"]
    rows.append("| time records, harmonic 1 | " + " | ".join(
        f"{g(t['value'], 7)} ± {g(t['std'], 2)}" for t in rec["joints"][0]["terms"]) + " |")
    rows.append("| stepped-sine table (fundamentals only) | " + " | ".join(
        f"{g(t['value'], 5)} ± {g(t['std'], 3)}" for t in tab["joints"][0]["terms"]) + " |")
    bias = ", ".join(f"{t['term']} {100 * (t['value'] / exact[t['term']] - 1):+.2g} %"
                     for t in tab["joints"][0]["terms"])
    cmds = command_block([TABLE_RECORDS, TABLE_TABLE, TABLE_ID_RECORDS, TABLE_ID_TABLE])
    return cmds + "\n\n" + "\n".join(rows) + f"\n\nThe table's errors: {bias}."


def render_stepped_sine_head(out) -> str:
    lines = out["table_csv"].splitlines()
    first = next(i for i, l in enumerate(lines) if l.startswith("freq_hz"))
    return code("\n".join(lines[:first + 3]) + "\n...")


def render_noise_estimate(out) -> str:
    est = [n["channels"]["f@7:uy"] for n in out["noisy"]["noise"]]
    added = 0.01 * 80.0 / math.sqrt(2.0)
    return (command_block([NOISE_SIM, NOISE_ID]) +
            f"\n\nThe force channel's noise is estimated from each record's scatter as "
            f"{g(min(est), 3)}–{g(max(est), 3)} N; the noise added was 0.01 × the force's RMS, "
            f"0.01 × 80 N / √2 = {g(added, 3)} N.")


def render_three_joints_design(out) -> str:
    d = out["tj_design_json"]
    left = [c for c in d["candidates"] if not c["usable"]]
    coexisting = sum("coexisting" in c.get("reason", "") for c in left)
    misfit = sum("miss by" in c.get("reason", "") for c in left)
    other = len(left) - coexisting - misfit
    text = command_block([TJ_DESIGN_ARGV]) + "\n\nprints\n\n" + code(
        printed_lines(out["tj_design"]))
    text += (f"\n\nOf the {len(d['candidates'])} candidates, {coexisting} were left out for "
             f"coexisting periodic responses and {misfit} because at the true values their "
             "equations miss by more than 0.2 noise standard deviations")
    text += f", {other} for other reasons." if other else "."
    return text


# --------------------------------------------------------------------------------------------
# Expensive groups: the studies of docs/

THREE_JOINTS_ARGV = ["./build/examples/three_joints/three_joints", "--reps", "200", "--png",
                     "out/three_joints_coverage.png"]
POLYETHYLENE_ARGV = ["./build/examples/polyethylene/polyethylene", "--check", "--png",
                     "out/polyethylene/spectra"]
DESIGN_STUDY_ARGV = ["./build/examples/paper_cantilever/paper_design_study", "200"]


def virtual_display():
    """The examples draw their figures through an X display: a virtual one where there is none
    (jointid itself does this on its own)."""
    return [] if os.environ.get("DISPLAY") or not shutil.which("xvfb-run") else ["xvfb-run", "-a"]


def run_three_joints(r: Runner, out: dict):
    if "tj_design_json" not in out:  # the design's predictions, beside the Monte Carlo
        r.run("three-joints", TJ_DESIGN_ARGV)
        out["tj_design_json"] = load_json(r.path("out/three_joints_design/design.json"))
    out["three_joints"] = r.run("three-joints", virtual_display() + THREE_JOINTS_ARGV)
    if not r.check and r.vtk:
        shutil.copyfile(r.path("out/three_joints_coverage.png"),
                        ROOT / "docs" / "three_joints_coverage.png")


def run_polyethylene(r: Runner, out: dict):
    (r.path("out/polyethylene")).mkdir(parents=True, exist_ok=True)
    out["polyethylene"] = r.run("polyethylene", virtual_display() + POLYETHYLENE_ARGV)
    if not r.check and r.vtk:
        for band in ("12-44Hz", "66-98Hz"):
            shutil.copyfile(r.path(f"out/polyethylene/spectra_{band}.png"),
                            ROOT / "docs" / "polyethylene" / f"spectra_{band}.png")


def run_design_study(r: Runner, out: dict):
    out["design_study"] = r.run("design-study", DESIGN_STUDY_ARGV)


def render_three_joints(out) -> str:
    text = printed_lines(out["three_joints"])
    # The design's predicted standard deviations beside the Monte Carlo scatter, when both ran.
    design = out.get("tj_design_json")
    if design:
        scatter = {}
        for m in re.finditer(r"^\| (\w+) (\w+) \| [^|]+\| [^|]+\| ([0-9.e+-]+) % \|", text, re.M):
            scatter[(m.group(1), m.group(2))] = float(m.group(3)) / 100
        ratios = [u["relative_std"] / scatter[(u["joint"], u["term"])]
                  for u in design["unknowns"] if (u["joint"], u["term"]) in scatter]
        if ratios:
            text += ("\n\nThe standard deviations `jointid design` predicted before any test was "
                     f"simulated are {min(ratios):.2f}–{max(ratios):.2f} times the Monte "
                     "Carlo scatter above.")
    return text


def render_polyethylene(out) -> str:
    return printed_lines(out["polyethylene"])


def render_design_study(out) -> str:
    return out["design_study"].strip()


# --------------------------------------------------------------------------------------------
# Run records: date, commit, machine and time ranges

def machine() -> str:
    info = read(Path("/proc/cpuinfo"), "")

    def field(name):
        m = re.search(rf"^{name}\s*:\s*(.*)$", info, re.M)
        return m.group(1).strip() if m else "?"
    return (f"{field('model name')} (family {field('cpu family')}, model {field('model')}), "
            f"{os.cpu_count()} cores")


def commit() -> str:
    p = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                       capture_output=True, text=True)
    return p.stdout.strip() or "?"


def log_runs(times):
    today = datetime.date.today().isoformat()
    new = not RUN_LOG.exists()
    with RUN_LOG.open("a", encoding="utf-8") as f:
        if new:
            f.write("# Runs of scripts/update_docs.py: date, commit, machine, group, wall s, "
                    "CPU s (user + system of the programs)\n")
        for group, (wall, cpu) in times.items():
            f.write(f"{today}\t{commit()}\t{machine()}\t{group}\t{wall:.1f}\t{cpu:.1f}\n")


def seconds(lo: float, hi: float) -> str:
    def one(s):
        return f"{s:.0f} s" if s < 100 else f"{s / 60:.1f} min"
    if one(lo) == one(hi):
        return one(lo)
    a, b = one(lo), one(hi)
    if a.split()[1] == b.split()[1]:
        return f"{a.split()[0]}–{b}"
    return f"{a}–{b}"


def render_run(group: str) -> str:
    rows = []
    for line in read(RUN_LOG, "").splitlines():
        if line.startswith("#") or not line.strip():
            continue
        date, rev, mach, grp, wall, cpu = line.split("\t")
        if grp == group:
            rows.append((date, rev, mach, float(wall), float(cpu)))
    if not rows:
        return "(not run yet: `bash scripts/update_docs.sh`)"
    last = rows[-1]
    same = [r for r in rows if r[2] == last[2]]
    walls = [r[3] for r in same]
    cpus = [r[4] for r in same]
    runs = f"{len(same)} run{'s' if len(same) > 1 else ''}"
    dates = sorted({r[0] for r in same})
    when = dates[0] if len(dates) == 1 else f"{dates[0]} to {dates[-1]}"
    return (f"Written by `scripts/update_docs.sh` from a run on {last[0]} at commit {last[1]}. "
            f"Time on {last[2]} ({runs}, {when}; shared with other work): "
            f"{seconds(min(walls), max(walls))} wall, {seconds(min(cpus), max(cpus))} CPU.")


# --------------------------------------------------------------------------------------------
# Regions

GROUPS = {
    "quickstart": run_quickstart,
    "paper": run_paper,
    "commands": run_commands,
    "three-joints": run_three_joints,
    "polyethylene": run_polyethylene,
    "design-study": run_design_study,
}

RENDERERS = {
    "quickstart-identify": ("quickstart", render_quickstart_identify),
    "quickstart-discover": ("quickstart", render_quickstart_discover),
    "paper-summary": ("paper", render_paper_summary),
    "paper-output": ("paper", render_paper_output),
    "paper-modes": ("paper", render_paper_modes),
    "modes-example": ("commands", render_modes_example),
    "frf-example": ("commands", render_frf_example),
    "frf-uff": ("commands", render_frf_uff),
    "simulate-example": ("commands", render_simulate_example),
    "identify-example": ("commands", render_identify_example),
    "record-head": ("commands", render_record_head),
    "json-identify": ("commands", render_json_identify),
    "json-modes": ("commands", render_json_modes),
    "json-response": ("commands", render_json_response),
    "json-design": ("commands", render_json_design),
    "json-compare": ("commands", render_json_compare),
    "json-modal-fit": ("commands", render_json_modal_fit),
    "json-discover": ("quickstart", render_json_discover),
    "response-example": ("commands", render_response_example),
    "design-example": ("commands", render_design_example),
    "compare-example": ("commands", render_compare_example),
    "modal-fit-example": ("commands", render_modal_fit_example),
    "stepped-sine-vs-records": ("commands", render_stepped_sine),
    "noise-estimate": ("commands", render_noise_estimate),
    "stepped-sine-head": ("commands", render_stepped_sine_head),
    "three-joints-design": ("commands", render_three_joints_design),
    "three-joints-output": ("three-joints", render_three_joints),
    "polyethylene-output": ("polyethylene", render_polyethylene),
    "design-study-output": ("design-study", render_design_study),
}
for _group in GROUPS:
    RENDERERS[f"run-{_group}"] = (_group, None)


def regions(text: str):
    """(name, options, start of content, end of content) for every region of a page."""
    for m in BEGIN.finditer(text):
        name = m.group(1)
        end = text.find(f"<!-- generated:{name} end -->", m.end())
        if end < 0:
            raise Failure(f"region {name}: no <!-- generated:{name} end -->")
        opts = dict(o.split("=", 1) for o in m.group(2).split())
        yield name, opts, m.end(), end


def unit(token: str) -> float:
    """One unit of the last digit printed in a number's text."""
    mantissa, _, exponent = token.lower().partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def compare(page: str, run: str, rtol: float, atol: float):
    """None if page and run agree (words exactly, numbers within tolerance), else why not."""
    def skeleton(s):
        return " ".join(NUMBER.sub("#", s).split())
    if skeleton(page) != skeleton(run):
        a, b = skeleton(page).split(), skeleton(run).split()
        i = next((k for k in range(min(len(a), len(b))) if a[k] != b[k]), min(len(a), len(b)))
        return (f"the words differ at word {i}: page '{' '.join(a[max(0, i - 5):i + 5])}', "
                f"run '{' '.join(b[max(0, i - 5):i + 5])}'")
    for x, y in zip(NUMBER.findall(page), NUMBER.findall(run)):
        a, b = float(x), float(y)
        allowed = max(rtol * max(abs(a), abs(b)), atol, unit(x), unit(y))
        if abs(a - b) > allowed * (1 + 1e-9):
            return f"page {x}, run {y} (allowed difference {allowed:.3g})"
    return None


def process(groups, out, check: bool) -> int:
    seen, differ, checked = set(), 0, 0
    for page in PAGES:
        text = read(page)
        pieces, last = [], 0
        for name, opts, start, end in regions(text):
            if name not in RENDERERS:
                raise Failure(f"{page.relative_to(ROOT)}: unknown region '{name}'")
            seen.add(name)
            group, render = RENDERERS[name]
            if group not in groups:
                continue
            if render is None:  # run-<group>: date, commit, machine and times
                if check:
                    continue
                new = render_run(group)
            else:
                new = render(out)
            pieces.append(text[last:start])
            pieces.append(new.rstrip("\n") + "\n")
            last = end
            if check:
                checked += 1
                why = compare(text[start:end], new,
                              float(opts.get("rtol", 0)), float(opts.get("atol", 0)))
                if why:
                    differ += 1
                    print(f"DIFFERS {page.relative_to(ROOT)} region {name}: {why}")
                else:
                    print(f"ok      {page.relative_to(ROOT)} region {name}")
        pieces.append(text[last:])
        if not check and "".join(pieces) != text:
            page.write_text("".join(pieces), encoding="utf-8")
            print(f"updated {page.relative_to(ROOT)}")
    missing = [n for n, (grp, _) in RENDERERS.items()
               if grp in groups and n not in seen and not n.startswith("run-")]
    if missing:
        raise Failure("regions on no page: " + ", ".join(missing))
    if check:
        print(f"{checked} regions checked, {differ} differ")
    return 1 if differ else 0


LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")


def slug(heading: str) -> str:
    """GitHub's anchor for a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower().replace("`", ""))
    return text.replace(" ", "-")


def check_links() -> int:
    """Every relative link of README.md and docs/ names a file that exists (and a heading of it,
    after a #). Returns the number of broken links."""
    broken = 0
    anchors = {}
    for page in PAGES:
        for m in LINK.finditer(read(page)):
            target = m.group(1) or m.group(2)
            if re.match(r"[a-z]+:", target):
                continue  # http:, https:, mailto:
            path, _, anchor = target.partition("#")
            file = (page.parent / path).resolve() if path else page
            where = f"{page.relative_to(ROOT)}: link {target}"
            if not file.exists():
                print(f"BROKEN  {where}: no such file")
                broken += 1
                continue
            if ROOT not in file.parents and file != ROOT:
                print(f"BROKEN  {where}: leaves the repository")
                broken += 1
                continue
            if anchor and file.suffix == ".md":
                if file not in anchors:
                    text = re.sub(r"```.*?```", "", read(file), flags=re.S)
                    anchors[file] = {slug(h) for h in re.findall(r"^#+ (.*)$", text, re.M)}
                if anchor not in anchors[file]:
                    print(f"BROKEN  {where}: no heading #{anchor}")
                    broken += 1
    print(f"links checked, {broken} broken")
    return broken


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="compare instead of rewriting")
    ap.add_argument("--only", help="comma-separated groups (default: all): " + ", ".join(GROUPS))
    ap.add_argument("--build", default=str(ROOT / "build"), help="build directory (./build)")
    ap.add_argument("--links", action="store_true",
                    help="only check that every relative link names an existing file and heading")
    args = ap.parse_args()
    if args.links:
        return 1 if check_links() else 0
    groups = args.only.split(",") if args.only else list(GROUPS)
    for grp in groups:
        if grp not in GROUPS:
            print(f"update_docs: --only: unknown group '{grp}' (groups: {', '.join(GROUPS)})",
                  file=sys.stderr)
            return 2
    build = Path(args.build).resolve()
    if not (build / "cli" / "jointid").is_file():
        print(f"update_docs: {build}/cli/jointid not found: build first (scripts/build.sh)",
              file=sys.stderr)
        return 2
    r = Runner(build, args.check)
    out = {}
    try:
        for grp in groups:
            print(f"running {grp} ...", flush=True)
            GROUPS[grp](r, out)
        if not args.check:
            log_runs(r.times)
        return process(groups, out, args.check)
    except Failure as e:
        print(f"update_docs: {e}", file=sys.stderr)
        return 1
    finally:
        r.close()


if __name__ == "__main__":
    sys.exit(main())
