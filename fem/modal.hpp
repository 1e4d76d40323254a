#pragma once
/// Undamped modal analysis K φ = ω² M φ with mass-normalised modes (φᵀ M φ = 1).
/// Two engines behind one interface: a dense generalised symmetric eigensolver for small
/// models and Spectra's shift-invert Lanczos on a CHOLMOD factorisation of K − σM for large ones.
#include "fem/assembly.hpp"

#include <Eigen/Core>

namespace jointid::fem {

enum class ModalEngine { automatic, dense, sparse };
enum class ModalStatus { success, not_converging, numerical_issue };

struct ModalOptions {
  int num_modes = 10;            ///< lowest modes wanted; 0 = all (dense engine only)
  double max_frequency_hz = 0.0; ///< > 0: every mode below this frequency, instead of a count
  ModalEngine engine = ModalEngine::automatic;
  int dense_limit = 1500;   ///< automatic: dense engine up to this many equations
  double shift_hz = 1.0;    ///< sparse: σ = -(2π·shift_hz)², below every ω² (rigid modes too)
  double tolerance = 1e-10; ///< sparse: Spectra convergence tolerance
  int max_iterations = 1000; ///< sparse: restarts
};

struct Modes {
  ModalStatus status = ModalStatus::success;
  Eigen::VectorXd omega; ///< circular frequencies ω_r, rad/s, ascending (rigid modes ≈ 0)
  Eigen::MatrixXd phi;   ///< n_eq × n_modes, mass-normalised
  int num_modes() const { return static_cast<int>(omega.size()); }
  double frequency_hz(int r) const;
};

/// Throws std::invalid_argument for bad options (e.g. more modes than equations).
Modes modal_analysis(const Assembled& system, const ModalOptions& options = {});

} // namespace jointid::fem
