"""jointid.response against `jointid response` on the same model."""

import numpy as np

import jointid
from conftest import CANTILEVER, assert_same, read_json, run_cli


def test_response_curves_as_the_cli(cantilever, tmp_path):
    run_cli("response", CANTILEVER, "--force", "7:uy", "--amplitude", "20,60",
            "--freq-range", "3:7", "--balance-harmonics", 5, "--no-plot", "-o", tmp_path)
    curves = jointid.response(cantilever, force="7:uy", amplitude=[20.0, 60.0],
                              freq_range=(3.0, 7.0), balance_harmonics=5)
    cli = read_json(tmp_path / "response.json")
    assert_same(curves.to_dict(), cli)

    # The arrays say what the JSON says: points × harmonics × DOFs.
    assert curves.harmonics == 5 and curves.dofs == ["7:uy"] and curves.amplitudes == [20.0, 60.0]
    for branch, c in zip(curves.curves, cli["curves"]):
        assert branch.amplitude == c["amplitude"] and branch.complete == c["complete"]
        assert branch.folds == c["folds"] and branch.X.shape == (len(c["points"]), 6, 1)
        np.testing.assert_array_equal(branch.freq_hz, [p["freq_hz"] for p in c["points"]])
        assert branch.stable == [p["stable"] for p in c["points"]]
        assert branch.stability_checked == [p["stability_checked"] for p in c["points"]]
        computed = np.array(branch.stability_checked)
        assert computed[0] and computed[-1] and computed[::8].all()
        assert np.isnan(branch.max_multiplier[~computed]).all()
        x = np.array([[complex(*h) for h in p["x"]["7:uy"]] for p in c["points"]])
        np.testing.assert_array_equal(branch.X[:, :, 0], x)
    # The joint hardens (k3 > 0): the larger force resonates at a higher frequency.
    peak = [b.freq_hz[np.argmax(np.abs(b.X[:, 1, 0]))] for b in curves.curves]
    assert peak[1] > peak[0]
