#include "io/modal_fit_output.hpp"

#include "io/files.hpp"
#include "io/json_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace jointid::io {

namespace {

using json::Json;
using json::number;

// A TOML float in its shortest exact form: "3", "1e-07" get ".0" or stay as they are where
// TOML reads them as floats.
std::string toml_number(double value) {
  std::string text = fmt::format("{}", value);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

std::string toml_list(const Eigen::Ref<const Eigen::RowVectorXd>& values) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < values.size(); ++i)
    out += (i ? ", " : "") + toml_number(values(i));
  return out + "]";
}

const char* quantity_name(identify::Quantity q) {
  switch (q) {
  case identify::Quantity::force:
    return "force";
  case identify::Quantity::displacement:
    return "displacement";
  case identify::Quantity::velocity:
    return "velocity";
  case identify::Quantity::acceleration:
    return "acceleration";
  }
  return "?";
}

const char* stability_name(identify::PoleStability s) {
  switch (s) {
  case identify::PoleStability::new_pole:
    return "new";
  case identify::PoleStability::frequency:
    return "frequency";
  case identify::PoleStability::stable:
    return "stable";
  }
  return "?";
}

} // namespace

std::string modal_fit_toml(const identify::ModalFit& fit, const identify::MeasuredFrfs& data,
                           const std::vector<std::string>& comments) {
  const frf::ModalModel& m = fit.substructure;
  if (m.num_modes() == 0)
    throw Error("modal fit: no mode in the model (none could be mass-normalised), so no model "
                "file to write");
  try {
    m.validate();
  } catch (const std::invalid_argument& e) {
    throw Error(std::string("modal fit: ") + e.what());
  }
  std::string out;
  for (const auto& c : comments)
    out += "# " + c + "\n";
  out += fmt::format(
      "# The linear substructure fitted to a low-level test (jointid modal-fit): {} mode{} at the "
      "responses' DOFs,\n# shapes mass-normalised at the driving point {} (1/sqrt(kg)), damping "
      "as ratios.\n",
      m.num_modes(), m.num_modes() == 1 ? "" : "s", fem::to_string(data.drive));
  if (m.residual_flexibility.size() > 0)
    out += fmt::format(
        "# residual_flexibility (m/N): the upper residual, measured in the column of {}; the "
        "other entries\n# are of rank one, R_ij = R_id R_jd / R_dd (the modes above the band as "
        "one).\n",
        fem::to_string(data.drive));
  out += "[modal]\ndofs = [";
  for (std::size_t i = 0; i < m.dofs.size(); ++i)
    out += fmt::format("{}\"{}\"", i ? ", " : "", fem::to_string(m.dofs[i]));
  out += "]\n";
  out += "frequencies_hz = " + toml_list(m.frequencies_hz.transpose()) + "\n";
  out += "damping = " + toml_list(m.damping.transpose()) + "\n";
  out += "shapes = [\n";
  for (Eigen::Index r = 0; r < m.num_modes(); ++r)
    out += fmt::format("  {}, # mode {}, {:.6g} Hz\n", toml_list(m.shapes.row(r)), r + 1,
                       m.frequencies_hz(r));
  out += "]\n";
  if (m.residual_flexibility.size() > 0) {
    out += "residual_flexibility = [\n";
    for (Eigen::Index i = 0; i < m.residual_flexibility.rows(); ++i)
      out += "  " + toml_list(m.residual_flexibility.row(i)) + ",\n";
    out += "]\n";
  }
  return out;
}

std::string modal_fit_json(const identify::ModalFit& fit, const identify::MeasuredFrfs& data,
                           const ModalFitRun& run) {
  const auto O = static_cast<std::size_t>(data.num_responses());
  const Eigen::Index L = data.num_lines();
  auto dof = [&](std::size_t c) { return fem::to_string(data.responses[c]); };
  Json j;
  j["status"] = std::string(fem::code_name(fit.status.code));
  j["reason"] = fit.status.reason;
  j["inputs"] = run.inputs;
  j["substructure"] = run.substructure_file;
  j["driving_point"] = fem::to_string(data.drive);
  j["force_channel"] = data.drive_name;
  j["band_hz"] = Json::array({number(run.f0_hz), number(run.f1_hz)});
  j["lines"] = L;
  j["lines_hz"] =
      L > 0 ? Json::array({number(data.frequency_hz(0)), number(data.frequency_hz(L - 1))})
            : Json::array();
  const bool converted =
      std::any_of(data.measured_as.begin(), data.measured_as.end(), [](identify::Quantity q) {
        return q == identify::Quantity::velocity || q == identify::Quantity::acceleration;
      });
  j["fitted_as"] =
      data.method == identify::SpectraMethod::measured
          ? "receptance (m/N), as read from the FRF files (mobility and accelerance converted "
            "when read)"
      : converted ? "receptance (m/N): the FRFs of velocity and acceleration channels divided by "
                    "iω and (iω)² = −ω² line by line before fitting (mobility and accelerance to "
                    "receptance)"
                  : "receptance (m/N)";
  Json spectra;
  spectra["method"] = identify::spectra_method_name(data.method);
  spectra["resolution_hz"] = number(data.resolution_hz);
  spectra["sample_rate_hz"] = number(data.sample_rate_hz);
  spectra["block_samples"] = data.block_samples;
  spectra["estimate"] =
      data.method == identify::SpectraMethod::measured
          ? "measured FRFs"
          : "H1 = Σ G_fx / Σ G_ff over the blocks; coherence γ² = |Σ G_fx|² / (Σ G_ff Σ G_xx)";
  j["spectra"] = std::move(spectra);
  Json estimator;
  estimator["poles"] = "LSCF (least-squares complex frequency domain, common denominator in z = "
                       "exp(iωT), T = 1/(2 f_top)), stabilisation diagram";
  estimator["residues"] = "LSFD (least squares with the poles fixed): real modal residues, lower "
                          "residual −L/ω² and upper residual U per response";
  estimator["max_order"] = fit.max_order;
  estimator["frequency_tolerance"] = number(fit.options.frequency_tolerance);
  estimator["damping_tolerance"] = number(fit.options.damping_tolerance);
  estimator["max_damping"] = number(fit.options.max_damping);
  estimator["modes_asked"] = fit.options.modes;
  j["estimator"] = std::move(estimator);

  Json modes = Json::array();
  for (std::size_t r = 0; r < fit.modes.size(); ++r) {
    const identify::FittedMode& m = fit.modes[r];
    Json mode;
    mode["mode"] = r + 1;
    mode["frequency_hz"] = number(m.frequency_hz);
    mode["damping"] = number(m.damping);
    mode["stable_orders"] = m.stable_orders;
    mode["in_model"] = m.in_model();
    Json shape = Json::object(), residues = Json::object();
    for (std::size_t c = 0; c < O; ++c) {
      const auto k = static_cast<Eigen::Index>(c);
      shape[dof(c)] = m.in_model() ? number(m.shape(k)) : Json(nullptr);
      residues[dof(c)] = m.residues.size() > k ? number(m.residues(k)) : Json(nullptr);
    }
    mode["shape"] = std::move(shape);
    mode["residues"] = std::move(residues);
    modes.push_back(std::move(mode));
  }
  j["modes"] = std::move(modes);

  Json fit_error = Json::object(), model_error = Json::object(), coherence = Json::object(),
       coherence_min = Json::object(), channels = Json::array();
  for (std::size_t c = 0; c < O; ++c) {
    const auto k = static_cast<Eigen::Index>(c);
    fit_error[dof(c)] = fit.fit_error.size() > k ? number(fit.fit_error(k)) : Json(nullptr);
    model_error[dof(c)] = fit.model_error.size() > k ? number(fit.model_error(k)) : Json(nullptr);
    const Eigen::VectorXd g = data.coherence.col(k);
    const bool known = g.size() > 0 && g.allFinite();
    coherence[dof(c)] = known ? number(g.mean()) : Json(nullptr);
    coherence_min[dof(c)] = known ? number(g.minCoeff()) : Json(nullptr);
    Json ch;
    ch["dof"] = dof(c);
    ch["channel"] = data.response_names[c];
    ch["measured_as"] = quantity_name(data.measured_as[c]);
    ch["blocks"] = data.blocks.size() > c ? data.blocks[c] : 0;
    ch["lower_residual"] = fit.lower_residual.size() > k ? number(fit.lower_residual(k)) : Json();
    ch["upper_residual"] = fit.upper_residual.size() > k ? number(fit.upper_residual(k)) : Json();
    channels.push_back(std::move(ch));
  }
  j["fit_error"] = std::move(fit_error);
  j["fit_error_meaning"] = "sqrt(Σ|H − H_fit|² / Σ|H|²) over the band's lines, per response: "
                           "fit_error for the fitted modes with both residuals, model_error for "
                           "the model written (no lower residual; only the modes in it)";
  j["model_error"] = std::move(model_error);
  j["coherence"] = std::move(coherence);
  j["coherence_min"] = std::move(coherence_min);
  j["channels"] = std::move(channels);
  Json diagram = Json::array();
  for (const identify::DiagramPole& p : fit.diagram)
    diagram.push_back({{"order", p.order},
                       {"frequency_hz", number(p.frequency_hz)},
                       {"damping", number(p.damping)},
                       {"stability", stability_name(p.stability)}});
  j["diagram"] = std::move(diagram);
  j["notes"] = data.notes;
  j["warnings"] = fit.warnings;
  return j.dump(1) + "\n";
}

} // namespace jointid::io
