"""jointid.read_model, Model.modes and Model.receptance against `jointid modes` and `jointid frf`
on the same model."""

import csv
import math

import numpy as np
import pytest

import jointid
from conftest import (CANTILEVER, SAME_CODE, SOURCE, assert_same, cantilever_dict, read_json,
                      run_cli)

MATRICES = SOURCE / "examples" / "matrices" / "cantilever_matrices.toml"


def test_the_model_file(cantilever):
    # 6 beam elements, node 1 clamped: nodes 2..7 with uy and rz each.
    assert cantilever.path == str(CANTILEVER)
    assert cantilever.given_by == "a finite element model"
    assert len(cantilever.dofs) == 12
    assert "7:uy" in cantilever.dofs and "1:uy" not in cantilever.dofs
    assert cantilever.joints == [{"name": "tip", "node": 7, "dof": "uy",
                                  "terms": ["k", "c", "c2", "k3"],
                                  "values": {"k": 4800.0, "c": 20.0, "c2": 500.0, "k3": 1.6e8},
                                  "fixed": []}]


def test_modes_as_the_cli_writes_them(cantilever, tmp_path):
    run_cli("modes", CANTILEVER, "-o", tmp_path, "--count", 4, "--no-plot")
    modes = cantilever.modes(4)
    assert_same(modes.to_dict(), read_json(tmp_path / "modes.json"))
    assert modes.frequencies_hz.shape == (4,)
    assert modes.frequencies_hz[0] == pytest.approx(3.0, rel=1e-4)  # the file's design value


def test_mode_shapes_are_views_with_their_dof_labels(cantilever):
    modes = cantilever.modes(3)
    shapes = modes.shapes
    assert shapes.shape == (12, 3) and modes.dofs == cantilever.dofs
    # The library's memory, not a copy: every access views the same doubles, read-only.
    assert np.shares_memory(shapes, modes.shapes)
    assert shapes.base is modes and not shapes.flags.owndata and shapes.flags.f_contiguous
    assert modes.omega.base is modes and not modes.omega.flags.owndata
    assert not shapes.flags.writeable
    with pytest.raises(ValueError):
        shapes[0, 0] = 1.0
    # The view keeps the modes alive after the Python object is gone.
    first = cantilever.modes(3).shapes
    assert np.array_equal(first, shapes)
    # ω and f agree; the tip moves most in the first mode (a cantilever).
    assert np.allclose(modes.omega, 2 * math.pi * modes.frequencies_hz, rtol=1e-15)
    tip = modes.dofs.index("7:uy")
    assert abs(shapes[tip, 0]) == np.abs(shapes[:, 0]).max()


def read_frf_csv(path):
    rows = [r for r in csv.reader(line for line in open(path) if not line.startswith("#"))]
    header, data = rows[0], np.array(rows[1:], dtype=float)
    return header, data


@pytest.mark.parametrize("kind", ["receptance", "mobility", "accelerance"])
def test_receptance_as_the_cli_writes_it(cantilever, tmp_path, kind):
    run_cli("frf", CANTILEVER, "--drive", "7:uy", "--response", "4:uy,7:uy,7:rz",
            "--freq-range", "0.5:40", "--points", 25, "--kind", kind, "--no-plot", "-o", tmp_path)
    header, data = read_frf_csv(tmp_path / "frf.csv")
    freq = data[:, 0]
    H = cantilever.receptance(freq, ["4:uy", "7:uy", "7:rz"], ["7:uy"], kind=kind)
    assert H.shape == (25, 3, 1) and H.dtype == np.complex128
    for j, name in enumerate(["4:uy", "7:uy", "7:rz"]):
        cli = data[:, header.index(name + ".re")] + 1j * data[:, header.index(name + ".im")]
        np.testing.assert_allclose(H[:, j, 0], cli, rtol=SAME_CODE, atol=0)


def test_receptance_is_reciprocal_and_takes_one_frequency(cantilever):
    # Maxwell–Betti: H_ij = H_ji, from a column-major numpy array read in place.
    freq = np.asfortranarray([2.0, 7.5, 19.0])
    H = cantilever.receptance(freq, ["4:uy", "7:uy"], ["4:uy", "7:uy"])
    np.testing.assert_allclose(H[:, 0, 1], H[:, 1, 0], rtol=1e-12)
    one = cantilever.receptance(7.5, ["4:uy", "7:uy"], ["4:uy", "7:uy"])
    assert one.shape == (2, 2)
    np.testing.assert_allclose(one, H[1], rtol=1e-13)
    # Equation numbers stand for the DOFs in model.dofs' order (a synthesis over one DOF: its
    # sums in another order).
    e = cantilever.dofs.index("7:uy")
    np.testing.assert_allclose(cantilever.receptance(7.5, e, e)[0, 0], one[1, 1], rtol=1e-13)


def test_a_model_from_dicts_is_the_model_of_the_file(cantilever):
    model = jointid.read_model(cantilever_dict(), directory=CANTILEVER.parent)
    assert model.path == str(CANTILEVER.parent / "<dict>")
    assert model.dofs == cantilever.dofs and model.joints == cantilever.joints
    np.testing.assert_array_equal(model.modes(3).frequencies_hz, cantilever.modes(3).frequencies_hz)
    # numpy arrays and numbers are taken as lists and floats.
    d = cantilever_dict(values={"k": np.float64(4800.0), "c": 20, "c2": 500.0, "k3": 1.6e8})
    d["mesh"]["elements"] = np.array(d["mesh"]["elements"])  # int64
    assert jointid.read_model(d).joints == cantilever.joints


def test_a_substructure_given_by_its_matrices(cantilever, tmp_path):
    # The cantilever's K and M as another program exports them: the modes as `jointid modes`
    # gives them, and those of the finite element model (to the export's 17 digits).
    model = jointid.read_model(MATRICES)
    assert model.given_by == "its matrices ([matrices])"
    run_cli("modes", MATRICES, "-o", tmp_path, "--count", 3, "--no-plot")
    modes = model.modes(3)
    assert_same(modes.to_dict()["modes"], read_json(tmp_path / "modes.json")["modes"])
    np.testing.assert_allclose(modes.frequencies_hz, cantilever.modes(3).frequencies_hz, rtol=1e-9)


def test_a_substructure_given_by_its_modes():
    # Two modes at two DOFs, as a dict: H_ij(ω) = Σ_r φ_ri φ_rj / (ω_r² − ω² + 2iζ_r ω_r ω) + R_ij.
    f, zeta = np.array([80.3, 212.0]), np.array([0.0012, 0.002])
    phi = np.array([[0.91, -0.40], [0.35, 0.88]])  # one row per mode
    R = np.array([[1e-7, 0.0], [0.0, 2e-7]])
    model = jointid.read_model({
        "model": {"dimension": 2},
        "modal": {"dofs": ["1:uy", "4:uy"], "frequencies_hz": f, "damping": zeta, "shapes": phi,
                  "residual_flexibility": R},
    })
    modes = model.modes(5)
    np.testing.assert_array_equal(modes.frequencies_hz, f)
    np.testing.assert_array_equal(modes.shapes, phi.T)  # n_dof x n_modes
    assert len(model.modes(1)) == 1 and model.modes(1).shapes.shape == (2, 1)
    freq = np.array([10.0, 80.3, 150.0])
    w, wr = 2 * np.pi * freq[:, None], 2 * np.pi * f[None, :]
    expected = np.einsum("ri,rj,fr->fij", phi, phi, 1 / (wr**2 - w**2 + 2j * zeta * wr * w)) + R
    np.testing.assert_allclose(model.receptance(freq, ["1:uy", "4:uy"], ["1:uy", "4:uy"]),
                               expected, rtol=1e-12)
