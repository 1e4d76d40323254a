#pragma once
/// Model discovery: find where simulation and measurement disagree, name the missing effect at
/// the right joint, add it, and show the gap shrink.
///
/// **The gap.** A model (the substructure and its joints with values) re-simulates every
/// measured test by harmonic balance, driven by the measured force harmonics, and is compared
/// with the measurement at every response channel and every compared harmonic k = 0 … K (only
/// harmonic 1 for stepped-sine rows, and harmonic 0 only where the mean displacement was
/// measured), all as displacements:
///
///     gap = sqrt( Σ |X_meas − X_sim|² / Σ |X_meas|² )       (sums over tests, channels, k)
///
/// A periodic broadband test (a multisine; identify/periodic.hpp) is compared at its lines
/// (Measurement::lines: the excited lines in the band and those where the joints put response
/// out of the noise), its noise per line from the scatter of its periods. It is re-simulated by
/// the harmonic balance at its line spacing 1/T, driven by the measured force at the lines that
/// drive it (its excited lines, and any other out of the force's noise), to its highest line or
/// max(K, 10) times its highest driven line where that is higher (K the largest harmonic
/// compared: the joints' harmonics and combinations); the simulation's error from twice that.
/// Its "harmonics" judged on their own (the stop rule's χ² per harmonic) are two groups: the
/// excited lines, and the others.
///
/// The noise level is what a perfect model would leave: the same formula with the variance of
/// each measured harmonic (identify::measure estimates it from the record itself) plus that of
/// the measured force's noise propagated through the model; it is unknown for stepped-sine
/// tables. The simulation's own error is measured at every step: against time integration with
/// exact stick–slip where the model has dry friction and the substructure is a finite element
/// model (the harmonic balance of a discontinuous force converges slowly), else against the
/// harmonic balance with twice the harmonics. χ² weighs each compared value by the sum of these
/// variances. "Explains p % of the gap" means the squared gap falls by p %.
///
/// **The loop.** Terms without values are identified first (with all tests: equation error,
/// then output error). Then, while the gap is above the noise level, every candidate — each term
/// of the library at each joint that lacks it, and a scale factor on the substructure's damping
/// (a linear model error) — is added in turn, every non-fixed term identified again by equation
/// error (identify::fit, METHOD.md), all tests re-simulated; the best `finalists` by the
/// criterion are identified again by output error (Levenberg–Marquardt on the weighted
/// re-simulation residual). A candidate may be added only if
///  1. every re-simulation converged and its value is physical (no negative damping; a stable
///     state at rest with the joints slipping and their gaps open: Problem::stability_problem),
///  2. its 95 % interval is known and excludes 0 (the damping scale: 1),
///  3. it lowers the Bayesian information criterion — with known noise χ² + p ln N, else
///     N ln(S/N) + p ln N (S the squared gap, N real compared values, p identified
///     parameters) — so an extra term must buy more than ln N in χ²,
///  4. it explains at least min_explained (5 %) of the squared gap or, with the noise known, of
///     χ² (tests at levels far apart weigh in the gap as their amplitudes squared, the largest
///     deciding; in χ² each as its own noise), and
///  5. it predicts held-out tests better: the cross-validated gap (leave one test out, or
///     `folds` folds above 30 tests) falls.
/// Besides these additions, every non-fixed term of the model is tried with a value per test
/// (identified from that test alone, the other terms held; with four tests or more), counted as
/// one parameter per test: a coefficient that changes with the amplitude or the frequency, which
/// no term of the library has (e.g. a friction whose normal load falls as the vibration grows).
/// It is admissible when the per-test values disagree beyond their intervals (and by rules 3 and
/// 4); it is never added, but when it is the best admissible candidate the loop stops and says
/// which coefficient changes, with what, and how much of the gap that explains (Variation) —
/// unless the library's best admissible term, and the best addition after it where that one
/// alone does not, end below the variation's criterion: two effects missing at once (a cubic
/// stiffness and a velocity-squared damping) can each explain less alone than a stiffness per
/// test, which absorbs part of both. Those terms are then added and the loop goes on.
/// The per-test values show the trend; where the held terms took over part of the effect in
/// the all-test fit (a viscous c absorbing friction), they are biased towards the mean.
/// The admissible candidate with the lowest criterion is added. The loop stops at the noise
/// level — χ²/N at most 3 standard deviations (3 √(2/N)) above 1, overall and for every compared
/// harmonic on its own — when no candidate is admissible, or after max_steps. Then, backward:
/// each coefficient term added is taken out in turn and the model without it identified again by
/// output error; one that would not be added to that model now (rules 3 and 4) is taken out, as
/// a step of its own (Step::removed), the one whose model has the lowest criterion first.
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "joints/joint.hpp"

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace jointid::discover {

struct Options {
  /// Harmonics used in the fits; the comparison uses 0 … max of them (tables: 1).
  std::vector<int> harmonics{1, 2, 3};
  /// The re-simulations' harmonic balance.
  frf::HarmonicBalanceOptions balance{.harmonics = 15};
  /// Terms tried at every joint (those a joint already has are skipped): every term of the
  /// library. A parametric one (jenkins, iwan, gap) is started by a describing-function fit to
  /// each test's equivalent stiffness of the joint and refined by output error at once (its
  /// parameters enter non-linearly: no equation-error screen); one per joint at a time.
  std::vector<joints::Term> terms{joints::all_terms.begin(), joints::all_terms.end()};
  /// Also try a scale factor on the substructure's modal damping (a linear model error).
  bool substructure_damping = true;
  int max_steps = 6;
  /// An addition must explain at least this share of the squared gap: below it, what it fits is
  /// as likely the simulation's or the measurement's own systematic error as a joint effect.
  double min_explained = 0.05;
  /// Cross-validation leaves one test out up to 30 tests, and uses this many folds above.
  int folds = 10;
  /// Candidates refined by output error at each step (the best by the equation-error screen),
  /// and besides them the best parametric one where its describing-function start ranks among
  /// the best finalists + 1, and the coefficient term whose equation-error fit leaves the
  /// smallest residual (its start's re-simulation can misjudge it when a second effect is
  /// missing too).
  int finalists = 3;
  /// Points of each state's response curves for the report (0: none).
  int curve_points = 30;
  /// A periodic test is re-simulated by a harmonic balance of its lines up to its highest line
  /// compared or max(K, 10) times its highest driven line (the simulation's error twice as
  /// many). Its Newton steps are solved by GMRES with FFT products (frf/hb_equations.hpp), so a
  /// solve costs about its Newton and GMRES iterations times O(lines log lines): 1024 lines
  /// 60 ms, 9216 lines 0.6 s with the benchmark's joint (docs/benchmarks.md), many times that
  /// with a strongly non-linear one; a discovery takes thousands. A test that needs more lines
  /// than this is refused, naming it, before any is solved (a ground-vibration test's 0.05 Hz
  /// lines to 15 Hz need about 3000).
  int max_balance_lines = 4096;
  /// Called before every re-simulation of a test (a harmonic balance, or a time integration
  /// for the simulation's own error), from the threads the candidates run on, possibly at the
  /// same time: an exception thrown from it stops the run and leaves discover() (e.g. an
  /// interrupt of a caller that checks for one). Empty: nothing is called.
  std::function<void()> checkpoint;
};

/// A term whose value, identified from each test alone (the other terms held), changes between
/// the tests beyond their intervals: a coefficient that depends on the amplitude or the
/// frequency, which no term of the library has. Such a candidate is never added to the model;
/// when it is the best admissible explanation of the gap, the loop stops and says so.
struct Variation {
  std::vector<std::string> tests;
  std::vector<double> value, std; ///< per test: the term from that test alone (SI)
  /// per test: |Y_1| of the joint's deformation (m or rad), and the test's frequency; a
  /// periodic test's lines as one sine of the same RMS (identify::joint_equivalent_sine)
  std::vector<double> amplitude;
  std::vector<double> frequency_hz;
  double chi2 = 0.0;                  ///< of the values about their weighted mean
  int dof = 0;                        ///< tests − 1
  double amplitude_correlation = 0.0; ///< Spearman's rank correlation of value and amplitude
  double frequency_correlation = 0.0; ///< and of value and frequency
  std::string description;            ///< what it says, in one sentence
};

/// One candidate addition to the model, and what it gave.
struct Candidate {
  std::string joint;                ///< joint name; "substructure" for the damping scale
  std::optional<joints::Term> term; ///< empty: the substructure's damping scale; or a refit
  bool refit = false;               ///< no addition: the starting values identified again
  /// Not an addition: the joint's `term` given a value per test (Variation). Its state
  /// simulates each test at its own value; `value` is their weighted mean.
  std::optional<Variation> varies;
  /// A second parametric term added together with `term` (jenkins with gap: a friction and a
  /// clearance, whose stiffness falls and then rises with the amplitude; started from one
  /// describing-function fit of both), and its parameters as identified.
  std::optional<joints::Term> with;
  std::vector<identify::ParameterEstimate> with_parameters;
  std::string name() const;   ///< "k3 at 'tip'", "jenkins and gap at 'mount'", "refit"
  std::string effect() const; ///< "cubic stiffness", "substructure damping", …
  bool linear() const;        ///< k, c, a refit or the damping scale
  double value = 0.0;         ///< identified coefficient (SI), or the damping scale; a
                              ///< parametric term: 1 (its parameters are the result)
  /// A parametric term (jenkins, iwan, gap): its parameters as identified, with their 95 %
  /// intervals; an undetermined one (the tests do not separate it) has no value (NaN).
  std::vector<identify::ParameterEstimate> parameters;
  double std = 0.0;
  double ci_low = 0.0, ci_high = 0.0;
  /// The 95 % interval is a result: finite, of non-zero width (false: "undetermined", never a
  /// number ± 0). A parametric term: some parameter is determined.
  bool determined() const;
  double gap = 0.0;       ///< after adding it
  double criterion = 0.0; ///< information criterion after adding it
  double explained = 0.0; ///< share of the squared gap it removes (negative: worse)
  /// A coefficient term: the relative residual of its equation-error fit (identify::FitResult::
  /// residual_relative, every test), before any re-simulation; NaN for the others.
  double equation_residual = std::numeric_limits<double>::quiet_NaN();
  /// With the noise known: its χ² (NaN otherwise), the model's before it on the same tests
  /// (< 0: the model's own), and the share of that χ² it removes (NaN: not known).
  double chi2 = std::numeric_limits<double>::quiet_NaN(), chi2_now = -1.0;
  double chi2_explained = std::numeric_limits<double>::quiet_NaN();
  bool converged = true; ///< every re-simulation converged
  /// Tests whose re-simulation with it did not converge, even from the measured response:
  /// left out of its comparison with the model before it, which is compared on the same tests
  /// (`gap` and `gap_now` are over those; its criterion is the model's plus the difference).
  std::vector<std::string> left_out;
  double gap_now = -1.0; ///< the model before it on the tests it is compared on (< 0: all)
  double cv_gap = -1.0;  ///< cross-validated gap (< 0: not computed)
  std::string rejected;  ///< why it may not be added; empty: admissible
};

/// A model and how well it reproduces the measurement.
struct State {
  std::vector<joints::Joint> joints;
  double damping_scale = 1.0; ///< on the substructure's damping
  int parameters = 0;         ///< identified coefficients (and the damping scale)
  double gap = 0.0;
  double chi2 = 0.0; ///< Σ |e|² / (E|δX|²/2) when the noise is known, else NaN
  double criterion = 0.0;
  bool converged = true; ///< every test's re-simulation converged
  /// Tests whose re-simulation did not converge (from the measured response, the nearest
  /// re-simulated test and the linear response), ascending: left out of the gap, χ² and
  /// criterion. More than a tenth of the tests: not compared at all (criterion +∞).
  std::vector<int> failed;
  /// Why each of `failed` did not converge: the harmonic balance's last status
  /// ("load steps stalled at step 13 of 20, residual 6.5e-05"; "" where it gave none).
  std::vector<std::string> failed_why;
  /// Why the model has no stable state at rest, or "" (Problem::stability_problem): rule 1.
  std::string unstable;
  std::vector<Eigen::MatrixXcd> X; ///< per test: simulated harmonics 0 … K at its responses
  std::vector<Eigen::MatrixXcd> Y; ///< per test: the joints' deformation harmonics (all solved)
  identify::FitResult fit;         ///< the identification that gave the values (if any)
};

struct Step {
  /// The term added; or, `removed`, the term taken out again (a backward step after the
  /// forward search: the terms added after it explain what it did), with its value before.
  Candidate added;
  bool removed = false;
  double gap_before = 0.0, gap_after = 0.0;
  double cv_before = -1.0, cv_after = -1.0;
  std::vector<Candidate> ranking; ///< every candidate tried, lowest criterion first
  std::string finding;            ///< one sentence
};

/// The fundamental of one test at one channel, measured and simulated; a periodic test has one
/// per excited line (its FRF over them: frequency_hz and force_phasor the line's; force the
/// test's level, identify::force_level), and as "harmonics" the lines where only the joints put
/// response, over the excited lines.
struct Comparison {
  std::string test, channel;
  double frequency_hz = 0.0, force = 0.0;
  std::complex<double> force_phasor;        ///< F_1 (or the line's) of its first force, N or N·m
  std::complex<double> measured, simulated; ///< X_1, m or rad
  double amplitude_error = 0.0;             ///< |X_sim| / |X_meas| − 1
  double phase_error_deg = 0.0;             ///< arg(X_sim / X_meas)
  double harmonics_measured = 0.0;          ///< sqrt(Σ_{k≥2} |X_k|²) / |X_1|, measured
  double harmonics_simulated = 0.0;
  bool converged = true; ///< false: its re-simulation did not converge (left out)
};

/// A model's response along a sweep through the tests: over frequency at one force level, or over
/// force level at one frequency (whichever the tests vary more), by harmonic balance with
/// continuation from point to point, driven by F0 sin ωt at the tests' force DOF. Swept up, and
/// down as well where that finds another branch (a jump: hardening or softening joints).
struct ResponseCurve {
  bool over_frequency = true;
  bool descending = false;           ///< swept down (kept only where it differs from the sweep up)
  double level = 0.0;                ///< force amplitude of the sweep over frequency (N or N·m)
  double frequency_hz = 0.0;         ///< frequency of the sweep over level
  std::vector<double> x;             ///< frequencies (Hz) or force levels
  std::vector<std::string> channels; ///< as the comparisons name them ("x@7:uy")
  std::vector<std::vector<std::complex<double>>> X1; ///< per channel, per point: X_1 (m or rad)
  std::vector<bool> converged;                       ///< per point
};

/// What the tests show of one joint's force against the amplitude of its deformation, each test
/// alone: the joint replaced by the linear spring and damper k_eq + iω c_eq that give its force's
/// fundamental there (equation error at harmonic 1, the other joints held at the starting
/// model's values). Its dissipation per cycle is D = π a² ω c_eq. On log axes, D grows with a
/// power of the amplitude: 2 for viscous damping, 1 for Coulomb sliding (macroslip: D = 4 f a),
/// 3 + χ (−1 < χ ≤ 0) for an Iwan joint in microslip; a clearance leaves D alone and stiffens the
/// joint from the amplitude where contact is made.
struct JointBehaviour {
  std::string joint;
  std::vector<std::string> tests;
  /// |Y₁| of the deformation, m (rad); a periodic test's lines as one sine of the same RMS, at
  /// the frequency of the same RMS rate (identify::joint_equivalent_sine)
  std::vector<double> amplitude;
  std::vector<double> frequency_hz; ///< of the test (a periodic test: that sine's)
  std::vector<double> dissipation;  ///< D per cycle, J
  std::vector<double> stiffness;    ///< k_eq, N/m (N m/rad)
  /// D fitted as π c ω a² + A a^s (c, A ≥ 0, s from a scan): the power s of the part that is not
  /// viscous and that part's largest share of D over the tests (NaN: not fitted, too few tests
  /// or amplitudes within 20 % of each other).
  double slope = std::numeric_limits<double>::quiet_NaN();
  double hysteretic_share = std::numeric_limits<double>::quiet_NaN();
  /// k_eq at the largest amplitude relative to the smallest, − 1.
  double stiffness_change = std::numeric_limits<double>::quiet_NaN();
  /// A clearance's amplitude: where k_eq starts to rise (NaN: no clearance seen).
  double contact_amplitude = std::numeric_limits<double>::quiet_NaN();
  /// "microslip", "macroslip", "microslip to macroslip", "clearance", or empty (none of these).
  std::string behaviour;
  std::string finding; ///< in one sentence
  /// Model lines: D per cycle (J) and k_eq of the starting and the final model's joint force at
  /// `model_amplitude`, at `model_frequency_hz` (the tests' median).
  std::vector<double> model_amplitude, start_dissipation, final_dissipation;
  std::vector<double> start_stiffness, final_stiffness;
  double model_frequency_hz = 0.0;
};

struct Diagnosis {
  /// Does the disagreement change with force level? Empty when nothing significant is found,
  /// or when the tests are all at one force level (they cannot tell).
  std::optional<bool> level_dependent;
  double linear_explains = 0.0;    ///< best linear candidate's share of the squared gap
  double nonlinear_explains = 0.0; ///< best non-linear candidate's share
  std::string joint;               ///< where it sits (joint name, or "substructure")
  std::string channel;             ///< the channel with the largest relative error
  double channel_error = 0.0;      ///< its relative error, ‖e‖/‖X_meas‖ over the tests
  std::string nature;              ///< "conservative", "dissipative", "hysteretic", or empty
  double conservative_explains = 0.0, dissipative_explains = 0.0;
  bool even_harmonics = false; ///< an unexplained 2nd harmonic, 5 × above the noise
  double even_content = 0.0;   ///< largest |X_meas − X_sim| at k = 2 over |X_1|
  /// The even harmonics point to an asymmetric joint force: k2 explains half the gap or more,
  /// or they appear in most tests (not in a few, as a symmetric system's lost symmetry would).
  bool asymmetric = false;
  /// Per joint whose DOFs the tests measure: its dissipation and stiffness against amplitude.
  std::vector<JointBehaviour> behaviour;
  std::vector<std::string> findings; ///< the diagnosis as sentences
};

struct Result {
  int tests = 0, compared_values = 0;
  double min_explained = 0.0;           ///< Options::min_explained of the run
  std::vector<std::string> start_notes; ///< what was identified to start
  std::vector<State> states;            ///< [0] the start, [i] after step i
  std::vector<Step> steps;
  /// The candidates of the last attempt, when it added nothing (empty otherwise).
  std::vector<Candidate> last_ranking;
  std::vector<double> gap; ///< per state
  double noise_gap = -1.0; ///< < 0: unknown (stepped-sine tables)
  /// The final model's simulation error as a gap: its harmonic balance against one with twice
  /// the harmonics (dry friction converges slowly with the harmonics; smooth joints fast).
  double simulation_gap = 0.0;
  bool at_noise_level = false;
  /// The final model's χ² per compared value (1 for a model that explains everything but the
  /// noise and its own simulation error); NaN when the noise is unknown.
  double chi2_per_value = 0.0;
  /// The same for each compared harmonic 0 … K (NaN where none is compared); empty when the
  /// noise is unknown.
  std::vector<double> chi2_by_harmonic;
  Diagnosis diagnosis;
  std::string stop_reason;
  std::vector<std::string> warnings;
  /// The rules these tests do not allow to be applied, and what that means for the result (also
  /// among the warnings): cross-validation and a value per test need four tests or more; the
  /// level dependence, tests at more than one force level; the noise level, records; even
  /// terms and harmonics, more than the fundamental; the damping scale, a substructure with
  /// modes.
  std::vector<std::string> limits;
  /// Per state: the fundamental at every test and channel.
  std::vector<std::vector<Comparison>> comparisons;
  /// Per state: the model's response curves through the tests (Options::curve_points > 0).
  std::vector<std::vector<ResponseCurve>> curves;
};

/// Runs the loop on measurements reduced by identify::measure (with harmonics ≥ those asked).
/// `start` holds the joints of the starting model (values not given are identified first).
/// Throws std::invalid_argument for inputs that cannot be compared (no tests, a channel at a
/// DOF the model lacks, joints whose DOFs are not measured).
Result discover(const frf::Substructure& substructure, const std::vector<joints::Joint>& start,
                const std::vector<identify::Measurement>& tests, const Options& options = {});

} // namespace jointid::discover
