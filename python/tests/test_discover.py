"""jointid.discover against `jointid discover` on the same model and records."""

import pytest

import jointid
from conftest import CANTILEVER, assert_same, read_json, run_cli


def model_file(path, joint):
    """The paper's cantilever with another [[joints]] table."""
    text = CANTILEVER.read_text()
    path.write_text(text[: text.index("[[joints]]")] + joint)
    return path


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """Tests of a tip joint that hides a cubic stiffness (1 % noise), and a starting model with
    the linear joint alone, its values unknown."""
    d = tmp_path_factory.mktemp("discover")
    hidden = model_file(d / "hidden.toml", '[[joints]]\nname = "tip"\nnode = 7\ndof = "uy"\n'
                        'terms = ["k", "c", "k3"]\nvalues = { k = 4800.0, c = 20.0, k3 = 1.6e8 }\n')
    start = model_file(d / "start.toml",
                       '[[joints]]\nname = "tip"\nnode = 7\ndof = "uy"\nterms = ["k", "c"]\n')
    run_cli("simulate", hidden, "--force", "7:uy", "--freq", "2.5,3.5,4.5", "--amplitude", "20,60",
            "--method", "hb", "--periods", 4, "--steps-per-period", 256, "--samples-per-period", 64,
            "--noise", 0.01, "--seed", 1, "-o", d / "data")
    return start, sorted((d / "data").glob("*.csv"))


OPTIONS = dict(harmonics=[1, 2, 3], balance_harmonics=7, max_steps=2, terms=["k3", "c2", "fc"],
               damping_candidate=False)


def test_discovery_as_the_cli(case, tmp_path):
    start, records = case
    run_cli("discover", start, *records, "-o", tmp_path, "--harmonics", "1,2,3",
            "--balance-harmonics", 7, "--max-steps", 2, "--terms", "k3,c2,fc",
            "--no-damping-candidate", "--no-plot")
    result = jointid.discover(jointid.read_model(start), records, **OPTIONS)
    assert_same(result.to_dict(), read_json(tmp_path / "discovery.json"))

    # What it found: k3 at the tip, near the hidden value, and the gap fell.
    steps = result.steps
    assert steps[0]["joint"] == "tip" and steps[0]["term"] == "k3"
    assert steps[0]["value"] == pytest.approx(1.6e8, rel=0.05)
    assert result.gap[-1] < 0.5 * result.gap[0]
    final = result.final_joints[0]
    assert final["terms"][:3] == ["k", "c", "k3"] and set(final["values"]) == set(final["terms"])
    assert result.findings and result.stop_reason
