#pragma once
/// `jointid modal-fit`'s outputs: the fitted substructure as a model file with `[modal]`
/// (substructure.toml) and the fit's record (modal_fit.json). SI units.
#include "identify/modal_fit.hpp"

#include <string>
#include <vector>

namespace jointid::io {

/// What the command adds to the JSON: the band asked and the files read.
struct ModalFitRun {
  double f0_hz = 0.0, f1_hz = 0.0; ///< --band as given
  std::vector<std::string> inputs; ///< the files, as given
  std::string substructure_file = "substructure.toml";
};

/// A complete model file: `#` comments (each of `comments`, then how the model was made), then
/// `[modal]` with dofs (the responses' "<node>:<dof>"), frequencies_hz, damping (ratios), shapes
/// (one row per mode, mass-normalised, 1/sqrt(kg)) and, when the fit has one,
/// residual_flexibility (m/N), every number in its shortest form that reads back exactly. It
/// reads back with io::read_model as a model and as a part (`[[substructures]] file = ...`).
/// Throws io::Error when the model has no mode or is not valid (frf::ModalModel::validate).
std::string modal_fit_toml(const identify::ModalFit& fit, const identify::MeasuredFrfs& data,
                           const std::vector<std::string>& comments = {});

/// {"status": "ok" | "not_separable" (fem::code_name), "reason", "inputs": [...], "substructure":
/// file,
///  "driving_point": "7:uy", "force_channel": "f@7:uy", "band_hz": [F0, F1],
///  "lines": n, "lines_hz": [first, last], "fitted_as": "receptance (m/N) ...",
///  "spectra": {"method", "resolution_hz", "sample_rate_hz", "block_samples"},
///  "estimator": {"poles", "residues", "max_order", "frequency_tolerance", "damping_tolerance",
///  "max_damping", "modes_asked"},
///  "modes": [{"mode", "frequency_hz", "damping", "stable_orders", "in_model",
///  "shape": {"<dof>": φ}, "residues": {"<dof>": a}}],
///  "fit_error": {"<dof>": e}, "model_error": {"<dof>": e}, "coherence": {"<dof>": mean γ²},
///  "coherence_min": {"<dof>": min γ²}, "channels": [{"dof", "channel", "measured_as",
///  "blocks", "lower_residual", "upper_residual"}], "diagram": [{"order", "frequency_hz",
///  "damping", "stability"}], "notes": [...], "warnings": [...]}. Non-finite numbers (a
///  coherence not estimated) are written as null.
std::string modal_fit_json(const identify::ModalFit& fit, const identify::MeasuredFrfs& data,
                           const ModalFitRun& run);

} // namespace jointid::io
