#include "discover/selection.hpp"

#include "discover/preconditions.hpp"
#include "discover/problem.hpp"
#include "discover/text.hpp"
#include "fem/constants.hpp"
#include "fem/parallel.hpp"

#include <Eigen/Core>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>

namespace jointid::discover::detail {

namespace {} // namespace

double information_criterion(const Compared& compared, const Misfit& misfit, int parameters,
                             bool converged) {
  const double N = misfit.values > 0 ? misfit.values : compared.values;
  const double measured2 = misfit.measured2 > 0.0 ? misfit.measured2 : compared.measured2;
  const double penalty = parameters * std::log(N);
  return !converged ? inf
         : compared.noise_known
             ? misfit.chi2 + penalty
             : N * std::log(std::max(misfit.squared, 1e-300 * measured2) / N) + penalty;
}

double criterion_on_measurement_noise(const Compared& compared, const State& state) {
  if (!comparable(compared, state)) return inf;
  Compared own = compared;
  for (Entry& e : own.entries)
    e.simulation = e.force = 0.0;
  return information_criterion(own, misfit(own, state.X, state.failed), state.parameters, true);
}

void score(State& state, const Compared& compared) {
  if (!comparable(compared, state)) { // too many tests left out: not compared at all
    state.gap = state.criterion = inf;
    state.chi2 = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  const Misfit m = misfit(compared, state.X, state.failed);
  state.gap = gap(compared, m);
  state.chi2 = m.chi2;
  state.criterion = information_criterion(compared, m, state.parameters, true);
}

void compare_on_common_tests(Candidate& candidate, const State& state, const State& now,
                             const Compared& compared, const std::vector<std::string>& sources) {
  if (state.X.empty()) return; // refused: no model to compare
  candidate.left_out.clear();
  for (int i : state.failed)
    candidate.left_out.push_back(sources[static_cast<std::size_t>(i)]);
  candidate.gap_now = -1.0;
  if (!comparable(compared, state)) {
    const std::vector<std::string> first(
        candidate.left_out.begin(),
        candidate.left_out.begin() +
            std::min<std::ptrdiff_t>(3, static_cast<std::ptrdiff_t>(candidate.left_out.size())));
    candidate.rejected = fmt::format(
        "a re-simulation did not converge (for {} tests, e.g. {}; at most {} of the {} may be "
        "left out)",
        state.failed.size(), join(first), max_left_out(compared.tests), compared.tests);
    return;
  }
  if ((state.failed.empty() && now.failed.empty()) || !std::isfinite(candidate.criterion)) return;
  // Both on the tests both re-simulated.
  const std::vector<int> out = united(state.failed, now.failed);
  const Misfit mc = misfit(compared, state.X, out), mn = misfit(compared, now.X, out);
  candidate.gap = gap(compared, mc);
  candidate.gap_now = gap(compared, mn);
  candidate.chi2 = mc.chi2, candidate.chi2_now = mn.chi2;
  candidate.criterion = now.criterion +
                        information_criterion(compared, mc, state.parameters, true) -
                        information_criterion(compared, mn, now.parameters, true);
}

std::string physical_problem(const std::vector<joints::Joint>& joints) {
  for (const auto& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      if (joints::term_info(j.terms[t]).nature == joints::Nature::dissipative && j.values[t] < 0.0)
        return fmt::format("not physical: {} of '{}' came out negative ({}), a joint that "
                           "gives energy",
                           joints::term_name(j.terms[t]), j.name, number(j.values[t]));
  return {};
}

std::string friction_problem(const std::vector<joints::Joint>& joints) {
  for (const auto& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      if (joints::is_dry_friction(j.terms[t]) && j.values[t] < 0.0)
        return fmt::format("not physical: fc of '{}' came out negative ({})", j.name,
                           number(j.values[t]));
  return {};
}

void clamp_dissipative(std::vector<joints::Joint>& joints) {
  for (auto& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      if (joints::term_info(j.terms[t]).nature == joints::Nature::dissipative && !j.fixed[t])
        j.values[t] = std::max(j.values[t], 0.0);
}

void fill(Candidate& candidate, const State& state) {
  candidate.gap = state.gap;
  candidate.chi2 = state.chi2;
  candidate.criterion = state.criterion;
  candidate.converged = state.converged;
  if (!std::isfinite(state.criterion)) candidate.rejected = "a re-simulation did not converge";
}

void take_fit(Candidate& candidate, const identify::FitResult& fit, const std::string& joint,
              joints::Term term) {
  for (const auto& je : fit.joints) {
    if (je.name != joint) continue;
    for (const auto& te : je.terms) {
      if (candidate.with && te.term == *candidate.with) {
        candidate.with_parameters = te.parameters;
      } else if (te.term == term) {
        candidate.parameters = te.parameters;
        candidate.value = te.value;
        candidate.std = te.std;
        candidate.ci_low = te.ci_low;
        candidate.ci_high = te.ci_high;
      }
    }
  }
}

void judge(Candidate& candidate, const State& state) {
  candidate.rejected.clear();
  if (candidate.term) take_fit(candidate, state.fit, candidate.joint, *candidate.term);
  fill(candidate, state);
  if (candidate.rejected.empty()) candidate.rejected = physical_problem(state.joints);
  if (candidate.rejected.empty()) candidate.rejected = state.unstable;
  if (candidate.rejected.empty() && !candidate.refit)
    candidate.rejected = interval_problem(candidate);
}

std::string interval_problem(const Candidate& candidate) {
  // A parametric term: its parameters are in their ranges by construction (identify/
  // parametric.hpp); what the tests leave undetermined is said, not held against it, as long
  // as they determine some of it (the criterion and cross-validation judge whether it matters).
  if (candidate.term && joints::has_parameters(*candidate.term)) {
    if (candidate.determined()) return {};
    return "not determined: the tests determine none of its parameters (no 95 % interval)";
  }
  const double none = candidate.term ? 0.0 : 1.0;
  if (!std::isfinite(candidate.ci_low) || !std::isfinite(candidate.ci_high))
    return "not determined: its 95 % interval could not be estimated";
  if (!(candidate.ci_high > candidate.ci_low))
    return "not determined: its 95 % interval has zero width (the tests do not constrain it, "
           "or it sits at a bound)";
  if (candidate.ci_low > none || candidate.ci_high < none) return {};
  return fmt::format("not significant: its 95 % interval [{}, {}] holds {}",
                     number(candidate.ci_low), number(candidate.ci_high), none);
}

std::string criterion_problem(const Candidate& candidate, double criterion_now) {
  if (candidate.criterion < criterion_now) return {};
  return fmt::format("not significant (information criterion {} vs {} now)",
                     number(candidate.criterion), number(criterion_now));
}

double explained(double gap, double gap_now) {
  return 1.0 - std::pow(gap / gap_now, 2);
}

std::string explained_problem(const Candidate& candidate, double min_explained) {
  if (!(candidate.explained < min_explained)) return {};
  // With the noise known, its χ² share counts too: tests at levels far apart weigh in the gap
  // as their amplitudes squared (the largest decides), in χ² each as its own noise.
  if (candidate.chi2_explained >= min_explained) return {};
  if (std::isfinite(candidate.chi2_explained))
    return fmt::format("explains too little: {} of the gap and {} of χ² (at least {} needed)",
                       pct(candidate.explained), pct(candidate.chi2_explained), pct(min_explained));
  return fmt::format("explains too little: {} of the gap (at least {} needed)",
                     pct(candidate.explained), pct(min_explained));
}

std::string cross_validation_problem(const CrossValidation& candidate, const CrossValidation& now) {
  // The rule cannot be applied: the addition is not checked, so it is not made.
  for (const CrossValidation* cv : {&now, &candidate})
    if (!(cv->gap >= 0.0))
      return std::string(not_checked) + ": " +
             (cv->why.empty() ? std::string("the cross-validated gap could not be computed")
                              : cv->why);
  if (candidate.gap < now.gap) return {};
  return fmt::format("does not predict held-out tests better (cross-validated gap {} vs {} now)",
                     number(candidate.gap), number(now.gap));
}

bool only_unchecked(const Candidate& candidate) {
  return candidate.rejected.starts_with(not_checked);
}

std::vector<std::size_t> screen(std::vector<Candidate>& ranking, const State& now,
                                double min_explained) {
  std::vector<std::size_t> order(ranking.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
    Candidate& c = ranking[i];
    c.explained = explained(c.gap, c.gap_now >= 0.0 ? c.gap_now : now.gap);
    const double chi2_now = c.chi2_now >= 0.0 ? c.chi2_now : now.chi2;
    c.chi2_explained = std::isfinite(c.chi2) && chi2_now > 0.0
                           ? 1.0 - c.chi2 / chi2_now
                           : std::numeric_limits<double>::quiet_NaN();
    if (c.rejected.empty()) c.rejected = criterion_problem(c, now.criterion);
    if (c.rejected.empty()) c.rejected = explained_problem(c, min_explained);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return ranking[a].criterion < ranking[b].criterion;
  });
  return order;
}

Choice choose(std::vector<Candidate>& ranking, const std::vector<std::size_t>& order,
              const std::function<CrossValidation(std::size_t)>& cv_now,
              const std::function<CrossValidation(std::size_t)>& cv_of) {
  Choice choice;
  for (std::size_t i : order) {
    Candidate& c = ranking[i];
    if (!c.rejected.empty()) continue;
    if (c.varies) {
      choice.outside = i;
      break;
    }
    const CrossValidation now = cv_now(i);
    if (now.gap >= 0.0) choice.cv_now = now.gap;
    const CrossValidation with = now.gap >= 0.0 ? cv_of(i) : CrossValidation{};
    c.cv_gap = with.gap;
    c.rejected = cross_validation_problem(with, now);
    if (!c.rejected.empty()) continue;
    choice.chosen = i;
    break;
  }
  return choice;
}

std::vector<std::size_t> finalists(const std::vector<Candidate>& ranking, int count) {
  std::vector<std::size_t> by(ranking.size());
  std::iota(by.begin(), by.end(), std::size_t{0});
  std::stable_sort(by.begin(), by.end(), [&](std::size_t a, std::size_t b) {
    return ranking[a].criterion < ranking[b].criterion;
  });
  std::vector<std::size_t> out;
  bool parametric_seen = false;
  int coefficient = 0, place = 0; // place: among the candidates that may be refined
  for (std::size_t i : by) {
    if (!std::isfinite(ranking[i].criterion) || ranking[i].varies) continue;
    if (ranking[i].with) { // two terms together: only tried where the joint asks for both
      out.push_back(i);
      continue;
    }
    if (ranking[i].term && joints::has_parameters(*ranking[i].term)) {
      // The best one, besides the count, where it ranks among the best count + 1 (its start
      // screens it: further down, coefficient terms explain the data better).
      if (!parametric_seen && place <= count) out.push_back(i);
      parametric_seen = true;
    } else if (coefficient < count) {
      out.push_back(i);
      ++coefficient;
    }
    ++place;
  }
  // The coefficient term whose equation error leaves the smallest residual: its re-simulated
  // start (the other terms identified beside it by equation error) can rank low when a second
  // effect is missing too, where output error would not.
  std::optional<std::size_t> closest;
  for (std::size_t i : by)
    if (std::isfinite(ranking[i].criterion) && !ranking[i].varies && !ranking[i].with &&
        std::isfinite(ranking[i].equation_residual) &&
        (!closest || ranking[i].equation_residual < ranking[*closest].equation_residual))
      closest = i;
  if (closest && std::find(out.begin(), out.end(), *closest) == out.end()) out.push_back(*closest);
  return out;
}

std::vector<std::vector<int>> held_out(int tests, int folds) {
  if (tests < min_tests_held_out) return {};
  const int k = tests <= 30 ? tests : folds;
  std::vector<std::vector<int>> held(k);
  for (int i = 0; i < tests; ++i)
    held[i % k].push_back(i);
  return held;
}

CrossValidation cross_validated(Problem& problem, const std::vector<joints::Joint>& joints,
                                double scale, const std::vector<int>& left_out, bool fit_per_fold) {
  const int n = static_cast<int>(problem.tests().size());
  const std::vector<std::vector<int>> folds = held_out(n, problem.options().folds);
  if (folds.empty())
    return {-1.0,
            fmt::format("{} test{}, at least {} needed", n, n == 1 ? "" : "s", min_tests_held_out)};
  const Simulator& sim = problem.simulator(scale);
  const Compared& compared = problem.compared();
  // One job per fold: the squared error of its held-out tests and their Σ |X_meas|², or why the
  // fold cannot be fitted.
  struct Part {
    double squared = 0.0, measured2 = 0.0;
    std::string why;
  };
  std::vector<std::function<Part()>> jobs;
  for (std::size_t f = 0; f < folds.size(); ++f)
    jobs.push_back([&, f]() -> Part {
      const std::vector<int>& held = folds[f];
      std::vector<int> train;
      for (int i = 0; i < n; ++i)
        if (std::find(held.begin(), held.end(), i) == held.end()) train.push_back(i);
      std::vector<joints::Joint> fitted = joints;
      try {
        if (fit_per_fold) fitted = problem.identify(joints, sim, train).identified(joints);
      } catch (const std::invalid_argument& e) {
        return {0.0, 0.0,
                fmt::format("without {} the terms cannot be identified ({})",
                            join(problem.sources(held)), e.what())};
      }
      // A fold's estimate may come out with negative damping or friction (fewer tests, more
      // noise): brought back to 0, as the output-error refinement does.
      if (fit_per_fold) clamp_dissipative(fitted);
      Part part;
      for (int i : held) {
        // Tests the models compared cannot re-simulate at all are in neither sum.
        if (std::binary_search(left_out.begin(), left_out.end(), i)) continue;
        const frf::HarmonicBalanceResult r = problem.solve(sim, i, fitted);
        for (const auto& e : compared.entries) // a failed prediction counts as predicting nothing
          if (e.test == i) {
            part.squared += r.status.ok() ? std::norm(e.measured - r.X(e.row, e.response))
                                          : std::norm(e.measured);
            part.measured2 += std::norm(e.measured);
          }
      }
      return part;
    });
  double S = 0.0, M = 0.0;
  for (const Part& part : fem::parallel_map(jobs)) {
    if (!part.why.empty()) return {-1.0, part.why};
    S += part.squared, M += part.measured2;
  }
  return {std::sqrt(S / M), {}};
}

void summarise(Variation& variation, Candidate& candidate, const joints::Joint& joint) {
  Variation& v = variation;
  double sw = 0.0, swv = 0.0;
  for (std::size_t i = 0; i < v.value.size(); ++i)
    sw += 1.0 / (v.std[i] * v.std[i]), swv += v.value[i] / (v.std[i] * v.std[i]);
  candidate.value = swv / sw;
  candidate.std = std::sqrt(1.0 / sw);
  candidate.ci_low = candidate.value - 1.96 * candidate.std;
  candidate.ci_high = candidate.value + 1.96 * candidate.std;
  v.chi2 = 0.0;
  for (std::size_t i = 0; i < v.value.size(); ++i)
    v.chi2 += std::pow((v.value[i] - candidate.value) / v.std[i], 2);
  v.dof = static_cast<int>(v.value.size()) - 1;
  v.amplitude_correlation = rank_correlation(v.value, v.amplitude);
  v.frequency_correlation = rank_correlation(v.value, v.frequency_hz);
  v.description = describe(v, candidate, joint);
}

std::string agreement_problem(const Variation& variation) {
  const Variation& v = variation;
  if (v.chi2 > v.dof + 3.0 * std::sqrt(2.0 * v.dof)) return {};
  return fmt::format("its values agree between the tests (χ² {} for {} degrees of freedom)",
                     number(v.chi2), v.dof);
}

void judge_variation(Candidate& candidate, Variation variation, const State& state,
                     const joints::Joint& joint) {
  summarise(variation, candidate, joint);
  fill(candidate, state);
  if (candidate.rejected.empty()) candidate.rejected = agreement_problem(variation);
  candidate.varies = std::move(variation);
}

double rank_correlation(const std::vector<double>& a, const std::vector<double>& b) {
  auto ranks = [](const std::vector<double>& x) {
    std::vector<std::size_t> order(x.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t p, std::size_t q) { return x[p] < x[q]; });
    Eigen::VectorXd r(static_cast<Eigen::Index>(x.size()));
    for (std::size_t i = 0; i < order.size();) {
      std::size_t j = i;
      while (j + 1 < order.size() && x[order[j + 1]] == x[order[i]])
        ++j;
      for (std::size_t q = i; q <= j; ++q)
        r(static_cast<Eigen::Index>(order[q])) = 0.5 * static_cast<double>(i + j);
      i = j + 1;
    }
    return r;
  };
  const Eigen::VectorXd ra = ranks(a), rb = ranks(b);
  const Eigen::VectorXd da = ra.array() - ra.mean(), db = rb.array() - rb.mean();
  const double d = da.norm() * db.norm();
  return d > 0.0 ? da.dot(db) / d : 0.0;
}

namespace {

// The indices of x in ascending order of x (ties in their order).
std::vector<std::size_t> ascending_order(const std::vector<double>& x) {
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t p, std::size_t q) { return x[p] < x[q]; });
  return order;
}

} // namespace

int turning_test(const std::vector<double>& x, const std::vector<double>& value,
                 const std::vector<double>& std) {
  const std::vector<std::size_t> order = ascending_order(x);
  // (a - b) in standard deviations of the difference.
  const auto apart = [&](std::size_t a, std::size_t b) {
    return (value[a] - value[b]) / std::hypot(std[a], std[b]);
  };
  const std::size_t n = order.size();
  int best = -1;
  double best_size = 0.0;
  for (std::size_t m = 1; m + 1 < n; ++m) {
    for (const double sign : {1.0, -1.0}) { // +1: a maximum; -1: a minimum
      double before = 0.0, after = 0.0;     // the largest rise to m and fall after it
      for (std::size_t i = 0; i < m; ++i)
        before = std::max(before, sign * apart(order[m], order[i]));
      for (std::size_t i = m + 1; i < n; ++i)
        after = std::max(after, sign * apart(order[m], order[i]));
      const double size = std::min(before, after);
      if (size >= 3.0 && size > best_size) best = static_cast<int>(order[m]), best_size = size;
    }
  }
  return best;
}

bool monotonic_within_noise(const std::vector<double>& x, const std::vector<double>& value,
                            const std::vector<double>& std) {
  const std::vector<std::size_t> order = ascending_order(x);
  bool rises = false, falls = false; // a step beyond 3 σ either way, between any two in order
  for (std::size_t i = 0; i < order.size(); ++i)
    for (std::size_t k = i + 1; k < order.size(); ++k) {
      const double d =
          (value[order[k]] - value[order[i]]) / std::hypot(std[order[k]], std[order[i]]);
      if (x[order[k]] == x[order[i]]) { // the same abscissa, values apart: no function of x
        if (std::abs(d) > 3.0) return false;
        continue;
      }
      rises = rises || d > 3.0;
      falls = falls || d < -3.0;
    }
  return !(rises && falls);
}

namespace {

// "k at 'mount' is not one number: … it falls from … then rises …": a value that turns at test
// m of the amplitude's order (turning_test), beyond the noise on both sides.
std::string describe_turn(const Variation& v, const Candidate& c, const joints::Joint& j,
                          std::size_t m) {
  const auto lo = std::min_element(v.amplitude.begin(), v.amplitude.end()) - v.amplitude.begin();
  const auto hi = std::max_element(v.amplitude.begin(), v.amplitude.end()) - v.amplitude.begin();
  const bool rotational = fem::is_rotation(j.dof);
  const joints::TermInfo& info = joints::term_info(*c.term);
  const std::string unit(rotational ? info.rotational_unit : info.unit);
  const auto at = [&](std::ptrdiff_t i) {
    return fmt::format("{} {} at {} {}", number(v.value[i]), unit, number(v.amplitude[i]),
                       rotational ? "rad" : "m");
  };
  const bool minimum = v.value[m] < v.value[lo];
  std::string meaning;
  if (*c.term == joints::Term::k && minimum)
    meaning = "a stiffness that softens and then stiffens as the joint deforms more, as a joint "
              "that slips and then closes a clearance does (friction with its own stiffness and "
              "a stop); the library's jenkins and gap together describe it, but discovery adds "
              "one such term at a joint at a time, and neither alone follows a turn";
  else if (*c.term == joints::Term::c && !minimum)
    meaning = "a damping that peaks at an amplitude, as the equivalent viscous damping of "
              "friction does where it starts to slip";
  else
    meaning = fmt::format("a {} that {} and then {} with the deformation amplitude",
                          joints::term_effect(*c.term), minimum ? "falls" : "grows",
                          minimum ? "grows" : "falls");
  return fmt::format(
      "{} at '{}' is not one number: identified from each test alone it {} from {} (the smallest "
      "deformation amplitude) to {}, then {} to {} (the largest), beyond the noise on both sides "
      "(χ² {} for {} degrees of freedom): {}.",
      joints::term_name(*c.term), j.name, minimum ? "falls" : "grows", at(lo),
      at(static_cast<std::ptrdiff_t>(m)), minimum ? "rises" : "falls", at(hi), number(v.chi2),
      v.dof, meaning);
}

} // namespace

// "fc at 'spring' is not one number: identified from each test alone it goes from 0.5963 N at
// the smallest deformation amplitude (0.98 mm) to 0.3412 N at the largest (2.94 mm), …"
std::string describe(const Variation& v, const Candidate& c, const joints::Joint& j) {
  // A turn with the amplitude that the frequency does not explain by a monotonic change (tests
  // at one level across a resonance: their amplitude's order is not the frequency's).
  if (v.value.size() >= 3 && v.std.size() == v.value.size()) {
    const int m = turning_test(v.amplitude, v.value, v.std);
    if (m >= 0 && !monotonic_within_noise(v.frequency_hz, v.value, v.std))
      return describe_turn(v, c, j, static_cast<std::size_t>(m));
  }
  const bool by_amplitude = std::abs(v.amplitude_correlation) >= std::abs(v.frequency_correlation);
  const std::vector<double>& x = by_amplitude ? v.amplitude : v.frequency_hz;
  const auto lo = std::min_element(x.begin(), x.end()) - x.begin();
  const auto hi = std::max_element(x.begin(), x.end()) - x.begin();
  const bool rotational = fem::is_rotation(j.dof);
  const joints::TermInfo& info = joints::term_info(*c.term);
  const std::string unit(rotational ? info.rotational_unit : info.unit);
  auto where = [&](std::ptrdiff_t i) {
    return by_amplitude ? fmt::format("{} {}", number(v.amplitude[i]), rotational ? "rad" : "m")
                        : fmt::format("{} Hz", number(v.frequency_hz[i]));
  };
  const double rho = by_amplitude ? v.amplitude_correlation : v.frequency_correlation;
  std::string law;
  if (std::abs(rho) >= 0.7)
    law = fmt::format(
        "; it {} with the {} (rank correlation {:+.2f}): the joint needs a {} whose coefficient "
        "depends on the {}{}",
        rho < 0 ? "falls" : "grows", by_amplitude ? "deformation amplitude" : "frequency", rho,
        joints::term_effect(*c.term), by_amplitude ? "amplitude" : "frequency",
        *c.term == joints::Term::fc && by_amplitude
            ? " (e.g. a contact whose normal load changes as the vibration grows)"
            : "");
  else
    law = fmt::format("; it follows neither the amplitude (rank correlation {:+.2f}) nor the "
                      "frequency ({:+.2f})",
                      v.amplitude_correlation, v.frequency_correlation);
  return fmt::format(
      "{} at '{}' is not one number: identified from each test alone it goes from {} {} at the "
      "{} {} ({}) to {} {} at the {} ({}), beyond the noise (χ² {} for {} degrees of freedom)"
      "{}. No term of the library has such a coefficient.",
      joints::term_name(*c.term), j.name, number(v.value[lo]), unit, "smallest",
      by_amplitude ? "amplitude" : "frequency", where(lo), number(v.value[hi]), unit, "largest",
      where(hi), number(v.chi2), v.dof, law);
}

} // namespace jointid::discover::detail
