#pragma once
/// Harmonic balance: the periodic steady state of the substructure with its joints under a
/// sine force, in the joint coordinates only. With y = Bᵀx the joints' deformations,
///     Y_k = H_yf(kω) F_k − H_yy(kω) G_k(Y),   k = 0 … K,
/// where G_k are the harmonics of the joint forces g(y(t), ẏ(t)) computed by alternating
/// frequency and time (AFT). Newton's method with a finite-difference Jacobian, amplitude
/// continuation when it fails. Dry friction is regularised here: sign(ẏ) ≈ tanh(ẏ/width).
#include "frf/receptance.hpp"
#include "joints/joint.hpp"

namespace jointid::frf {

struct HarmonicBalanceOptions {
  int harmonics = 9;            ///< K, harmonics 0 … K
  int time_samples = 0;         ///< AFT samples per period; 0: 32 (K + 1)
  double friction_width = 1e-4; ///< m/s (or rad/s): tanh regularisation of Coulomb friction
  double tolerance = 1e-12;     ///< on the residual, relative to |Y|
  int max_iterations = 60;
  int continuation_steps = 20; ///< amplitude steps tried when the direct solve fails
};

struct HarmonicBalanceResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;
  Eigen::MatrixXcd Y; ///< (K+1) × n_joints: harmonics of the joint deformations
  Eigen::MatrixXcd X; ///< (K+1) × n_outputs: harmonics of the output displacements
  double frequency_hz = 0.0;
  /// Displacement and velocity of output j at times t (reconstructed from the harmonics).
  double displacement(int j, double t) const;
  double velocity(int j, double t) const;
};

/// `synthesis` must cover the joint DOFs, the force DOF and the outputs.
HarmonicBalanceResult
harmonic_balance(const ModalSynthesis& synthesis, const std::vector<joints::Joint>& joints,
                 const fem::DofMap& dofs, int force_equation, double amplitude, double frequency_hz,
                 std::span<const int> outputs, const HarmonicBalanceOptions& options = {});

} // namespace jointid::frf
