#include "io/results_json.hpp"

#include "identify/random_tests.hpp"
#include "io/files.hpp"
#include "io/json_text.hpp"

#include <cmath>

namespace jointid::io {

namespace {

using json::Json;
using json::number;
using json::text;

} // namespace

std::string identify_result_json(const identify::FitResult& result,
                                 const std::vector<std::string>& extra,
                                 const std::vector<identify::Measurement>* measured) {
  Json joints = Json::array();
  for (const auto& joint : result.joints) {
    Json terms = Json::array();
    for (const auto& t : joint.terms) {
      Json term;
      term["term"] = std::string(joints::term_name(t.term));
      term["effect"] = std::string(joints::term_effect(t.term));
      if (!t.parameters.empty()) { // a parametric term: its named parameters
        Json parameters = Json::object();
        for (const auto& p : t.parameters) {
          Json one; // an undetermined parameter has no value (null), never a number
          one["value"] = number(p.value);
          one["std"] = number(p.std);
          one["ci95"] = Json::array({number(p.ci_low), number(p.ci_high)});
          one["fixed"] = p.fixed;
          one["determined"] = p.determined;
          // keyed as in the model file's values: "<term>.<parameter>"
          parameters[std::string(joints::term_name(t.term)) + "." + p.name] = std::move(one);
        }
        term["parameters"] = std::move(parameters);
        term["fixed"] = t.fixed;
        term["determined"] = t.determined;
        terms.push_back(std::move(term));
        continue;
      }
      term["value"] = number(t.value);
      term["std"] = number(t.std);
      term["ci95"] = Json::array({number(t.ci_low), number(t.ci_high)});
      term["fixed"] = t.fixed;
      term["determined"] = t.determined;
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
  out["status"] = std::string(fem::code_name(result.status.code));
  out["reason"] = result.status.reason;
  out["joints"] = std::move(joints);
  out["equations"] = result.equations;
  out["unknowns"] = result.unknowns;
  out["condition_number"] = number(result.condition_number);
  out["residual_rms"] = number(result.residual_rms);
  out["residual_relative"] = number(result.residual_relative);
  out["interval_method"] = result.interval_method;
  out["chi2_per_dof"] = number(result.chi2_per_dof);
  Json sv = Json::array();
  for (double v : result.singular_values)
    sv.push_back(number(v));
  out["singular_values"] = std::move(sv);
  out["identifiability"] = result.identifiability;
  if (measured) {
    Json noise = Json::array();
    for (const auto& m : *measured) {
      Json channels = Json::object();
      for (std::size_t r = 0; r < m.response_at.size(); ++r) {
        const char q = identify::quantity_letter(m.measured_as[r]);
        const std::string at = fem::to_string(m.response_at[r]);
        channels[std::string(1, q) + "@" + at] =
            r < m.channel_noise.size() ? number(m.channel_noise[r]) : Json(nullptr);
        if (r < m.velocity_noise.size() && std::isfinite(m.velocity_noise[r]) &&
            m.measured_as[r] != identify::Quantity::velocity)
          channels["v@" + at] = number(m.velocity_noise[r]);
      }
      for (std::size_t f = 0; f < m.force_at.size(); ++f)
        channels["f@" + fem::to_string(m.force_at[f])] =
            f < m.force_noise.size() ? number(m.force_noise[f]) : Json(nullptr);
      noise.push_back({{"test", m.source},
                       {"frequency_hz", m.frequency_hz},
                       {"periods_averaged", m.periods_averaged},
                       {"channels", std::move(channels)}});
    }
    out["noise"] = std::move(noise);
  }
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

namespace {

// A multisine candidate: its band, RMS force, period, sample rate and the record name simulate
// gives such a test.
Json periodic_json(const identify::PeriodicPlan& p) {
  identify::ExcitationSpec spec;
  spec.kind = identify::Excitation::multisine;
  spec.f0_hz = p.f0_hz, spec.f1_hz = p.f1_hz, spec.level = p.rms;
  return {{"band_hz", {p.f0_hz, p.f1_hz}},
          {"rms", p.rms},
          {"period_s", p.period_s},
          {"sample_rate_hz", p.sample_rate_hz},
          {"record", identify::excitation_record_name(spec)}};
}

} // namespace

std::string design_json(const identify::Design& design,
                        const std::vector<identify::CandidateTest>& candidates,
                        const std::vector<identify::DesignUnknown>& unknowns,
                        const identify::DesignOptions& options,
                        const std::vector<identify::ParametricLevel>& levels) {
  Json out;
  const bool periodic = !candidates.empty() && candidates.front().periodic.has_value();
  out["excitation"] = periodic ? "multisine" : "sine";
  out["noise"] = options.noise;
  out["periods"] = options.periods;
  out["harmonics"] = options.harmonics;
  Json list = Json::array();
  for (std::size_t u = 0; u < unknowns.size(); ++u) {
    Json j;
    j["joint"] = unknowns[u].joint;
    j["term"] = std::string(joints::term_name(unknowns[u].term));
    j["prior"] = number(unknowns[u].prior);
    const double sd = design.std(static_cast<Eigen::Index>(u));
    j["std"] = number(sd);
    j["relative_std"] =
        unknowns[u].prior != 0.0 ? number(sd / std::abs(unknowns[u].prior)) : Json(nullptr);
    j["bias"] = number(design.bias(static_cast<Eigen::Index>(u)));
    list.push_back(std::move(j));
  }
  out["unknowns"] = std::move(list);
  Json chosen = Json::array();
  std::vector<bool> is_chosen(candidates.size(), false);
  for (int i : design.chosen) {
    const auto& c = candidates[static_cast<std::size_t>(i)];
    is_chosen[static_cast<std::size_t>(i)] = true;
    chosen.push_back(c.periodic ? periodic_json(*c.periodic)
                                : Json{{"freq_hz", c.plan.frequency_hz},
                                       {"amplitude", c.plan.amplitude},
                                       {"record", identify::sine_test_name(c.plan)}});
  }
  out["chosen"] = std::move(chosen);
  out["log_det"] = number(design.log_det);
  out["exchanges"] = design.exchanges;
  Json all = Json::array();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const auto& c = candidates[i];
    Json j = c.periodic ? periodic_json(*c.periodic) : Json::object();
    if (!c.periodic) {
      j["freq_hz"] = c.plan.frequency_hz;
      j["amplitude"] = c.plan.amplitude;
    }
    j["usable"] = c.usable;
    j["misfit"] = number(c.misfit);
    if (!c.usable) j["reason"] = c.reason;
    Json amp = Json::array();
    for (double a : c.joint_amplitude)
      amp.push_back(number(a));
    j["joint_amplitude"] = std::move(amp);
    j["chosen"] = static_cast<bool>(is_chosen[i]);
    all.push_back(std::move(j));
  }
  out["candidates"] = std::move(all);
  if (!levels.empty()) {
    Json parametric = Json::array();
    for (const auto& l : levels) {
      Json per = Json::array();
      for (std::size_t f = 0; f < l.frequency_hz.size(); ++f)
        per.push_back({{"freq_hz", l.frequency_hz[f]},
                       {"lowest_force", number(l.lowest_force[f])},
                       {"guess_force", number(l.guess_force[f])}});
      Json j;
      j["joint"] = l.joint;
      j["term"] = std::string(joints::term_name(l.term));
      j["regime"] = l.regime;
      j["threshold"] = number(l.threshold);
      j["levels"] = std::move(per);
      j["sentence"] = l.sentence;
      parametric.push_back(std::move(j));
    }
    out["parametric"] = std::move(parametric);
  }
  out["warnings"] = design.warnings;
  return text(out);
}

void write_json(const std::filesystem::path& path, const std::string& json) {
  write_file_atomically(path, json);
}

} // namespace jointid::io
