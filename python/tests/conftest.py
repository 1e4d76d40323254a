"""What the tests of the module jointid share: the CLI they compare with, the example models,
and a comparison of JSON results to rounding.

Run by CTest (python_* tests) with PYTHONPATH=<build>/python and JOINTID_CLI=<build>/cli/jointid;
by hand: PYTHONPATH=build/python JOINTID_CLI=build/cli/jointid /usr/bin/python3 -m pytest python/tests
"""

import json
import math
import os
import pathlib
import subprocess
import tomllib

import pytest

SOURCE = pathlib.Path(os.environ.get("JOINTID_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
CLI = pathlib.Path(os.environ.get("JOINTID_CLI", SOURCE / "build" / "cli" / "jointid"))
CANTILEVER = SOURCE / "examples" / "paper_cantilever" / "cantilever.toml"

# Where Python and the CLI run the same code on the same inputs, they agree to the last bits;
# 1e-12 (relative) leaves room for nothing but the printing of numbers, which is exact here
# (shortest round-trip forms in CSV, 17 digits in JSON).
SAME_CODE = 1e-12


# No display, and no re-run under xvfb-run to draw: the tests give --no-plot where pictures
# would be drawn, and the errors come before any.
CLI_ENV = {**os.environ, "DISPLAY": "", "JOINTID_UNDER_XVFB": "1"}


def run_cli(*args):
    """Runs the CLI; fails the test with its stderr when it fails."""
    done = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=CLI_ENV)
    assert done.returncode == 0, f"jointid {' '.join(map(str, args))}: {done.stderr}"
    return done


def cli_error(*args):
    """The one-line reason the CLI gives for refusing these arguments (without "jointid: ")."""
    done = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=CLI_ENV)
    assert done.returncode != 0, f"jointid {' '.join(map(str, args))} did not fail"
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith("jointid: "), line
    return line[len("jointid: "):]


def one_line(text):
    """As the CLI prints a message: newlines as spaces."""
    return " ".join(text.replace("\r", "\n").split("\n")).rstrip()


def assert_same(a, b, rel=SAME_CODE, where="$"):
    """JSON-like values equal, numbers to `rel` (relative; 1e-300 absolute for zeros)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), f"{where}: keys {a.keys()} vs {b.keys()}"
        for k in a:
            assert_same(a[k], b[k], rel, f"{where}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{where}: lengths differ"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, rel, f"{where}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert math.isclose(a, b, rel_tol=rel, abs_tol=1e-300), f"{where}: {a} vs {b}"
    else:
        assert a == b, f"{where}: {a!r} vs {b!r}"


def read_json(path):
    return json.loads(pathlib.Path(path).read_text())


def cantilever_dict(**joint):
    """The paper's cantilever as dicts (tomllib), its tip joint changed by `joint`."""
    with open(CANTILEVER, "rb") as f:
        d = tomllib.load(f)
    d["joints"][0].update(joint)
    return d


@pytest.fixture(scope="session")
def cantilever():
    import jointid

    return jointid.read_model(CANTILEVER)
