"""jointid.identify against `jointid identify` on the same model and records."""

import pytest

import jointid
from conftest import CANTILEVER, assert_same, read_json, run_cli

TESTS = dict(freq_hz=[2.0, 2.6, 3.2, 3.8], amplitude=[40.0, 80.0])


@pytest.fixture(scope="module")
def records_dir(tmp_path_factory):
    """Model I's tests with 1 % noise (4 periods: the noise is estimated from the records)."""
    d = tmp_path_factory.mktemp("records")
    run_cli("simulate", CANTILEVER, "--force", "7:uy", "--freq", "2,2.6,3.2,3.8",
            "--amplitude", "40,80", "--method", "hb", "--periods", 4, "--steps-per-period", 256,
            "--samples-per-period", 64, "--noise", 0.01, "--seed", 7, "-o", d)
    return d


def paths(d):
    return sorted(d.glob("sine_*.csv"))


@pytest.mark.parametrize("harmonics", [[1], [1, 2, 3]])
def test_equation_error_as_the_cli(cantilever, records_dir, tmp_path, harmonics):
    run_cli("identify", CANTILEVER, *paths(records_dir), "-o", tmp_path / "r.json", "--harmonics",
            ",".join(map(str, harmonics)), "--no-plot")
    cli = read_json(tmp_path / "r.json")
    from_files = jointid.identify(cantilever, paths(records_dir), harmonics=harmonics)
    assert_same(from_files.to_dict(), cli)
    # The same records in memory (read, or simulated here with the same seed) give the same.
    records = [jointid.read_record(p) for p in paths(records_dir)]
    assert_same(jointid.identify(cantilever, records, harmonics=harmonics).to_dict(), cli)
    simulated = jointid.simulate_sine(cantilever, force="7:uy", method="hb", periods=4,
                                      steps_per_period=256, samples_per_period=64, noise=0.01,
                                      seed=7, **TESTS)
    simulated.sort(key=lambda r: r.source)
    assert [r.source for r in simulated] == [p.name for p in paths(records_dir)]
    for r, p in zip(simulated, paths(records_dir)):
        r.source = str(p)  # as the CLI names them (in the result's noise table)
    assert_same(jointid.identify(cantilever, simulated, harmonics=harmonics).to_dict(), cli)


def test_output_error_as_the_cli(cantilever, records_dir, tmp_path):
    run_cli("identify", CANTILEVER, *paths(records_dir), "-o", tmp_path / "r.json",
            "--output-error", "--balance-harmonics", 9, "--no-plot")
    result = jointid.identify(cantilever, paths(records_dir), output_error=True,
                              balance_harmonics=9)
    assert_same(result.to_dict(), read_json(tmp_path / "r.json"))
    assert result.interval_method == "output error"


def test_values_std_and_intervals(cantilever, records_dir):
    result = jointid.identify(cantilever, paths(records_dir))
    d = result.to_dict()
    terms = {t["term"]: t for t in d["joints"][0]["terms"]}
    assert list(result.values) == ["tip"] and list(result.values["tip"]) == ["k", "c", "c2", "k3"]
    for term, t in terms.items():
        assert result.values["tip"][term] == t["value"]
        assert result.std["tip"][term] == t["std"]
        assert list(result.ci95["tip"][term]) == t["ci95"]
    # The truth (the model's values) within 4 standard deviations (1 % noise): a miss has odds
    # of 6e-5 when the intervals are right.
    truth = cantilever.joints[0]["values"]
    for term, value in result.values["tip"].items():
        assert abs(value - truth[term]) <= 4 * result.std["tip"][term], term
    assert result.values["tip"]["k"] == pytest.approx(4800.0, rel=1e-2)
    assert result.warnings == d["warnings"] and result.equations == d["equations"]
    assert result.joints[0]["values"] == result.values["tip"]
