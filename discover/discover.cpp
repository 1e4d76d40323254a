// The discovery loop (discover.hpp): identify the starting model; then, while the gap is above
// the noise level, try every candidate, keep the admissible one with the lowest criterion, and
// stop when none is admissible, when the best explanation is outside the library, or after
// max_steps. The parts: gap.hpp (the disagreement), problem.hpp (set-up, re-simulation,
// identification), refine.hpp (output error), candidates.hpp, selection.hpp (the rules),
// diagnosis.hpp, curves.hpp and result.hpp (what the report shows).
#include "discover/discover.hpp"

#include "discover/candidates.hpp"
#include "discover/curves.hpp"
#include "discover/diagnosis.hpp"
#include "discover/gap.hpp"
#include "discover/problem.hpp"
#include "discover/refine.hpp"
#include "discover/result.hpp"
#include "discover/selection.hpp"
#include "discover/text.hpp"
#include "fem/constants.hpp"
#include "fem/parallel.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace jointid::discover {

namespace detail {
namespace {

class Loop {
public:
  explicit Loop(Problem& problem) : problem_(problem), o_(problem.options()) {}

  Result run() {
    Result out = begin();
    State state = start(out);
    const Result at_start = out;
    const State start_state = state;
    const bool fitted = values_fitted_;
    // The first path is only screened past its first step when a second path will be compared
    // with it and the tests are many (its refinements search on the spread of tests alone:
    // RefineScope::spread_only); followed in full where it is kept.
    screen_first_path_ = static_cast<int>(problem_.tests().size()) > RefineScope{}.spread;
    double simulation_gap = follow(out, state); // of `state`, once estimated (else < 0)
    screen_first_path_ = false;
    // A parametric term added first can stand in for two coefficient terms at once (an iwan's
    // softening and its damping that grows with amplitude, for k3 and c3), and the forward
    // search never takes a term back out: the path that starts from the best coefficient term
    // is followed too, and the one that ends with the lower criterion kept.
    if (parametric_first(out) && first_) {
      Result other = at_start;
      State other_state = start_state;
      values_fitted_ = fitted;
      coefficients_first_ = true;
      avoid_ = out.steps.front().added;
      const double other_gap = follow(other, other_state);
      coefficients_first_ = false;
      values_fitted_ = true;
      // A second path that adds the first path's parametric term after all only puts terms
      // before it that the first path found no need for beside it: the first path stands.
      const bool compared = !other.steps.empty() && !added(other, *avoid_);
      const double b = criterion_on_measurement_noise(problem_.compared(), other_state);
      double a = criterion_on_measurement_noise(problem_.compared(), state);
      bool second = compared && b < a;
      // A screened path is followed again in full from its first step unless the second path
      // is clearly better than anything the screening met (its candidates included, refined
      // on the spread alone): by 10 (a "very strong" difference of the criterion) and a tenth
      // of the values compared (a misfit 10 % smaller than the spread's minimum).
      const double margin = 10.0 + 0.1 * problem_.compared().values;
      const bool screened = after_first_.has_value();
      if (screened && second && !(b < screened_best_ - margin)) second = false;
      std::string screening;
      const bool again = screened && !second; // the first path followed again in full
      if (again) {
        out = std::move(after_first_->first);
        state = std::move(after_first_->second);
        after_first_.reset();
        simulation_gap = follow(out, state, 1);
        a = criterion_on_measurement_noise(problem_.compared(), state);
        second = compared && b < a;
        screening = fmt::format(" (The first path was screened past its first step, its "
                                "candidates refined on {} of the {} tests alone; not clearly "
                                "worse, it was then followed in full.)",
                                RefineScope{}.spread, problem_.tests().size());
      } else {
        simulation_gap = -1.0; // the problem's error estimates are the second path's now
        if (screened)
          screening = fmt::format(
              " (The first path was screened past its first step, its candidates refined on {} "
              "of the {} tests alone: the second path's criterion is below anything the "
              "screening met, {}, by more than {}.)",
              RefineScope{}.spread, problem_.tests().size(), number(screened_best_),
              number(margin));
      }
      if (compared) {
        const std::string said = fmt::format(
            "The first addition, {}, is a parametric term: it can stand in for two coefficient "
            "terms at once, and the forward search cannot take it back out. So the search also "
            "started from the best coefficient term. Judged on the measurement's own noise, the "
            "path {} ends at a criterion of {} (gap {}), the path {} at {} (gap {}): the {} is "
            "kept.{}",
            out.steps.front().added.name(), path(out), number(a), number(state.gap), path(other),
            number(b), number(other_state.gap), second ? "second" : "first", screening);
        if (second) {
          out = std::move(other);
          state = std::move(other_state);
          // Followed again, the first path made the problem's error estimates its own: they
          // are made again for the second path's end (finish()).
          simulation_gap = again ? -1.0 : other_gap;
        }
        out.diagnosis.findings.push_back(said);
      }
    }
    if (prune(out, state)) simulation_gap = -1.0;
    finish(out, state, simulation_gap);
    return out;
  }

private:
  // The steps from `state` until the loop stops; the simulation's error of the state reached
  // if it was estimated there (else < 0).
  double follow(Result& out, State& state, int first_step = 0) {
    double simulation_gap = -1.0;
    for (int step = first_step; step < o_.max_steps; ++step) {
      // The simulation's own error weighs the misfit and judges the noise level only where
      // the noise is known: without, it is estimated once, for the model the loop ends at.
      if (problem_.compared().noise_known)
        simulation_gap = problem_.estimate_simulation_error(state);
      identify_again_if_simulation_error_matters(state, out, simulation_gap);
      if (at_noise_level(problem_.compared(), state)) {
        out.stop_reason = fmt::format(
            "the gap ({}) is at the level of the noise ({}) and of the simulation's own error "
            "({}): nothing significant is left to explain",
            number(state.gap), number(problem_.compared().noise_gap), number(simulation_gap));
        break;
      }
      if (!add_the_best(step, state, out)) {
        // The best explanation outside the library: unless the library's terms, one or two
        // more, explain more (look_ahead).
        const int taken = outside_ && !library_only_ ? look_ahead(step, state, out) : 0;
        if (taken == 0) break;
        step += taken - 1;
        simulation_gap = -1.0;
        continue;
      }
      simulation_gap = -1.0;
      if (step == 0 && screen_first_path_ && !avoid_ && parametric_first(out)) {
        after_first_.emplace(out, state);
        screening_ = true;
        screened_best_ = criterion_on_measurement_noise(problem_.compared(), state);
      }
      if (avoid_ && added(out, *avoid_)) break; // a second path that is moot (run())
    }
    screening_ = false;
    return simulation_gap;
  }

  // When a coefficient with a value per test (outside the library) is the best explanation at
  // `step`, the library may still explain more with two terms than with one: two effects
  // missing at once (a cubic stiffness and a quadratic damping) each explain less alone than a
  // stiffness per test, which absorbs part of both. So the best admissible term of the library
  // is added on trial and, unless that alone does, the step after it taken too; the terms are
  // kept where the model they give ends below the variation's criterion. Returns the steps
  // kept (0: none, `out` and `state` as they were, the stop reason saying what was tried).
  int look_ahead(int step, State& state, Result& out) {
    const Candidate outside = *outside_;
    Result trial = out;
    State trial_state = state;
    trial.stop_reason.clear();
    trial.last_ranking.clear();
    library_only_ = true;
    const bool first = add_the_best(step, trial_state, trial);
    library_only_ = false;
    outside_.reset();
    kept_.reset();
    if (!first) return 0;
    int taken = 1;
    if (!(trial_state.criterion < outside.criterion) && step + 1 < o_.max_steps &&
        !at_noise_level(problem_.compared(), trial_state)) {
      if (add_the_best(step + 1, trial_state, trial)) taken = 2;
      outside_.reset(), kept_.reset();
    }
    const std::string compared = fmt::format(
        "{} ends at a criterion of {} (gap {}); {} at {} (gap {})", path(trial, out.steps.size()),
        number(trial_state.criterion), number(trial_state.gap), outside.name(),
        number(outside.criterion), number(outside.gap));
    if (!(trial_state.criterion < outside.criterion)) {
      out.stop_reason +=
          fmt::format("; the library's best path from here, {}: not lower", compared);
      return 0;
    }
    trial.diagnosis.findings.push_back(fmt::format(
        "At step {} the best single explanation was outside the library ({}). But the "
        "library's best path from there, {}: so the terms were added (two effects missing at "
        "once can each explain less alone than a coefficient per test, which absorbs part of "
        "both).",
        out.steps.size() + 1, outside.varies ? outside.varies->description : outside.name(),
        compared));
    out = std::move(trial);
    state = std::move(trial_state);
    return taken;
  }

  // 3. Backward: the forward search never takes a term back out, so a term added early can
  // stand for effects that the terms added after it explain better (a cubic damping chosen first
  // for the velocity-squared damping added later). Each coefficient term added (but the last,
  // whose addition judged exactly that) is taken out in turn and the model without it
  // identified again by output error; judged as an addition to that model, a term that would
  // not be added now (rule 3: it does not lower the criterion; rule 4: it explains less than
  // min_explained) is taken out — where several, the one whose model has the lowest criterion
  // — as a step of its own, and the others are judged again. True if any was taken out.
  bool prune(Result& out, State& state) {
    bool any = false;
    for (bool first_round = true;; first_round = false) {
      struct Trial {
        std::size_t joint, term;
      };
      std::vector<Trial> trials;
      for (std::size_t i = 0; i < out.steps.size(); ++i) {
        const Candidate& c = out.steps[i].added;
        if (out.steps[i].removed || c.refit || c.varies || !c.term ||
            joints::has_parameters(*c.term) || (first_round && i + 1 == out.steps.size()))
          continue;
        for (std::size_t j = 0; j < state.joints.size(); ++j)
          if (const int t = state.joints[j].term_index(*c.term);
              state.joints[j].name == c.joint && t >= 0 &&
              !state.joints[j].fixed[static_cast<std::size_t>(t)])
            trials.push_back({j, static_cast<std::size_t>(t)});
      }
      if (trials.empty()) return any;
      const Simulator& sim = problem_.simulator(state.damping_scale);
      std::vector<std::function<State()>> jobs;
      for (const Trial& t : trials)
        jobs.push_back([&, t] {
          std::vector<joints::Joint> without = state.joints;
          remove_term(without[t.joint], t.term);
          // Started as a candidate is, from equation error with every test: the other terms'
          // values as they are would drive the model without it far from the measurement (a
          // cubic stiffness without the damping that held its resonance down), where a
          // re-simulation costs the most.
          identify::FitResult fit = state.fit;
          try {
            fit = problem_.identify(without, sim, problem_.all_tests());
            without = fit.identified(without);
          } catch (const std::invalid_argument&) {
            // (the values as they are)
          }
          State start = problem_.evaluate(without, sim, &state);
          start.fit = fit;
          if (!std::isfinite(start.criterion)) return start;
          return refine(problem_, start, sim, scope());
        });
      std::vector<State> models = fem::parallel_map(jobs);
      std::optional<std::size_t> best;
      Candidate judged;
      for (std::size_t i = 0; i < trials.size(); ++i) {
        const State& m = models[i];
        if (!std::isfinite(m.criterion) || m.failed.size() > state.failed.size()) continue;
        Candidate c;
        c.criterion = state.criterion, c.gap = state.gap, c.chi2 = state.chi2;
        c.explained = explained(state.gap, m.gap);
        c.chi2_explained = std::isfinite(state.chi2) && m.chi2 > 0.0
                               ? 1.0 - state.chi2 / m.chi2
                               : std::numeric_limits<double>::quiet_NaN();
        std::string why = criterion_problem(c, m.criterion);
        if (why.empty()) why = explained_problem(c, o_.min_explained);
        if (why.empty()) continue;
        if (!best || m.criterion < models[*best].criterion)
          best = i, judged = c, judged.rejected = why;
      }
      if (!best) return any;
      const joints::Joint& j = state.joints[trials[*best].joint];
      const std::size_t t = trials[*best].term;
      Step s;
      s.removed = true;
      s.added.joint = j.name;
      s.added.term = j.terms[t];
      s.added.value = j.values[t];
      take_fit(s.added, state.fit, j.name, j.terms[t]); // its value and interval before
      s.added.criterion = models[*best].criterion;
      s.added.gap = models[*best].gap;
      s.added.explained = explained(models[*best].gap, state.gap); // (the removal's)
      s.gap_before = state.gap;
      s.gap_after = models[*best].gap;
      s.finding = fmt::format(
          "Took out {} ({}), added before the terms that now explain what it did: without it the "
          "model, identified again, leaves a gap of {} (from {}), and as an addition to that "
          "model it would be rejected ({}).",
          s.added.name(), s.added.effect(), number(s.gap_after), number(s.gap_before),
          judged.rejected);
      state = std::move(models[*best]);
      warn_left_out(out, state,
                    "the model after step " + std::to_string(out.steps.size() + 1) + " (− " +
                        s.added.name() + ")");
      out.stop_reason += fmt::format("; then, backward, {} was taken out (gap {})", s.added.name(),
                                     number(s.gap_after));
      out.steps.push_back(std::move(s));
      out.states.push_back(state);
      any = true;
    }
  }

  // `term` of `j` taken out (its value, fixed flag, given flag and parameters with it).
  static void remove_term(joints::Joint& j, std::size_t term) {
    const auto at = [term](auto& v) {
      if (term < v.size()) v.erase(v.begin() + static_cast<std::ptrdiff_t>(term));
    };
    at(j.terms), at(j.values), at(j.fixed), at(j.given), at(j.parameters);
  }

  // The first step of `r` added a parametric term.
  static bool parametric_first(const Result& r) {
    return !r.steps.empty() && r.steps.front().added.term &&
           joints::has_parameters(*r.steps.front().added.term);
  }

  // How a candidate is refined: on the spread of tests alone while a path is screened.
  RefineScope scope() const {
    RefineScope s;
    s.spread_only = screening_;
    return s;
  }

  // Some step of `r` added the term of `c` at its joint.
  static bool added(const Result& r, const Candidate& c) {
    return std::any_of(r.steps.begin(), r.steps.end(), [&](const Step& s) {
      return s.added.joint == c.joint && s.added.term == c.term;
    });
  }

  // "(k3 at 'tip', then c3 at 'tip')": the steps of `r` from `from` on.
  static std::string path(const Result& r, std::size_t from = 0) {
    std::vector<std::string> names;
    for (std::size_t i = from; i < r.steps.size(); ++i)
      names.push_back(r.steps[i].added.name());
    return "(" + fmt::format("{}", fmt::join(names, ", then ")) + ")";
  }

  Result begin() const {
    Result out;
    out.tests = static_cast<int>(problem_.tests().size());
    out.compared_values = problem_.compared().values;
    out.min_explained = o_.min_explained;
    out.noise_gap = problem_.compared().noise_known ? problem_.compared().noise_gap : -1.0;
    out.warnings = problem_.notes();
    for (const auto& m : problem_.tests())
      out.warnings.insert(out.warnings.end(), m.warnings.begin(), m.warnings.end());
    out.limits = problem_.preconditions().limits;
    out.warnings.insert(out.warnings.end(), out.limits.begin(), out.limits.end());
    return out;
  }

  // "a.csv:3, a.csv:7 and 2 more".
  std::string named(const std::vector<int>& tests) const {
    std::vector<std::string> names = problem_.sources(tests);
    if (names.size() > 4) {
      const std::size_t more = names.size() - 3;
      names.resize(3);
      names.push_back(fmt::format("{} more", more));
    }
    return join(names);
  }

  // A state's tests whose re-simulation did not converge, in a warning, with the harmonic
  // balance's reason for the first of them.
  void warn_left_out(Result& out, const State& state, const std::string& model) const {
    if (state.failed.empty()) return;
    std::string why;
    if (!state.failed_why.empty() && !state.failed_why.front().empty())
      why = fmt::format(" ({}: {})", problem_.sources({state.failed.front()}).front(),
                        state.failed_why.front());
    out.warnings.push_back(fmt::format(
        "the re-simulation of {} test{} with {} did not converge, even from the measured "
        "response and from the nearest tests: {}; left out of its gap{}{}",
        state.failed.size(), state.failed.size() == 1 ? "" : "s", model, named(state.failed),
        comparable(problem_.compared(), state) ? std::string()
                                               : " (too many: the model could not be compared)",
        why));
  }

  // 1. The starting model: values not given are identified from all tests.
  State start(Result& out) {
    std::vector<joints::Joint> joints = problem_.layout();
    std::vector<std::string> missing;
    for (const auto& j : joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t)
        if (!j.has_value(t) && !j.fixed[t])
          missing.push_back(fmt::format("{} of '{}'", joints::term_name(j.terms[t]), j.name));
    values_fitted_ = !missing.empty();
    identify::FitResult start_fit;
    if (values_fitted_) {
      start_fit = problem_.identify(joints, problem_.simulator(1.0), problem_.all_tests());
      joints = start_fit.identified(joints);
    }
    State state = problem_.evaluate(joints, problem_.simulator(1.0));
    state.fit = start_fit;
    if (values_fitted_) {
      state = refine(problem_, state, problem_.simulator(1.0));
      std::string values;
      for (const auto& je : state.fit.joints)
        for (const auto& te : je.terms)
          if (!te.fixed)
            values += fmt::format("{}{} of '{}' = {} {}", values.empty() ? "" : ", ",
                                  joints::term_name(te.term), je.name, number(te.value),
                                  joints::term_unit(te.term));
      std::vector<std::string> harmonics;
      for (int k : o_.harmonics)
        harmonics.push_back(std::to_string(k));
      out.start_notes.push_back(fmt::format(
          "No value was given for {}: the starting terms were identified from all {} tests "
          "(equation error with harmonics {}, then output error): {}.",
          join(missing), problem_.tests().size(), join(harmonics), values));
    } else {
      out.start_notes.push_back("Every starting term has a value in the model file; those values "
                                "are the starting model.");
    }
    warn_left_out(out, state, "the starting model");
    out.states.push_back(state);
    return state;
  }

  // Where the simulation's own error matters (dry friction), identify again with it in the
  // weights: values that fit the harmonic balance's error at a few tests (a stuck friction
  // joint) would misfit all the others. The last step's numbers are then these.
  void identify_again_if_simulation_error_matters(State& state, Result& out,
                                                  double& simulation_gap) {
    const Compared& compared = problem_.compared();
    if (!(compared.noise_known && simulation_gap > 0.3 * compared.noise_gap && values_fitted_))
      return;
    State again = refine(problem_, state, problem_.simulator(state.damping_scale), scope());
    if (!std::isfinite(again.criterion) || again.failed.size() > state.failed.size()) return;
    state = std::move(again);
    simulation_gap = problem_.estimate_simulation_error(state);
    out.states.back() = state;
    if (out.steps.empty()) return;
    Step& last = out.steps.back();
    if (last.added.term) take_fit(last.added, state.fit, last.added.joint, *last.added.term);
    last.gap_after = last.added.gap = state.gap;
    last.added.explained = explained(last.gap_after, last.gap_before);
    const std::size_t n = out.states.size();
    last.finding = last.added.refit && n >= 2
                       ? refit_finding(last, out.states[n - 2].joints, state.joints)
                       : finding(last);
  }

  // Every candidate, evaluated in parallel (each only reads the shared problem); the finalists
  // — the best few by the criterion, simulated and converged — identified again by output
  // error, and judged again (the equation-error estimate screens; noise in the measured
  // deformation biases it, e.g. a stiff joint's damping).
  void try_candidates(const std::vector<std::function<Outcome()>>& jobs, const State& now,
                      const Simulator& current, std::vector<Candidate>& ranking,
                      std::vector<State>& states) {
    const std::vector<std::string> sources = problem_.sources(problem_.all_tests());
    for (auto& [c, s] : fem::parallel_map(jobs)) {
      if (c.with && c.rejected == pair_not_asked) continue; // the joint did not ask for it
      compare_on_common_tests(c, s, now, problem_.compared(), sources);
      ranking.push_back(std::move(c));
      states.push_back(std::move(s));
    }
    const std::vector<std::size_t> best = finalists(ranking, o_.finalists);
    std::vector<std::function<State()>> refinements;
    for (std::size_t i : best)
      refinements.push_back([&, i] {
        std::unique_ptr<Simulator> own;
        if (states[i].damping_scale != current.scale)
          own = problem_.make_simulator(states[i].damping_scale, false);
        const Simulator& sim = own ? *own : current;
        State refined = refine(problem_, states[i], sim, scope());
        // Also from the model now with the term at 0; the better of the two (on the same tests).
        // Not while a path is screened: the one start is near enough for a screen.
        if (const auto js = screening_ ? std::nullopt : nested_start(ranking[i], states[i], now)) {
          State start = problem_.evaluate(*js, sim, &now);
          start.fit = states[i].fit;
          if (std::isfinite(start.criterion)) {
            State other = refine(problem_, start, sim, scope());
            if (other.failed == refined.failed && other.criterion < refined.criterion)
              refined = std::move(other);
          }
        }
        return refined;
      });
    std::vector<State> refined = fem::parallel_map(refinements);
    for (std::size_t f = 0; f < best.size(); ++f) {
      const std::size_t i = best[f];
      states[i] = std::move(refined[f]);
      judge(ranking[i], states[i]);
      compare_on_common_tests(ranking[i], states[i], now, problem_.compared(), sources);
    }
    if (screening_)
      for (std::size_t i = 0; i < ranking.size(); ++i)
        if (!ranking[i].varies && states[i].X.size() == problem_.tests().size() &&
            std::isfinite(states[i].criterion))
          screened_best_ = std::min(screened_best_,
                                    criterion_on_measurement_noise(problem_.compared(), states[i]));
  }

  // The cross-validated gap of a state on the tests that it and the model now re-simulated,
  // kept per set of tests left out for the model now (computed once per step for most). Values
  // given and never fitted are used as given in every fold: refitting them per fold would make
  // the model now's held-out gap that of the refit candidate, which then never passes.
  CrossValidation cross_validated_now(const State& now, const State& candidate,
                                      std::map<std::vector<int>, CrossValidation>& kept) {
    const std::vector<int> out = united(now.failed, candidate.failed);
    const auto it = kept.find(out);
    if (it != kept.end()) return it->second;
    return kept[out] =
               cross_validated(problem_, now.joints, now.damping_scale, out, values_fitted_);
  }

  // 2. One step: the admissible candidate with the lowest criterion is added. False when the
  // loop stops (the reason said in `out`).
  bool add_the_best(int step, State& state, Result& out) {
    const Simulator& current = problem_.simulator(state.damping_scale);
    std::vector<Candidate> ranking;
    std::vector<State> states;
    std::vector<std::size_t> order;
    outside_.reset();
    const bool cached = step == 0 && first_.has_value();
    if (cached) { // the first step of a second path: its candidates are the first path's
      ranking = first_->ranking, states = first_->states, order = first_->order;
    } else if (library_only_ && kept_ && kept_->step == step) { // a look-ahead: the same step's
      ranking = std::move(kept_->ranking), states = std::move(kept_->states);
      order = std::move(kept_->order);
      kept_.reset();
    } else {
      const auto jobs = candidate_jobs(problem_, state, current, values_fitted_);
      if (jobs.empty()) {
        out.stop_reason = "no candidate is left to try: every joint already has every term "
                          "asked for, and the substructure's damping is not tried";
        return false;
      }
      try_candidates(jobs, state, current, ranking, states);
      order = screen(ranking, state, o_.min_explained);
    }
    if (step == 0 && !first_) first_ = FirstStep{ranking, states, order, {}};
    std::vector<std::size_t> open = order;
    if (step == 0 && coefficients_first_)
      std::erase_if(open, [&](std::size_t i) {
        return ranking[i].term && joints::has_parameters(*ranking[i].term);
      });
    if (library_only_)
      std::erase_if(open, [&](std::size_t i) { return ranking[i].varies.has_value(); });
    std::map<std::vector<int>, CrossValidation> cv_now;
    const Choice choice = choose(
        ranking, open, [&](std::size_t i) { return cross_validated_now(state, states[i], cv_now); },
        [&](std::size_t i) {
          return cross_validated(problem_, states[i].joints, states[i].damping_scale,
                                 united(state.failed, states[i].failed));
        });
    if (cached) {
      out.diagnosis = first_->diagnosis;
    } else if (step == 0) {
      std::vector<Candidate> additions;
      for (const auto& c : ranking)
        if (!c.varies) additions.push_back(c);
      out.diagnosis =
          diagnose(problem_.compared(), problem_.tests(), state, additions,
                   choice.outside ? &ranking[*choice.outside] : nullptr, problem_.preconditions());
      // What the tests show of each joint's force against its amplitude: slip or clearance.
      for (std::size_t j = 0; j < state.joints.size(); ++j) {
        std::vector<int> used;
        const auto points = equivalent_stiffness(problem_, state, current, j, &used);
        JointBehaviour b = behaviour(state.joints[j].name, points, problem_.sources(used));
        if (!b.finding.empty()) out.diagnosis.findings.push_back(b.finding);
        out.diagnosis.behaviour.push_back(std::move(b));
      }
      first_->diagnosis = out.diagnosis;
    }
    Step s;
    for (std::size_t i : order)
      s.ranking.push_back(ranking[i]);
    if (choice.outside || !choice.chosen) {
      if (choice.outside) {
        out.stop_reason = outside_the_library(ranking, order, *choice.outside, state.gap);
        out.diagnosis.findings.push_back(ranking[*choice.outside].varies->description);
        outside_ = ranking[*choice.outside];
      } else {
        out.stop_reason = nothing_added(ranking, order, state);
      }
      out.last_ranking = std::move(s.ranking);
      if (outside_ && !cached)
        kept_ = Kept{std::move(ranking), std::move(states), std::move(order), step};
      return false;
    }
    s.added = ranking[*choice.chosen];
    // On the tests both models re-simulated, when either left some out.
    s.gap_before = s.added.gap_now >= 0.0 ? s.added.gap_now : state.gap;
    s.cv_before = choice.cv_now.value_or(-1.0);
    s.cv_after = s.added.cv_gap;
    const std::vector<joints::Joint> before = state.joints;
    state = std::move(states[*choice.chosen]);
    s.gap_after = s.added.gap_now >= 0.0 ? s.added.gap : state.gap;
    s.finding = s.added.refit ? refit_finding(s, before, state.joints) : finding(s);
    values_fitted_ = true;
    warn_left_out(out, state,
                  "the model after step " + std::to_string(out.steps.size() + 1) + " (+ " +
                      s.added.name() + ")");
    for (const std::string& said : state.fit.identifiability)
      out.warnings.push_back(fmt::format("step {}: {}", out.steps.size() + 1, said));
    if (!s.added.determined())
      out.warnings.push_back(fmt::format("the 95 % interval of {} added in step {} could not be "
                                         "determined: its value is not a result",
                                         s.added.name(), out.steps.size() + 1));
    out.steps.push_back(std::move(s));
    out.states.push_back(state);
    return true;
  }

  // Why nothing is added: the best addition cannot be checked against held-out tests, or none
  // is significant; and what the rules could not judge.
  std::string nothing_added(const std::vector<Candidate>& ranking,
                            const std::vector<std::size_t>& order, const State& now) const {
    std::string reason;
    for (std::size_t i : order)
      if (only_unchecked(ranking[i])) {
        const Candidate& c = ranking[i];
        reason = fmt::format("nothing is added: the best addition, {} (it explains {} of the "
                             "squared gap), {}; more tests would decide",
                             c.name(), pct(c.explained), c.rejected);
        break;
      } else if (ranking[i].rejected.empty()) {
        break;
      }
    if (reason.empty()) {
      const Candidate& best = ranking[order.front()];
      reason = fmt::format(
          "no addition is significant (the best, {}, was rejected: {}); the gap stays at {}",
          best.name(), best.rejected, number(now.gap));
    }
    std::vector<Candidate> additions;
    for (const auto& c : ranking)
      if (!c.varies) additions.push_back(c);
    if (const std::string why = unjudged(additions, now, problem_.tests()); !why.empty())
      reason += "; but the conclusion is limited: " + why +
                ", so what they would explain there is unknown";
    return reason;
  }

  static std::string outside_the_library(const std::vector<Candidate>& ranking,
                                         const std::vector<std::size_t>& order, std::size_t outside,
                                         double gap_now) {
    const Candidate& c = ranking[outside];
    std::string library = "no term of the library is admissible";
    for (std::size_t i : order)
      if (!ranking[i].varies && std::isfinite(ranking[i].gap)) {
        library = fmt::format("the best term of the library, {}, leaves {}{}", ranking[i].name(),
                              number(ranking[i].gap),
                              ranking[i].rejected.empty() ? "" : " and is not admissible");
        break;
      }
    return fmt::format("the best explanation is not in the library: {} (a value per test leaves "
                       "a gap of {} from {}; {})",
                       c.name(), number(c.gap), number(gap_now), library);
  }

  // 3. The final model's numbers, every state's comparisons and curves, and the summary.
  void finish(Result& out, State& state, double simulation_gap) {
    const Compared& compared = problem_.compared();
    if (out.stop_reason.empty())
      out.stop_reason = fmt::format("stopped after the maximum of {} steps", o_.max_steps);
    out.simulation_gap =
        simulation_gap >= 0.0 ? simulation_gap : problem_.estimate_simulation_error(state);
    out.states.back() = state;
    if (compared.noise_known) out.noise_gap = compared.noise_gap;
    for (const auto& s : out.states) {
      out.gap.push_back(s.gap);
      out.comparisons.push_back(comparisons(problem_.tests(), compared.harmonics, s));
      out.curves.push_back(curves(problem_, s));
    }
    for (JointBehaviour& b : out.diagnosis.behaviour)
      for (std::size_t j = 0; j < state.joints.size(); ++j)
        if (state.joints[j].name == b.joint && j < out.states.front().joints.size())
          model_lines(b, out.states.front().joints[j], state.joints[j]);
    out.at_noise_level = at_noise_level(compared, out.states.back());
    out.chi2_per_value = out.states.back().chi2 / misfit(compared, state.X, state.failed).values;
    if (compared.noise_known) out.chi2_by_harmonic = chi2_by_harmonic(compared, state.X);
    if (out.steps.empty() && out.at_noise_level && out.diagnosis.findings.empty())
      out.diagnosis.findings.push_back(fmt::format(
          "The starting model reproduces the measurement to the noise level (gap {}, noise {}): "
          "nothing is missing.",
          number(state.gap), number(compared.noise_gap)));
    out.diagnosis.findings.push_back(summary(out, compared));
  }

  // The first step's candidates, before any was chosen, and the diagnosis made there: a second
  // path starts from them.
  struct FirstStep {
    std::vector<Candidate> ranking;
    std::vector<State> states;
    std::vector<std::size_t> order;
    Diagnosis diagnosis;
  };

  // A step's candidates, kept where it stopped at an explanation outside the library: a
  // look-ahead chooses among them again.
  struct Kept {
    std::vector<Candidate> ranking;
    std::vector<State> states;
    std::vector<std::size_t> order;
    int step = -1;
  };

  Problem& problem_;
  const Options& o_;
  std::optional<Kept> kept_;         // the candidates of a step that stopped outside the library
  std::optional<Candidate> outside_; // the last step stopped at it (a value per test)
  bool library_only_ = false;        // the step chooses among the library's terms alone
  bool values_fitted_ = false;       // the model's values were identified (not all given)
  std::optional<FirstStep> first_;   // once the first step's candidates were tried
  bool coefficients_first_ = false;  // the first step takes a coefficient term only
  std::optional<Candidate> avoid_;   // a second path stops when it adds this term
  bool screen_first_path_ = false;   // the first path is screened past its first step
  bool screening_ = false;           // candidates are refined on the spread of tests alone
  std::optional<std::pair<Result, State>> after_first_; // a screened path, after its first step
  double screened_best_ = inf; // the lowest criterion a screened path met (its candidates too)
};

} // namespace
} // namespace detail

Result discover(const frf::Substructure& substructure, const std::vector<joints::Joint>& start,
                const std::vector<identify::Measurement>& tests, const Options& options) {
  // Tests left out (too few steady periods) are passed over, with their reason.
  std::vector<std::string> left_out;
  const std::vector<identify::Measurement> kept = identify::usable(tests, left_out);
  // (No tests at all is refused by the Problem, which says what it needs.)
  if (kept.empty() && !left_out.empty())
    throw std::invalid_argument("discover: every test is left out: " + left_out.front());
  detail::Problem problem(substructure, start, kept, options);
  Result result = detail::Loop(problem).run();
  result.warnings.insert(result.warnings.begin(), left_out.begin(), left_out.end());
  return result;
}

} // namespace jointid::discover
