"""jointid.simulate_sine against `jointid simulate` on the same model; records from numpy arrays
and from files, their arrays as views."""

import numpy as np
import pytest

import jointid
from conftest import CANTILEVER, SAME_CODE, run_cli

HB = dict(freq_hz=[2.0, 3.5], amplitude=[40.0, 80.0], periods=4, steps_per_period=256,
          samples_per_period=64)


def cli_simulate(tmp_path, method, **extra):
    args = ["simulate", CANTILEVER, "--force", "7:uy", "--freq", "2,3.5", "--amplitude", "40,80",
            "--method", method, "--periods", 4, "--steps-per-period", 256,
            "--samples-per-period", 64, "-o", tmp_path]
    for k, v in extra.items():
        args += ["--" + k.replace("_", "-"), v]
    run_cli(*args)


def assert_same_records(records, directory):
    assert len(records) == 4
    for r in records:
        cli = jointid.read_record(directory / r.source)  # the CLI's file of the same test
        assert r.channel_names == cli.channel_names == ["f@7:uy", "x@7:uy", "v@7:uy"]
        assert r.excitation_hz == cli.excitation_hz
        np.testing.assert_allclose(r.t, cli.t, rtol=SAME_CODE, atol=0)
        for name in r.channel_names:
            np.testing.assert_allclose(r[name], cli[name], rtol=SAME_CODE, atol=1e-300)


def test_harmonic_balance_as_the_cli(cantilever, tmp_path):
    cli_simulate(tmp_path, "hb")
    records = jointid.simulate_sine(cantilever, force="7:uy", method="hb", **HB)
    assert [r.source for r in records] == ["sine_f2Hz_F40N.csv", "sine_f2Hz_F80N.csv",
                                           "sine_f3.5Hz_F40N.csv", "sine_f3.5Hz_F80N.csv"]
    assert_same_records(records, tmp_path)
    assert all(r.warnings == [] for r in records)
    # 4 periods of 64 samples; the force acts at the joint's DOF (one response channel each).
    assert len(records[0]) == 256 and records[0].dt == pytest.approx(1 / (2.0 * 64), rel=1e-12)


def test_time_integration_with_noise_as_the_cli(cantilever, tmp_path):
    cli_simulate(tmp_path, "time", noise=0.01, seed=3)
    records = jointid.simulate_sine(cantilever, force="7:uy", method="time", noise=0.01, seed=3,
                                    **HB)
    assert_same_records(records, tmp_path)
    assert any("noise" in c for c in records[0].comments)


def test_record_arrays_are_views_of_the_record(cantilever):
    r = jointid.simulate_sine(cantilever, force="7:uy", method="hb", **HB)[0]
    x = r["x@7:uy"]
    assert np.shares_memory(x, r["x@7:uy"]) and np.shares_memory(x, r.channels["x@7:uy"])
    assert np.shares_memory(r.t, r.t) and x.flags.writeable
    assert x.base is r and r.t.base is r and not x.flags.owndata and not r.t.flags.owndata
    before, x0 = r.to_csv(), x[0]
    x[0] = 0.125  # in place: the record itself changes
    assert r["x@7:uy"][0] == 0.125 and r.to_csv() != before
    x[0] = x0
    assert r.to_csv() == before
    # A view outlives the name of its record.
    t = jointid.simulate_sine(cantilever, force="7:uy", method="hb", **HB)[0].t
    np.testing.assert_array_equal(t, r.t)


def test_a_record_from_arrays_round_trips_through_its_file(cantilever, tmp_path):
    source = jointid.simulate_sine(cantilever, force="7:uy", method="hb", **HB)[3]
    t, x = np.array(source.t), np.array(source["x@7:uy"])
    f = 80.0 * np.sin(2 * np.pi * 3.5 * t)
    r = jointid.Record(t, {"f@7:uy": f, "x@7:uy": x}, excitation_hz=3.5, source="made.csv",
                       comments=["made in Python"])
    # Copied once into the record (which owns its samples), then seen through views.
    assert not np.shares_memory(r.t, t)
    np.testing.assert_array_equal(r["f@7:uy"], f)
    r.to_csv(tmp_path / "made.csv")
    back = jointid.read_record(tmp_path / "made.csv")
    assert back.channel_names == ["f@7:uy", "x@7:uy"] and back.excitation_hz == 3.5
    for name in back.channel_names:
        np.testing.assert_array_equal(back[name], r[name])  # shortest round-trip numbers
    np.testing.assert_array_equal(back.t, r.t)
    assert (tmp_path / "made.csv").read_text().startswith("# made in Python\n")


def test_stepped_sine_tables_are_read_as_rows(tmp_path):
    run_cli("simulate", CANTILEVER, "--force", "7:uy", "--freq", "2,3", "--amplitude", 50,
            "--method", "hb", "--table", "-o", tmp_path)
    rows = jointid.read_tests([tmp_path / "stepped_sine.csv"])
    assert [type(r) for r in rows] == [jointid.SteppedSineRow] * 2
    assert [r.frequency_hz for r in rows] == [2.0, 3.0]
    assert set(rows[0].channels) == {"f@7:uy", "x@7:uy", "v@7:uy"}
    # F sin(ωt) = Re(-i F e^{iωt}): the force's phasor is -50 i.
    assert rows[0].channels["f@7:uy"] == pytest.approx(-50j, abs=1e-9)
