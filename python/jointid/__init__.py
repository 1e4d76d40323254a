"""jointid from Python: the C++ library's objects, numpy in and numpy out.

    import jointid
    model = jointid.read_model("examples/paper_cantilever/cantilever.toml")
    modes = model.modes(3)                   # .frequencies_hz, .shapes (n_dof x n_modes), .dofs
    records = jointid.simulate_sine(model, force="7:uy", freq_hz=[2.0, 3.0], amplitude=80.0,
                                    method="hb")
    result = jointid.identify(model, records, harmonics=[1])
    result.values["tip"]["k"], result.ci95["tip"]["k"], result.to_dict()

Every call does what the command of the same name does (`jointid modes`, `frf`, `simulate`,
`identify`, `discover`, `response`, `modal-fit`) and raises what it reports: jointid.Error (a ValueError)
with the command's message for bad input. Long calls release the GIL and stop on Ctrl-C
(KeyboardInterrupt). See docs/python.md.
"""

from ._jointid import (
    DiscoveryResult,
    Error,
    IdentifyResult,
    ModalFitResult,
    Model,
    Modes,
    Record,
    ResponseBranch,
    ResponseCurves,
    SteppedSineRow,
    __version__,
    discover,
    identify,
    modal_fit,
    read_model,
    read_record,
    read_tests,
    response,
    simulate_sine,
)

__all__ = [
    "DiscoveryResult",
    "Error",
    "IdentifyResult",
    "ModalFitResult",
    "Model",
    "Modes",
    "Record",
    "ResponseBranch",
    "ResponseCurves",
    "SteppedSineRow",
    "__version__",
    "discover",
    "identify",
    "modal_fit",
    "read_model",
    "read_record",
    "read_tests",
    "response",
    "simulate_sine",
]
