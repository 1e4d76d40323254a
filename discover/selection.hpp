#pragma once
/// Which candidate is added (discover.hpp states the rules): the information criterion, the five
/// admissibility rules — each a function that gives the reason a candidate fails it, empty when
/// it passes —, the choice among the admissible, cross-validation, and the test that a
/// coefficient identified per test varies between the tests.
#include "discover/discover.hpp"
#include "discover/gap.hpp"

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace jointid::discover::detail {

class Problem;

// The information criterion.

/// The Bayesian information criterion of a model with `parameters` identified coefficients:
/// χ² + p ln N with known noise, else N ln(S/N) + p ln N (S the squared misfit, N the real
/// values compared); +∞ for a model whose re-simulations did not all converge.
double information_criterion(const Compared& compared, const Misfit& misfit, int parameters,
                             bool converged);
/// The criterion of a state judged on the measurement's own noise alone (the responses'
/// variances; without the simulation's error and the force's noise, which depend on the model
/// and would favour the model whose simulation is less exact); on the misfit alone where the
/// noise is unknown. +∞ for a state that left out more tests than max_left_out.
double criterion_on_measurement_noise(const Compared& compared, const State& state);
/// A simulated state's gap, χ² (NaN when the noise is unknown) and information criterion, over
/// the tests it re-simulated; +∞ (gap and criterion) when it left out more than max_left_out.
void score(State& state, const Compared& compared);
/// A candidate whose state (or the model now) left tests out is compared with the model now on
/// the tests both re-simulated: its gap and `gap_now` over those, its criterion now's plus the
/// difference there (so that every candidate is on now's scale). Names the tests it left out
/// (`sources`: every test's), and, when it left out too many to be compared, rejects it saying
/// how many and which. Nothing for a refused candidate (a state without simulations).
void compare_on_common_tests(Candidate& candidate, const State& state, const State& now,
                             const Compared& compared, const std::vector<std::string>& sources);

// Rule 1: every re-simulation converged and the values are physical.

/// Negative damping or friction: "not physical: c of 'tip' came out negative (…), …".
std::string physical_problem(const std::vector<joints::Joint>& joints);
/// A negative friction limit, which has no steady state to simulate.
std::string friction_problem(const std::vector<joints::Joint>& joints);
/// Negative damping and friction among the identified terms brought back to 0.
void clamp_dissipative(std::vector<joints::Joint>& joints);
/// The candidate's gap, criterion and convergence from its state; a state that could not be
/// compared (too many tests left out) rejects it ("a re-simulation did not converge").
void fill(Candidate& candidate, const State& state);
/// The value and interval of `joint`'s `term` in a fit.
void take_fit(Candidate& candidate, const identify::FitResult& fit, const std::string& joint,
              joints::Term term);
/// Rules 1 and 2 for a candidate and the state it gives (its value taken from the state's fit).
void judge(Candidate& candidate, const State& state);

// Rule 2: the 95 % interval is known, of non-zero width, and excludes 0 (a term) or 1 (the
// damping scale).
std::string interval_problem(const Candidate& candidate);

// Rule 3: the information criterion falls.
std::string criterion_problem(const Candidate& candidate, double criterion_now);

// Rule 4: the candidate explains at least `min_explained` of the squared gap or, with the
// noise known, of χ² (Candidate::chi2_explained).
/// The share of the squared gap that a state with `gap` removes from one with `gap_now`.
double explained(double gap, double gap_now);
std::string explained_problem(const Candidate& candidate, double min_explained);

// Rule 5: the cross-validated gap falls.

/// How rule 5's reason starts when the rule could not be applied.
inline constexpr std::string_view not_checked = "cannot be checked against held-out tests";
/// Rejected only because rule 5 could not be applied: admissible by the other rules.
bool only_unchecked(const Candidate& candidate);

/// A cross-validated gap, or why it could not be computed (gap < 0).
struct CrossValidation {
  double gap = -1.0;
  std::string why;
};
/// The candidate's cross-validated gap must be below the model's. Where either could not be
/// computed the rule cannot be applied, and the candidate is not added: "cannot be checked
/// against held-out tests: …" (fewer than four tests, or a fold that cannot be identified).
std::string cross_validation_problem(const CrossValidation& candidate, const CrossValidation& now);

/// Sets every candidate's share explained and applies rules 3 and 4 to those not yet rejected.
/// Returns the candidates' indices by criterion, lowest first (a stable order).
std::vector<std::size_t> screen(std::vector<Candidate>& ranking, const State& now,
                                double min_explained);

struct Choice {
  std::optional<std::size_t> chosen;  ///< the addition
  std::optional<std::size_t> outside; ///< the best admissible is a coefficient varying per test
  std::optional<double> cv_now;       ///< the current model's cross-validated gap, if computed
};
/// Walks `order` (from screen) to the first candidate not rejected: a coefficient that varies
/// per test is `outside`; an addition must also pass rule 5, else it is rejected with the reason
/// and the walk goes on. The cross-validated gaps are computed as needed, for each candidate
/// walked to: the current model's on the tests that candidate is compared on (`cv_now(i)`; the
/// caller keeps what it computed), then the candidate's (stored in its cv_gap) if that one
/// could be computed.
Choice choose(std::vector<Candidate>& ranking, const std::vector<std::size_t>& order,
              const std::function<CrossValidation(std::size_t)>& cv_now,
              const std::function<CrossValidation(std::size_t)>& cv_of);

/// The candidates refined by output error: the best `count` by the criterion among those with a
/// finite criterion, converged, not varying per test and not parametric; and besides them the
/// best parametric one (jenkins, iwan, gap) when it ranks among the best `count` + 1 of all
/// those (its start, a describing-function fit, screens it; output error gives its parameters
/// and their intervals); every pair of parametric terms (Candidate::with), which is only
/// tried where the joint's stiffness falls and then rises over the tests; and the coefficient
/// term whose equation-error fit leaves the smallest residual (Candidate::equation_residual),
/// which its re-simulated start can misjudge when a second effect is missing too.
std::vector<std::size_t> finalists(const std::vector<Candidate>& ranking, int count);

// Cross-validation.

/// The held-out tests of each fold: every test alone up to 30 tests, else `folds` folds (test i
/// in fold i mod folds). Empty below 4 tests (too few to leave any out).
std::vector<std::vector<int>> held_out(int tests, int folds);
/// The gap of the folds' predictions: each fold's tests predicted by the model identified from
/// the others (negative damping or friction brought back to 0; a failed prediction counts as
/// predicting nothing), the tests `left_out` (ascending: those the models compared cannot
/// re-simulate) in neither sum. Not computed, saying why, for fewer than 4 tests or a fold that
/// cannot be identified. With `fit_per_fold` false the joints' values are used as they are in
/// every fold: a model whose values were given, never fitted to any test, predicts held-out
/// tests with those values (refitting them per fold would cross-validate a refit instead).
CrossValidation cross_validated(Problem& problem, const std::vector<joints::Joint>& joints,
                                double scale, const std::vector<int>& left_out = {},
                                bool fit_per_fold = true);

// A coefficient identified per test.

/// From the per-test values and standard deviations of `variation`: the candidate's value (their
/// weighted mean), its standard deviation and 95 % interval, the values' χ² about the mean and
/// its degrees of freedom, their rank correlations with the amplitude and the frequency, and the
/// description.
void summarise(Variation& variation, Candidate& candidate, const joints::Joint& joint);
/// Its values must disagree: χ² about their weighted mean more than 3 standard deviations
/// (√(2 dof)) above its degrees of freedom, else "its values agree between the tests (…)".
std::string agreement_problem(const Variation& variation);
/// A per-test candidate's verdict: `variation` summarised into the candidate (summarise), its
/// gap and criterion from the state that simulates each test at its own value (rule 1), and its
/// values must disagree (agreement_problem); the candidate then holds the variation.
void judge_variation(Candidate& candidate, Variation variation, const State& state,
                     const joints::Joint& joint);
/// Spearman's rank correlation (ties get their mean rank); 0 when either side is constant.
double rank_correlation(const std::vector<double>& a, const std::vector<double>& b);
/// The test (an index into x) where a per-test value turns as x grows: an interior extremum of
/// the values in the order of x whose rise to it from some test before and fall to some test
/// after (or fall and rise) are both at least 3 standard deviations of their difference; the
/// largest such turn, or -1.
int turning_test(const std::vector<double>& x, const std::vector<double>& value,
                 const std::vector<double>& std);
/// Whether the values are a monotonic function of x within the noise: false when, in the order
/// of x, they both rise and fall by more than 3 standard deviations of a difference between
/// some two tests, or when two tests at the same x differ by that much.
bool monotonic_within_noise(const std::vector<double>& x, const std::vector<double>& value,
                            const std::vector<double>& std);
/// What a variation says, in one sentence: "fc at 'spring' is not one number: …". A value that
/// turns with the deformation amplitude (turning_test) where the frequency does not order it
/// monotonically is described by its turn: "k at 'mount' … falls from … to …, then rises to …".
std::string describe(const Variation& variation, const Candidate& candidate,
                     const joints::Joint& joint);

} // namespace jointid::discover::detail
