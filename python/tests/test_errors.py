"""Bad input raises jointid.Error (a ValueError) with the message the CLI prints for the same
input; an argument is named by its keyword where the CLI names its option."""

import numpy as np
import pytest

import jointid
from conftest import CANTILEVER, cli_error, one_line


def message(call):
    with pytest.raises(jointid.Error) as caught:
        call()
    return one_line(str(caught.value))


def test_error_is_a_value_error():
    assert issubclass(jointid.Error, ValueError)


def test_a_bad_model_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(CANTILEVER.read_text().replace('dof = "uy"', 'dof = "uw"'))
    python = message(lambda: jointid.read_model(bad))
    assert python == cli_error("modes", bad, "-o", tmp_path / "out", "--no-plot")
    assert "bad.toml:" in python and "'dof'" in python and '"uw"' in python
    missing = tmp_path / "missing.toml"
    assert message(lambda: jointid.read_model(missing)) == cli_error("modes", missing, "-o",
                                                                     tmp_path / "out")


def test_a_bad_model_dict():
    d = {"model": {"dimension": 2}, "materials": [{"name": "steel", "E": "stiff"}]}
    text = message(lambda: jointid.read_model(d))
    assert text.startswith("<dict>: ") and "[[materials]]" in text and "'E'" in text
    assert "key" in message(lambda: jointid.read_model({"model": {1: 2}}))
    text = message(lambda: jointid.read_model({"model": {"dimension": object()}}))
    assert text.startswith("model.dimension: expected a dict, list, str, int, float or bool")


def test_a_dof_the_model_lacks(cantilever, tmp_path):
    python = message(lambda: jointid.simulate_sine(cantilever, force="9:uy", freq_hz=3.0,
                                                   amplitude=10.0))
    cli = cli_error("simulate", CANTILEVER, "--force", "9:uy", "--freq", 3, "--amplitude", 10,
                    "-o", tmp_path)
    assert python == cli.replace("--force", "force")
    python = message(lambda: jointid.response(cantilever, force="7:ux", amplitude=10.0,
                                              freq_range=(2, 4)))
    cli = cli_error("response", CANTILEVER, "--force", "7:ux", "--amplitude", 10,
                    "--freq-range", "2:4", "-o", tmp_path)
    assert python == cli.replace("--force", "force")
    assert "rows" in message(lambda: cantilever.receptance(3.0, "7:uz", "7:uy"))


@pytest.mark.parametrize("harmonics,option", [([0], "0"), ([1, 1], "1,1"), ([51], "51")])
def test_bad_harmonics(cantilever, tmp_path, harmonics, option):
    record = tmp_path / "r.csv"
    record.write_text("t,f@7:uy,x@7:uy\n0,0,0\n1,1,1\n2,0,0\n3,1,1\n")
    python = message(lambda: jointid.identify(cantilever, [record], harmonics=harmonics))
    cli = cli_error("identify", CANTILEVER, record, "-o", tmp_path / "r.json", "--harmonics", option)
    assert python == cli.replace("--harmonics", "harmonics")
    if harmonics == [51]:  # no fixed cap: the record's sampling refuses it, naming the record
        assert python.startswith(str(record)) and "Nyquist" in python


def test_bad_records(cantilever, tmp_path):
    uneven = tmp_path / "uneven.csv"
    uneven.write_text("t,f@7:uy,x@7:uy\n0,0,0\n1,1,1\n2.5,0,0\n3,1,1\n")
    python = message(lambda: jointid.identify(cantilever, [uneven]))
    assert python == cli_error("identify", CANTILEVER, uneven, "-o", tmp_path / "r.json")
    assert "uneven.csv:4:" in python
    twice = message(lambda: jointid.identify(cantilever, [uneven, uneven]))
    assert twice == cli_error("identify", CANTILEVER, uneven, uneven, "-o", tmp_path / "r.json")
    # From arrays: the same contract.
    t = np.array([0.0, 1.0, 2.5, 3.0])
    assert "sampling must be uniform" in message(
        lambda: jointid.Record(t, {"f@7:uy": t, "x@7:uy": t}))
    t = np.arange(8.0)
    assert message(lambda: jointid.Record(t, {"y@7:uy": t})) == (
        "Record record: channels: channel 'y@7:uy': quantity must be f, x, v or a")
    assert "has 3 samples but t has 8" in message(
        lambda: jointid.Record(t, {"x@7:uy": t[:3]}))
    with pytest.raises(KeyError, match="no channel f@7:uy"):
        jointid.Record(t, {"x@7:uy": t})["f@7:uy"]


def test_a_model_without_joints(tmp_path):
    bare = tmp_path / "bare.toml"
    text = CANTILEVER.read_text()
    bare.write_text(text[: text.index("[[joints]]")])
    record = tmp_path / "r.csv"
    record.write_text("t,f@7:uy,x@7:uy\n0,0,0\n1,1,1\n2,0,0\n3,1,1\n")
    python = message(lambda: jointid.identify(jointid.read_model(bare), [record]))
    assert python == cli_error("identify", bare, record, "-o", tmp_path / "r.json")
    python = message(lambda: jointid.discover(jointid.read_model(bare), [record]))
    assert python == cli_error("discover", bare, record, "-o", tmp_path / "d")


def test_bad_arguments(cantilever):
    assert message(lambda: cantilever.modes(0)) == "count: expected at least 1, got 0"
    assert "method: expected time or hb" in message(
        lambda: jointid.simulate_sine(cantilever, force="7:uy", freq_hz=3.0, amplitude=1.0,
                                      method="fft"))
    assert message(lambda: jointid.simulate_sine(cantilever, force="7:uy", freq_hz=3.0,
                                                 amplitude=-1.0)) == (
        "amplitude: expected finite amplitudes > 0 (N or N m), got -1")
    assert "tests: expected a list" in message(lambda: jointid.identify(cantilever, "r.csv"))
    t = np.arange(8.0)
    r = jointid.Record(t, {"f@7:uy": t, "x@7:uy": t}, source="r.csv")
    assert message(lambda: jointid.identify(cantilever, [r, r])) == (
        "tests: r.csv is given twice (each test would count twice and the uncertainty come out "
        "falsely small)")
    with pytest.raises(TypeError):
        jointid.identify(cantilever, [1.5])
    assert message(lambda: jointid.discover(cantilever, [r], max_balance_lines=0)) == (
        "max_balance_lines: expected at least 1, got 0")
