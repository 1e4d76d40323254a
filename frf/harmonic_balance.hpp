#pragma once
/// Harmonic balance: the periodic steady state of the substructure with its joints under a
/// periodic force, in the joint coordinates only. With y = Bᵀx the joints' deformations,
///     Y_k = H_yf(kω) F_k − H_yy(kω) G_k(Y),   k = 0 … K,
/// where G_k are the harmonics of the joint forces g(y(t), ẏ(t)) computed by alternating
/// frequency and time (AFT). Newton's method with the analytic Jacobian of the AFT forces
/// (from ∂g/∂y and ∂g/∂ẏ at the time samples), load continuation when it fails.
///
/// Dry friction is exact (set-valued, no regularisation): a friction joint's force harmonics Λ
/// are unknowns too, and at the time samples t_n the Coulomb law holds in the form
///     λ(t_n) = proj_[−fc, fc]( λ(t_n) + r ẏ(t_n) )      (r > 0),
/// which says |λ| ≤ fc with ẏ = 0 (stick) or λ = fc sign(ẏ) (slip) — the same law the time
/// integrator enforces at each step; its residual Λ − AFT[proj(…)] is solved with the rest by
/// semi-smooth Newton. With `exact_friction = false` friction is regularised instead:
/// sign(ẏ) ≈ tanh(ẏ/width). Complex amplitudes are peak values with
/// x(t) = Re Σ_k X_k e^{ikωt}; units SI.
///
/// The parametric terms (joints/basis.hpp): a gap is a piecewise-linear force of y, sampled as
/// the others. A hysteretic term (jenkins, iwan: elements in parallel, joints/hysteresis.hpp)
/// gives the steady loop at the samples: its elements start at rest at zero deformation and run
/// over the period (over both halves, the second −y of the first, when half-wave symmetric)
/// until their state at the period's end repeats; the Jacobian is the loop's exact derivative
/// (an element stuck at sample n since its last slide at sample m gives k at (n, n) and −k at
/// (n, m)), so Newton converges as for a smooth force. An element that never slides keeps its
/// rest position: where time integration from rest left it elsewhere (a slide during the
/// transient only), the two steady states differ by a mean, not in their harmonics k ≥ 1.
#include "fem/assert.hpp"
#include "fem/status.hpp"
#include "frf/receptance.hpp"
#include "joints/joint.hpp"

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace jointid::frf {

namespace detail {
struct Equations; // frf/hb_equations.hpp, internal
struct Tables;    // frf/harmonic_balance.cpp: AFT sample tables, shared by (K, samples)

/// A matrix per harmonic k = 0 … K, side by side in one allocation: [k] is harmonic k's.
struct HarmonicBlocks {
  CMatrix data; // rows × cols (K + 1)
  Eigen::Index cols = 0;
  void resize(Eigen::Index rows, Eigen::Index columns, int K) {
    data.resize(rows, columns * (K + 1)), cols = columns;
  }
  auto operator[](int k) {
    JOINTID_ASSERT(k >= 0 && (k + 1) * cols <= data.cols(), "harmonic k is one of 0 … K");
    return data.middleCols(k * cols, cols);
  }
  auto operator[](int k) const {
    JOINTID_ASSERT(k >= 0 && (k + 1) * cols <= data.cols(), "harmonic k is one of 0 … K");
    return data.middleCols(k * cols, cols);
  }
};
} // namespace detail

struct HarmonicBalanceOptions {
  int harmonics = 9;            ///< K, harmonics 0 … K
  int time_samples = 0;         ///< AFT samples per period; 0: 16 (K + 1)
  bool exact_friction = true;   ///< set-valued Coulomb friction; false: regularised
  double friction_width = 1e-4; ///< m/s (or rad/s): tanh regularisation, when not exact
  double tolerance = 1e-12;     ///< on the residual, relative to |Y|
  int max_iterations = 60;
  int continuation_steps = 20; ///< amplitude steps tried when the direct solve fails
  /// Solve for the odd harmonics only, sampling half the period, where the steady state is
  /// half-wave symmetric, x(t + T/2) = −x(t): when every joint force is odd, g(−y, −ẏ) =
  /// −g(y, ẏ) (every term but k2, or k2 = 0), and the force has no mean and no even harmonics.
  /// The even harmonics are then exactly 0 in the results. From the default start Newton's
  /// iterates never leave that subspace anyway (they agree to rounding, with Nt even); this
  /// halves the unknowns and the samples. A start with even harmonics (beyond 1e-12 of its
  /// largest) is solved with all harmonics: such a system can have asymmetric steady states
  /// besides the symmetric one (a symmetry-breaking bifurcation; the paper's cantilever with a
  /// hardening joint at 3 Hz, 100 N has one, stable where the symmetric one is not), and the
  /// start says which is wanted. Off: all harmonics always.
  bool half_wave_symmetry = true;
};

struct HarmonicBalanceResult {
  /// ok, or not_converging with the residual reached and how the solve went, e.g. "no
  /// convergence: relative residual 3.2e-04 after 60 Newton iterations from the linear
  /// response; then load steps stalled at step 7 of 20 (…)". A result not (yet) solved is
  /// not_converging.
  fem::Status status{fem::Status::Code::not_converging, "not solved"};
  int iterations = 0;
  double residual = 0.0;
  Eigen::MatrixXcd Y; ///< (K+1) × n_joints: harmonics of the joint deformations
  Eigen::MatrixXcd G; ///< (K+1) × n_joints: harmonics of the joint forces g (friction included)
  Eigen::MatrixXcd X; ///< (K+1) × n_outputs: harmonics of the output displacements
  double frequency_hz = 0.0;
  /// Displacement and velocity of output j at times t (reconstructed from the harmonics).
  double displacement(int j, double t) const;
  double velocity(int j, double t) const;
};

/// The harmonics of F0 sin ωt: F_1 = −i F0 (a 2 × 1 matrix, rows 0 and 1).
Eigen::MatrixXcd sine_force(double amplitude);

/// The harmonic-balance problem at one excitation frequency: the substructure's receptances at
/// the harmonics are computed once, so that solve() can be called for many joint values and
/// force levels (discovery re-simulates the same tests with many candidate models).
class HarmonicBalance {
public:
  /// `synthesis` must cover the joints' DOFs, the force equations and the outputs. `joints`
  /// fixes the layout (nodes and DOFs); their terms and values are given to solve().
  HarmonicBalance(const ModalSynthesis& synthesis, const std::vector<joints::Joint>& joints,
                  const fem::DofMap& dofs, std::vector<int> force_equations,
                  std::vector<int> outputs, double frequency_hz,
                  const HarmonicBalanceOptions& options = {});
  /// F: harmonics 0, 1, … of the forces (rows beyond K are ignored, missing ones are 0), one
  /// column per force equation. `start` (K+1 × n_joints), if given, is the first Newton guess;
  /// otherwise the steady state with the fundamental alone (K = 1, from the linear response
  /// with the joints' linear terms k, c, scaled and shifted in time to the least residual) is,
  /// or that linear response if the fundamental-only problem does not converge. Throws
  /// std::invalid_argument for a negative friction limit fc (a joint that gives energy).
  HarmonicBalanceResult solve(const std::vector<joints::Joint>& joints, const Eigen::MatrixXcd& F,
                              const Eigen::MatrixXcd* start = nullptr) const;
  const HarmonicBalanceOptions& options() const { return options_; }
  double frequency_hz() const { return frequency_hz_; }

  /// The derivatives of a steady state's outputs with respect to the joints' values and
  /// parameters, by implicit differentiation. The steady state z is the one solve() reaches from
  /// `start` (a converged steady state of `joints`: Newton confirms it in an iteration or two).
  /// For each `moved[p]` (the joints with one value or parameter moved by steps[p]) the entry is
  /// (X(moved) − X)/steps[p] to first order: the step dz = −J⁻¹ (R_moved(z) − R(z)), with J the
  /// equations' (generalised) Jacobian at z, and the outputs of z + dz under the moved joints.
  /// One factorisation for every move, where a finite difference solves the steady state again
  /// per move. Returns no entries where the steady state is not reached from `start` or J is
  /// singular (a friction joint stuck throughout the period), and an empty entry where a move
  /// changes the equations' unknowns (an even term moved from 0 breaks half-wave symmetry) or
  /// leaves the joints' range: re-simulate those.
  std::vector<Eigen::MatrixXcd>
  output_derivatives(const std::vector<joints::Joint>& joints, const Eigen::MatrixXcd& F,
                     const Eigen::MatrixXcd& start,
                     const std::vector<std::vector<joints::Joint>>& moved,
                     std::span<const double> steps) const;

  /// Low level, for the frequency continuation: the equations R(z) = 0 for these joints and
  /// force (they refer to `joints` and to this object, which must outlive them), the packed
  /// first guess, and the result for a solution z.
  /// `start`, if given, is the start first_guess() will be given: with even harmonics (beyond
  /// rounding) the equations hold all harmonics even where the joints and force are odd.
  std::unique_ptr<detail::Equations> equations(const std::vector<joints::Joint>& joints,
                                               const Eigen::MatrixXcd& F,
                                               const Eigen::MatrixXcd* start = nullptr) const;
  Eigen::VectorXd first_guess(const detail::Equations& equations,
                              const Eigen::MatrixXcd* start) const;
  HarmonicBalanceResult result(const detail::Equations& equations, const Eigen::VectorXd& z) const;

private:
  struct Layout {
    int node, node_b;
    fem::Dof dof;
  };
  std::vector<Layout> layout_;
  HarmonicBalanceOptions options_;
  int K_, nj_, nf_, Nt_;
  double omega_, frequency_hz_;
  detail::HarmonicBlocks Hyy_, HyF_, HoB_, HoF_; // per harmonic
  // AFT sample tables independent of ω (cached): all harmonics, and the half-wave symmetric
  // problem's (odd harmonics, half the period) when options.half_wave_symmetry.
  std::array<const detail::Tables*, 2> tables_{};
  // The same for the first guess's problem with the fundamental alone (K = 1), when K > 1.
  static constexpr int coarse_samples = 16;
  std::array<const detail::Tables*, 2> coarse_tables_{};
};

/// One steady state under F0 sin(2π f t) at `force_equation`.
HarmonicBalanceResult
harmonic_balance(const ModalSynthesis& synthesis, const std::vector<joints::Joint>& joints,
                 const fem::DofMap& dofs, int force_equation, double amplitude, double frequency_hz,
                 std::span<const int> outputs, const HarmonicBalanceOptions& options = {});

} // namespace jointid::frf
