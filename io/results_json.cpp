#include "io/results_json.hpp"

#include "io/files.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace jointid::io {

namespace {

using Json = nlohmann::ordered_json; // keeps the contract's key order

Json number(double value) {
  return std::isfinite(value) ? Json(value) : Json(nullptr);
}

std::string text(const Json& json) {
  return json.dump(2) + "\n";
}

} // namespace

std::string identify_result_json(const identify::FitResult& result,
                                 const std::vector<std::string>& extra) {
  Json joints = Json::array();
  for (const auto& joint : result.joints) {
    Json terms = Json::array();
    for (const auto& t : joint.terms) {
      Json term;
      term["term"] = std::string(joints::term_name(t.term));
      term["effect"] = std::string(joints::term_effect(t.term));
      term["value"] = number(t.value);
      term["std"] = number(t.std);
      term["ci95"] = Json::array({number(t.ci_low), number(t.ci_high)});
      term["fixed"] = t.fixed;
      terms.push_back(std::move(term));
    }
    Json j;
    j["name"] = joint.name;
    j["terms"] = std::move(terms);
    joints.push_back(std::move(j));
  }
  Json warnings = Json::array();
  for (const auto& w : result.warnings)
    warnings.push_back(w);
  for (const auto& w : extra)
    warnings.push_back(w);

  Json out;
  out["joints"] = std::move(joints);
  out["equations"] = result.equations;
  out["unknowns"] = result.unknowns;
  out["condition_number"] = number(result.condition_number);
  out["residual_rms"] = number(result.residual_rms);
  out["residual_relative"] = number(result.residual_relative);
  out["warnings"] = std::move(warnings);
  return text(out);
}

std::string modes_json(const fem::Modes& modes, int count,
                       const std::vector<std::string>& warnings) {
  const int n = count < 0 ? modes.num_modes() : std::min(count, modes.num_modes());
  Json list = Json::array();
  for (int r = 0; r < n; ++r) {
    Json mode;
    mode["mode"] = r + 1;
    mode["frequency_hz"] = number(modes.frequency_hz(r));
    list.push_back(std::move(mode));
  }
  Json out;
  out["modes"] = std::move(list);
  out["warnings"] = warnings;
  return text(out);
}

void write_json(const std::filesystem::path& path, const std::string& json) {
  write_file_atomically(path, json);
}

} // namespace jointid::io
