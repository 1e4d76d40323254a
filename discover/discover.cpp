#include "discover/discover.hpp"

#include "fem/minimise.hpp"
#include "fem/parallel.hpp"
#include "fem/time_integration.hpp"
#include "identify/harmonics.hpp"
#include "identify/statistics.hpp"

#include <Eigen/Dense>

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <stdexcept>

namespace jointid::discover {

namespace {

using Complex = std::complex<double>;
constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

std::string pct(double fraction) {
  return fmt::format("{:.3g} %", 100.0 * fraction);
}

std::string number(double v) {
  return fmt::format("{:.4g}", v);
}

void add_unique(std::vector<int>& list, int value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

// A value compared: test i, response j, harmonic k.
struct Entry {
  int test, response, harmonic;
  Complex measured;
  double variance;         // E|δX|² of the measurement noise, NaN when unknown
  double simulation = 0.0; // E|δX|² of the simulation's own error (harmonic truncation)
  double force = 0.0;      // E|δX_sim|² from the noise in the measured force that drives it
  // The variance of the difference measured − simulated, and its real degrees of freedom.
  double total() const { return variance + simulation + force; }
  int dof() const { return harmonic == 0 ? 1 : 2; }
};

// The substructure's receptance (its damping scaled) and the harmonic-balance problems of
// every test built on it.
struct Simulator {
  double scale = 1.0;
  int harmonics = 0;
  frf::ModalSynthesis synthesis;
  std::vector<frf::HarmonicBalance> balance;
};

class Engine {
public:
  Engine(const frf::Substructure& sub, const std::vector<joints::Joint>& start,
         const std::vector<identify::Measurement>& tests, const Options& o)
      : sub_(sub), dofs_(sub.dofs()), tests_(tests), o_(o) {
    if (tests.empty()) throw std::invalid_argument("discover: no tests");
    if (start.empty()) throw std::invalid_argument("discover: the model has no joints");
    if (o.harmonics.empty()) throw std::invalid_argument("discover: no harmonics to fit");
    for (int k : o.harmonics)
      if (k < 0) throw std::invalid_argument("discover: harmonics must be >= 0");
    K_ = std::max(1, *std::max_element(o.harmonics.begin(), o.harmonics.end()));
    if (o.balance.harmonics < K_)
      throw std::invalid_argument("discover: the harmonic balance needs at least as many "
                                  "harmonics as are compared");
    joints::validate_joints(start, dofs_);
    layout_ = start;

    // Equations: the joints' DOFs, every force and every response of every test.
    synthesis_dofs_ = joints::joint_dof_set(start, dofs_);
    double f_max = 0.0;
    for (const auto& m : tests) {
      if (m.harmonics < K_ && !m.fundamental_only)
        throw std::invalid_argument(m.source + ": measured to harmonic " +
                                    std::to_string(m.harmonics) + ", but " + std::to_string(K_) +
                                    " are compared");
      std::vector<int> forces, responses;
      for (const auto& at : m.force_at)
        forces.push_back(equation(m, "force channel f@", at));
      for (std::size_t j = 0; j < m.response_at.size(); ++j)
        responses.push_back(
            equation(m, std::string(1, identify::quantity_letter(m.measured_as[j])) + "@",
                     m.response_at[j]));
      for (int e : forces)
        add_unique(synthesis_dofs_, e);
      for (int e : responses)
        add_unique(synthesis_dofs_, e);
      force_eq_.push_back(std::move(forces));
      response_eq_.push_back(std::move(responses));
      f_max = std::max(f_max, m.frequency_hz);
    }
    // Measured FRFs end at their band: the re-simulations keep to the harmonics whose doubles
    // (the refined simulations) stay in it.
    if (const double top = sub.band_top_hz(synthesis_dofs_); std::isfinite(top)) {
      const int reach = static_cast<int>(std::floor(top / f_max * (1.0 + 1e-12)));
      const int usable = std::min(o_.balance.harmonics, reach / 2);
      if (usable < K_)
        throw std::invalid_argument(fmt::format(
            "discover: the measured FRFs reach {} Hz; the re-simulations need harmonic {} (twice "
            "the {} compared, to estimate their own error) of the highest test frequency, {} Hz: "
            "{} Hz. Measure to that, or compare fewer harmonics",
            top, 2 * K_, K_, f_max, 2 * K_ * f_max));
      if (usable < o_.balance.harmonics) {
        notes_.push_back(fmt::format(
            "the measured FRFs reach {} Hz: the re-simulations use {} harmonics (not {}), so "
            "that the refined ones (twice as many) at {} Hz stay in the band",
            top, usable, o_.balance.harmonics, f_max));
        o_.balance.harmonics = usable;
      }
    }
    f_max_ = frf::synthesis_band_hz(f_max, 2 * o_.balance.harmonics); // refined: twice K
    // The force that drives each re-simulation: the measured harmonics, except those that are
    // noise (a force harmonic within 5 standard deviations of 0 is taken as 0): driven through
    // a resonance, noise alone would give the model responses the structure never had.
    for (const auto& m : tests) {
      Eigen::MatrixXcd F = m.F;
      for (Eigen::Index k = 0; k < F.rows(); ++k)
        for (Eigen::Index c = 0; c < F.cols(); ++c)
          if (k != 1 && m.F_variance.size() > 0 && std::norm(F(k, c)) <= 25.0 * m.F_variance(k, c))
            F(k, c) = 0.0;
      drive_.push_back(std::move(F));
    }
    // The measured joint deformations: the harmonic balance starts from them, so that it
    // finds the periodic solution on the measured branch (hardening joints have several).
    const std::vector<int> set2 = joints::joint_dof_set(start, dofs_);
    const Eigen::MatrixXd B = joints::joint_coordinates_on(start, dofs_, set2);
    for (const auto& m : tests) {
      Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(o_.balance.harmonics + 1, B.cols());
      for (std::size_t d = 0; d < set2.size(); ++d) {
        const int r = m.response_index(dofs_.node_dof(set2[d]));
        if (r < 0)
          throw std::invalid_argument(m.source + ": no response channel at joint DOF " +
                                      fem::to_string(dofs_.node_dof(set2[d])) +
                                      " (discovery needs x, v or a at every joint DOF)");
        for (int k = 0; k <= std::min(m.harmonics, o_.balance.harmonics); ++k) {
          if (!m.has_harmonic(k) || (k == 0 && !m.has_mean[r])) continue;
          Y.row(k) += m.X(k, r) * B.row(static_cast<Eigen::Index>(d)).cast<Complex>();
        }
      }
      measured_start_.push_back(std::move(Y));
    }
    base_ = std::make_unique<frf::ModalSynthesis>(sub.synthesis(synthesis_dofs_, f_max_, &notes_));

    // The compared values.
    for (std::size_t i = 0; i < tests.size(); ++i) {
      const auto& m = tests[i];
      for (std::size_t j = 0; j < m.response_at.size(); ++j)
        for (int k = 0; k <= K_; ++k) {
          if (!m.has_harmonic(k) || (k == 0 && !m.has_mean[j])) continue;
          entries_.push_back({static_cast<int>(i), static_cast<int>(j), k,
                              m.X(k, static_cast<Eigen::Index>(j)),
                              m.X_variance(k, static_cast<Eigen::Index>(j))});
          values_ += k == 0 ? 1 : 2;
          measured2_ += std::norm(entries_.back().measured);
          if (!(entries_.back().variance > 0.0)) noise_known_ = false;
        }
    }
    if (!(measured2_ > 0.0)) throw std::invalid_argument("discover: every response is zero");
    if (noise_known_) {
      double noise2 = 0.0;
      for (const auto& e : entries_)
        noise2 += e.variance;
      noise_gap_ = std::sqrt(noise2 / measured2_);
    }
  }

  Result run() {
    Result out;
    out.tests = static_cast<int>(tests_.size());
    out.compared_values = values_;
    out.min_explained = o_.min_explained;
    out.noise_gap = noise_known_ ? noise_gap_ : -1.0;
    out.warnings = notes_;
    for (const auto& m : tests_)
      out.warnings.insert(out.warnings.end(), m.warnings.begin(), m.warnings.end());

    // 1. The starting model: values not given are identified from all tests.
    State state;
    std::vector<joints::Joint> joints = layout_;
    std::vector<std::string> missing;
    for (const auto& j : joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t)
        if (!j.has_value(t) && !j.fixed[t])
          missing.push_back(fmt::format("{} of '{}'", joints::term_name(j.terms[t]), j.name));
    const bool fitted = !missing.empty();
    identify::FitResult start_fit;
    if (fitted) {
      start_fit = identify(joints, simulator(1.0), all_tests());
      joints = start_fit.identified(joints);
    }
    state = evaluate(joints, simulator(1.0));
    state.fit = start_fit;
    if (fitted) {
      state = refine(state, simulator(1.0));
      std::string values;
      for (const auto& je : state.fit.joints)
        for (const auto& te : je.terms)
          if (!te.fixed)
            values += fmt::format("{}{} of '{}' = {} {}", values.empty() ? "" : ", ",
                                  joints::term_name(te.term), je.name, number(te.value),
                                  joints::term_unit(te.term));
      out.start_notes.push_back(fmt::format(
          "No value was given for {}: the starting terms were identified from all {} tests "
          "(equation error with harmonics {}, then output error): {}.",
          join(missing), tests_.size(), join_harmonics(), values));
    } else {
      out.start_notes.push_back("Every starting term has a value in the model file; those values "
                                "are the starting model.");
    }
    if (!state.converged)
      out.warnings.push_back("the harmonic balance did not converge for every test with the "
                             "starting model");
    out.states.push_back(state);
    bool values_fitted = fitted;

    // 2. Add what explains the disagreement, while something significant is left.
    double simulation_gap = -1.0; // of `state`, once estimated
    for (int step = 0; step < o_.max_steps; ++step) {
      simulation_gap = estimate_simulation_error(state);
      // Where the simulation's own error matters (dry friction), identify again with it in the
      // weights: values that fit the harmonic balance's error at a few tests (a stuck friction
      // joint) would misfit all the others.
      if (noise_known_ && simulation_gap > 0.3 * noise_gap_ && values_fitted) {
        State again = refine(state, simulator(state.damping_scale));
        if (again.converged) {
          state = std::move(again);
          simulation_gap = estimate_simulation_error(state);
          out.states.back() = state;
          if (!out.steps.empty()) { // the last step's numbers are now these
            Step& last = out.steps.back();
            if (last.added.term)
              take_fit(last.added, state.fit, last.added.joint, *last.added.term);
            last.gap_after = last.added.gap = state.gap;
            last.added.explained = 1.0 - std::pow(last.gap_after / last.gap_before, 2);
            last.finding = finding(last);
          }
        }
      }
      if (at_noise_level(state)) {
        out.stop_reason = fmt::format(
            "the gap ({}) is at the level of the noise ({}) and of the simulation's own error "
            "({}): nothing significant is left to explain",
            number(state.gap), number(noise_gap_), number(simulation_gap));
        break;
      }
      // Every candidate, evaluated in parallel (each only reads the shared problem).
      const Simulator& current = simulator(state.damping_scale);
      std::vector<std::function<Outcome()>> jobs;
      if (!values_fitted) jobs.push_back([&] { return consider_refit(state, current); });
      for (const auto& j : state.joints)
        for (joints::Term t : o_.terms)
          if (j.term_index(t) < 0)
            jobs.push_back(
                [&, name = j.name, t] { return consider_term(state, current, name, t); });
      if (o_.substructure_damping && base_->num_modes() > 0)
        jobs.push_back([&] { return consider_damping(state); });
      // What the library cannot add: a term of the model whose coefficient changes between
      // tests (with four tests or more: fewer leave too little to tell a trend from a fit).
      if (tests_.size() >= 4)
        for (const auto& j : state.joints)
          for (std::size_t t = 0; t < j.terms.size(); ++t)
            if (!j.fixed[t])
              jobs.push_back([&, name = j.name, term = j.terms[t]] {
                return consider_variation(state, current, name, term);
              });
      if (jobs.empty()) {
        out.stop_reason = "no candidate is left to try: every joint already has every term "
                          "asked for, and the substructure's damping is not tried";
        break;
      }
      std::vector<Outcome> outcomes = fem::parallel_map(jobs);
      std::vector<Candidate> ranking;
      std::vector<State> states;
      for (auto& [c, s] : outcomes) {
        ranking.push_back(std::move(c));
        states.push_back(std::move(s));
      }
      // The finalists — the best few by the criterion, simulated and converged — identified
      // again by output error, and judged again (the equation-error estimate screens; noise in
      // the measured deformation biases it, e.g. a stiff joint's damping).
      {
        std::vector<std::size_t> by(ranking.size());
        std::iota(by.begin(), by.end(), std::size_t{0});
        std::stable_sort(by.begin(), by.end(), [&](std::size_t a, std::size_t b) {
          return ranking[a].criterion < ranking[b].criterion;
        });
        std::vector<std::size_t> finalists;
        for (std::size_t i : by)
          if (std::isfinite(ranking[i].criterion) && ranking[i].converged && !ranking[i].varies &&
              finalists.size() < static_cast<std::size_t>(o_.finalists))
            finalists.push_back(i);
        std::vector<std::function<State()>> refinements;
        for (std::size_t i : finalists)
          refinements.push_back([&, i] {
            if (states[i].damping_scale == current.scale) return refine(states[i], current);
            const auto sim = make_simulator(states[i].damping_scale, false); // the damping scale
            return refine(states[i], *sim);
          });
        std::vector<State> refined = fem::parallel_map(refinements);
        for (std::size_t f = 0; f < finalists.size(); ++f) {
          const std::size_t i = finalists[f];
          states[i] = std::move(refined[f]);
          judge(ranking[i], states[i]);
        }
      }

      // Admissible and better than the current model by the criterion, best first.
      std::vector<std::size_t> order(ranking.size());
      for (std::size_t i = 0; i < order.size(); ++i) {
        order[i] = i;
        Candidate& c = ranking[i];
        c.explained = 1.0 - std::pow(c.gap / state.gap, 2);
        if (c.rejected.empty() && !(c.criterion < state.criterion))
          c.rejected = fmt::format("not significant (information criterion {} vs {} now)",
                                   number(c.criterion), number(state.criterion));
        if (c.rejected.empty() && c.explained < o_.min_explained)
          c.rejected = fmt::format("explains too little: {} of the gap (at least {} needed)",
                                   pct(c.explained), pct(o_.min_explained));
      }
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return ranking[a].criterion < ranking[b].criterion;
      });

      std::optional<std::size_t> chosen;
      std::optional<double> cv_now;       // < 0: the folds cannot be identified
      std::optional<std::size_t> outside; // the best explanation is a varying coefficient
      for (std::size_t i : order) {
        Candidate& c = ranking[i];
        if (!c.rejected.empty()) continue;
        if (c.varies) {
          outside = i;
          break;
        }
        if (!cv_now) cv_now = cross_validated(state.joints, state.damping_scale);
        c.cv_gap = cross_validated(states[i].joints, states[i].damping_scale);
        if (*cv_now >= 0.0 && c.cv_gap >= 0.0 && !(c.cv_gap < *cv_now)) {
          c.rejected = fmt::format("does not predict held-out tests better (cross-validated "
                                   "gap {} vs {} now)",
                                   number(c.cv_gap), number(*cv_now));
          continue;
        }
        chosen = i;
        break;
      }
      if (step == 0) {
        std::vector<Candidate> additions;
        for (const auto& c : ranking)
          if (!c.varies) additions.push_back(c);
        out.diagnosis = diagnose(state, additions, outside ? &ranking[*outside] : nullptr);
      }
      Step s;
      for (std::size_t i : order)
        s.ranking.push_back(ranking[i]);
      if (outside) {
        const Candidate& c = ranking[*outside];
        std::string library = "no term of the library is admissible";
        for (std::size_t i : order)
          if (!ranking[i].varies && std::isfinite(ranking[i].gap)) {
            library = fmt::format("the best term of the library, {}, leaves {}{}",
                                  ranking[i].name(), number(ranking[i].gap),
                                  ranking[i].rejected.empty() ? "" : " and is not admissible");
            break;
          }
        out.stop_reason = fmt::format(
            "the best explanation is not in the library: {} (a value per test leaves a gap of {} "
            "from {}; {})",
            c.name(), number(c.gap), number(state.gap), library);
        out.diagnosis.findings.push_back(c.varies->description);
        out.last_ranking = std::move(s.ranking);
        break;
      }
      if (!chosen) {
        const Candidate& best = ranking[order.front()];
        out.stop_reason = fmt::format(
            "no addition is significant (the best, {}, was rejected: {}); the gap stays at {}",
            best.name(), best.rejected, number(state.gap));
        out.last_ranking = std::move(s.ranking);
        break;
      }
      s.added = ranking[*chosen];
      s.gap_before = state.gap;
      s.cv_before = cv_now.value_or(-1.0);
      s.cv_after = s.added.cv_gap;
      state = std::move(states[*chosen]);
      simulation_gap = -1.0;
      s.gap_after = state.gap;
      s.finding = finding(s);
      values_fitted = true;
      out.steps.push_back(std::move(s));
      out.states.push_back(state);
    }
    if (out.stop_reason.empty())
      out.stop_reason = fmt::format("stopped after the maximum of {} steps", o_.max_steps);
    out.simulation_gap = simulation_gap >= 0.0 ? simulation_gap : estimate_simulation_error(state);
    out.states.back() = state;
    if (noise_known_) out.noise_gap = noise_gap_;
    for (const auto& s : out.states) {
      out.gap.push_back(s.gap);
      out.comparisons.push_back(compare(s));
      out.curves.push_back(curves(s));
    }
    out.at_noise_level = at_noise_level(out.states.back());
    out.chi2_per_value = out.states.back().chi2 / values_;
    if (noise_known_) out.chi2_by_harmonic = chi2_by_harmonic(out.states.back());
    if (out.steps.empty() && out.at_noise_level && out.diagnosis.findings.empty())
      out.diagnosis.findings.push_back(fmt::format(
          "The starting model reproduces the measurement to the noise level (gap {}, noise {}): "
          "nothing is missing.",
          number(state.gap), number(noise_gap_)));
    out.diagnosis.findings.push_back(summary(out));
    return out;
  }

private:
  int equation(const identify::Measurement& m, const std::string& what, const fem::NodeDof& at) {
    try {
      return dofs_.equation(at);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(m.source + ": channel " + what + fem::to_string(at) + ": " +
                                  e.what());
    }
  }

  static std::string join(const std::vector<std::string>& items) {
    std::string s;
    for (std::size_t i = 0; i < items.size(); ++i)
      s += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + items[i];
    return s;
  }
  std::string join_harmonics() const {
    std::vector<std::string> h;
    for (int k : o_.harmonics)
      h.push_back(std::to_string(k));
    return join(h);
  }

  std::vector<int> all_tests() const {
    std::vector<int> all(tests_.size());
    for (std::size_t i = 0; i < all.size(); ++i)
      all[i] = static_cast<int>(i);
    return all;
  }

  // The harmonic-balance problems of every test with the damping scaled, at the options'
  // harmonics or (`refined`) twice as many, to estimate the truncation error.
  std::unique_ptr<Simulator> make_simulator(double scale, bool refined) const {
    const int harmonics = o_.balance.harmonics * (refined ? 2 : 1);
    auto s = std::make_unique<Simulator>(
        Simulator{scale, harmonics, scale == 1.0 ? *base_ : base_->with_damping_scale(scale), {}});
    frf::HarmonicBalanceOptions options = o_.balance;
    options.harmonics = harmonics;
    for (std::size_t i = 0; i < tests_.size(); ++i)
      s->balance.emplace_back(s->synthesis, layout_, dofs_, force_eq_[i], response_eq_[i],
                              tests_[i].frequency_hz, options);
    return s;
  }
  // The same, kept for reuse: never evicted (a run makes a few: the model's damping, and each
  // damping scale that was added or cross-validated), so references stay valid. Not for
  // concurrent use: the candidates of a step share one made before they run.
  const Simulator& simulator(double scale, bool refined = false) {
    const int harmonics = o_.balance.harmonics * (refined ? 2 : 1);
    for (const auto& s : simulators_)
      if (s->scale == scale && s->harmonics == harmonics) return *s;
    simulators_.push_back(make_simulator(scale, refined));
    return *simulators_.back();
  }

  // Identifies every non-fixed term from the tests `use`, with the damping scaled.
  identify::FitResult identify(const std::vector<joints::Joint>& joints, const Simulator& sim,
                               const std::vector<int>& use) const {
    std::vector<std::string> warnings;
    std::vector<identify::TestSpectrum> spectra;
    for (int i : use)
      spectra.push_back(identify::spectrum(tests_[i], dofs_, joints, warnings));
    const identify::ReceptanceFn H = [&sim](double w, std::span<const int> rows,
                                            std::span<const int> cols) {
      return sim.synthesis.receptance(w, rows, cols);
    };
    identify::FitOptions fo;
    fo.harmonics = o_.harmonics;
    identify::FitResult fit = identify::fit(H, dofs_, joints, spectra, fo, std::move(warnings));
    // Terms the tests cannot separate: this model cannot be identified (a refused candidate).
    if (!fit.status.ok()) throw std::invalid_argument("identify: " + fit.status.reason);
    return fit;
  }

  int parameters(const std::vector<joints::Joint>& joints, double scale) const {
    int p = scale != 1.0 ? 1 : 0;
    for (const auto& j : joints)
      for (bool f : j.fixed)
        p += f ? 0 : 1;
    return p;
  }

  // Simulates every test with these joints.
  State evaluate(const std::vector<joints::Joint>& joints, const Simulator& sim,
                 const State* warm = nullptr) const {
    return evaluate_each(joints, {}, sim, warm);
  }
  // The same with test i's joints `per_test[i]` where given (the state holds `joints` and
  // counts, for the criterion, one parameter per test for the term that varies).
  State evaluate_each(const std::vector<joints::Joint>& joints,
                      const std::vector<std::vector<joints::Joint>>& per_test, const Simulator& sim,
                      const State* warm = nullptr) const {
    State s;
    s.joints = joints;
    s.damping_scale = sim.scale;
    s.parameters = parameters(joints, sim.scale) +
                   (per_test.empty() ? 0 : static_cast<int>(per_test.size()) - 1);
    s.X.assign(tests_.size(), Eigen::MatrixXcd());
    s.Y.assign(tests_.size(), Eigen::MatrixXcd());
    for (std::size_t i = 0; i < tests_.size(); ++i) {
      const Eigen::MatrixXcd* start = warm && i < warm->Y.size() ? &warm->Y[i] : nullptr;
      const frf::HarmonicBalanceResult r =
          solve(sim, static_cast<int>(i), per_test.empty() ? joints : per_test[i], start);
      s.converged = s.converged && r.status.ok() && r.X.allFinite();
      s.X[i] = r.X.topRows(K_ + 1);
      s.Y[i] = r.Y;
    }
    score(s);
    return s;
  }

  // Output-error refinement (maximum likelihood under the noise model): every non-fixed term is
  // adjusted by Levenberg–Marquardt to minimise the weighted squared difference between the
  // re-simulated and the measured harmonics, starting from the equation-error estimate (which
  // the noise in the measured deformation makes less efficient). The 95 % intervals then come
  // from the output-error Jacobian J (finite differences): σ̂² (JᵀJ)⁻¹, with σ̂² the weighted
  // residual variance (at least 1 when the noise is known: a misfit beyond the noise widens the
  // intervals, never narrows them).
  State refine(const State& start, const Simulator& sim) const {
    struct Param {
      std::size_t joint, term;
    };
    std::vector<Param> params;
    for (std::size_t j = 0; j < start.joints.size(); ++j)
      for (std::size_t t = 0; t < start.joints[j].terms.size(); ++t)
        if (!start.joints[j].fixed[t]) params.push_back({j, t});
    const auto p = static_cast<Eigen::Index>(params.size());
    if (p == 0) return start;
    // Steps stay among physical models (no negative damping or friction); a start outside them
    // (an equation-error estimate biased by noise) is first brought back to zero damping there.
    State begin = start;
    if (!physical_problem(start.joints).empty()) {
      std::vector<joints::Joint> clamped = start.joints;
      for (auto& j : clamped)
        for (std::size_t t = 0; t < j.terms.size(); ++t)
          if (joints::term_info(j.terms[t]).nature == joints::Nature::dissipative && !j.fixed[t])
            j.values[t] = std::max(j.values[t], 0.0);
      begin = evaluate(clamped, sim, &start);
      begin.fit = start.fit;
    }
    if (!begin.converged || !physical_problem(begin.joints).empty()) return start;
    std::vector<double> weight;
    for (const auto& e : entries_)
      weight.push_back(noise_known_ ? 1.0 / std::sqrt(e.total() / e.dof()) : 1.0);
    auto residual = [&](const State& st) {
      Eigen::VectorXd r(values_);
      Eigen::Index n = 0;
      for (std::size_t i = 0; i < entries_.size(); ++i) {
        const auto& e = entries_[i];
        const Complex err = e.measured - st.X[e.test](e.harmonic, e.response);
        r(n++) = weight[i] * err.real();
        if (e.harmonic != 0) r(n++) = weight[i] * err.imag();
      }
      return r;
    };
    auto joints_with = [&](const Eigen::VectorXd& b) {
      std::vector<joints::Joint> j = begin.joints;
      for (Eigen::Index q = 0; q < p; ++q)
        j[params[q].joint].values[params[q].term] = b(q);
      return j;
    };
    Eigen::VectorXd b(p), step(p);
    std::vector<bool> dissipative(p);
    for (Eigen::Index q = 0; q < p; ++q) {
      dissipative[q] =
          joints::term_info(begin.joints[params[q].joint].terms[params[q].term]).nature ==
          joints::Nature::dissipative;
      b(q) = begin.joints[params[q].joint].values[params[q].term];
      // A finite-difference step of the parameter's own scale: its value, or (at 0, e.g. a
      // damping brought back to 0) its equation-error estimate and standard deviation.
      double scale =
          std::max(std::abs(b(q)), std::abs(start.joints[params[q].joint].values[params[q].term]));
      for (const auto& je : start.fit.joints)
        if (je.name == begin.joints[params[q].joint].name)
          for (const auto& te : je.terms)
            if (te.term == begin.joints[params[q].joint].terms[params[q].term] &&
                std::isfinite(te.std))
              scale = std::max(scale, te.std);
      step(q) = 1e-5 * std::max(scale, 1e-12);
    }
    State current = begin;
    Eigen::VectorXd r = residual(current);
    double cost = r.squaredNorm(), mu = 1e-3;
    Eigen::MatrixXd J(r.size(), p);
    auto jacobian = [&]() -> bool {
      for (Eigen::Index q = 0; q < p; ++q) {
        for (double h : {step(q), -step(q)}) {
          Eigen::VectorXd bq = b;
          bq(q) += h;
          const std::vector<joints::Joint> jq = joints_with(bq);
          if (!physical_problem(jq).empty()) continue;
          const State sq = evaluate(jq, sim, &current);
          if (!sq.converged) continue;
          J.col(q) = (residual(sq) - r) / h;
          break;
        }
        if (!J.col(q).allFinite()) return false;
      }
      return true;
    };
    for (int iteration = 0; iteration < 12; ++iteration) {
      J.setConstant(nan);
      if (!jacobian()) break; // keep what was reached
      const Eigen::MatrixXd A = J.transpose() * J;
      const Eigen::VectorXd g = J.transpose() * r;
      bool accepted = false;
      double gain = 0.0;
      for (int tries = 0; tries < 10 && !accepted; ++tries, mu *= 10.0) {
        Eigen::MatrixXd M = A;
        M.diagonal() += mu * A.diagonal() + Eigen::VectorXd::Constant(p, 1e-300);
        Eigen::VectorXd nb = b - M.ldlt().solve(g);
        for (Eigen::Index q = 0; q < p; ++q) // projected onto non-negative damping and friction
          if (dissipative[q]) nb(q) = std::max(nb(q), 0.0);
        const std::vector<joints::Joint> nj = joints_with(nb);
        if (!nb.allFinite() || !physical_problem(nj).empty()) continue;
        State sn = evaluate(nj, sim, &current);
        if (!sn.converged) continue;
        const Eigen::VectorXd rn = residual(sn);
        if (rn.squaredNorm() < cost) {
          gain = (cost - rn.squaredNorm()) / cost;
          b = nb, current = std::move(sn), r = rn, cost = r.squaredNorm();
          mu = std::max(mu / 100.0, 1e-9); // (×10 on leaving the loop)
          accepted = true;
        }
      }
      if (!accepted || gain < 1e-5) break; // a 0.001 % smaller misfit is no longer worth a step
    }
    J.setConstant(nan);
    // The fit of the values reached: intervals from the Jacobian there, or NaN (undetermined)
    // when it cannot be formed or there is no redundancy.
    const int dof = values_ - static_cast<int>(p);
    const bool determined = jacobian() && dof > 0;
    Eigen::MatrixXd C = Eigen::MatrixXd::Constant(p, p, nan);
    double tq = nan;
    if (determined) {
      double s2 = cost / dof;
      if (noise_known_) s2 = std::max(s2, 1.0);
      C = s2 * (J.transpose() * J).completeOrthogonalDecomposition().pseudoInverse();
      tq = identify::student_t_quantile(0.975, dof);
    }
    identify::FitResult fit = begin.fit;
    std::size_t q = 0;
    fit.joints.clear();
    for (std::size_t j = 0; j < current.joints.size(); ++j) {
      identify::JointEstimate je{current.joints[j].name, {}};
      for (std::size_t t = 0; t < current.joints[j].terms.size(); ++t) {
        identify::TermEstimate te;
        te.term = current.joints[j].terms[t];
        te.value = current.joints[j].values[t];
        te.fixed = current.joints[j].fixed[t];
        if (!te.fixed) {
          const auto qi = static_cast<Eigen::Index>(q++);
          te.std = std::isfinite(C(qi, qi)) ? std::sqrt(std::max(C(qi, qi), 0.0)) : nan;
        }
        te.ci_low = te.value - tq * te.std;
        te.ci_high = te.value + tq * te.std;
        if (te.fixed) te.ci_low = te.ci_high = te.value;
        je.terms.push_back(te);
      }
      fit.joints.push_back(std::move(je));
    }
    fit.equations = values_;
    fit.unknowns = static_cast<int>(p);
    fit.residual_relative = current.gap;
    current.fit = std::move(fit);
    return current;
  }

  // The gap, χ² (with the noise and the simulation's own error as the variance of each value)
  // and the information criterion of a simulated state.
  void score(State& s) const {
    double S = 0.0, chi2 = 0.0;
    for (const auto& e : entries_) {
      const double d = std::norm(e.measured - s.X[e.test](e.harmonic, e.response));
      S += d;
      chi2 += noise_known_ ? e.dof() * d / e.total() : 0.0;
    }
    s.gap = std::sqrt(S / measured2_);
    s.chi2 = noise_known_ ? chi2 : nan;
    const double N = values_, penalty = s.parameters * std::log(N);
    s.criterion = !s.converged   ? inf
                  : noise_known_ ? chi2 + penalty
                                 : N * std::log(std::max(S, 1e-300 * measured2_) / N) + penalty;
  }

  // What a perfect model would still miss at this state, besides the response's own noise:
  //  - the simulation's error: every test solved again with twice the harmonics, and twice the
  //    difference taken as the truncation error of the solution used (for an error falling like
  //    1/K — dry friction: the switching times of a truncated velocity — that is what remains;
  //    smooth joints' error falls exponentially and is negligible);
  //  - the noise of the measured force that drives the simulation, propagated through the model:
  //    the fundamental of each force perturbed by its standard deviation, in phase and in
  //    quadrature, E|δX|² = (|ΔX_re|² + |ΔX_im|²) / 2.
  // The state is scored again with them. Returns the simulation error as a gap.
  double estimate_simulation_error(State& s) {
    const Simulator& fine = simulator(s.damping_scale, true);
    const Simulator& sim = simulator(s.damping_scale);
    for (auto& e : entries_)
      e.force = 0.0;
    for (std::size_t i = 0; i < tests_.size(); ++i) {
      const auto& m = tests_[i];
      for (Eigen::Index c = 0; c < drive_[i].cols(); ++c) {
        const double v = m.F_variance.size() > 0 ? m.F_variance(1, c) : nan;
        if (!(v > 0.0) || !noise_known_) continue;
        for (Complex unit : {Complex(1.0, 0.0), Complex(0.0, 1.0)}) {
          Eigen::MatrixXcd F = drive_[i];
          F(1, c) += std::sqrt(v) * unit;
          const frf::HarmonicBalanceResult r =
              sim.balance[i].solve(s.joints, F, s.Y[i].size() > 0 ? &s.Y[i] : nullptr);
          if (!r.status.ok()) continue;
          for (auto& e : entries_)
            if (e.test == static_cast<int>(i))
              e.force +=
                  0.5 * std::norm(r.X(e.harmonic, e.response) - s.X[i](e.harmonic, e.response));
        }
      }
    }
    // The simulation's error: against time integration with exact stick–slip where the model
    // has dry friction and the substructure is a finite element model (the harmonic balance of
    // a discontinuous force converges slowly with the harmonics), else against the harmonic
    // balance with twice the harmonics.
    std::vector<Eigen::MatrixXcd> exact;
    if (has_friction(s.joints)) exact = time_integrated(s);
    double E = 0.0;
    for (std::size_t i = 0; i < tests_.size(); ++i) {
      Eigen::MatrixXcd reference;
      double factor = 1.0;
      // Time integration from rest may settle on another branch than the measured one (a jump):
      // a difference beyond 5 % of a fundamental is a different solution, not the harmonic
      // balance's error, and the refined harmonic balance is the reference there.
      bool same_branch = i < exact.size() && exact[i].size() > 0;
      if (same_branch)
        for (Eigen::Index j = 0; j < exact[i].cols(); ++j)
          same_branch = same_branch &&
                        std::abs(exact[i](1, j) - s.X[i](1, j)) <= 0.05 * std::abs(s.X[i](1, j));
      if (same_branch) {
        reference = exact[i];
      } else {
        Eigen::MatrixXcd start = Eigen::MatrixXcd::Zero(fine.harmonics + 1, layout_.size());
        start.topRows(measured_start_[i].rows()) = measured_start_[i];
        frf::HarmonicBalanceResult r = fine.balance[i].solve(s.joints, drive_[i], &start);
        if (!r.status.ok()) r = fine.balance[i].solve(s.joints, drive_[i]);
        if (r.status.ok()) reference = r.X;
        factor = 4.0; // twice the difference
      }
      for (auto& e : entries_)
        if (e.test == static_cast<int>(i)) {
          e.simulation = reference.size() > 0
                             ? factor * std::norm(reference(e.harmonic, e.response) -
                                                  s.X[i](e.harmonic, e.response))
                             : 0.0;
          E += e.simulation;
        }
    }
    if (noise_known_) { // the noise level: the response's noise and the force's, propagated
      double noise2 = 0.0;
      for (const auto& e : entries_)
        noise2 += e.variance + e.force;
      noise_gap_ = std::sqrt(noise2 / measured2_);
    }
    score(s);
    return std::sqrt(E / measured2_);
  }

  static std::string finding(const Step& s) {
    return fmt::format(
        "Added {} ({}) = {} [{}, {}]: the gap fell from {} to {} ({} of it explained).",
        s.added.name(), s.added.effect(), number(s.added.value), number(s.added.ci_low),
        number(s.added.ci_high), number(s.gap_before), number(s.gap_after), pct(s.added.explained));
  }

  static bool has_friction(const std::vector<joints::Joint>& joints) {
    for (const auto& j : joints)
      if (j.term_index(joints::Term::fc) >= 0) return true;
    return false;
  }

  // Every test's steady state by implicit time integration of the finite element model with the
  // state's joints (exact stick–slip), driven by the measured fundamental force: F0 sin ωt with
  // F0 = |F_1|, its harmonics then turned by the force's phase. Harmonics 0 … K at the
  // responses; an empty matrix where that is not possible (a modal substructure, several
  // forces, modal damping above the dense limit, no steady state).
  std::vector<Eigen::MatrixXcd> time_integrated(const State& s) const {
    std::vector<Eigen::MatrixXcd> out(tests_.size());
    const fem::Assembled* system = sub_.system();
    if (!system) return out;
    fem::SparseMatrix C;
    try {
      const fem::Outcome<fem::SparseMatrix> damping = sub_.damping_matrix();
      if (!damping.status.ok()) return out;
      C = damping.value * s.damping_scale;
    } catch (const std::exception&) {
      return out;
    }
    const joints::JointForces forces(s.joints, dofs_);
    std::vector<std::function<Eigen::MatrixXcd()>> jobs;
    for (std::size_t i = 0; i < tests_.size(); ++i)
      jobs.push_back([&, i]() -> Eigen::MatrixXcd {
        const auto& m = tests_[i];
        // One force, a pure sine: what the integrator's load can be.
        if (force_eq_[i].size() != 1) return {};
        for (Eigen::Index k = 0; k < drive_[i].rows(); ++k)
          if (k != 1 && std::abs(drive_[i](k, 0)) > 0.0) return {};
        const Complex F1 = drive_[i](1, 0);
        // 512 steps a period: a period error of (ωh)²/12 = 1.3e-5, well below the harmonic
        // balance's friction error this estimates; steady to 1e-8 of the response.
        fem::SteadyStateOptions o;
        o.steps_per_period = 512;
        o.output_periods = 1;
        o.tolerance = 1e-8;
        const fem::SteadyState ss =
            fem::steady_state(*system, C, &forces, {force_eq_[i][0], std::abs(F1), m.frequency_hz},
                              response_eq_[i], o);
        if (!ss.status.ok()) return {};
        Eigen::MatrixXcd X =
            identify::fit_harmonics(ss.t, ss.u, 2.0 * std::numbers::pi * m.frequency_hz, K_);
        const Complex turn = F1 / Complex(0.0, -std::abs(F1)); // sin → the measured phase
        for (int k = 1; k <= K_; ++k)
          X.row(k) *= std::pow(turn, k);
        return X;
      });
    return fem::parallel_map(jobs);
  }

  // Test i's steady state: from the measured deformation first, else from the linear response
  // with load continuation.
  frf::HarmonicBalanceResult solve(const Simulator& sim, int i,
                                   const std::vector<joints::Joint>& joints,
                                   const Eigen::MatrixXcd* warm = nullptr) const {
    if (!friction_problem(joints).empty()) { // fc < 0: no steady state to speak of
      frf::HarmonicBalanceResult none;
      none.X = Eigen::MatrixXcd::Constant(sim.harmonics + 1, response_eq_[i].size(), nan);
      return none;
    }
    frf::HarmonicBalanceResult r;
    if (warm && warm->rows() == sim.harmonics + 1) {
      r = sim.balance[i].solve(joints, drive_[i], warm);
      if (r.status.ok()) return r;
    }
    r = sim.balance[i].solve(joints, drive_[i], &measured_start_[i]);
    if (!r.status.ok()) {
      frf::HarmonicBalanceResult again = sim.balance[i].solve(joints, drive_[i]);
      again.iterations += r.iterations;
      if (again.status.ok() || again.residual < r.residual) r = std::move(again);
    }
    return r;
  }

  // χ² (noise and simulation error as the variance) within 3 standard deviations of its
  // expectation N.
  // χ² per value of each compared harmonic (0 … K; NaN where none is compared).
  std::vector<double> chi2_by_harmonic(const State& s) const {
    std::vector<double> chi2(K_ + 1, 0.0), n(K_ + 1, 0.0);
    for (const auto& e : entries_) {
      chi2[e.harmonic] +=
          e.dof() * std::norm(e.measured - s.X[e.test](e.harmonic, e.response)) / e.total();
      n[e.harmonic] += e.dof();
    }
    for (int k = 0; k <= K_; ++k)
      chi2[k] = n[k] > 0 ? chi2[k] / n[k] : nan;
    return chi2;
  }

  // At the noise level: χ² per value within 3 standard deviations (√(2/N)) of 1, overall and
  // for every compared harmonic on its own (so that a misfit of the few large fundamentals is
  // not averaged away by many small harmonics).
  bool at_noise_level(const State& s) const {
    if (!noise_known_ || !s.converged) return false;
    if (!(s.chi2 / values_ <= 1.0 + 3.0 * std::sqrt(2.0 / values_))) return false;
    std::vector<double> n(K_ + 1, 0.0);
    for (const auto& e : entries_)
      n[e.harmonic] += e.dof();
    const std::vector<double> chi2 = chi2_by_harmonic(s);
    for (int k = 0; k <= K_; ++k)
      if (n[k] > 0 && !(chi2[k] <= 1.0 + 3.0 * std::sqrt(2.0 / n[k]))) return false;
    return true;
  }

  // Fills a candidate from a fit and the state it gave.
  static void take_fit(Candidate& c, const identify::FitResult& fit, const std::string& joint,
                       joints::Term term) {
    for (const auto& je : fit.joints)
      if (je.name == joint)
        for (const auto& te : je.terms)
          if (te.term == term) {
            c.value = te.value;
            c.std = te.std;
            c.ci_low = te.ci_low;
            c.ci_high = te.ci_high;
          }
  }

  // A negative friction limit: the harmonic balance (and the physics) has no answer for it.
  static std::string friction_problem(const std::vector<joints::Joint>& joints) {
    for (const auto& j : joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t)
        if (joints::is_dry_friction(j.terms[t]) && j.values[t] < 0.0)
          return fmt::format("not physical: fc of '{}' came out negative ({})", j.name,
                             number(j.values[t]));
    return {};
  }

  static std::string physical_problem(const std::vector<joints::Joint>& joints) {
    for (const auto& j : joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t)
        if (joints::term_info(j.terms[t]).nature == joints::Nature::dissipative &&
            j.values[t] < 0.0)
          return fmt::format("not physical: {} of '{}' came out negative ({}), a joint that "
                             "gives energy",
                             joints::term_name(j.terms[t]), j.name, number(j.values[t]));
    return {};
  }

  using Outcome = std::pair<Candidate, State>;

  static Outcome refused(Candidate c, const State& state, const std::string& why) {
    c.rejected = why;
    c.gap = c.criterion = inf;
    return {std::move(c), state};
  }

  Outcome consider_refit(const State& state, const Simulator& sim) const {
    Candidate c;
    c.refit = true;
    c.joint = state.joints.front().name;
    try {
      const identify::FitResult fit = identify(state.joints, sim, all_tests());
      State s = evaluate(fit.identified(state.joints), sim);
      s.fit = fit;
      fill(c, s);
      if (c.rejected.empty()) c.rejected = physical_problem(s.joints);
      return {std::move(c), std::move(s)};
    } catch (const std::invalid_argument& e) {
      return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
    }
  }

  Outcome consider_term(const State& state, const Simulator& sim, const std::string& joint,
                        joints::Term term) const {
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
      }
    try {
      const identify::FitResult fit = identify(joints, sim, all_tests());
      joints = fit.identified(joints);
      take_fit(c, fit, joint, term);
      // Not simulated: negative dry friction has no steady state to compare.
      if (const std::string problem = friction_problem(joints); !problem.empty())
        return refused(std::move(c), state, problem);
      State s = evaluate(joints, sim);
      s.fit = fit;
      judge(c, s);
      return {std::move(c), std::move(s)};
    } catch (const std::invalid_argument& e) {
      return refused(std::move(c), state, std::string("cannot be identified: ") + e.what());
    }
  }

  // The joint's `term` identified from each test alone (every other term held at the state's
  // value), and every test simulated at its own value: does the coefficient change between
  // tests, beyond the noise, and with what? Admissible when the values disagree (χ² about
  // their weighted mean more than 3 standard deviations above its degrees of freedom).
  Outcome consider_variation(const State& state, const Simulator& sim, const std::string& joint,
                             joints::Term term) const {
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
    for (std::size_t i = 0; i < tests_.size(); ++i) {
      try {
        const identify::FitResult fit = identify(held, sim, {static_cast<int>(i)});
        Candidate one;
        take_fit(one, fit, joint, term);
        if (!std::isfinite(one.std) || !(one.std > 0.0))
          return refused(std::move(c), state,
                         fmt::format("not determined by {} alone", tests_[i].source));
        per_test.push_back(fit.identified(held));
        v.value.push_back(one.value);
        v.std.push_back(one.std);
      } catch (const std::invalid_argument& e) {
        return refused(
            std::move(c), state,
            fmt::format("cannot be identified from {} alone: {}", tests_[i].source, e.what()));
      }
      if (std::string problem = physical_problem(per_test.back()); !problem.empty())
        return refused(std::move(c), state, tests_[i].source + ": " + problem);
      if (std::string problem = friction_problem(per_test.back()); !problem.empty())
        return refused(std::move(c), state, tests_[i].source + ": " + problem);
      v.tests.push_back(tests_[i].source);
      v.amplitude.push_back(std::abs(measured_start_[i](1, static_cast<Eigen::Index>(jj))));
      v.frequency_hz.push_back(tests_[i].frequency_hz);
    }
    State s = evaluate_each(state.joints, per_test, sim, &state);
    double sw = 0.0, swv = 0.0;
    for (std::size_t i = 0; i < v.value.size(); ++i)
      sw += 1.0 / (v.std[i] * v.std[i]), swv += v.value[i] / (v.std[i] * v.std[i]);
    c.value = swv / sw;
    c.std = std::sqrt(1.0 / sw);
    c.ci_low = c.value - 1.96 * c.std;
    c.ci_high = c.value + 1.96 * c.std;
    for (std::size_t i = 0; i < v.value.size(); ++i)
      v.chi2 += std::pow((v.value[i] - c.value) / v.std[i], 2);
    v.dof = static_cast<int>(v.value.size()) - 1;
    v.amplitude_correlation = rank_correlation(v.value, v.amplitude);
    v.frequency_correlation = rank_correlation(v.value, v.frequency_hz);
    v.description = describe(v, c, state.joints[jj]);
    fill(c, s);
    if (c.rejected.empty() && !(v.chi2 > v.dof + 3.0 * std::sqrt(2.0 * v.dof)))
      c.rejected = fmt::format("its values agree between the tests (χ² {} for {} degrees of "
                               "freedom)",
                               number(v.chi2), v.dof);
    c.varies = std::move(v);
    return {std::move(c), std::move(s)};
  }

  // Spearman's rank correlation (ties get their mean rank); 0 when either side is constant.
  static double rank_correlation(const std::vector<double>& a, const std::vector<double>& b) {
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

  // "fc at 'spring' is not one number: identified from each test alone it goes from 0.5963 N at
  // the smallest deformation amplitude (0.98 mm) to 0.3412 N at the largest (2.94 mm), …"
  static std::string describe(const Variation& v, const Candidate& c, const joints::Joint& j) {
    const bool by_amplitude =
        std::abs(v.amplitude_correlation) >= std::abs(v.frequency_correlation);
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

  // The substructure's damping scaled by s: ln s is searched by a coarse scan and a golden
  // section on the criterion, every joint term identified again at each trial.
  Outcome consider_damping(const State& state) const {
    Candidate c;
    c.joint = "substructure";
    std::map<double, State> tried;
    auto trial = [&](double u) -> double {
      if (const auto it = tried.find(u); it != tried.end()) return it->second.criterion;
      try {
        const auto sim = make_simulator(std::exp(u), false);
        const identify::FitResult fit = identify(state.joints, *sim, all_tests());
        State st = evaluate(fit.identified(state.joints), *sim);
        st.fit = fit;
        if (!st.converged || !physical_problem(st.joints).empty()) return inf;
        const double f = st.criterion;
        tried.emplace(u, std::move(st));
        return f;
      } catch (const std::invalid_argument&) {
        return inf;
      }
    };
    const double lo = std::log(0.05), hi = std::log(20.0);
    double best_u = 0.0, best_f = inf;
    for (int i = 0; i <= 6; ++i) {
      const double u = lo + (hi - lo) * i / 6.0, f = trial(u);
      if (f < best_f) best_f = f, best_u = u;
    }
    const double width = (hi - lo) / 6.0;
    fem::golden_section_minimum(trial, best_u - width, best_u + width, 10); // (tried: the best)
    if (tried.empty()) return refused(std::move(c), state, "no damping scale gives a model");
    const double u = std::min_element(tried.begin(), tried.end(), [](const auto& x, const auto& y) {
                       return x.second.criterion < y.second.criterion;
                     })->first;
    // Its uncertainty from the curvature of the misfit in ln s: χ² with known noise, else
    // S / σ̂² with σ̂² = S_min / (N − p); σ_u² = 2 / (∂²misfit/∂u²).
    const double h = 0.02;
    double sigma_u = nan;
    if (std::isfinite(trial(u + h)) && std::isfinite(trial(u - h))) {
      const State &s0 = tried.at(u), &sp = tried.at(u + h), &sm = tried.at(u - h);
      const double sigma2 = s0.gap * s0.gap * measured2_ / std::max(1, values_ - s0.parameters);
      auto misfit = [&](const State& st) {
        return noise_known_ ? st.chi2 : st.gap * st.gap * measured2_ / sigma2;
      };
      const double curvature = (misfit(sp) - 2.0 * misfit(s0) + misfit(sm)) / (h * h);
      if (curvature > 0.0) sigma_u = std::sqrt(2.0 / curvature);
    }
    State st = tried.at(u);
    c.value = std::exp(u);
    c.std = c.value * sigma_u;
    c.ci_low = std::exp(u - 1.96 * sigma_u);
    c.ci_high = std::exp(u + 1.96 * sigma_u);
    fill(c, st);
    if (c.rejected.empty()) c.rejected = interval_problem(c);
    return {std::move(c), std::move(st)};
  }

  // A term candidate's value and interval from its state's fit, and its verdict: converged,
  // physical, its interval clear of 0 (the damping scale: of 1).
  void judge(Candidate& c, const State& s) const {
    c.rejected.clear();
    if (c.term) take_fit(c, s.fit, c.joint, *c.term);
    fill(c, s);
    if (c.rejected.empty()) c.rejected = physical_problem(s.joints);
    if (c.rejected.empty() && !c.refit) c.rejected = interval_problem(c);
  }

  // An addition must be determined: its 95 % interval known and clear of 0 (a term) or of 1
  // (the damping scale).
  static std::string interval_problem(const Candidate& c) {
    const double none = c.term ? 0.0 : 1.0;
    if (!std::isfinite(c.ci_low) || !std::isfinite(c.ci_high))
      return "not determined: its 95 % interval could not be estimated";
    if (c.ci_low > none || c.ci_high < none) return {};
    return fmt::format("not significant: its 95 % interval [{}, {}] holds {}", number(c.ci_low),
                       number(c.ci_high), none);
  }

  void fill(Candidate& c, const State& s) const {
    c.gap = s.gap;
    c.criterion = s.criterion;
    c.converged = s.converged;
    if (!s.converged) c.rejected = "a re-simulation did not converge";
  }

  // The gap of leave-one-test-out (or k-fold) predictions: each fold's tests are predicted by
  // the model identified from the others. < 0 when the folds cannot be identified.
  double cross_validated(const std::vector<joints::Joint>& joints, double scale) {
    const int n = static_cast<int>(tests_.size());
    if (n < 4) return -1.0;
    const int folds = n <= 30 ? n : o_.folds;
    const Simulator& sim = simulator(scale);
    // One job per fold: the squared error of its held-out tests; -1 when it cannot be fitted.
    std::vector<std::function<double()>> jobs;
    for (int f = 0; f < folds; ++f)
      jobs.push_back([&, f]() -> double {
        std::vector<int> train, held;
        for (int i = 0; i < n; ++i)
          (i % folds == f ? held : train).push_back(i);
        std::vector<joints::Joint> fitted;
        try {
          fitted = identify(joints, sim, train).identified(joints);
        } catch (const std::invalid_argument&) {
          return -1.0;
        }
        // A fold's estimate may come out with negative damping or friction (fewer tests, more
        // noise): brought back to 0, as the output-error refinement does.
        for (auto& j : fitted)
          for (std::size_t t = 0; t < j.terms.size(); ++t)
            if (joints::term_info(j.terms[t]).nature == joints::Nature::dissipative && !j.fixed[t])
              j.values[t] = std::max(j.values[t], 0.0);
        double S = 0.0;
        for (int i : held) {
          const frf::HarmonicBalanceResult r = solve(sim, i, fitted);
          for (const auto& e : entries_) // a failed prediction counts as predicting nothing
            if (e.test == i)
              S += r.status.ok() ? std::norm(e.measured - r.X(e.harmonic, e.response))
                                 : std::norm(e.measured);
        }
        return S;
      });
    double S = 0.0;
    for (double part : fem::parallel_map(jobs)) {
      if (part < 0.0) return -1.0;
      S += part;
    }
    return std::sqrt(S / measured2_);
  }

  // Groups of values closer than `tolerance` (relative): each value's group, and the groups'
  // mean values, ascending.
  static std::pair<std::vector<int>, std::vector<double>> cluster(const std::vector<double>& v,
                                                                  double tolerance) {
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    std::vector<std::vector<double>> groups;
    for (double x : sorted)
      if (groups.empty() || x - groups.back().back() > tolerance * std::abs(x))
        groups.push_back({x});
      else
        groups.back().push_back(x);
    std::vector<double> means;
    for (const auto& g : groups)
      means.push_back(std::accumulate(g.begin(), g.end(), 0.0) / static_cast<double>(g.size()));
    std::vector<int> of(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t g = 0; g < groups.size(); ++g)
        if (v[i] >= groups[g].front() && v[i] <= groups[g].back()) of[i] = static_cast<int>(g);
    return {of, means};
  }

  // The model's response curves through the tests: per force level over frequency (or per
  // frequency over level), at the force DOF of the first test, continuation point to point.
  std::vector<ResponseCurve> curves(const State& state) const {
    std::vector<ResponseCurve> out;
    const int points = o_.curve_points;
    if (points < 2) return out;
    std::vector<double> freq, level;
    for (const auto& m : tests_)
      freq.push_back(m.frequency_hz), level.push_back(identify::force_level(m));
    const auto [fg, fmeans] = cluster(freq, 0.01);
    const auto [lg, lmeans] = cluster(level, 0.03);
    const bool over_frequency = fmeans.size() >= lmeans.size();
    const auto& group = over_frequency ? lg : fg;
    const auto& means = over_frequency ? lmeans : fmeans;
    const frf::ModalSynthesis synthesis =
        state.damping_scale == 1.0 ? *base_ : base_->with_damping_scale(state.damping_scale);
    std::vector<std::function<ResponseCurve()>> jobs;
    for (std::size_t g = 0; g < 2 * means.size(); ++g)
      jobs.push_back([&, g = g / 2, down = g % 2 == 1]() {
        // The group's tests: their span, and the first one's force DOF and outputs.
        double lo = inf, hi = -inf;
        int first = -1;
        for (std::size_t i = 0; i < tests_.size(); ++i)
          if (group[i] == static_cast<int>(g)) {
            const double x = over_frequency ? freq[i] : level[i];
            lo = std::min(lo, x), hi = std::max(hi, x);
            if (first < 0) first = static_cast<int>(i);
          }
        const auto& m = tests_[first];
        ResponseCurve c;
        c.over_frequency = over_frequency;
        c.descending = down;
        c.level = over_frequency ? means[g] : 0.0;
        c.frequency_hz = over_frequency ? 0.0 : means[g];
        for (std::size_t j = 0; j < m.response_at.size(); ++j) {
          c.channels.push_back(std::string(1, identify::quantity_letter(m.measured_as[j])) + "@" +
                               fem::to_string(m.response_at[j]));
          c.X1.emplace_back();
        }
        if (hi <= lo) hi = lo * 1.001, lo *= 0.999;
        const std::vector<int> force{force_eq_[first].front()};
        std::optional<Eigen::MatrixXcd> previous;
        std::optional<frf::HarmonicBalance> fixed_frequency;
        for (int p = 0; p < points; ++p) {
          const double u = static_cast<double>(down ? points - 1 - p : p) / (points - 1);
          const double x = over_frequency ? lo + (hi - lo) * u : lo * std::pow(hi / lo, u);
          const double f = over_frequency ? x : means[g], amplitude = over_frequency ? means[g] : x;
          std::optional<frf::HarmonicBalance> at_f;
          if (over_frequency || !fixed_frequency)
            (over_frequency ? at_f : fixed_frequency)
                .emplace(synthesis, layout_, dofs_, force, response_eq_[first], f, o_.balance);
          const frf::HarmonicBalance& hb = over_frequency ? *at_f : *fixed_frequency;
          frf::HarmonicBalanceResult r;
          const Eigen::MatrixXcd F = frf::sine_force(amplitude);
          if (friction_problem(state.joints).empty()) {
            r = hb.solve(state.joints, F, previous ? &*previous : nullptr);
            if (!r.status.ok() && previous) r = hb.solve(state.joints, F);
          }
          c.x.push_back(x);
          c.converged.push_back(r.status.ok());
          for (std::size_t j = 0; j < c.channels.size(); ++j)
            c.X1[j].push_back(r.status.ok() ? r.X(1, static_cast<Eigen::Index>(j))
                                            : std::complex<double>(nan, nan));
          if (r.status.ok()) previous = r.Y;
        }
        if (down) { // ascending order, as the sweep up
          std::reverse(c.x.begin(), c.x.end());
          std::reverse(c.converged.begin(), c.converged.end());
          for (auto& X : c.X1)
            std::reverse(X.begin(), X.end());
        }
        return c;
      });
    std::vector<ResponseCurve> both = fem::parallel_map(jobs);
    for (std::size_t g = 0; g < both.size(); g += 2) {
      const ResponseCurve& up = both[g];
      ResponseCurve& down = both[g + 1];
      double differs = 0.0;
      for (std::size_t j = 0; j < up.X1.size(); ++j)
        for (std::size_t p = 0; p < up.x.size(); ++p)
          if (up.converged[p] && down.converged[p])
            differs = std::max(differs, std::abs(up.X1[j][p] - down.X1[j][p]) /
                                            std::max(std::abs(up.X1[j][p]), 1e-300));
      out.push_back(std::move(both[g]));
      if (differs > 0.01) out.push_back(std::move(down));
    }
    return out;
  }

  std::vector<Comparison> compare(const State& s) const {
    std::vector<Comparison> out;
    for (std::size_t i = 0; i < tests_.size(); ++i) {
      const auto& m = tests_[i];
      for (std::size_t j = 0; j < m.response_at.size(); ++j) {
        const auto jj = static_cast<Eigen::Index>(j);
        Comparison c;
        c.test = m.source;
        c.channel = std::string(1, identify::quantity_letter(m.measured_as[j])) + "@" +
                    fem::to_string(m.response_at[j]);
        c.frequency_hz = m.frequency_hz;
        c.force = identify::force_level(m);
        c.measured = m.X(1, jj);
        c.simulated = s.X[i](1, jj);
        c.amplitude_error = std::abs(c.simulated) / std::max(std::abs(c.measured), 1e-300) - 1.0;
        c.phase_error_deg = std::arg(c.simulated / c.measured) * 180.0 / std::numbers::pi;
        double hm = 0.0, hs = 0.0;
        if (!m.fundamental_only)
          for (int k = 2; k <= K_; ++k)
            hm += std::norm(m.X(k, jj)), hs += std::norm(s.X[i](k, jj));
        c.harmonics_measured = std::sqrt(hm) / std::max(std::abs(c.measured), 1e-300);
        c.harmonics_simulated = std::sqrt(hs) / std::max(std::abs(c.measured), 1e-300);
        out.push_back(c);
      }
    }
    return out;
  }

  // `outside`: the best explanation, when it is a coefficient that changes between tests.
  Diagnosis diagnose(const State& s, const std::vector<Candidate>& ranking,
                     const Candidate* outside) const {
    Diagnosis d;
    // Which channel disagrees most.
    std::map<std::string, std::pair<double, double>> per_channel; // error², measured²
    double even = 0.0, even_noise = 0.0;
    std::string even_where, even_test;
    std::set<int> even_tests; // tests with a second harmonic 5 × beyond the noise
    for (const auto& e : entries_) {
      const auto& m = tests_[e.test];
      const std::string ch = std::string(1, identify::quantity_letter(m.measured_as[e.response])) +
                             "@" + fem::to_string(m.response_at[e.response]);
      const Complex err = e.measured - s.X[e.test](e.harmonic, e.response);
      per_channel[ch].first += std::norm(err);
      per_channel[ch].second += std::norm(e.measured);
      // The second harmonic (a mean displacement can also come from a sensor's offset or a
      // friction joint's memory of where it stuck).
      if (e.harmonic == 2) {
        const double x1 = std::abs(m.X(1, e.response));
        const double ratio = std::abs(err) / std::max(x1, 1e-300);
        const double noise = e.variance > 0.0 ? std::sqrt(e.variance) / std::max(x1, 1e-300) : 0.0;
        if (ratio - 3.0 * noise > even - 3.0 * even_noise)
          even = ratio, even_noise = noise, even_where = ch, even_test = m.source;
        if (ratio > 5.0 * noise && (noise > 0.0 || ratio > 1e-3)) even_tests.insert(e.test);
      }
    }
    for (const auto& [ch, v] : per_channel) {
      const double rel = std::sqrt(v.first / std::max(v.second, 1e-300));
      if (rel > d.channel_error) d.channel_error = rel, d.channel = ch;
    }
    d.even_content = even;
    const bool any_harmonics = std::any_of(tests_.begin(), tests_.end(),
                                           [](const auto& m) { return !m.fundamental_only; });
    d.even_harmonics = any_harmonics && even > 5.0 * even_noise && (noise_known_ || even > 1e-3);

    // Best admissible-looking candidates of each family (by how much of the gap they explain).
    // The best of a family by the criterion (the rule that adds terms), and its share.
    auto best = [&](auto&& keep) {
      const Candidate* who = nullptr;
      for (const auto& c : ranking)
        if (c.converged && std::isfinite(c.criterion) && keep(c) &&
            (!who || c.criterion < who->criterion))
          who = &c;
      return std::pair{who ? std::max(who->explained, 0.0) : 0.0, who};
    };
    const auto [lin, lin_c] = best([](const Candidate& c) { return c.linear(); });
    const auto [non, non_c] = best([](const Candidate& c) { return !c.linear(); });
    const auto [cons, cons_c] = best([](const Candidate& c) {
      return c.term && !c.linear() &&
             joints::term_info(*c.term).nature == joints::Nature::conservative;
    });
    const auto [diss, diss_c] = best([](const Candidate& c) {
      return c.term && !c.linear() &&
             joints::term_info(*c.term).nature == joints::Nature::dissipative;
    });
    d.linear_explains = lin;
    d.nonlinear_explains = non;
    d.conservative_explains = cons;
    d.dissipative_explains = diss;
    const bool significant = std::any_of(ranking.begin(), ranking.end(),
                                         [](const Candidate& c) { return c.rejected.empty(); });

    if (noise_known_)
      d.findings.push_back(fmt::format(
          "The starting model leaves a gap of {} against a noise level of {} (the gap a perfect "
          "model would leave, from the records' own scatter).",
          number(s.gap), number(noise_gap_)));
    else
      d.findings.push_back(fmt::format("The starting model leaves a gap of {}; the noise level "
                                       "is unknown (stepped-sine tables carry no time records).",
                                       number(s.gap)));
    if (!d.channel.empty())
      d.findings.push_back(fmt::format("The largest disagreement is at channel {} ({} of its "
                                       "measured amplitude over all tests).",
                                       d.channel, pct(d.channel_error)));
    for (const auto& f : level_evidence())
      d.findings.push_back(f);
    if (outside) {
      const auto best = std::min_element(
          ranking.begin(), ranking.end(),
          [](const Candidate& a, const Candidate& b) { return a.criterion < b.criterion; });
      d.joint = outside->joint;
      d.findings.push_back(fmt::format(
          "No addition explains it as well as a coefficient that changes between tests: {} "
          "explains {} of it{}.",
          outside->name(), pct(outside->explained),
          best != ranking.end() && std::isfinite(best->gap)
              ? fmt::format(", the best addition ({}) {}", best->name(), pct(best->explained))
              : std::string()));
      return d;
    }
    if (!significant) {
      d.findings.push_back(
          "No candidate explains a significant share of the disagreement: nothing is missing "
          "that these tests can reveal.");
      return d;
    }
    // Linear or not: can a linear correction do as well as a non-linear term?
    const double N = values_;
    const double lin_crit = lin_c ? lin_c->criterion : inf,
                 non_crit = non_c ? non_c->criterion : inf;
    d.level_dependent = non_crit + std::log(N) < lin_crit;
    if (*d.level_dependent) {
      d.findings.push_back(fmt::format(
          "The disagreement changes with force level (non-linear): the best linear correction{} "
          "explains {} of it, the best non-linear term ({}) {}.",
          lin_c ? " (" + lin_c->name() + ")" : std::string(), pct(std::max(lin, 0.0)),
          non_c->name(), pct(non)));
    } else {
      d.findings.push_back(fmt::format(
          "The disagreement does not change with force level: a linear model error. The best "
          "linear correction ({}) explains {} of it{}; no non-linear term does better.",
          lin_c ? lin_c->name() : std::string("none"), pct(std::max(lin, 0.0)),
          non_c ? fmt::format(", the best non-linear term ({}) {}", non_c->name(), pct(non))
                : std::string()));
    }
    // Where.
    std::map<std::string, double> by_joint;
    for (const auto& c : ranking)
      if (c.converged && std::isfinite(c.gap) && (!c.refit))
        by_joint[c.joint] = std::max(by_joint[c.joint], c.explained);
    const Candidate* where = *d.level_dependent ? non_c : lin_c;
    if (where) {
      d.joint = where->joint;
      std::string others;
      for (const auto& [name, share] : by_joint)
        if (name != d.joint)
          others += fmt::format("{}{} at most {}", others.empty() ? "" : ", ",
                                name == "substructure" ? std::string("the substructure")
                                                       : "terms at '" + name + "'",
                                pct(std::max(share, 0.0)));
      d.findings.push_back(fmt::format(
          "It sits at {}: {} explain{} {}{}.",
          d.joint == "substructure" ? std::string("the substructure") : "joint '" + d.joint + "'",
          d.joint == "substructure" ? std::string("its damping") : "terms at '" + d.joint + "'",
          d.joint == "substructure" ? "s" : "", pct(by_joint[d.joint]),
          others.empty() ? "" : "; " + others));
    }
    if (*d.level_dependent) {
      d.nature = cons > diss ? "conservative" : "dissipative";
      if (d.nature == "conservative") {
        std::string how;
        if (cons_c && cons_c->term == joints::Term::k3)
          how = cons_c->value > 0.0 ? " (hardening: the resonance rises with level)"
                                    : " (softening: the resonance falls with level)";
        d.findings.push_back(fmt::format(
            "Conservative: a stiffness term ({}) explains {}, the best damping term {}{}.",
            cons_c->name(), pct(cons), diss_c ? "(" + diss_c->name() + ") " + pct(diss) : "none",
            how));
      } else {
        d.findings.push_back(fmt::format(
            "Dissipative: a damping term ({}) explains {}, the best stiffness term {}; the "
            "damping changes with level.",
            diss_c->name(), pct(diss),
            cons_c ? "(" + cons_c->name() + ") " + pct(cons) : std::string("none")));
      }
    }
    if (d.even_harmonics) {
      // An asymmetric joint force (k2) makes even harmonics in every test that moves it; a
      // symmetric system's response can also lose its symmetry in a few tests (a bifurcation).
      double k2_share = 0.0;
      for (const auto& c : ranking)
        if (c.term == joints::Term::k2 && std::isfinite(c.explained))
          k2_share = std::max(k2_share, c.explained);
      const std::string seen = fmt::format(
          "Even harmonics: the measured response at {} holds a second harmonic of {} of its "
          "fundamental in {}{} that the model does not produce{}",
          even_where, pct(even), even_test,
          even_tests.size() > 1 ? fmt::format(" (and {} other tests)", even_tests.size() - 1)
                                : std::string(),
          noise_known_ ? fmt::format(" (noise {})", pct(even_noise)) : std::string());
      d.asymmetric = k2_share >= 0.5 || even_tests.size() * 2 > tests_.size();
      if (d.asymmetric)
        d.findings.push_back(seen + fmt::format(": an asymmetric force (k2 explains {}).",
                                                pct(std::max(k2_share, 0.0))));
      else
        d.findings.push_back(
            seen + fmt::format(": confined to {} of {} tests, it is not what an asymmetric joint "
                               "force would give (k2 explains {}); a symmetric system's response "
                               "can lose its symmetry at some frequencies and levels.",
                               even_tests.size(), tests_.size(), pct(std::max(k2_share, 0.0))));
    } else if (any_harmonics)
      d.findings.push_back("No even harmonics beyond the noise: the missing force is symmetric.");
    else
      d.findings.push_back("The tables give the fundamental only: harmonics cannot be judged.");
    return d;
  }

  // Direct evidence of level dependence: tests at the same frequency (within 0.5 %) and force
  // levels apart by 1.5× or more, compared by their measured receptance X₁/F₁.
  std::vector<std::string> level_evidence() const {
    // The pair that says most: the largest change in standard deviations of the noise (or, the
    // noise unknown, the largest change).
    double best = -1.0;
    std::string text;
    for (std::size_t a = 0; a < tests_.size(); ++a)
      for (std::size_t b = a + 1; b < tests_.size(); ++b) {
        const auto &ta = tests_[a], &tb = tests_[b];
        if (std::abs(ta.frequency_hz - tb.frequency_hz) > 0.005 * ta.frequency_hz) continue;
        const double Fa = identify::force_level(ta), Fb = identify::force_level(tb);
        if (std::max(Fa, Fb) < 1.5 * std::min(Fa, Fb) || ta.force_at.empty() || tb.force_at.empty())
          continue;
        for (std::size_t j = 0; j < ta.response_at.size(); ++j) {
          const int jb = tb.response_index(ta.response_at[j]);
          if (jb < 0) continue;
          const Complex Ra = ta.X(1, static_cast<Eigen::Index>(j)) / ta.F(1, 0),
                        Rb = tb.X(1, jb) / tb.F(1, 0);
          const double change = std::abs(Ra - Rb) / std::max(std::abs(Rb), 1e-300);
          const double va = ta.X_variance(1, static_cast<Eigen::Index>(j)),
                       vb = tb.X_variance(1, jb);
          const double sd =
              va > 0.0 && vb > 0.0
                  ? std::sqrt(va / std::norm(ta.F(1, 0)) + vb / std::norm(tb.F(1, 0))) /
                        std::abs(Rb)
                  : 0.0;
          const double score = sd > 0.0 ? change / sd : change;
          if (score <= best) continue;
          best = score;
          const std::string verdict =
              sd <= 0.0 ? std::string()
              : change > 5 * sd
                  ? fmt::format(", far beyond what the noise allows (about {})", pct(sd))
                  : fmt::format(", which the noise explains (about {})", pct(sd));
          text =
              fmt::format("At {} Hz the measured receptance at {}@{} changes by {} between force "
                          "amplitudes {} and {}{}.",
                          number(ta.frequency_hz), identify::quantity_letter(ta.measured_as[j]),
                          fem::to_string(ta.response_at[j]), pct(change), number(std::min(Fa, Fb)),
                          number(std::max(Fa, Fb)), verdict);
        }
      }
    if (text.empty()) return {};
    return {text};
  }

  std::string summary(const Result& r) const {
    std::string added;
    for (const auto& s : r.steps)
      added += (added.empty() ? "" : ", ") + s.added.name();
    const double first = r.gap.front(), last = r.gap.back();
    std::string floor;
    if (!noise_known_)
      floor = "; the noise level is unknown (stepped-sine tables)";
    else
      floor = fmt::format(
          "; the noise level is {}{}, {}", number(noise_gap_),
          r.simulation_gap > 0.1 * noise_gap_
              ? fmt::format(" and the simulation's own error {}", number(r.simulation_gap))
              : std::string(),
          r.at_noise_level ? "which it has reached"
                           : fmt::format("not reached (χ² per value {:.3g})", r.chi2_per_value));
    if (added.empty())
      return fmt::format("Nothing was added: the gap stays at {}{}.", number(last), floor);
    return fmt::format("Added {}: the gap shrank from {} to {} ({}× smaller){}.", added,
                       number(first), number(last), number(first / std::max(last, 1e-300)), floor);
  }

  const frf::Substructure& sub_;
  const fem::DofMap& dofs_;
  const std::vector<identify::Measurement>& tests_;
  Options o_;
  int K_ = 1;
  std::vector<joints::Joint> layout_;
  std::vector<int> synthesis_dofs_;
  std::vector<std::vector<int>> force_eq_, response_eq_;
  double f_max_ = 0.0;
  std::vector<std::string> notes_;
  std::unique_ptr<frf::ModalSynthesis> base_;
  std::vector<std::unique_ptr<Simulator>> simulators_;
  std::vector<Entry> entries_;
  std::vector<Eigen::MatrixXcd> measured_start_; // per test: (K_hb+1) × joints
  std::vector<Eigen::MatrixXcd> drive_;          // per test: the force harmonics that drive it
  int values_ = 0;
  double measured2_ = 0.0;
  bool noise_known_ = true;
  double noise_gap_ = nan;
};

} // namespace

std::string Candidate::name() const {
  if (refit) return "refit of the starting values";
  if (!term) return "substructure damping";
  if (varies) return fmt::format("{} at '{}', a value per test", joints::term_name(*term), joint);
  return fmt::format("{} at '{}'", joints::term_name(*term), joint);
}

std::string Candidate::effect() const {
  if (refit) return "linear terms identified again";
  if (!term) return "substructure damping";
  if (varies)
    return fmt::format("{} that changes between tests (no term of the library)",
                       joints::term_effect(*term));
  return std::string(joints::term_effect(*term));
}

bool Candidate::linear() const {
  return !varies && (refit || !term || joints::is_linear(*term));
}

Result discover(const frf::Substructure& substructure, const std::vector<joints::Joint>& start,
                const std::vector<identify::Measurement>& tests, const Options& options) {
  Engine engine(substructure, start, tests, options);
  return engine.run();
}

} // namespace jointid::discover
