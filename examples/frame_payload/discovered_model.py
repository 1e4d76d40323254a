#!/usr/bin/env python3
"""Writes the model that `jointid discover` ended at as a model file that `jointid compare` and
`jointid simulate` read: the starting model file with its [[joints]] tables given the terms and
values of discovery.json's final_model (joints matched by name; their nodes and DOFs as in the
starting model).

Usage: discovered_model.py START.toml DISCOVERY.json OUT.toml

The starting model's [[joints]] must be its last tables (as in examples/frame_payload/start.toml):
everything before the first [[joints]] is copied as it is. A substructure damping scale other
than 1 cannot be written into a [[substructures]] model and is refused."""
import json
import os
import re
import sys


def toml_value(x, what):
    if not isinstance(x, (int, float)):
        sys.exit(f"{what}: expected a number, got {x!r}")
    return repr(float(x))


def main(start_path, discovery_path, out_path):
    start = open(start_path, encoding="utf-8").read()
    with open(discovery_path, encoding="utf-8") as f:
        final = json.load(f)["final_model"]
    scale = final.get("substructure_damping_scale", 1.0)
    if scale is not None and abs(scale - 1.0) > 1e-12:
        sys.exit(f"{discovery_path}: final_model.substructure_damping_scale is {scale}; this "
                 "script writes joints only (a [[substructures]] model has no damping scale)")
    head, sep, rest = start.partition("[[joints]]")
    if not sep:
        sys.exit(f"{start_path}: no [[joints]] table")
    # Each starting joint's geometry: node, node_b, dof (the lines other than terms/values/fixed).
    geometry = {}
    for block in ("[[joints]]" + rest).split("[[joints]]")[1:]:
        name = re.search(r'^\s*name\s*=\s*"([^"]+)"', block, re.M)
        if not name:
            sys.exit(f"{start_path}: a [[joints]] table without a name")
        lines = [l for l in block.strip().splitlines()
                 if re.match(r"\s*(node|node_b|dof)\s*=", l)]
        geometry[name.group(1)] = lines
    out = [head.rstrip() + "\n"]
    for joint in final["joints"]:
        name = joint["name"]
        if name not in geometry:
            sys.exit(f"{discovery_path}: joint '{name}' is not in {start_path}")
        terms, values = [], []
        for t in joint["terms"]:
            terms.append(t["term"])
            if "parameters" in t:
                for p in t["parameters"]:
                    if p["value"] is None:
                        sys.exit(f"{discovery_path}: {t['term']}.{p['name']} of '{name}' has no "
                                 "value (undetermined)")
                    values.append(f'"{t["term"]}.{p["name"]}" = '
                                  f'{toml_value(p["value"], name + "." + t["term"])}')
            else:
                values.append(f'{t["term"]} = {toml_value(t["value"], name + "." + t["term"])}')
        out.append("\n[[joints]]  # as discovered: " + discovery_path + "\n")
        out.append(f'name = "{name}"\n')
        out.extend(l.strip() + "\n" for l in geometry[name])
        out.append("terms = [" + ", ".join(f'"{t}"' for t in terms) + "]\n")
        out.append("values = { " + ", ".join(values) + " }\n")
    with open(out_path + ".part", "w", encoding="utf-8") as f:
        f.writelines(out)
    os.replace(out_path + ".part", out_path)
    print(f"wrote {out_path}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
