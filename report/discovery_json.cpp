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

// A parametric term's parameters: name, unit, value and 95 % interval (null where the tests do
// not determine it: never a value then).
Json parameters_json(const std::vector<identify::ParameterEstimate>& list, joints::Term term) {
  Json out = Json::array();
  const auto& info = joints::term_info(term).parameters;
  for (std::size_t p = 0; p < list.size(); ++p) {
    const auto& e = list[p];
    const bool determined = !e.fixed && e.determined && std::isfinite(e.value) &&
                            std::isfinite(e.ci_low) && std::isfinite(e.ci_high) &&
                            e.ci_high > e.ci_low;
    Json j;
    j["name"] = e.name;
    j["unit"] = p < info.size() ? std::string(info[p].unit) : std::string();
    j["value"] = e.fixed || determined ? number(e.value) : Json(nullptr);
    j["std"] = determined ? number(e.std) : Json(nullptr);
    j["ci95"] = determined ? Json::array({number(e.ci_low), number(e.ci_high)})
                           : Json::array({nullptr, nullptr});
    j["fixed"] = e.fixed;
    j["determined"] = e.fixed || determined;
    out.push_back(std::move(j));
  }
  return out;
}

Json behaviour_json(const discover::JointBehaviour& b) {
  Json j;
  j["joint"] = b.joint;
  j["behaviour"] = b.behaviour.empty() ? Json(nullptr) : Json(b.behaviour);
  j["finding"] = b.finding;
  Json points = Json::array();
  for (std::size_t i = 0; i < b.amplitude.size(); ++i)
    points.push_back({{"test", b.tests.size() > i ? b.tests[i] : std::string()},
                      {"frequency_hz", number(b.frequency_hz[i])},
                      {"amplitude", number(b.amplitude[i])},
                      {"dissipation_per_cycle", number(b.dissipation[i])},
                      {"stiffness", number(b.stiffness[i])}});
  j["tests"] = std::move(points);
  const auto or_null = [](double v) { return std::isfinite(v) ? number(v) : Json(nullptr); };
  j["slope"] = or_null(b.slope);
  j["hysteretic_share"] = or_null(b.hysteretic_share);
  j["stiffness_change"] = or_null(b.stiffness_change);
  j["contact_amplitude"] = or_null(b.contact_amplitude);
  j["model_frequency_hz"] = number(b.model_frequency_hz);
  const auto list = [](const std::vector<double>& v) {
    Json out = Json::array();
    for (double x : v)
      out.push_back(number(x));
    return out;
  };
  Json lines;
  lines["amplitude"] = list(b.model_amplitude);
  lines["start_dissipation"] = list(b.start_dissipation);
  lines["final_dissipation"] = list(b.final_dissipation);
  lines["start_stiffness"] = list(b.start_stiffness);
  lines["final_stiffness"] = list(b.final_stiffness);
  j["model"] = std::move(lines);
  return j;
}

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
  if (!c.parameters.empty() && c.term) { // a parametric term: its parameters are the result
    j.erase("value");
    j.erase("std");
    j.erase("ci95");
    j["parameters"] = parameters_json(c.parameters, *c.term);
  }
  if (c.with) // a second parametric term added with it: its term, effect and parameters
    j["with"] = {{"term", std::string(joints::term_name(*c.with))},
                 {"effect", std::string(joints::term_effect(*c.with))},
                 {"parameters", parameters_json(c.with_parameters, *c.with)}};
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
      if (joints::has_parameters(joint.terms[t])) { // its parameters, as identified
        std::vector<identify::ParameterEstimate> list = identify::parameters_of(joint, t);
        if (fit)
          for (const auto& je : fit->joints)
            if (je.name == joint.name)
              for (const auto& te : je.terms)
                if (te.term == joint.terms[t] && te.parameters.size() == list.size())
                  list = te.parameters;
        term.erase("value");
        term["parameters"] = parameters_json(list, joint.terms[t]);
        term["fixed"] = static_cast<bool>(joint.fixed[t]);
        terms.push_back(std::move(term));
        continue;
      }
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
    j["action"] = s.removed ? "removed" : "added";
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
  Json behaviour = Json::array();
  for (const auto& b : d.behaviour)
    behaviour.push_back(behaviour_json(b));
  diag["behaviour"] = std::move(behaviour);
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
