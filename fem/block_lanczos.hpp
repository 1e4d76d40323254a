#pragma once
/// Thick-restart block Lanczos for the lowest modes of K φ = λ M φ by shift-invert: the largest
/// eigenvalues θ = 1/(λ − σ) of Op = (K − σM)⁻¹ M, which is self-adjoint in the M-inner
/// product, so its Krylov basis is kept M-orthonormal and its projection is symmetric.
///
/// Why blocks: on a large model every application of Op is a solve with the factor of K − σM,
/// and a single-vector solve is bound by the memory bandwidth of reading the factor (20 GiB at
/// 10⁶ DOFs, 1.0–1.5 s a pass). A block of b right-hand sides is solved in one pass over the
/// factor (fem/supernodal_solve.hpp on large factors, CHOLMOD's solve on small ones), so the
/// iteration needs 3–5× fewer passes (8 columns: 18–19 instead of Spectra's 64–86 on the
/// 10⁴–10⁶ lattices). At 10⁶ DOFs a pass of 8 columns costs about what one column costs
/// (1.48 s against CHOLMOD's 1.49 s, measured; docs/benchmarks.md, "Own block solve").
///
/// Why thick restart (Wu & Simon's, the symmetric form of Stewart's Krylov–Schur): when the
/// basis reaches its cap the iteration keeps the wanted Ritz vectors and the residual block
/// and goes on from there. That is as good as an implicit restart for a symmetric operator,
/// keeps memory fixed (n × (cap + b) doubles), needs no shifted QR steps on a block
/// tridiagonal matrix, and its basis stays orthonormal by construction (every new block is
/// orthogonalised twice, CGS2 in the M-inner product, BLAS-3: first by the Lanczos step against
/// the blocks it couples to, whose coefficients are known, then against the whole basis).
/// After convergence the wanted vectors take one more power step, φ ← Op φ / θ, read off the
/// Krylov relation (no solve): it brings ‖KΦ − MΦΛ‖/‖KΦ‖ from ~1e-8 to ~1e-11 on the 10⁴
/// lattice (Spectra's: 1e-9 … 1e-12).
///
/// A multiple eigenvalue whose multiplicity is at most the block size is found like a simple
/// one (a random start block has a component in every direction of its eigenspace); a larger
/// multiplicity only through rounding, as in single-vector Lanczos, so keep the block at least
/// as large as the multiplicities expected (6 rigid-body modes of a free 3D body).
#include "fem/status.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace jointid::fem {

/// What the iteration needs of the pencil: solves with the factor of K − σM, a block at a
/// time, and products with M. Both K − σM and M are symmetric, K − σM positive definite.
class ShiftInvertPencil {
public:
  virtual ~ShiftInvertPencil() = default;
  virtual Eigen::Index rows() const = 0;
  /// X = (K − σM)⁻¹ B for an n × b block B.
  virtual void solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) = 0;
  /// Y = M X for an n × b block X.
  virtual void mass(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const = 0;
};

struct BlockLanczosOptions {
  int nev = 10;       ///< wanted eigenpairs: the nev largest θ (the lowest λ)
  int block_size = 8; ///< right-hand sides per solve (≥ 1)
  /// basis vectors at most, besides the next block; 0: 2 nev + 6 b
  int max_basis = 0;
  int max_dimension = 0; ///< dimension of the space Op works in (M's rank); 0: rows()
  /// A Ritz pair (θ, y) has converged when ‖Op y − θ y‖_M ≤ tolerance · max(ε^⅔, θ) (Spectra's
  /// test). With λ = σ + 1/θ that is ‖(K − σM)⁻¹(K y − λ M y)‖_M ≤ tolerance for θ ≥ ε^⅔: the
  /// residual of K φ = λ M φ relative to the pencil, measured without an extra solve.
  double tolerance = 1e-10;
  int max_restarts = 1000; ///< restarts (basis rebuilds) before giving up
  /// M singular (massless DOFs): M's null space is invisible to the M-inner product, so start
  /// from Op applied to a random block and purify the eigenvectors (φ ← Op φ / θ) at the end,
  /// a solve each. (Without it that step is taken from the Krylov relation, without a solve.)
  bool purify = false;
  std::uint64_t seed = 20261201; ///< of the random start block
};

struct BlockLanczosResult {
  /// not_converging when the wanted pairs did not all meet the tolerance within max_restarts
  /// (the reason says how many did and the largest residual)
  Status status;
  int converged_count = 0; ///< wanted pairs that met the tolerance at the last check
  Eigen::VectorXd theta;   ///< the nev largest eigenvalues of Op, descending
  Eigen::MatrixXd vectors; ///< n × nev, M-orthonormal (θ's eigenvectors, in its order)
  int block_size = 0;      ///< block size used (reduced for a small space)
  int max_basis = 0;       ///< basis cap used
  int restarts = 0;
  long long solves = 0;           ///< calls of ShiftInvertPencil::solve (passes over the factor)
  long long right_hand_sides = 0; ///< columns solved in all
  double max_residual = 0.0; ///< max over the wanted pairs of ‖Op y − θ y‖_M / θ, last check
};

/// The nev largest eigenpairs of Op = (K − σM)⁻¹ M. Throws std::invalid_argument for bad
/// options (nev ≥ the dimension of the space, block size < 1, negative tolerance or restarts).
/// Not converging within max_restarts is a result (status not_converging), not an exception.
BlockLanczosResult block_lanczos(ShiftInvertPencil& pencil, const BlockLanczosOptions& options);

namespace detail {
/// Coefficients of an orthonormalisation: Z_in = V C + Z_out R (V the basis it was made
/// orthogonal to); `rounds`: the re-check rounds it took after the passes (0 when the last
/// pass removed little, "twice is enough").
struct Projection {
  Eigen::MatrixXd C; ///< m × q
  Eigen::MatrixXd R; ///< kept × q
  int rounds = 0;
};
/// The block Lanczos's orthonormalisation, exposed for its tests: makes Z M-orthonormal and
/// M-orthogonal to the first m columns of the M-orthonormal V by `passes` passes of block
/// classical Gram–Schmidt, then SVQB, then re-check rounds while the last pass removed more
/// than half of a column (see block_lanczos.cpp). MZ holds M Z of the result.
Projection orthonormalise(const ShiftInvertPencil& P, const Eigen::MatrixXd& V, Eigen::Index m,
                          Eigen::MatrixXd& Z, Eigen::MatrixXd& MZ, double relative_floor,
                          Eigen::MatrixXd& scratch, int passes = 2,
                          const Eigen::RowVectorXd& removed = {});
} // namespace detail

} // namespace jointid::fem
