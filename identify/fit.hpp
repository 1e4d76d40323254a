#pragma once
/// Joint identification in the frequency domain (METHOD.md). For every test and harmonic k,
///     H22(kω) · (−Σ_i B_i Σ_j b_ij G_ij(kω)) = X2(kω) − H2f(kω) F(kω) =: R(kω),
/// where set 2 holds the joints' DOFs, B_i maps joint i's force onto them (+1 at its node,
/// −1 at node_b: the structure receives −g at the node), G_ij are the harmonics of the basis
/// functions evaluated on the measured deformation, and b_ij are the unknown real
/// coefficients. Real and imaginary parts of all equations are stacked into Q b = p, the
/// columns of Q scaled to unit norm, and solved by SVD.
#include "fem/dof_map.hpp"
#include "frf/receptance.hpp"
#include "frf/substructure.hpp"
#include "identify/measurement.hpp"
#include "identify/record.hpp"
#include "joints/joint.hpp"

#include <functional>
#include <span>
#include <string>
#include <vector>

namespace jointid::identify {

/// Receptance of the substructure: H(ω) restricted to rows × cols (equation numbers), m/N.
using ReceptanceFn =
    std::function<frf::CMatrix(double omega, std::span<const int> rows, std::span<const int> cols)>;

struct FitOptions {
  /// Harmonics whose equations are used: {1} is the paper's method; {1, 2, 3} adds the
  /// higher harmonics of the periodic response (true by the same linearity). 0 adds the
  /// static (mean) balance.
  std::vector<int> harmonics{1};
  /// Warn when the two halves of a record differ by more than this (relative fundamental).
  double steady_tolerance = 1e-3;
  /// Warn when a parameter's standard deviation exceeds this fraction of its value.
  double poorly_determined = 0.05;
  /// Where every test's noise is known (records of two or more whole periods), propagate it:
  /// weight the equations by the covariance the noise gives them — through the measured
  /// response and force, and through the basis functions evaluated on the noisy deformation
  /// (errors in variables) — and take the intervals from it (generalised least squares). Else,
  /// or when false, the intervals come from the residual of ordinary least squares.
  bool propagate_noise = true;
  /// measure(): average each record's periods before the basis functions (MeasureOptions).
  bool average_periods = true;
};

/// A named parameter of a parametric term as identified (or held).
struct ParameterEstimate {
  std::string name; ///< "fs"
  /// NaN when the tests do not determine it (determined false): never a value then.
  double value = 0.0;
  double std = 0.0; ///< of the value; NaN when unknown
  double ci_low = 0.0, ci_high = 0.0;
  bool fixed = false;
  /// False when the tests do not determine it apart from another parameter (FitResult::
  /// identifiability says which combination they do determine) or its std is too large.
  bool determined = true;
};

struct TermEstimate {
  joints::Term term = joints::Term::k;
  /// A parametric term (jenkins, iwan, gap): its named parameters, in the table's order (empty
  /// for a coefficient term; `value` is then its coefficient, 1).
  std::vector<ParameterEstimate> parameters;
  double value = 0.0;
  double std = 0.0;    ///< standard deviation (FitResult::interval_method says how)
  double ci_low = 0.0; ///< 95 % confidence interval (Student's t)
  double ci_high = 0.0;
  bool fixed = false; ///< held at the model's value, not identified
  /// False when the tests do not determine it (std above FitOptions::poorly_determined of its
  /// value): FitResult::identifiability says why.
  bool determined = true;
};

struct JointEstimate {
  std::string name;
  std::vector<TermEstimate> terms;
};

struct FitResult {
  /// The outcome (bad input throws; a numerical outcome is a status): ok; not_separable, the
  /// equations do not separate the unknowns (condition number of the column-scaled Q at least
  /// 1e13): every non-fixed value, std and interval is NaN and the reason names the term; or
  /// the status of the substructure's modal analysis or of a harmonic balance (output error)
  /// that failed, with no estimates.
  fem::Status status;
  std::vector<JointEstimate> joints;
  int equations = 0;
  int unknowns = 0;
  double condition_number = 0.0;  ///< of the column-scaled Q
  double residual_rms = 0.0;      ///< rms of Q b − p, m
  double residual_relative = 0.0; ///< |Q b − p| / |p|
  /// "propagated noise": generalised least squares with the equations' noise covariance,
  /// intervals from it, widened by the residual where that is larger (χ² per degree of freedom
  /// above 1); "residual": ordinary least squares, intervals from the residual alone.
  std::string interval_method;
  double chi2_per_dof =
      0.0; ///< the weighted residual's χ² / (equations − unknowns); NaN: residual method
  std::vector<double> singular_values;      ///< of the column-scaled (weighted) Q, largest first
  std::vector<std::string> identifiability; ///< what the tests do not determine, in words
  std::vector<std::string> warnings;
  /// The joints with their identified values (fixed terms unchanged). Throws
  /// std::invalid_argument with the status' reason when it is not ok (there are no values).
  std::vector<joints::Joint> identified(const std::vector<joints::Joint>& model_joints) const;
};

/// One test reduced, for these joints, to harmonics 0 … K at its excitation frequency (a
/// periodic test: to its lines, the harmonics of 1/T).
struct TestSpectrum {
  std::string source;
  double frequency_hz = 0.0;
  bool fundamental_only = false;    ///< a stepped-sine row: only harmonic 1 is usable
  std::vector<int> force_equations; ///< equations of the force channels
  Eigen::MatrixXcd F;               ///< (K+1) × n_forces
  Eigen::MatrixXcd X2;              ///< (K+1) × n_set2 displacements at the joints' DOFs
  std::vector<Eigen::MatrixXcd> G;  ///< per joint: (K+1) × n_terms basis-function harmonics

  /// What propagating the measurement noise into the fit needs (`noise_known` false for tables
  /// and records whose noise could not be estimated).
  bool noise_known = false;
  Eigen::VectorXd t;         ///< the analysed samples (whole periods; one when averaged), s
  Eigen::MatrixXd y, ydot;   ///< joint deformations and rates there (samples × joints)
  int derived_harmonics = 0; ///< harmonics of the signals derived from others
  /// Per set-2 DOF: the channel its displacement comes from — its power p (x = (iω)^−p times
  /// it: 0 x, 1 v, 2 a) and the noise variance of one analysed sample — and the variance of a
  /// separately measured velocity channel (NaN: the velocity is derived from that channel).
  std::vector<int> x_power;
  std::vector<double> x_variance, v_variance;
  std::vector<double> f_variance; ///< per force channel, of one analysed sample

  /// A periodic test (Measurement::lines): the lines whose equations are used, in place of
  /// FitOptions::harmonics (empty for sine tests).
  std::vector<int> lines;
  /// A periodic test with two or more periods averaged: each period's X2, F and G at `lines`
  /// (rows in the order of `lines`). The covariance of a line's equations is the scatter of
  /// the periods' equations about their mean, divided by the periods (errors in variables
  /// included: the basis functions are evaluated on each period's deformation); the lines are
  /// taken as independent.
  struct Period {
    Eigen::MatrixXcd F, X2;
    std::vector<Eigen::MatrixXcd> G;
  };
  std::vector<Period> periods;
};

/// The joints' DOFs (set 2), in the order used by TestSpectrum::X2.
using joints::joint_dof_set;

/// The equation-error route (and the design built on it) identifies the coefficients of the
/// terms k … fc. A parametric term (jenkins, iwan, gap) enters its force non-linearly: it is
/// used only with all of its parameters fixed (a known force); output error
/// (identify/output_error.hpp) identifies its parameters. Throws std::invalid_argument naming
/// the joint, the term and its parameters otherwise.
void check_identifiable(const std::vector<joints::Joint>& joints);
/// The parameters of term t of joint j for a TermEstimate (empty for a coefficient term).
std::vector<ParameterEstimate> parameters_of(const joints::Joint& joint, std::size_t term);

/// A measured test as the identification of these joints needs it: the forces on free DOFs of
/// the model, the displacement at every joint DOF, and the harmonics of every joint term's
/// basis function evaluated on the measured deformation y = x(node) − x(node_b) — for a
/// parametric term its force with its (fixed) parameters, a hysteretic one's steady loop over
/// the analysed span taken as one period (check_identifiable()). Throws
/// std::invalid_argument naming the test and the missing or misplaced channel. Adds a warning
/// when a dry-friction joint sticks in the record.
TestSpectrum spectrum(const Measurement& measurement, const fem::DofMap& dofs,
                      const std::vector<joints::Joint>& joints, std::vector<std::string>& warnings);

/// Identifies the non-fixed terms of every joint from the tests. Throws std::invalid_argument
/// for bad input: no joints or tests, a term whose basis function is zero in every test, fewer
/// equations than unknowns. Unknowns the tests cannot separate give the status not_separable
/// with its reason (no values). Tests from
/// stepped-sine tables contribute harmonic 1 only (with a warning if others were asked).
FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<TestSpectrum>& tests,
              const FitOptions& options = {}, std::vector<std::string> warnings = {});
/// The same from measurements: their warnings are passed on.
FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints,
              const std::vector<Measurement>& measurements, const FitOptions& options = {});
/// The same from sine tests (time records or stepped-sine rows, e.g. from io::read_tests),
/// reduced with measure() to the largest harmonic asked.
FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<SineTest>& tests,
              const FitOptions& options = {});
FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<Record>& records,
              const FitOptions& options = {});

/// The whole pipeline for a substructure: its receptance over the joints' DOFs and the tests'
/// force DOFs, for the tests' frequencies and the harmonics asked (frf::Substructure::synthesis),
/// then fit(). What the synthesis leaves out (modes without residual flexibility) is added to
/// the result's warnings; a synthesis whose modal analysis failed is the result's status.
FitResult fit(const frf::Substructure& substructure, const std::vector<joints::Joint>& joints,
              const std::vector<Measurement>& measurements, const FitOptions& options = {});

/// What one test tells about the joints' non-fixed terms (in the order of the joints and their
/// terms, in the terms' units), with Qᵢ the test's equations at the harmonics given, Cᵢ their
/// covariance from the test's measurement noise (errors in variables included) at the joints'
/// values, and rᵢ = pᵢ − Qᵢ b their residual at those values.
struct TestInformation {
  /// Qᵢᵀ Cᵢ⁻¹ Qᵢ: what fit() weights the test with; the inverse of the sum over a set of tests
  /// is the covariance fit() predicts for them.
  Eigen::MatrixXd information;
  /// Qᵢᵀ Cᵢ⁻¹ rᵢ: a set of tests' estimates are biased by (Σ Iᵢ)⁻¹ Σ scoreᵢ where the basis
  /// functions do not describe the joints' forces in the test (0 where they do).
  Eigen::VectorXd score;
  /// √(rᵢᵀ Cᵢ⁻¹ rᵢ / rows): the test's misfit at the joints' values in units of its noise.
  double misfit = 0.0;
  int rows = 0;
};

/// Throws std::invalid_argument when the test's noise is not known.
TestInformation information(const ReceptanceFn& H, const fem::DofMap& dofs,
                            const std::vector<joints::Joint>& joints, const TestSpectrum& test,
                            const std::vector<int>& harmonics);

/// The options measure() needs for a fit with these options.
MeasureOptions measure_options(const FitOptions& options);

} // namespace jointid::identify
