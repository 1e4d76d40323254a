#pragma once
/// Experiment design: which sine tests to run so that the joints' terms are best determined.
///
/// Each candidate test (a frequency and a force level at one DOF) is predicted with the joints
/// at prior values (harmonic balance to the periodic steady state), "measured" with the noise
/// expected — white, of RMS `noise` × each channel's RMS on every channel, force included, over
/// `periods` periods averaged — and turned into the information it gives about the unknown terms:
/// Iᵢ = Qᵢᵀ Cᵢ⁻¹ Qᵢ, the test's equations weighted by their noise covariance exactly as fit()
/// weights them (identify::information). The inverse of the sum over a set of tests is the
/// covariance fit() predicts for those tests, so its diagonal gives the standard deviations to
/// expect. The design is D-optimal: it maximises det(Σ Iᵢ) over sets of N distinct candidates
/// (greedy choice, then exchanges of one chosen test for one not chosen while the determinant
/// grows). D-optimality does not depend on the parameters' units.
#include "fem/dof.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"
#include "identify/record.hpp"
#include "identify/sine_tests.hpp"
#include "joints/joint.hpp"

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace jointid::identify {

struct DesignOptions {
  std::vector<int> harmonics{1}; ///< the harmonics whose equations the fit will use
  double noise = 0.01;           ///< noise RMS / channel RMS, every channel (force too)
  int periods = 8;               ///< periods in each record, averaged before the fit
  /// Samples of a period; 0: max(256, 8 (K + 1)) for the prediction's harmonics 0 … K, eight
  /// samples to the highest harmonic's period and never fewer than 256.
  int samples_per_period = 0;
  /// Response channels recorded at the joints' DOFs and the force DOF.
  std::vector<Quantity> quantities{Quantity::displacement, Quantity::velocity};
  frf::HarmonicBalanceOptions balance{}; ///< the prediction (harmonics 0 … K)
  /// Leave out candidates whose equations, at the prior values, miss by more than this many
  /// noise standard deviations (CandidateTest::misfit): there the basis functions do not
  /// describe the joints' forces (dry friction that sticks: sign(ẏ) says nothing of the stuck
  /// force), so such a test biases the estimates beyond what its noise says. Infinite: keep all.
  double max_misfit = 0.2;
  /// Called with the fraction of the predictions done (0 … 1], from one thread at a time (each
  /// candidate is solved twice: swept up, then from the linear response); empty: not called.
  std::function<void(double)> progress;
};

/// A periodic broadband candidate: a Schroeder multisine over [f0_hz, f1_hz] at an RMS force,
/// of period period_s, sampled at sample_rate_hz (identify/random_tests.hpp's multisine).
struct PeriodicPlan {
  double f0_hz = 0.0, f1_hz = 0.0, rms = 0.0; ///< Hz, Hz, N or N·m
  double period_s = 0.0, sample_rate_hz = 0.0;
};

/// The sample rate a periodic candidate is predicted at when none is given: the smallest power
/// of two (Hz) at or above 32 f1 and 8 (K + 1) f1, K the largest harmonic fitted (the joints'
/// harmonics up to K times the highest line stay well below the Nyquist frequency).
double default_periodic_sample_rate(double f1_hz, int harmonics);

/// One candidate test as predicted at the prior values.
struct CandidateTest {
  /// A sine test's frequency and amplitude; a periodic candidate's: 1/period_s (its lines'
  /// spacing) and its RMS force.
  SineTestPlan plan;
  std::optional<PeriodicPlan> periodic; ///< set for a periodic broadband candidate
  bool usable = false;                  ///< predicted (the harmonic balance converged)
  std::string reason;                   ///< why not usable
  /// Peak deformation (fundamental) of every joint, m or rad.
  std::vector<double> joint_amplitude;
  /// The information it gives about the unknowns (unknowns × unknowns, their units).
  Eigen::MatrixXd information;
  /// Its contribution to the bias (identify::TestInformation::score) and its misfit at the
  /// prior values in noise standard deviations.
  Eigen::VectorXd score;
  double misfit = 0.0;
};

/// The unknown terms (the joints' non-fixed terms, in order) and their prior values.
struct DesignUnknown {
  std::string joint;
  joints::Term term = joints::Term::k;
  double prior = 0.0;
};

/// Predicts every candidate (in parallel). Throws std::invalid_argument for bad options
/// (naming them), no unknowns, or a force DOF the model lacks. A candidate that cannot be
/// predicted (its harmonic balance, or the modal analysis, failed) is not usable, and its
/// reason is that status' reason.
std::vector<CandidateTest> predict_candidates(const frf::Substructure& substructure,
                                              const std::vector<joints::Joint>& joints,
                                              const fem::NodeDof& force_at,
                                              const std::vector<SineTestPlan>& candidates,
                                              const DesignOptions& options = {});

/// Predicts periodic broadband candidates (in parallel): each multisine is integrated in time at
/// the prior values (identify::simulate_forced: the modal route, from rest, faded in over its
/// first period) for `transient_periods` + `periods` periods, the transient's periods cut off,
/// white noise of RMS `noise` × each channel's RMS added to every channel (force too, seeded by
/// the candidate's index: the design is repeatable), and the record measured as identify
/// measures a periodic test (identify::measure: its lines, their noise from the scatter of the
/// periods, the periods averaged). Its information is that of its equations at every line
/// `identify` would use (the excited ones, and those up to max(harmonics) times the highest
/// excited line where the response stands out of its noise), weighted by that noise: what
/// identify's equation error weights such a record with. joint_amplitude is each joint's
/// equivalent sine (joint_equivalent_sine: the amplitude of the same RMS). Throws
/// std::invalid_argument for bad options or plans (naming them), no unknowns, or a substructure
/// that cannot be integrated in time (measured FRFs). A candidate whose simulation fails or whose
/// periods do not settle is not usable, with the reason.
std::vector<CandidateTest> predict_periodic_candidates(const frf::Substructure& substructure,
                                                       const std::vector<joints::Joint>& joints,
                                                       const fem::NodeDof& force_at,
                                                       const std::vector<PeriodicPlan>& candidates,
                                                       const DesignOptions& options = {},
                                                       int transient_periods = 3);

/// The unknowns of these joints, in the order of CandidateTest::information.
std::vector<DesignUnknown> design_unknowns(const std::vector<joints::Joint>& joints);

/// The standard deviations fit() predicts for the unknowns from these tests (indices into
/// `candidates`): the square roots of the diagonal of (Σ Iᵢ)⁻¹; infinite where the tests
/// leave an unknown undetermined.
Eigen::VectorXd predicted_std(const std::vector<CandidateTest>& candidates,
                              const std::vector<int>& tests);

/// The bias of fit()'s estimates from these tests where the basis functions do not describe the
/// joints' forces exactly: (Σ Iᵢ)⁻¹ Σ scoreᵢ (0 where they do; NaN where undetermined).
Eigen::VectorXd predicted_bias(const std::vector<CandidateTest>& candidates,
                               const std::vector<int>& tests);

/// log det(Σ Iᵢ) of the tests with the unknowns scaled by `scale` (−∞ when singular).
double log_det_information(const std::vector<CandidateTest>& candidates,
                           const std::vector<int>& tests, const Eigen::VectorXd& scale);

struct Design {
  std::vector<int> chosen; ///< indices into the candidates, by frequency then force
  double log_det = 0.0;    ///< of Σ Iᵢ over the chosen, unknowns scaled by their priors
  Eigen::VectorXd std;     ///< predicted standard deviations of the unknowns
  Eigen::VectorXd bias;    ///< predicted bias of the unknowns (predicted_bias)
  int exchanges = 0;       ///< exchanges that improved on the greedy choice
  std::vector<std::string> warnings;
};

/// What a joint's parametric term (jenkins, iwan, gap) with parameters not fixed needs of the
/// tests: its parameters are determined apart only by tests whose deformation reaches a regime
/// (the term's force below it depends on fewer combinations of them), and the design says, by
/// the model's values, which candidate force levels reach it.
struct ParametricLevel {
  std::string joint;
  joints::Term term = joints::Term::jenkins;
  std::string regime;     ///< "slip" (jenkins), "macroslip" (iwan), "contact" (gap)
  double threshold = 0.0; ///< the deformation that reaches it: fs/kt, φ_max, δ (m or rad)
  /// Per candidate frequency (ascending): the smallest candidate force whose predicted
  /// deformation (its fundamental's amplitude) reaches the threshold; NaN where none does.
  std::vector<double> frequency_hz, lowest_force;
  /// Where none does: the force scaled linearly from the largest usable candidate's deformation
  /// to the threshold (a rough guess, beyond the candidates); NaN where one does.
  std::vector<double> guess_force;
  std::string sentence; ///< all of it in words: what the tests there determine
};

/// One ParametricLevel per joint term with parameters not all fixed, from the candidates (as
/// predict_candidates() made them with those terms held at the joints' values). Throws
/// std::invalid_argument for a parameter without a value (the prediction needs every one).
std::vector<ParametricLevel> parametric_levels(const std::vector<joints::Joint>& joints,
                                               const std::vector<CandidateTest>& candidates);

/// The D-optimal set of `n` distinct usable candidates (list a candidate twice to allow it to
/// be repeated). Throws std::invalid_argument when n is not positive or exceeds the usable
/// candidates; warns, naming the term, when the best set leaves an unknown undetermined
/// (singular information) or its predicted standard deviation above `poorly_determined` of its
/// prior value.
Design choose_tests(const std::vector<CandidateTest>& candidates,
                    const std::vector<DesignUnknown>& unknowns, int n,
                    double poorly_determined = 0.05);

} // namespace jointid::identify
