#pragma once
/// Undamped modal analysis K φ = ω² M φ with mass-normalised modes (φᵀ M φ = 1).
/// Two engines behind one interface: a dense generalised symmetric eigensolver for small
/// models and, for large ones, shift-invert on a supernodal CHOLMOD factorisation of K − σM:
/// by default our thick-restart block Lanczos (`fem/block_lanczos.hpp`), which solves a block
/// of right-hand sides per pass over the factor; Spectra's single-vector Lanczos
/// (`SymGEigsShiftSolver`) is kept as an option to compare with.
#include "fem/assembly.hpp"
#include "fem/sparse_cholesky.hpp"
#include "fem/status.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace jointid::fem {

enum class ModalEngine { automatic, dense, sparse };
/// The sparse engine's iteration on the factor of K − σM.
enum class SparseMethod {
  block_lanczos, ///< thick-restart block Lanczos, `block_size` right-hand sides per solve
  spectra,       ///< Spectra's SymGEigsShiftSolver: implicitly restarted, one vector per solve
};

struct ModalOptions {
  int num_modes = 10;            ///< lowest modes wanted; 0 = all (dense engine only)
  double max_frequency_hz = 0.0; ///< > 0: every mode below this frequency, instead of a count
  ModalEngine engine = ModalEngine::automatic;
  int dense_limit = 1500; ///< automatic: dense engine up to this many equations
  double shift_hz = 1.0;  ///< sparse: σ = -(2π·shift_hz)², below every ω² (rigid modes too)
  /// sparse: a mode has converged when ‖Op φ − θ φ‖_M ≤ tolerance · θ for Op = (K − σM)⁻¹M,
  /// θ = 1/(ω² − σ), i.e. ‖(K − σM)⁻¹(Kφ − ω²Mφ)‖_M ≤ tolerance (Spectra's test, both methods)
  double tolerance = 1e-10;
  int max_iterations = 1000; ///< sparse: restarts before the status is not_converging
  SparseMethod sparse_method = SparseMethod::block_lanczos; ///< sparse: the iteration
  /// sparse, block Lanczos: right-hand sides per solve. At least the largest multiplicity
  /// expected (6 rigid-body modes of a free 3D frame): a larger one is found only by rounding.
  int block_size = 8;
  /// sparse: basis vectors at most (memory: rows × (basis + block) doubles); 0: automatic
  /// (block Lanczos 2 nev + 6 block_size, Spectra max(2 nev + 1, nev + 20)), capped at the
  /// DOFs with mass
  int basis_vectors = 0;
  CholeskyOptions cholesky{}; ///< sparse: ordering and memory check of the K − σM factor
};

/// What the sparse engine did, for reports and benchmarks (times in s, wall clock).
struct SparseModalStats {
  CholeskyAnalysis factor;          ///< predicted size of the K − σM factor
  double analyze_s = 0.0;           ///< ordering and symbolic analysis
  double factorize_s = 0.0;         ///< numeric factorisation
  double cholesky_peak_bytes = 0.0; ///< CHOLMOD's peak memory
  std::string method;               ///< "block Lanczos" or "Spectra"
  int block_size = 1;               ///< right-hand sides per solve (Spectra: 1)
  int ncv = 0;                      ///< basis vectors at most (besides the next block)
  int restarts = 0;                 ///< restarts the iteration needed
  long long solves = 0;             ///< solves with the factor: passes over it (a block is one)
  long long right_hand_sides = 0;   ///< columns solved in those solves
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
  /// not_converging (the sparse engine's restarts ran out), numerical_issue (a dense solver
  /// failed), with the reason
  Status status;
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
