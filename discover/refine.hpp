#pragma once
/// Output-error refinement (maximum likelihood under the noise model): every non-fixed term is
/// adjusted by Levenberg–Marquardt to minimise the weighted squared difference between the
/// re-simulated and the measured harmonics, starting from the equation-error estimate (which the
/// noise in the measured deformation makes less efficient). The 95 % intervals then come from
/// the output-error Jacobian J (each test's harmonic balance differentiated implicitly, or a
/// finite difference of re-simulations where that cannot be formed): σ̂² (JᵀJ)⁻¹, with σ̂² the
/// weighted residual
/// variance (at least 1 when the noise is known: a misfit beyond the noise widens the
/// intervals, never narrows them).
#include "discover/problem.hpp"

#include <optional>
#include <vector>

namespace jointid::discover::detail {

/// What a refinement compares and how far it goes.
struct RefineScope {
  std::vector<int> held_out; ///< tests left out of the search too (ascending): a fold's
  int iterations = 12;       ///< Levenberg–Marquardt iterations at most (both stages together)
  bool intervals = true;     ///< the fit's intervals (one more Jacobian)
  /// With more tests than this, the search first runs on this many of them (Problem::spread;
  /// the others not simulated), then goes on from there with all of them: a stepped-sine
  /// table's hundreds of tests determine a few parameters far beyond what the first stage needs
  /// to get near the minimum, and the second then takes one or two iterations instead of all.
  /// The second stage takes the iterations the first left, and at least two: a first stage that
  /// used them all is in a slow valley (an iwan's parameters), where iterations on every test
  /// cost n / spread times as much and buy little.
  /// 0: one stage. The result is that of all the tests either way.
  int spread = 96;
  /// With more tests than `spread`: the first stage alone. Every test is then simulated at the
  /// values it reached (kept where they fit all the tests better than the start did), and the
  /// intervals are those of all the tests there. For a path that is only screened
  /// (discover.cpp): near the full refinement at a fraction of its cost.
  bool spread_only = false;
};

/// The state refined from `start` (its fit replaced by the output-error one, when
/// scope.intervals); `start` itself when nothing is identified, or its values are not physical
/// and cannot be brought back. The tests the start could not re-simulate and those held out stay
/// out of the search, and every trial must re-simulate all the others.
State refine(const Problem& problem, const State& start, const Simulator& sim,
             const RefineScope& scope = {});

/// The second start of a candidate `c` that adds a coefficient term: the candidate's joints with
/// the values and parameters of the model `now` and the added term at 0. Refined from there,
/// output error can only improve on the model now; from the candidate's equation-error values
/// alone it may stop in a worse minimum (a bolted beam's stepped-sine table: beside an iwan
/// refined first, k3 from its equation-error start left a gap of 0.053 where the model without
/// it left 0.041). Empty where there is no such start: a parametric term, a refit, a value per
/// test, another damping scale, or a candidate that differs from the model now in more than the
/// added term.
std::optional<std::vector<joints::Joint>> nested_start(const Candidate& c, const State& candidate,
                                                       const State& now);

/// The parameters' covariance s² (JᵀJ)⁻¹ from the Jacobian J of the residual (columns scaled to
/// unit norm first: their units differ by orders of magnitude). NaN throughout — undetermined,
/// never 0 — when J is not finite, a column is zero, or its singular values are more than 1e6
/// apart (the parameters act alike beyond what a Jacobian by finite differences resolves).
Eigen::MatrixXd covariance(const Eigen::MatrixXd& J, double s2);

/// The covariance of what the tests determine when `nulls` directions of the parameters are not
/// seen at all (an iwan in microslip): the pseudo-inverse with the `nulls` smallest singular
/// values of the column-scaled J left out. Right for every combination the tests determine
/// (orthogonal to those directions); the parameters along them are undetermined.
Eigen::MatrixXd covariance_without(const Eigen::MatrixXd& J, double s2, int nulls);

/// The same where the tests leave some parameters of a parametric term undetermined (an iwan in
/// microslip: fs apart from beta): while the covariance is undetermined, the `droppable`
/// parameter that leans most on the direction the Jacobian does not resolve is marked in
/// `undetermined` and held; the others' covariance is then that with it held (NaN in its row and
/// column). NaN throughout when no droppable parameter is left.
Eigen::MatrixXd covariance_of_determined(const Eigen::MatrixXd& J, double s2,
                                         const std::vector<bool>& droppable,
                                         std::vector<bool>& undetermined);

} // namespace jointid::discover::detail
