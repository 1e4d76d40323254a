#include "discover/candidates.hpp"

#include "discover/diagnosis.hpp"
#include "discover/refine.hpp"
#include "discover/selection.hpp"
#include "fem/constants.hpp"
#include "fem/minimise.hpp"
#include "identify/parametric.hpp"

#include <fmt/format.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <span>
#include <stdexcept>

namespace jointid::discover::detail {

namespace {} // namespace

Outcome refused(Candidate c, const State& state, const std::string& why) {
  c.rejected = why;
  c.gap = c.criterion = inf;
  State none; // no model: nothing simulated
  none.joints = state.joints;
  none.damping_scale = state.damping_scale;
  none.gap = none.criterion = inf;
  return {std::move(c), std::move(none)};
}

Outcome consider_refit(const Problem& problem, const State& state, const Simulator& sim) {
  Candidate c;
  c.refit = true;
  c.joint = state.joints.front().name;
  try {
    const identify::FitResult fit = problem.identify(state.joints, sim, problem.all_tests());
    State s = problem.evaluate(fit.identified(state.joints), sim);
    s.fit = fit;
    fill(c, s);
    if (c.rejected.empty()) c.rejected = physical_problem(s.joints);
    return {std::move(c), std::move(s)};
  } catch (const std::invalid_argument& e) {
    return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
  }
}

Outcome consider_term(const Problem& problem, const State& state, const Simulator& sim,
                      const std::string& joint, joints::Term term) {
  Candidate c;
  c.joint = joint;
  c.term = term;
  std::vector<joints::Joint> joints = state.joints;
  for (auto& j : joints)
    if (j.name == joint) {
      j.terms.push_back(term);
      j.values.push_back(0.0);
      j.fixed.push_back(false);
      if (!j.given.empty()) j.given.push_back(false);
      if (!j.parameters.empty()) j.parameters.emplace_back(); // a coefficient term: none
    }
  try {
    const identify::FitResult fit = problem.identify(joints, sim, problem.all_tests());
    joints = fit.identified(joints);
    take_fit(c, fit, joint, term);
    c.equation_residual = fit.residual_relative;
    // Not simulated: negative dry friction has no steady state to compare.
    if (const std::string why = friction_problem(joints); !why.empty())
      return refused(std::move(c), state, why);
    State s = problem.evaluate(joints, sim);
    s.fit = fit;
    judge(c, s);
    return {std::move(c), std::move(s)};
  } catch (const std::invalid_argument& e) {
    return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
  }
}

namespace {

// The index of the joint named `name` (one of them: the candidates are made from the joints).
std::size_t position(const std::vector<joints::Joint>& joints, const std::string& name) {
  std::size_t jj = 0;
  while (joints[jj].name != name)
    ++jj;
  return jj;
}

// The peak of the joint's deformation over a test's period against that of the sine of the same
// RMS (√2 RMS): 1 for a sine test; a multisine's 1.4 to 2 (its slips and contacts start at its
// peaks, which its equivalent sine does not reach). NaN where a DOF of the joint is not measured.
double peak_ratio(const identify::Measurement& m, const joints::Joint& j) {
  const int a = m.response_index({j.node, j.dof});
  const int b = j.to_ground() ? -1 : m.response_index({j.node_b, j.dof});
  if (a < 0 || (!j.to_ground() && b < 0) || m.x.rows() < 4) return nan;
  Eigen::VectorXd y = m.x.col(a);
  if (b >= 0) y -= m.x.col(b);
  y.array() -= y.mean();
  const double rms = std::sqrt(y.squaredNorm() / static_cast<double>(y.size()));
  return rms > 0.0 ? y.cwiseAbs().maxCoeff() / (std::sqrt(2.0) * rms) : nan;
}

// The joint's equivalent stiffness per test less its other terms at the state's values (but k
// and c, which the describing-function fit takes with it). With `at_peaks`, each test's
// amplitude is its deformation's peak instead of its equivalent sine's (peak_ratio).
std::vector<identify::EquivalentStiffness> parametric_points(const Problem& problem,
                                                             const State& state,
                                                             const Simulator& sim, std::size_t jj,
                                                             bool at_peaks = false) {
  std::vector<int> used;
  std::vector<identify::EquivalentStiffness> points =
      equivalent_stiffness(problem, state, sim, jj, &used);
  if (at_peaks)
    for (std::size_t i = 0; i < points.size(); ++i)
      if (const double r =
              peak_ratio(problem.tests()[static_cast<std::size_t>(used[i])], state.joints[jj]);
          std::isfinite(r) && r > 1.0)
        points[i].amplitude *= r;
  const joints::Joint& now = state.joints[jj];
  const auto other = [&now](std::size_t t) {
    return !((now.terms[t] == joints::Term::k || now.terms[t] == joints::Term::c) && !now.fixed[t]);
  };
  for (auto& p : points)
    p.Z -= joint_describing_function(now, p.amplitude, p.omega, other);
  return points;
}

// Candidate c: the terms added to the joint, their parameters started by one describing-function
// fit, the coefficient terms by equation error with their force known, and judged.
Outcome add_parametric(const Problem& problem, const State& state, const Simulator& sim,
                       Candidate c, const std::vector<joints::Term>& terms,
                       std::vector<identify::EquivalentStiffness> points) {
  std::vector<joints::Joint> joints = state.joints;
  const std::size_t jj = position(joints, c.joint);
  joints::Joint& J = joints[jj];
  std::vector<std::size_t> added;
  for (const joints::Term term : terms) {
    const std::size_t T = J.terms.size();
    added.push_back(T);
    J.terms.push_back(term);
    J.values.push_back(1.0);
    J.fixed.push_back(false);
    if (!J.given.empty()) J.given.push_back(false);
    J.parameters.resize(T + 1);
    const auto& info = joints::term_info(term).parameters;
    J.set_parameters(T, std::vector<double>(info.size(), 0.0), false);
    for (joints::Parameter& p : J.parameters[T])
      p.given = false; // no start of its own: the describing-function fit's
  }
  try {
    const joints::Joint& now = state.joints[jj];
    const int k = now.term_index(joints::Term::k), cc = now.term_index(joints::Term::c);
    const bool k_open = k >= 0 && !now.fixed[static_cast<std::size_t>(k)];
    const bool c_open = cc >= 0 && !now.fixed[static_cast<std::size_t>(cc)];
    // Its parameters from the describing function(s) fitted to the points.
    std::string note;
    J = identify::fit_describing_functions(J, added, std::move(points), k_open, c_open, note);
    // The coefficient terms by equation error with its force known, then every non-fixed
    // term and parameter by output error.
    const identify::FitResult fit = problem.identify(joints, sim, problem.all_tests());
    joints = fit.identified(joints);
    // Two terms' start: a damping the equation error drove below zero beside them (their
    // describing functions from equivalent sines misjudge a broadband test's dissipation) is
    // brought back to zero, as the output error's search starts (refine.cpp).
    if (c.with) clamp_dissipative(joints);
    State s = problem.evaluate(joints, sim);
    s.fit = fit;
    judge(c, s);
    // Its parameters from the start have no intervals: only output error (finalists) gives them.
    for (auto* list : {&c.parameters, &c.with_parameters})
      for (auto& p : *list) {
        p.fixed = p.determined = false;
        p.std = p.ci_low = p.ci_high = std::numeric_limits<double>::quiet_NaN();
      }
    if (c.rejected.empty()) c.rejected = interval_problem(c);
    return {std::move(c), std::move(s)};
  } catch (const std::invalid_argument& e) {
    return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
  }
}

} // namespace

Outcome consider_parametric(const Problem& problem, const State& state, const Simulator& sim,
                            const std::string& joint, joints::Term term) {
  Candidate c;
  c.joint = joint;
  c.term = term;
  const std::size_t jj = position(state.joints, joint);
  try {
    return add_parametric(problem, state, sim, std::move(c), {term},
                          parametric_points(problem, state, sim, jj));
  } catch (const std::invalid_argument& e) {
    return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
  }
}

bool softens_then_stiffens(const std::vector<identify::EquivalentStiffness>& points) {
  if (points.size() < 3) return false;
  std::vector<identify::EquivalentStiffness> sorted = points;
  std::sort(sorted.begin(), sorted.end(),
            [](const auto& p, const auto& q) { return p.amplitude < q.amplitude; });
  double largest = 0.0;
  for (const auto& p : sorted)
    largest = std::max(largest, std::abs(p.Z));
  std::size_t m = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i)
    if (sorted[i].Z.real() < sorted[m].Z.real()) m = i;
  if (m == 0 || m + 1 == sorted.size()) return false;
  const double least = sorted[m].Z.real();
  double before = 0.0, after = 0.0;
  for (std::size_t i = 0; i < m; ++i)
    before = std::max(before, sorted[i].Z.real() - least);
  for (std::size_t i = m + 1; i < sorted.size(); ++i)
    after = std::max(after, sorted[i].Z.real() - least);
  return before > 0.1 * largest && after > 0.1 * largest;
}

Outcome consider_pair(const Problem& problem, const State& state, const Simulator& sim,
                      const std::string& joint, joints::Term term, joints::Term with) {
  Candidate c;
  c.joint = joint;
  c.term = term;
  c.with = with;
  const std::size_t jj = position(state.joints, joint);
  try {
    std::vector<identify::EquivalentStiffness> points = parametric_points(problem, state, sim, jj);
    if (!softens_then_stiffens(points))
      return refused(std::move(c), state, std::string(pair_not_asked));
    // Broadband tests: also started with each test at its deformation's peak (a multisine's
    // slip and contact begin at its peaks, 1.4-2 times its equivalent sine's amplitude); the
    // start that leaves the lower criterion is kept.
    std::vector<identify::EquivalentStiffness> peaks =
        parametric_points(problem, state, sim, jj, true);
    bool broadband = false;
    for (std::size_t i = 0; i < points.size() && i < peaks.size(); ++i)
      broadband = broadband || peaks[i].amplitude > 1.02 * points[i].amplitude;
    Outcome out = add_parametric(problem, state, sim, c, {term, with}, std::move(points));
    if (broadband) {
      Outcome other = add_parametric(problem, state, sim, c, {term, with}, std::move(peaks));
      if (std::isfinite(other.second.criterion) &&
          !(other.second.criterion >= out.second.criterion))
        out = std::move(other);
    }
    return out;
  } catch (const std::invalid_argument& e) {
    return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
  }
}

Outcome consider_variation(const Problem& problem, const State& state, const Simulator& sim,
                           const std::string& joint, joints::Term term) {
  const auto& tests = problem.tests();
  Candidate c;
  c.joint = joint;
  c.term = term;
  Variation v;
  std::vector<joints::Joint> held = state.joints;
  std::size_t jj = 0;
  for (std::size_t j = 0; j < held.size(); ++j)
    for (std::size_t t = 0; t < held[j].terms.size(); ++t) {
      const bool free = held[j].name == joint && held[j].terms[t] == term;
      held[j].fixed[t] = !free;
      if (free) jj = j;
    }
  std::vector<std::vector<joints::Joint>> per_test;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    try {
      const identify::FitResult fit = problem.identify(held, sim, {static_cast<int>(i)});
      Candidate one;
      take_fit(one, fit, joint, term);
      if (!std::isfinite(one.std) || !(one.std > 0.0))
        return refused(std::move(c), state,
                       fmt::format("not determined by {} alone", tests[i].source));
      per_test.push_back(fit.identified(held));
      v.value.push_back(one.value);
      v.std.push_back(one.std);
    } catch (const std::invalid_argument& e) {
      return refused(
          std::move(c), state,
          fmt::format("cannot be identified from {} alone: {}", tests[i].source, e.what()));
    }
    if (std::string why = physical_problem(per_test.back()); !why.empty())
      return refused(std::move(c), state, tests[i].source + ": " + why);
    if (std::string why = friction_problem(per_test.back()); !why.empty())
      return refused(std::move(c), state, tests[i].source + ": " + why);
    v.tests.push_back(tests[i].source);
    // (a periodic test's lines as one sine: identify::joint_equivalent_sine)
    const auto [a, omega] = identify::joint_equivalent_sine(tests[i], state.joints[jj]);
    v.amplitude.push_back(a);
    v.frequency_hz.push_back(omega / (2.0 * std::numbers::pi));
  }
  State s = problem.evaluate_each(state.joints, per_test, sim, &state);
  judge_variation(c, std::move(v), s, state.joints[jj]);
  return {std::move(c), std::move(s)};
}

Outcome consider_damping(const Problem& problem, const State& state) {
  const Compared& compared = problem.compared();
  Candidate c;
  c.joint = "substructure";
  // With more tests than a refinement's spread (RefineScope::spread), the search runs on that
  // spread alone (the trials, all with the same parameters, compared by their gap there), and
  // the scale it finds is then judged on every test, with one parabolic step from the
  // misfit's curvature there: a table's hundreds of tests fix one scale far beyond what the
  // search needs.
  const std::vector<int> skip = problem.outside_spread(RefineScope{}.spread);
  // Trials on the tests `out` leaves (the spread, or all of them), kept by ln s.
  const auto evaluate = [&](std::map<double, State>& tried, double u,
                            std::span<const int> out) -> double {
    if (const auto it = tried.find(u); it != tried.end()) return it->second.criterion;
    try {
      const auto sim = problem.make_simulator(std::exp(u), false);
      const identify::FitResult fit = problem.identify(state.joints, *sim, problem.all_tests());
      State st = problem.evaluate(fit.identified(state.joints), *sim, nullptr, out);
      st.fit = fit;
      // The trials are compared with each other: each must re-simulate every test the model
      // now does.
      if (!std::isfinite(st.criterion) ||
          !std::includes(state.failed.begin(), state.failed.end(), st.failed.begin(),
                         st.failed.end()) ||
          !physical_problem(st.joints).empty())
        return inf;
      const double f = st.criterion;
      tried.emplace(u, std::move(st));
      return f;
    } catch (const std::invalid_argument&) {
      return inf;
    }
  };
  std::map<double, State> searched, on_all;
  std::map<double, State>& judged = skip.empty() ? searched : on_all; // on every test
  const auto search = [&](double u) { return evaluate(searched, u, skip); };
  const auto trial = [&](double u) { return evaluate(judged, u, {}); };
  const double lo = std::log(0.05), hi = std::log(20.0);
  double best_u = 0.0, best_f = inf;
  for (int i = 0; i <= 6; ++i) {
    const double u = lo + (hi - lo) * i / 6.0, f = search(u);
    if (f < best_f) best_f = f, best_u = u;
  }
  const double width = (hi - lo) / 6.0;
  fem::golden_section_minimum(search, best_u - width, best_u + width, 10); // (tried: the best)
  if (searched.empty()) return refused(std::move(c), state, "no damping scale gives a model");
  const auto lowest = [](const std::map<double, State>& tried) {
    return std::min_element(
               tried.begin(), tried.end(),
               [](const auto& x, const auto& y) { return x.second.criterion < y.second.criterion; })
        ->first;
  };
  double u = lowest(searched);
  // Its uncertainty from the curvature of the misfit in ln s: χ² with known noise, else
  // S / σ̂² with σ̂² = S_min / (N − p); σ_u² = 2 / (∂²misfit/∂u²).
  const double h = 0.02;
  double sigma_u = nan;
  if (std::isfinite(trial(u)) && std::isfinite(trial(u + h)) && std::isfinite(trial(u - h))) {
    const State &s0 = judged.at(u), &sp = judged.at(u + h), &sm = judged.at(u - h);
    const double sigma2 =
        s0.gap * s0.gap * compared.measured2 / std::max(1, compared.values - s0.parameters);
    auto misfit = [&](const State& st) {
      return compared.noise_known ? st.chi2 : st.gap * st.gap * compared.measured2 / sigma2;
    };
    const double m0 = misfit(s0), mp = misfit(sp), mm = misfit(sm);
    const double curvature = (mp - 2.0 * m0 + mm) / (h * h);
    if (curvature > 0.0) {
      sigma_u = std::sqrt(2.0 / curvature);
      // Searched on the spread: the parabola's vertex on every test, where it lies further
      // than the step (within the search's bracket).
      const double vertex = std::clamp(u - (mp - mm) / (2.0 * h * curvature), u - width, u + width);
      if (!skip.empty() && std::abs(vertex - u) > h) (void)trial(vertex);
    }
  }
  if (judged.empty()) return refused(std::move(c), state, "no damping scale gives a model");
  if (!skip.empty()) u = lowest(judged);
  State st = judged.at(u);
  c.value = std::exp(u);
  c.std = c.value * sigma_u;
  c.ci_low = std::exp(u - 1.96 * sigma_u);
  c.ci_high = std::exp(u + 1.96 * sigma_u);
  fill(c, st);
  if (c.rejected.empty()) c.rejected = interval_problem(c);
  return {std::move(c), std::move(st)};
}

std::vector<std::function<Outcome()>> candidate_jobs(const Problem& problem, const State& state,
                                                     const Simulator& current, bool values_fitted) {
  const Problem* p = &problem;
  const State* s = &state;
  const Simulator* sim = &current;
  const Preconditions& can = problem.preconditions();
  std::vector<std::function<Outcome()>> jobs;
  if (!values_fitted) jobs.push_back([=] { return consider_refit(*p, *s, *sim); });
  for (const auto& j : state.joints)
    for (joints::Term t : problem.options().terms) {
      // An even force has no fundamental for a sinusoidal deformation: from the fundamentals
      // alone (tables) it cannot be identified (Preconditions::harmonics).
      if (j.term_index(t) >= 0 || (!can.harmonics && joints::term_info(t).even)) continue;
      if (!joints::has_parameters(t)) {
        jobs.push_back([=, name = j.name] { return consider_term(*p, *s, *sim, name, t); });
        continue;
      }
      // One parametric term identified at a time per joint (identify/parametric.hpp).
      bool open = false;
      for (std::size_t u = 0; u < j.terms.size(); ++u)
        open = open || (joints::has_parameters(j.terms[u]) && !j.fixed[u]);
      if (!open)
        jobs.push_back([=, name = j.name] { return consider_parametric(*p, *s, *sim, name, t); });
    }
  // A friction and a clearance together, where the joint has no parametric term yet and both are
  // candidates: tried only where its stiffness falls and then rises over the tests.
  const auto& terms = problem.options().terms;
  const auto offered = [&](joints::Term t) {
    return std::find(terms.begin(), terms.end(), t) != terms.end();
  };
  if (offered(joints::Term::jenkins) && offered(joints::Term::gap))
    for (const auto& j : state.joints)
      if (!j.has_parametric_terms())
        jobs.push_back([=, name = j.name] {
          return consider_pair(*p, *s, *sim, name, joints::Term::jenkins, joints::Term::gap);
        });
  if (can.damping_scale) jobs.push_back([=] { return consider_damping(*p, *s); });
  // What the library cannot add: a term of the model whose coefficient changes between tests
  // (with four tests or more: fewer leave too little to tell a trend from a fit).
  if (can.per_test_values)
    for (const auto& j : state.joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t)
        if (!j.fixed[t] && !joints::has_parameters(j.terms[t])) // (a coefficient per test)
          jobs.push_back([=, name = j.name, term = j.terms[t]] {
            return consider_variation(*p, *s, *sim, name, term);
          });
  return jobs;
}

} // namespace jointid::discover::detail
