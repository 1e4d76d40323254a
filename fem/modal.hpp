#pragma once
/// Undamped modal analysis K φ = ω² M φ with mass-normalised modes (φᵀ M φ = 1).
/// Two engines behind one interface: a dense generalised symmetric eigensolver for small
/// models and Spectra's shift-invert Lanczos on a CHOLMOD factorisation of K − σM for large ones.
#include "fem/assembly.hpp"
#include "fem/sparse_cholesky.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

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

/// What the distributed engine (SLEPc, `fem/slepc_modal.hpp`) did; times in s, wall clock.
struct DistributedModalStats {
  int ranks = 1;                 ///< MPI processes
  double assemble_s = 0.0;       ///< each rank's rows of K and M
  double factorize_s = 0.0;      ///< MUMPS ordering and factorisation of K − σM
  double solve_s = 0.0;          ///< Krylov–Schur iteration (its solves with the factor)
  int restarts = 0;              ///< Krylov–Schur restarts (last pass for a band)
  double factor_entries = 0.0;   ///< entries of the factor, all ranks (MUMPS INFOG(29))
  double factor_flops = 0.0;     ///< flops of the factorisation (MUMPS RINFOG(3))
  double factor_max_bytes = 0.0; ///< MUMPS memory of the largest rank (INFOG(21))
  double factor_sum_bytes = 0.0; ///< MUMPS memory of all ranks (INFOG(22))
};

struct Modes {
  ModalStatus status = ModalStatus::success;
  std::string reason;    ///< why, when status is not success
  Eigen::VectorXd omega; ///< circular frequencies ω_r, rad/s, ascending (rigid modes ≈ 0)
  /// n_eq × n_modes, mass-normalised; or |rows| × n_modes when `rows` is not empty.
  Eigen::MatrixXd phi;
  /// Empty: phi has a row for every equation. Otherwise row i of phi is equation rows[i]: an
  /// engine asked for only the rows a synthesis needs (the distributed engine).
  std::vector<int> rows;
  std::optional<SparseModalStats> sparse; ///< set by the sparse engine (last pass for a band)
  std::optional<DistributedModalStats> distributed; ///< set by the distributed engine
  int num_modes() const { return static_cast<int>(omega.size()); }
  double frequency_hz(int r) const;
};

/// Throws std::invalid_argument for bad options (e.g. more modes than equations) and for a model
/// with a DOF that has neither stiffness nor mass (K − σM not positive definite), naming it.
/// Massless DOFs that have stiffness are no error: they have no finite mode, so both engines
/// return the finite modes only (a count is capped at their number). A solver that fails or
/// does not converge gives a status with its reason.
Modes modal_analysis(const Assembled& system, const ModalOptions& options = {});

} // namespace jointid::fem
