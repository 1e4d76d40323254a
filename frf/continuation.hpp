#pragma once
/// Frequency-response curves of the substructure with its joints: the harmonic-balance steady
/// states traced over a frequency band by pseudo-arclength continuation, with folds located
/// and each point's stability from its Floquet multipliers.
///
/// Continuation. The unknowns are the packed harmonics z of the joint deformations (and the
/// exact friction forces) and the angular frequency ω; each step predicts along the tangent of
/// the branch and corrects with Newton on [R(z, ω); tᵀ(u − u_pred)] = 0, in scaled coordinates
/// u = (z / a, ω / Δω) with a the largest joint amplitude met so far and Δω the band, so that a
/// step of length s moves at most s of the band or s of the amplitude. ∂R/∂ω is a central
/// difference (relative step 1e-5). The step grows after easy corrections and shrinks after hard
/// or failed ones; a step whose tangent turns by more than 25° is retried shorter, down to 1e-3
/// of the largest step, below which the turn is taken as a corner of the branch (exact friction
/// has them where a time sample's stick state changes). A fold
/// (turning point in frequency) is where the tangent's ω component changes sign; it is located
/// by the secant method on the arclength and inserted as a point of its own. The branch ends
/// with a point solved exactly at the last frequency of the band.
///
/// Stability. The Floquet multipliers μ of the linearised equations of motion about the steady
/// state, in modal coordinates q of the modes below 2 (K + 1) ω (at least the lowest 3, at most
/// 60), the others (and the synthesis' residual flexibility) taken quasi-statically, a
/// flexibility R in series with the joints:
///     δq̈ + D δq̇ + Ω² δq + Pᵀ (S_y(t) P δq + S_v(t) P δq̇) = 0,   P = Bᵀ Φ_J,
///     [S_y, S_v] = (I + G_y R)⁻¹ [G_y, G_ẏ],   G = diag(∂g/∂y), diag(∂g/∂ẏ) on the orbit
/// (the left-out modes' share of the joint's rate is neglected in the damping term), integrated
/// over one period by the classical Runge–Kutta method (h ω_est ≤ 0.5) — over half of it when
/// the orbit is half-wave symmetric and the joint forces odd: their derivatives then repeat
/// every half period, and the monodromy is the half period's squared. Stable when every
/// |μ| < 1 + 1e-6. On the tests' cantilever |μ|max at a fold is 1 to 6e-5 (1 − 2e-2 without R).
/// With exact dry friction the force is set-valued and has no derivative while a joint sticks:
/// stability is then not determined (reported as such, never guessed). A gap's force is
/// continuous and piecewise linear: its slope (kg in contact, 0 open) is G_y. Hysteretic joints
/// (jenkins, iwan) are linearised exactly, memory included: an element stuck since its last
/// slide at t_a has the force perturbation k (δy(t) − δy(t_a)) (0 while it slides), so each
/// anchor t_a of the loop adds a state s_a = δy(t_a) to the variational equations (reset at
/// t_a, constant between) — the stuck elements' tangent stiffness alone would forget where the
/// stick phase began and miss the loop's damping (on a Jenkins oscillator it gives |μ| of the
/// undamped joint, 0.92, where the time integrator's perturbations decay by 0.42 a period). The
/// loop is taken on the check's time steps, from rest over two periods (as the harmonic balance
/// does on its samples).
///
/// Where the multipliers are computed. A point's stability changes only where a multiplier
/// leaves the unit circle: at a fold (+1, located by the continuation), at a symmetry-breaking
/// bifurcation (+1 with an asymmetric perturbation), at a period doubling (−1) or a torus
/// bifurcation (a complex pair). The multipliers are computed at the first and last points, at
/// every `stability_stride`-th point, at each fold and its two neighbours, and, when the
/// equations are half-wave symmetric, on both sides of each sign change of the determinant of
/// the even harmonics' block of the all-harmonics Jacobian (block-diagonal at a symmetric
/// orbit; singular where an asymmetric perturbation has multiplier +1): every
/// symmetry-breaking bifurcation is bracketed. Where two computed points disagree, every point
/// between them is computed. A point between two computed points that agree takes their
/// verdict (`stability_checked` false, `max_multiplier` NaN): only a period doubling or torus
/// bifurcation and its return within fewer than `stability_stride` points could go unseen;
/// `stability_stride = 1` computes every point.
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace jointid::frf {

struct ContinuationOptions {
  HarmonicBalanceOptions hb;  ///< harmonics, AFT samples, friction, Newton tolerance
  double initial_step = 0.01; ///< scaled arclength (fractions of band and amplitude)
  double max_step = 0.02;
  double min_step = 1e-7;
  int max_points = 4000;
  bool stability = true; ///< each point's stability from Floquet multipliers
  /// Floquet multipliers computed at least at every stability_stride-th point (see above; 1:
  /// at every point)
  int stability_stride = 8;
};

struct ResponsePoint {
  HarmonicBalanceResult hb;   ///< the steady state: frequency_hz, Y, G, X (outputs)
  std::optional<bool> stable; ///< empty: not determined (see notes)
  double max_multiplier = std::numeric_limits<double>::quiet_NaN(); ///< max |μ|
  /// its multipliers were computed; else its stability is that of the computed points on both
  /// sides, which agree (see above)
  bool stability_checked = false;
};

struct ResponseBranch {
  std::vector<ResponsePoint> points; ///< in the order of the branch (ω may turn back)
  std::vector<int> folds;            ///< indices into points of the turning points in ω
  bool complete = false;             ///< reached the end of the band
  std::vector<std::string> notes;    ///< why it stopped early, what was not determined
};

/// Traces the steady states under the force harmonics F (as HarmonicBalance::solve(), one
/// column per force equation; the fundamental's frequency is the one that varies) from
/// `start_hz` to `end_hz` (either order). Throws std::invalid_argument for bad arguments
/// (frequencies not > 0 or equal, bad options); a branch that cannot be continued is returned
/// with complete = false and a note saying where and why. `progress(fraction)` is called after
/// each point: the fraction of the band covered, then, with stability, after each point whose
/// multipliers are computed (tracing takes the first half of the fraction, the Floquet checks
/// the second: each is about half of a curve's time).
ResponseBranch trace_response(const ModalSynthesis& synthesis,
                              const std::vector<joints::Joint>& joints, const fem::DofMap& dofs,
                              std::vector<int> force_equations, const Eigen::MatrixXcd& F,
                              std::vector<int> outputs, double start_hz, double end_hz,
                              const ContinuationOptions& options = {},
                              const std::function<void(double)>& progress = {});

/// Response curves of a model: one branch per force amplitude of F0 sin ωt at one DOF.
struct ResponseCurves {
  /// ok, or the synthesis' status (its modal analysis failed; then no curves)
  fem::Status status;
  int harmonics = 0;
  std::vector<fem::NodeDof> dofs; ///< the outputs: every joint DOF, then the force DOF (once each)
  std::vector<double> amplitudes; ///< N (or N m)
  std::vector<ResponseBranch> curves; ///< one per amplitude, in the same order
  std::vector<std::string> notes;     ///< about the substructure's synthesis
};

/// The model's response curves over start_hz … end_hz for each amplitude, by trace_response()
/// on the synthesis of `substructure` over the band the harmonics need
/// (synthesis_band_hz(max frequency, K)). Throws std::invalid_argument for a force DOF not in
/// the model, amplitudes not > 0, or the arguments trace_response() refuses. A modal analysis
/// that fails is the result's status. `progress(curve, fraction)` follows each curve.
ResponseCurves response_curves(const Substructure& substructure,
                               const std::vector<joints::Joint>& joints, const fem::NodeDof& force,
                               const std::vector<double>& amplitudes, double start_hz,
                               double end_hz, const ContinuationOptions& options = {},
                               const std::function<void(std::size_t, double)>& progress = {});

struct Stability {
  std::optional<bool> stable;   ///< empty: not determined (`note` says why)
  Eigen::VectorXcd multipliers; ///< Floquet multipliers
  int modes = 0;                ///< modes in the check
  std::string note;
};

/// The Floquet multipliers of a harmonic-balance steady state `r` of these joints (see above).
/// `options` are those r was solved with (friction handling).
Stability floquet_stability(const ModalSynthesis& synthesis,
                            const std::vector<joints::Joint>& joints, const fem::DofMap& dofs,
                            const HarmonicBalanceResult& r, const HarmonicBalanceOptions& options);

} // namespace jointid::frf
