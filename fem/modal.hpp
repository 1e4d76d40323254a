#pragma once
/// Undamped modal analysis K φ = ω² M φ with mass-normalised modes (φᵀ M φ = 1).
/// Two engines behind one interface: a dense generalised symmetric eigensolver for small
/// models and Spectra's shift-invert Lanczos on a CHOLMOD factorisation of K − σM for large ones.
#include "fem/assembly.hpp"
#include "fem/sparse_cholesky.hpp"

#include <Eigen/Core>

#include <optional>

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
  int max_iterations = 1000;  ///< sparse: restarts
  CholeskyOptions cholesky{}; ///< sparse: ordering and memory check of the K − σM factor
};

/// What the sparse engine did, for reports and benchmarks (times in s, wall clock).
struct SparseModalStats {
  CholeskyAnalysis factor;          ///< predicted size of the K − σM factor
  double analyze_s = 0.0;           ///< ordering and symbolic analysis
  double factorize_s = 0.0;         ///< numeric factorisation
  double cholesky_peak_bytes = 0.0; ///< CHOLMOD's peak memory
  int ncv = 0;                      ///< Lanczos basis size
  int restarts = 0;                 ///< implicit restarts Spectra needed
  long long solves = 0;             ///< solves with the factor
  double solve_s = 0.0;             ///< time in those solves
  double lanczos_s = 0.0;           ///< whole Lanczos iteration, solves included
};

struct Modes {
  ModalStatus status = ModalStatus::success;
  Eigen::VectorXd omega; ///< circular frequencies ω_r, rad/s, ascending (rigid modes ≈ 0)
  Eigen::MatrixXd phi;   ///< n_eq × n_modes, mass-normalised
  std::optional<SparseModalStats> sparse; ///< set by the sparse engine (last pass for a band)
  int num_modes() const { return static_cast<int>(omega.size()); }
  double frequency_hz(int r) const;
};

/// Throws std::invalid_argument for bad options (e.g. more modes than equations).
Modes modal_analysis(const Assembled& system, const ModalOptions& options = {});

} // namespace jointid::fem
