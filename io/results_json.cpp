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

Json candidate_json(const discover::Candidate& c) {
  Json j;
  j["joint"] = c.joint;
  j["term"] = c.refit  ? std::string("refit")
              : c.term ? std::string(joints::term_name(*c.term))
                       : std::string("damping_scale");
  j["effect"] = c.effect();
  j["value"] = number(c.value);
  j["std"] = number(c.std);
  j["ci95"] = Json::array({number(c.ci_low), number(c.ci_high)});
  j["gap"] = number(c.gap);
  j["explained"] = number(c.explained);
  j["criterion"] = number(c.criterion);
  j["cv_gap"] = c.cv_gap >= 0.0 ? number(c.cv_gap) : Json(nullptr);
  j["converged"] = c.converged;
  j["admissible"] = c.rejected.empty();
  if (!c.rejected.empty()) j["rejected"] = c.rejected;
  if (c.varies) {
    const discover::Variation& v = *c.varies;
    Json per_test = Json::array();
    for (std::size_t i = 0; i < v.tests.size(); ++i)
      per_test.push_back({{"test", v.tests[i]},
                          {"frequency_hz", number(v.frequency_hz[i])},
                          {"amplitude", number(v.amplitude[i])},
                          {"value", number(v.value[i])},
                          {"std", number(v.std[i])}});
    j["varies"] = {{"per_test", std::move(per_test)},
                   {"chi2", number(v.chi2)},
                   {"dof", v.dof},
                   {"amplitude_correlation", number(v.amplitude_correlation)},
                   {"frequency_correlation", number(v.frequency_correlation)},
                   {"description", v.description}};
  }
  return j;
}

Json joints_json(const std::vector<joints::Joint>& joints, const identify::FitResult* fit) {
  Json out = Json::array();
  for (const auto& joint : joints) {
    Json terms = Json::array();
    for (std::size_t t = 0; t < joint.terms.size(); ++t) {
      Json term;
      term["term"] = std::string(joints::term_name(joint.terms[t]));
      term["effect"] = std::string(joints::term_effect(joint.terms[t]));
      term["unit"] = std::string(joints::term_unit(joint.terms[t]));
      term["value"] = number(joint.values[t]);
      if (fit)
        for (const auto& je : fit->joints)
          if (je.name == joint.name)
            for (const auto& te : je.terms)
              if (te.term == joint.terms[t]) {
                term["std"] = number(te.std);
                term["ci95"] = Json::array({number(te.ci_low), number(te.ci_high)});
              }
      term["fixed"] = static_cast<bool>(joint.fixed[t]);
      terms.push_back(std::move(term));
    }
    Json j;
    j["name"] = joint.name;
    j["terms"] = std::move(terms);
    out.push_back(std::move(j));
  }
  return out;
}

Json comparisons_json(const std::vector<discover::Comparison>& list) {
  Json out = Json::array();
  for (const auto& c : list) {
    Json j;
    j["test"] = c.test;
    j["channel"] = c.channel;
    j["frequency_hz"] = number(c.frequency_hz);
    j["force"] = number(c.force);
    j["measured"] = Json::array({number(c.measured.real()), number(c.measured.imag())});
    j["simulated"] = Json::array({number(c.simulated.real()), number(c.simulated.imag())});
    j["amplitude_error"] = number(c.amplitude_error);
    j["phase_error_deg"] = number(c.phase_error_deg);
    j["harmonics_measured"] = number(c.harmonics_measured);
    j["harmonics_simulated"] = number(c.harmonics_simulated);
    out.push_back(std::move(j));
  }
  return out;
}

} // namespace

std::string discovery_json(const discover::Result& r) {
  Json out;
  out["tests"] = r.tests;
  out["compared_values"] = r.compared_values;
  out["noise_gap"] = r.noise_gap >= 0.0 ? number(r.noise_gap) : Json(nullptr);
  out["simulation_gap"] = number(r.simulation_gap);
  out["at_noise_level"] = r.at_noise_level;
  out["chi2_per_value"] = number(r.chi2_per_value);
  Json by_harmonic = Json::array();
  for (double c : r.chi2_by_harmonic)
    by_harmonic.push_back(number(c));
  out["chi2_by_harmonic"] = std::move(by_harmonic);
  Json start;
  start["notes"] = r.start_notes;
  start["gap"] = number(r.states.front().gap);
  start["joints"] =
      joints_json(r.states.front().joints,
                  r.states.front().fit.joints.empty() ? nullptr : &r.states.front().fit);
  out["start"] = std::move(start);
  Json steps = Json::array();
  for (const auto& s : r.steps) {
    Json j = candidate_json(s.added);
    j.erase("gap");
    j.erase("admissible");
    j["gap_before"] = number(s.gap_before);
    j["gap_after"] = number(s.gap_after);
    j["cv_gap_before"] = s.cv_before >= 0.0 ? number(s.cv_before) : Json(nullptr);
    j["cv_gap_after"] = s.cv_after >= 0.0 ? number(s.cv_after) : Json(nullptr);
    j["finding"] = s.finding;
    Json ranking = Json::array();
    for (const auto& c : s.ranking)
      ranking.push_back(candidate_json(c));
    j["ranking"] = std::move(ranking);
    steps.push_back(std::move(j));
  }
  out["steps"] = std::move(steps);
  Json gap = Json::array();
  for (double g : r.gap)
    gap.push_back(number(g));
  out["gap"] = std::move(gap);
  const discover::Diagnosis& d = r.diagnosis;
  Json diag;
  diag["level_dependent"] = d.level_dependent ? Json(*d.level_dependent) : Json(nullptr);
  diag["linear_explains"] = number(d.linear_explains);
  diag["nonlinear_explains"] = number(d.nonlinear_explains);
  diag["joint"] = d.joint.empty() ? Json(nullptr) : Json(d.joint);
  diag["channel"] = d.channel.empty() ? Json(nullptr) : Json(d.channel);
  diag["channel_error"] = number(d.channel_error);
  diag["nature"] = d.nature.empty() ? Json(nullptr) : Json(d.nature);
  diag["conservative_explains"] = number(d.conservative_explains);
  diag["dissipative_explains"] = number(d.dissipative_explains);
  diag["even_harmonics"] = d.even_harmonics;
  diag["even_content"] = number(d.even_content);
  diag["asymmetric"] = d.asymmetric;
  diag["findings"] = d.findings;
  out["diagnosis"] = std::move(diag);
  Json model;
  const discover::State& last = r.states.back();
  model["joints"] = joints_json(last.joints, last.fit.joints.empty() ? nullptr : &last.fit);
  model["substructure_damping_scale"] = number(last.damping_scale);
  out["final_model"] = std::move(model);
  out["stop_reason"] = r.stop_reason;
  Json last_ranking = Json::array();
  for (const auto& c : r.last_ranking)
    last_ranking.push_back(candidate_json(c));
  out["last_ranking"] = std::move(last_ranking);
  Json comparisons;
  comparisons["start"] = comparisons_json(r.comparisons.front());
  comparisons["final"] = comparisons_json(r.comparisons.back());
  out["comparisons"] = std::move(comparisons);
  out["warnings"] = r.warnings;
  return text(out);
}

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

std::string design_json(const identify::Design& design,
                        const std::vector<identify::CandidateTest>& candidates,
                        const std::vector<identify::DesignUnknown>& unknowns,
                        const identify::DesignOptions& options) {
  Json out;
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
    const auto& plan = candidates[static_cast<std::size_t>(i)].plan;
    is_chosen[static_cast<std::size_t>(i)] = true;
    chosen.push_back({{"freq_hz", plan.frequency_hz},
                      {"amplitude", plan.amplitude},
                      {"record", identify::sine_test_name(plan)}});
  }
  out["chosen"] = std::move(chosen);
  out["log_det"] = number(design.log_det);
  out["exchanges"] = design.exchanges;
  Json all = Json::array();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const auto& c = candidates[i];
    Json j;
    j["freq_hz"] = c.plan.frequency_hz;
    j["amplitude"] = c.plan.amplitude;
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
  out["warnings"] = design.warnings;
  return text(out);
}

void write_json(const std::filesystem::path& path, const std::string& json) {
  write_file_atomically(path, json);
}

} // namespace jointid::io
