#pragma once
/// What discovery works on: the substructure, the tests and the values compared, set up once;
/// the re-simulation of every test with a model (harmonic balance, driven by the measured force,
/// started from the measured deformation), the identification of a model's terms from the tests,
/// and the estimate of what a perfect model would still miss (the simulation's own error and the
/// measured force's noise).
#include "discover/discover.hpp"
#include "discover/gap.hpp"
#include "discover/preconditions.hpp"

#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

namespace jointid::discover::detail {

/// The substructure's receptance (its damping scaled) and the harmonic-balance problems of
/// every test built on it (a sine test's at its frequency with the options' harmonics, a
/// periodic test's at 1/T up to Problem::balance_harmonics; each twice as many when refined).
struct Simulator {
  double scale = 1.0;
  int harmonics = 0; ///< the sine tests'

  frf::ModalSynthesis synthesis;
  std::vector<frf::HarmonicBalance> balance;
};

/// An even spread of at most `taken` of n items, ascending (the first and last among them).
std::vector<int> even_spread(std::size_t n, std::size_t taken);

class Problem {
public:
  /// Checks and sets up the comparison. Throws std::invalid_argument as discover() says.
  /// `substructure` and `tests` are referred to, not copied: they must outlive the problem.
  Problem(const frf::Substructure& substructure, const std::vector<joints::Joint>& start,
          const std::vector<identify::Measurement>& tests, const Options& options);

  /// The options of the run (the harmonic balance's harmonics possibly lowered to the band of
  /// measured FRFs).
  const Options& options() const { return o_; }
  const std::vector<identify::Measurement>& tests() const { return tests_; }
  const Compared& compared() const { return compared_; }
  /// The joints as given at the start: the layout every model shares.
  const std::vector<joints::Joint>& layout() const { return layout_; }
  const fem::DofMap& dofs() const { return dofs_; }
  /// The substructure's receptance with its own damping.
  const frf::ModalSynthesis& synthesis() const { return *base_; }
  /// Test i's force and response equations.
  const std::vector<int>& force_equations(std::size_t i) const { return force_eq_[i]; }
  const std::vector<int>& response_equations(std::size_t i) const { return response_eq_[i]; }
  /// Test i's harmonic balance: harmonics 0 … this (not refined): the options' for a sine test;
  /// for a periodic test its highest line compared, or max(K, 10) times its highest driven line
  /// where that is higher (K the largest harmonic compared: the joints' harmonics and
  /// combinations, which a strongly driven cubic joint spreads far beyond the third).
  int balance_harmonics(std::size_t i) const { return balance_harmonics_[i]; }
  /// Test i's simulated harmonics kept in a State: 0 … K (a periodic test: to its highest line).
  int rows(std::size_t i) const { return rows_[i]; }
  /// Test i's measured joint deformations: (harmonic-balance harmonics + 1) × joints.
  const Eigen::MatrixXcd& measured_deformation(std::size_t i) const { return measured_start_[i]; }
  /// What the set-up had to say (e.g. fewer harmonics in the band of measured FRFs).
  const std::vector<std::string>& notes() const { return notes_; }
  /// The rules these tests allow, and those they do not (said in sentences).
  const Preconditions& preconditions() const { return preconditions_; }
  std::vector<int> all_tests() const;
  /// At most `taken` of the tests, ascending, to stand for all of them in a first search (the
  /// misfit is absolute: a stepped-sine table's few tests at a sharp resonance carry most of
  /// it, and an even spread by index misses them): half of them those whose measured values
  /// are largest (their sum of squares), the rest an even spread of the others.
  std::vector<int> spread(std::size_t taken) const;
  /// The tests that spread(taken) leaves out, ascending (none when taken covers them all).
  std::vector<int> outside_spread(std::size_t taken) const;
  /// The sources of these tests ("table.csv:12"), for messages.
  std::vector<std::string> sources(const std::vector<int>& tests) const;

  /// The harmonic-balance problems of every test with the damping scaled, at the options'
  /// harmonics or (`refined`) twice as many, to estimate the truncation error.
  std::unique_ptr<Simulator> make_simulator(double scale, bool refined) const;
  /// The same, kept for reuse: never evicted (a run makes a few: the model's damping, and each
  /// damping scale that was added or cross-validated), so references stay valid. Not for
  /// concurrent use: the candidates of a step share one made before they run.
  const Simulator& simulator(double scale, bool refined = false);

  /// Identifies every non-fixed term from the tests `use`, with the damping scaled. Throws
  /// std::invalid_argument when the tests cannot separate the terms.
  /// A parametric term (jenkins, iwan, gap) is held at its parameters (its force known; output
  /// error refines them: refine.hpp). `harmonics`, if
  /// given, replaces the options' (the equivalent linear joint of the diagnosis: 1).
  identify::FitResult identify(const std::vector<joints::Joint>& joints, const Simulator& sim,
                               const std::vector<int>& use,
                               const std::vector<int>* harmonics = nullptr) const;
  /// Every test's spectrum for these joints' terms (their basis functions on the measured
  /// deformation, which do not depend on the values), and its warnings: computed once per set
  /// of terms and kept (identify() needs them for every candidate, trial and fold). Safe to call
  /// from several threads.
  struct Spectra {
    std::vector<identify::TestSpectrum> tests;
    std::vector<std::vector<std::string>> warnings; ///< per test
  };
  const Spectra& spectra(const std::vector<joints::Joint>& joints) const;
  /// Identified coefficients: the non-fixed terms (a parametric term's non-fixed parameters),
  /// and the damping scale if not 1.
  int parameters(const std::vector<joints::Joint>& joints, double scale) const;
  /// Simulates every test with these joints, and scores the state. A test whose re-simulation
  /// does not converge (solve(), then from the nearest tests already re-simulated: a stepped
  /// sweep's neighbours) is left out (State::failed); past max_left_out the rest are not
  /// tried (the state is not compared: its criterion is +∞).
  /// Tests in `skip` (ascending) are not simulated (X NaN, Y empty; not failed) and the state is
  /// scored on the others alone: its gap and criterion compare only with states that skipped
  /// the same tests (a refinement's first stage: refine.hpp).
  State evaluate(const std::vector<joints::Joint>& joints, const Simulator& sim,
                 const State* warm = nullptr, std::span<const int> skip = {}) const;
  /// The same with test i's joints `per_test[i]` where given (the state holds `joints` and
  /// counts, for the criterion, one parameter per test for the term that varies).
  State evaluate_each(const std::vector<joints::Joint>& joints,
                      const std::vector<std::vector<joints::Joint>>& per_test, const Simulator& sim,
                      const State* warm = nullptr, std::span<const int> skip = {}) const;
  /// Why the joined structure has no stable state at rest with these joints, or "": with
  /// every friction element slipping and every gap open (a joint's tangent stiffness then its
  /// linear k alone; k2 and k3 add none at zero deformation), the static stiffness between the
  /// joints' ends, (Bᵀ H(0) B)⁻¹ + diag(k), must be positive definite. A harmonic balance finds
  /// periodic solutions of an unstable model too, so the fits can reach one (a slipping joint
  /// that takes away more stiffness than the substructure has there); a time simulation of it
  /// grows without bound. Not judged (""): measured FRFs, or a substructure with a rigid-body
  /// mode or a singular static flexibility at the joints.
  std::string stability_problem(const std::vector<joints::Joint>& joints) const;
  /// The derivatives of every test's simulated harmonics at `at` (State::X: rows(i) + 1 ×
  /// responses) with respect to moves of its joints, `moved[p]` by steps[p], by implicit
  /// differentiation of each test's harmonic balance (frf::HarmonicBalance::output_derivatives):
  /// [test][p], no entries for a test `at` left out, an empty matrix where a derivative could
  /// not be formed (the caller re-simulates for it). No entries either for the tests in `skip`
  /// (ascending: those the caller does not compare).
  std::vector<std::vector<Eigen::MatrixXcd>>
  derivatives(const State& at, const std::vector<std::vector<joints::Joint>>& moved,
              const std::vector<double>& steps, const Simulator& sim,
              std::span<const int> skip = {}) const;
  /// Test i's steady state: from `warm` or the measured deformation first, else from the linear
  /// response with load continuation.
  frf::HarmonicBalanceResult solve(const Simulator& sim, int i,
                                   const std::vector<joints::Joint>& joints,
                                   const Eigen::MatrixXcd* warm = nullptr) const;
  /// Test i's steady state by continuation in the joints' non-linear forces: every term but k
  /// and c scaled by s = 1/8, 1/4, 1/2, 3/4, 1 (a coefficient's value; a jenkins' or an iwan's
  /// kt and fs, a gap's kg: each of these forces scales with s), each step from the last, the
  /// first from the linear response. For a test that no start reaches directly (a clearance that
  /// closes on part of a multisine's period beside a friction that slips); the last status.
  frf::HarmonicBalanceResult by_continuation(const Simulator& sim, int i,
                                             const std::vector<joints::Joint>& joints) const;
  /// The tests nearest to test i in frequency and force level (|ln f/fᵢ| + |ln F/Fᵢ|), nearest
  /// first, among `candidates`.
  std::vector<int> nearest(int i, const std::vector<int>& candidates, std::size_t count) const;
  /// The gap, χ² and criterion of a simulated state.
  void score(State& state) const;

  /// What a perfect model would still miss at this state, besides the response's own noise:
  /// the simulation's error and the measured force's noise propagated through the model, kept
  /// as every compared value's variances (and in the noise level). The state is scored again
  /// with them. Returns the simulation error as a gap.
  double estimate_simulation_error(State& state);

private:
  int equation(const identify::Measurement& m, const std::string& what, const fem::NodeDof& at);
  void set_up_equations(const std::vector<joints::Joint>& start);
  void fit_to_measured_band(double f_max);
  void set_up_drive_and_start(const std::vector<joints::Joint>& start);
  /// Every test's steady state by time integration with exact stick–slip (empty where that is
  /// not possible, and for the tests beyond the first max_time_integrated of an even spread).
  std::vector<Eigen::MatrixXcd> time_integrated(const State& state) const;
  /// The tests integrated in time for the simulation's error at most: each settles over
  /// hundreds of periods at 256 steps a period (about 0.1 s for a beam with a 100-slider
  /// iwan), so a table of hundreds of tests takes an even spread of them; the others take the
  /// harmonic balance with twice the harmonics (estimate_simulation_error).
  static constexpr std::size_t max_time_integrated = 24;
  /// Each test's force harmonics perturbed by their noise: E|δX_sim|² into Entry::force.
  void propagate_force_noise(const State& state, const Simulator& sim);

  const frf::Substructure& sub_;
  const fem::DofMap& dofs_;
  const std::vector<identify::Measurement>& tests_;
  Options o_;
  int K_ = 1;
  std::vector<joints::Joint> layout_;
  std::vector<int> synthesis_dofs_;
  std::vector<std::vector<int>> force_eq_, response_eq_;
  std::vector<int> balance_harmonics_, rows_; // per test
  double f_max_ = 0.0;
  std::vector<std::string> notes_;
  std::unique_ptr<frf::ModalSynthesis> base_;
  /// The static flexibility between the joints' ends, Bᵀ H(0) B, as V diag(g) Vᵀ: its square
  /// root V diag(√g) Vᵀ (empty: not judged; stability_problem).
  Eigen::MatrixXd flexibility_root_;
  Eigen::VectorXd stiffness_held_; ///< 1 / (Bᵀ H(0) B)_jj: what the substructure holds at joint j
  void set_up_static_flexibility();
  std::vector<std::unique_ptr<Simulator>> simulators_;
  Compared compared_;
  std::vector<Eigen::MatrixXcd> measured_start_;  // per test: (K_hb+1) × joints
  std::vector<Eigen::MatrixXcd> drive_;           // per test: the force harmonics that drive it
  std::vector<double> log_frequency_, log_level_; // per test, for nearest()
  Preconditions preconditions_;
  mutable std::mutex spectra_mutex_;
  mutable std::map<std::string, std::unique_ptr<const Spectra>> spectra_; // by the joints' terms
};

} // namespace jointid::discover::detail
