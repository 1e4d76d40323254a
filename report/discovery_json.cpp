#include "report/discovery_json.hpp"

#include "io/json_text.hpp"

#include <cmath>
#include <complex>
#include <limits>

namespace jointid::report {

namespace {

using io::json::Json;
using io::json::number;
using io::json::text;

Json candidate_json(const discover::Candidate& c) {
  Json j;
  j["joint"] = c.joint;
  j["term"] = c.refit  ? std::string("refit")
              : c.term ? std::string(joints::term_name(*c.term))
                       : std::string("damping_scale");
  j["effect"] = c.effect();
  j["value"] = number(c.value);
  // An undetermined interval (not finite, or of zero width) is never written as a result.
  const bool determined = c.determined();
  j["std"] = determined ? number(c.std) : Json(nullptr);
  j["ci95"] = determined ? Json::array({number(c.ci_low), number(c.ci_high)})
                         : Json::array({nullptr, nullptr});
  j["determined"] = determined;
  j["gap"] = number(c.gap);
  j["explained"] = number(c.explained);
  j["criterion"] = number(c.criterion);
  j["cv_gap"] = c.cv_gap >= 0.0 ? number(c.cv_gap) : Json(nullptr);
  j["converged"] = c.converged;
  if (!c.left_out.empty()) {
    j["left_out"] = c.left_out;
    j["gap_now"] = number(c.gap_now);
  }
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
              if (te.term == joint.terms[t] && !te.fixed) {
                const bool determined = std::isfinite(te.std) && te.std > 0.0 &&
                                        std::isfinite(te.ci_low) && std::isfinite(te.ci_high) &&
                                        te.ci_high > te.ci_low;
                term["std"] = determined ? number(te.std) : Json(nullptr);
                term["ci95"] = determined ? Json::array({number(te.ci_low), number(te.ci_high)})
                                          : Json::array({nullptr, nullptr});
                term["determined"] = determined;
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

// The tests a state left out (its re-simulation did not converge), by name.
Json left_out_json(const std::vector<discover::Comparison>& list) {
  Json out = Json::array();
  for (const auto& c : list)
    if (!c.converged && (out.empty() || out.back() != c.test)) out.push_back(c.test);
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
    // A re-simulation that did not converge left its last iterate, which is not a result.
    const double none = std::numeric_limits<double>::quiet_NaN();
    const std::complex<double> simulated = c.converged ? c.simulated : std::complex(none, none);
    j["simulated"] = Json::array({number(simulated.real()), number(simulated.imag())});
    j["amplitude_error"] = number(c.converged ? c.amplitude_error : none);
    j["phase_error_deg"] = number(c.converged ? c.phase_error_deg : none);
    j["harmonics_measured"] = number(c.harmonics_measured);
    j["harmonics_simulated"] = number(c.converged ? c.harmonics_simulated : none);
    j["converged"] = c.converged;
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
  start["left_out"] = left_out_json(r.comparisons.front());
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
  model["left_out"] = left_out_json(r.comparisons.back());
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
  out["limits"] = r.limits;
  out["warnings"] = r.warnings;
  return text(out);
}

} // namespace jointid::report
