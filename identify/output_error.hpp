#pragma once
/// Output-error identification: maximum likelihood under the records' measured noise.
///
/// The equation-error fit (fit()) evaluates the joints' basis functions on the measured, noisy
/// deformation; it is fast and needs no simulation, but it is not efficient: its scatter is 2–7
/// times the Cramér–Rao bound on the studies of docs/identification_uncertainty.md. Here the
/// model itself is fitted to the data: every non-fixed joint term, and each test's force
/// fundamental (measured with its own noise: errors in variables), are adjusted by
/// Levenberg–Marquardt until the harmonic balance of the substructure with its joints, driven by
/// that force, reproduces the measured displacement harmonics at every response DOF — and the
/// velocity harmonics where a velocity channel was measured beside the displacement (its own
/// noise makes it data too) — each residual weighted by its noise variance
/// (Measurement::X_variance, the velocity channel's noise; the force fundamental by F_variance).
/// The force's other harmonics drive the model as measured (those within 5 standard deviations of 0
/// as 0: noise alone).
///
/// At the optimum the covariance (Jᵀ J)⁻¹ of the weighted residual's Jacobian J is the inverse
/// Fisher information of this data model: the Cramér–Rao bound, which the estimator attains when
/// the model holds (tests/identify/output_error_test.cpp checks the scatter against it by Monte
/// Carlo). It is widened by χ²/dof when that exceeds 1 (a misfit beyond the noise). Dissipative
/// terms stay >= 0.
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"

#include <vector>

namespace jointid::identify {

struct OutputErrorOptions {
  /// The response harmonics compared (0: the mean, where it was measured).
  std::vector<int> harmonics{1, 2, 3};
  /// The model's harmonic balance (its harmonics at least the largest compared).
  frf::HarmonicBalanceOptions balance{.harmonics = 15};
  int max_iterations = 30;
  /// Warn when a parameter's standard deviation exceeds this fraction of its value.
  double poorly_determined = 0.05;
};

/// Refines `start` (an equation-error fit of `joints` from the same tests) by output error on
/// the synthesis `H`, which must cover the joints', forces' and responses' equations. A start
/// whose status is not ok is returned as it is. Throws std::invalid_argument naming the test: a
/// test whose noise is unknown (a stepped-sine table, a record of one period), no response
/// harmonic to compare. A harmonic balance that does not converge at the start is the status
/// not_converging, naming the test, with no estimates. FitResult::interval_method is "output
/// error"; equations is the number of real residuals (data), unknowns the terms plus two per force
/// channel and test.
FitResult output_error(const frf::ModalSynthesis& H, const fem::DofMap& dofs,
                       const std::vector<joints::Joint>& joints,
                       const std::vector<Measurement>& tests, const FitResult& start,
                       const OutputErrorOptions& options = {});

/// The whole pipeline: a parametric term's non-fixed parameters (jenkins, iwan, gap; one such
/// term a joint) started by describing_function_start(), whose failure is the result's status
/// (naming the joint and the term); fit() (equation error, its options) with those forces
/// known; then output_error() on the substructure's synthesis over the joints', forces' and
/// responses' DOFs. A parameter the tests do not determine (an iwan kept in microslip) has no
/// value, `determined` false, and FitResult::identifiability says which combinations the tests
/// determine, with their intervals.
FitResult output_error(const frf::Substructure& substructure,
                       const std::vector<joints::Joint>& joints,
                       const std::vector<Measurement>& tests, const FitOptions& fit_options,
                       const OutputErrorOptions& options = {});

} // namespace jointid::identify
