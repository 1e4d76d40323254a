#!/usr/bin/python3
"""Writes the measured part of docs/benchmarks_modal.md from the run records of
scripts/bench_modal_scale.sh (one JSON object a line). Only the text between
<!-- BEGIN GENERATED --> and <!-- END GENERATED --> is replaced; a missing file is created.

  benchmarks_modal_table.py RUNS.jsonl OUT.md [--limits TEXT] [--quiet-load L] [--note TEXT]
"""
import argparse
import datetime
import json
import os
import platform
import re
import subprocess

BEGIN, END = "<!-- BEGIN GENERATED -->", "<!-- END GENERATED -->"


def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True).stdout.strip()
    except OSError:
        return ""


def machine():
    model = sh("lscpu | sed -n 's/^Model name:[ \\t]*//p' | head -1")
    cores = os.cpu_count()
    mem_kib = int(re.search(r"MemTotal:\s+(\d+)", open("/proc/meminfo").read()).group(1))
    os_name = sh(". /etc/os-release && echo $PRETTY_NAME")
    blas = sh("readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3")
    pkgs = sh("dpkg-query -W -f='${Package} ${Version}\\n' libcholmod3 libspectra-dev "
              "libeigen3-dev libblas3 libopenblas0-pthread python3-scipy python3-numpy g++ "
              "2>/dev/null")
    return [f"- CPU: {model}, {cores} cores; RAM {mem_kib / 1024 / 1024:.1f} GiB; {os_name}, "
            f"kernel {platform.release()}",
            f"- BLAS behind CHOLMOD and scipy: `{blas}`",
            "- packages: " + "; ".join(f"{p}" for p in pkgs.splitlines())]


def fmt(x, digits=3):
    if x is None:
        return "–"
    if isinstance(x, float):
        return f"{x:.{digits}g}" if abs(x) < 1e4 else f"{x:,.0f}"
    if isinstance(x, int):
        return f"{x:,}"
    return str(x)


def outcome(rec):
    if rec is None:
        return "not run"
    if rec["rc"] == 0:
        return "ok"
    if rec["rc"] == 124:
        return (f"timed out after {rec['wall_s']:.0f} s (peak RSS until then "
                f"{rec['time_maxrss_mib']:.0f} MiB)")
    tail = " / ".join(rec.get("output_tail", []))
    return f"failed (exit {rec['rc']}) after {rec['wall_s']:.0f} s: `{tail}`"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs")
    ap.add_argument("out")
    ap.add_argument("--limits", default="")
    ap.add_argument("--quiet-load", default="")
    ap.add_argument("--note", default="", help="a line to add under the date, e.g. how runs were merged")
    args = ap.parse_args()
    recs = [json.loads(line) for line in open(args.runs) if line.strip()]
    by = {(r["size"], r["tool"]): r for r in recs}
    sizes = list(dict.fromkeys(r["size"] for r in recs))

    lines = [BEGIN, "",
             f"Measured {datetime.date.today().isoformat()} by `scripts/bench_modal_scale.sh`."
             + (f" {args.note}" if args.note else ""), ""]
    lines += machine()
    lines += [f"- limits: {args.limits}",
              f"- each run started when the 1-minute load average was below {args.quiet_load} "
              "(or after the wait limit); the load before/after each run is in the last column",
              ""]
    lines += ["Problem and jointid (`fem::assemble`, then `fem::modal_analysis` with the sparse "
              "engine, 20 modes, σ = −(2π·1 Hz)²):", "",
              "| size | grid (nodes/axis) | nodes | elements | free DOFs | nnz(K) | "
              "assembly s | eigen s | peak RSS MiB (to assembly / eigen stage) | "
              "‖KΦ−MΦΛ‖/‖KΦ‖ | max abs(ΦᵀMΦ−I) | load before→after |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    scipy_rows = []
    stage_rows = []
    notes = []
    for size in sizes:
        j = by.get((size, "jointid"))
        jr = j.get("result") if j else None
        geo = jr or (j.get("partial") if j else None) or {}
        row = [size, "×".join(str(g) for g in geo.get("grid", [])), fmt(geo.get("nodes")),
               fmt(geo.get("elements")), fmt(geo.get("dofs")), fmt(geo.get("nnz_K"))]
        if jr and j["rc"] == 0:
            row += [fmt(jr["assembly_s"]), fmt(jr["modal_s"]),
                    f"{jr['peak_rss_to_assembly_mib']:.0f} / {jr['peak_rss_modal_mib']:.0f}",
                    f"{jr['residual']:.1e}", f"{jr['orthonormality']:.1e}"]
        else:
            part = j.get("partial", {}) if j else {}
            row += [fmt(part.get("assembly_s")), "–",
                    f"{part['peak_rss_to_assembly_mib']:.0f} / –" if part else "–", "–", "–"]
            notes.append(f"- {size} jointid (fem::assemble + fem::modal_analysis): {outcome(j)}")
        row.append(f"{j['load_before']:.2f}→{j['load_after']:.2f}" if j else "–")
        lines.append("| " + " | ".join(row) + " |")
        sp = jr.get("sparse") if jr else None
        if sp:
            stage_rows.append("| " + " | ".join([
                size, sp["ordering_used"], f"{sp['lnz']:.3g}", f"{sp['factor_entries']:.3g}",
                f"{sp['factor_gib']:.2f}", f"{sp['factor_flops']:.3g}", fmt(sp["analyze_s"]),
                fmt(sp["factorize_s"]), f"{sp['factor_flops'] / sp['factorize_s'] / 1e9:.0f}",
                f"{fmt(sp['lanczos_s'])} ({sp['solves']} solves, {fmt(sp['solve_s'])} s)",
                str(sp["restarts"])]) + " |")
        for tool, label in (("scipy", "eigsh default (splu, COLAMD)"),
                            ("scipy_sym", "eigsh + OPinv = splu symmetric mode (MMD_AT_PLUS_A)")):
            s = by.get((size, tool))
            if s is None:
                continue
            sr = s.get("result")
            srow = [size, label]
            if sr and s["rc"] == 0:
                srow += [fmt(sr["eigsh_s"]),
                         f"{sr['peak_rss_read_mib']:.0f} / {sr['peak_rss_solve_mib']:.0f}"]
                if jr and j["rc"] == 0:
                    srow += [f"{sr['eigsh_s'] / jr['modal_s']:.1f}×",
                             f"{sr['max_rel_diff']:.1e}" if "max_rel_diff" in sr else "–"]
                else:
                    srow += ["–", "–"]
                srow.append(f"{sr['residual']:.1e}")
            else:
                srow += [outcome(s), "–", "–", "–", "–"]
            srow.append(f"{s['load_before']:.2f}→{s['load_after']:.2f}")
            scipy_rows.append("| " + " | ".join(srow) + " |")
    lines += ["", "jointid's sparse engine stage by stage (`Modes::sparse`; CHOLMOD supernodal, 64-bit "
              "indices; the ordering is the candidate with the smallest predicted factor):", "",
              "| size | ordering | nnz(L) | stored values | predicted factor + workspace GiB | "
              "flops | analysis s | factorisation s | GFlop/s | Lanczos s (solves) | restarts |",
              "|---|---|---|---|---|---|---|---|---|---|---|"] + stage_rows
    lines += ["", "scipy on the same K and M (MatrixMarket files written by the bench; reading "
              "excluded from the time):", "",
              "| size | scipy call | eigsh s | peak RSS MiB (after reading / eigsh stage) | "
              "speed-up of jointid (scipy s / jointid eigen s) | max rel. Δλ vs jointid | "
              "‖KΦ−MΦΛ‖/‖KΦ‖ | load before→after |",
              "|---|---|---|---|---|---|---|---|"] + scipy_rows
    lines += [""] + notes + ["", "Raw records (one JSON line per run; eigenvalues left out, first five frequencies in Hz):", "", "```"]
    for r in recs:  # eigenvalues stay in the JSONL file; the first five frequencies here
        short = dict(r)
        if isinstance(r.get("result"), dict):
            res = dict(r["result"])
            res.pop("eigenvalues", None)
            if "frequencies_hz" in res:
                res["frequencies_hz"] = [round(f, 6) for f in res["frequencies_hz"][:5]]
            short["result"] = res
        lines.append(json.dumps(short))
    lines += ["```", "", END]
    block = "\n".join(lines)

    if os.path.exists(args.out):
        text = open(args.out).read()
        if BEGIN in text and END in text:
            text = text[:text.index(BEGIN)] + block + text[text.index(END) + len(END):]
        else:
            text = text.rstrip("\n") + "\n\n" + block + "\n"
    else:
        text = "# Modal analysis at scale: jointid and scipy\n\n" + block + "\n"
    with open(args.out, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
