"""jointid.modal_fit against `jointid modal-fit` on the same records, and the substructure it
writes against the finite element model the records came from."""

import math
import tomllib

import numpy as np
import pytest

import jointid
from conftest import CANTILEVER, assert_same, cli_error, read_json, run_cli

BAND = (10.0, 70.0)
SUBSTEPS = 8


def newmark_frequency(f):
    """The frequency Newmark's average acceleration gives a mode of frequency f at the step h:
    tan(ω_d h/2) = ω h/2 (its period elongation, 0.2 % at 52.7 Hz here)."""
    h = 1.0 / (256.0 * SUBSTEPS)
    return math.atan(math.pi * f * h) / (math.pi * h)


@pytest.fixture(scope="module")
def beam_and_record(tmp_path_factory):
    """The paper's cantilever without its joint, and a random test of it: 2–80 Hz, 64 s at 256
    Hz by Newmark on the full model (SUBSTEPS steps a sample), accelerations at 7, 3 and 5, 1 %
    noise."""
    d = tmp_path_factory.mktemp("modal_fit")
    beam = d / "beam.toml"
    text = CANTILEVER.read_text()
    beam.write_text(text[: text.index("[[joints]]")])
    run_cli("simulate", beam, "--force", "7:uy", "--excitation", "random", "--band", "2:80",
            "--rms", 20, "--duration", 64, "--sample-rate", 256, "--route", "full",
            "--substeps", SUBSTEPS,
            "--channels", "a", "--outputs", "3:uy,5:uy", "--noise", 0.01, "-o", d / "random")
    record = next((d / "random").glob("*.csv"))
    return beam, record


def test_as_the_cli(beam_and_record, tmp_path):
    beam, record = beam_and_record
    run_cli("modal-fit", record, "--band", "10:70", "--segment", 2048, "--no-plot", "-o",
            tmp_path / "fit")
    cli = read_json(tmp_path / "fit" / "modal_fit.json")
    result = jointid.modal_fit([str(record)], BAND, segment=2048)
    assert_same(result.to_dict(), cli)
    # The model file written, but for its comments (they say which front end wrote it).
    written = tomllib.loads((tmp_path / "fit" / "substructure.toml").read_text())
    assert_same(tomllib.loads(result.substructure_toml()), written)
    # The record in memory gives the same fit.
    in_memory = jointid.modal_fit([jointid.read_record(record)], BAND, segment=2048)
    assert np.array_equal(in_memory.frequencies_hz, result.frequencies_hz)
    assert np.array_equal(in_memory.H, result.H)


def test_the_modes_are_the_models(beam_and_record):
    # Modes 2 and 3 of the beam lie in the band. The fitted frequencies must be the finite element
    # model's as Newmark shifts them to within half a line of the Welch estimate (0.0625 Hz; the
    # shift itself is 0.11 Hz at mode 3); the shapes, mass-normalised at the driving point, the
    # model's at the three DOFs (MAC > 0.99).
    beam, _ = beam_and_record
    _, record = beam_and_record
    result = jointid.modal_fit([record], BAND, segment=2048)
    model = jointid.read_model(beam)
    modes = model.modes(4)
    fe = modes.frequencies_hz[1:3]
    assert len(result.frequencies_hz) == 2
    for f, f_fe in zip(result.frequencies_hz, fe):
        assert abs(f - newmark_frequency(f_fe)) < 0.0625, (f, f_fe, newmark_frequency(f_fe))
    assert all(result.in_model)
    rows = [modes.dofs.index(d) for d in result.dofs]
    for r in range(2):
        a = result.shapes[:, r]
        b = modes.shapes[rows, r + 1]
        mac = (a @ b) ** 2 / ((a @ a) * (b @ b))
        assert mac > 0.99, (r, mac)
    assert result.H.dtype == np.complex128 and result.H.shape == (len(result.freq_hz), 3)
    # The fit follows the measured FRF to its own scatter: 15 Welch averages at 1 % noise leave
    # about 5 % (measured 0.052-0.055); a mode missed or misplaced by a line leaves far more.
    assert np.all(result.fit_error < 0.08), result.fit_error


@pytest.mark.parametrize(
    "kwargs,option,cli_args",
    [
        (dict(modes=-1), "--modes", ["--modes", "-1"]),
        (dict(max_order=2), "--max-order", ["--max-order", "2"]),
        (dict(segment=4), "--segment", ["--segment", "4"]),
        (dict(spectra="whole", period=0.5), "--period", ["--spectra", "whole", "--period", "0.5"]),
    ],
)
def test_bad_arguments_as_the_cli(beam_and_record, tmp_path, kwargs, option, cli_args):
    _, record = beam_and_record
    with pytest.raises(jointid.Error) as caught:
        jointid.modal_fit([record], BAND, **kwargs)
    cli = cli_error("modal-fit", record, "--band", "10:70", *cli_args, "-o", tmp_path / "out")
    python_spelling = {"--max-order": "max_order", "--spectra": "spectra"}
    expected = cli
    for o, p in python_spelling.items():
        expected = expected.replace(o, p)
    expected = expected.replace(option, option.lstrip("-").replace("-", "_"))
    assert str(caught.value) == expected
    assert not (tmp_path / "out").exists()


def test_bad_inputs(beam_and_record, tmp_path):
    _, record = beam_and_record
    with pytest.raises(jointid.Error, match="given twice"):
        jointid.modal_fit([record, record], BAND)
    with pytest.raises(jointid.Error, match="expected a list"):
        jointid.modal_fit(record, BAND)
    with pytest.raises(TypeError):
        jointid.modal_fit([3.0], BAND)
    with pytest.raises(jointid.Error, match="band: expected 0 <= F0 < F1"):
        jointid.modal_fit([record], (70.0, 10.0))
