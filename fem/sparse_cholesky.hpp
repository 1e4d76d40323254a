#pragma once
/// Sparse Cholesky factorisation A = L Lᵀ of a symmetric positive definite matrix, by CHOLMOD's
/// supernodal method with 64-bit indices (`cholmod_l_*`), so that factors with more than 2³¹
/// nonzeros can be formed (a 10⁶-DOF 3D frame has ~2.6·10⁹). Eigen's CHOLMOD wrapper uses the
/// index type of the Eigen matrix, 32-bit here, and CHOLMOD crashes when the factor overflows it.
///
/// Two steps, so that a caller can see the cost before paying it: `analyze` orders the matrix
/// and predicts the factor's size; `factorize` refuses, with a clear error, a factor that
/// would not fit in the memory the machine has available (rather than being killed by the
/// kernel half-way through), and reports a matrix that is not positive definite.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace jointid::fem {

enum class CholeskyOrdering {
  automatic, ///< CHOLMOD's default (AMD, then METIS if AMD's factor looks dense); with groups
             ///< also METIS and NESDIS on the groups, and the factor needing least memory kept
  amd,       ///< approximate minimum degree
  metis,     ///< METIS nested dissection
  nesdis,    ///< CHOLMOD's own nested dissection (METIS bisection, constrained AMD)
};

struct CholeskyOptions {
  CholeskyOrdering ordering = CholeskyOrdering::automatic;
  /// Refuse to factorise when the predicted factor exceeds this fraction of the memory the
  /// system reports available (/proc/meminfo MemAvailable); 0 disables the check.
  double max_memory_fraction = 0.95;
  /// Fraction of explicit zeros allowed when merging supernodes of more than 48 columns
  /// (CHOLMOD's zrelax[2], whose own default is 0.05). Those supernodes hold most of a large
  /// factor: 0 saved 10 % of the factor's memory on a 10⁶-DOF frame for ~10 % more time.
  double large_supernode_zeros = 0.0;
  /// Blocks of at least this many right-hand sides are solved by our own supernodal
  /// substitution on every core (fem/supernodal_solve.hpp), smaller ones by CHOLMOD's
  /// `cholmod_l_solve2`; 0: CHOLMOD's always; −1 (the default): ours from 2 columns on for a
  /// factor of at least 2·10⁶ values, where it was measured faster (8 columns: 1.48 s against
  /// 3.70 s on the 10⁶-DOF lattice, 63 ms against 167 ms on the 10⁵ one, 4.5 ms against 9.5 ms
  /// on the 10⁴ one of 2.8·10⁶ values; docs/benchmarks.md, "Own block solve"). On smaller
  /// factors starting the cores costs more than the solve.
  int own_solve_columns = -1;
  /// Cores our block solve uses; 0 (or less): every core the machine has.
  int own_solve_threads = 0;
};

/// What the symbolic analysis predicts.
struct CholeskyAnalysis {
  std::int64_t rows = 0;
  double factor_nonzeros = 0.0; ///< nnz(L), exact count of the simplicial factor
  double factor_entries = 0.0;  ///< stored values of the supernodal factor (≥ nnz(L))
  double factor_bytes = 0.0;    ///< memory the numeric factor will take (values + indices)
  double flops = 0.0;           ///< floating-point operations of the factorisation
  std::string ordering;         ///< ordering used: "metis", "nesdis on groups", …
};

/// Thrown by SparseCholesky::factorize when the matrix is not positive definite; names the
/// equation (0-based, the caller's numbering) at which the factorisation broke down.
class NotPositiveDefinite : public std::domain_error {
public:
  NotPositiveDefinite(std::int64_t equation, std::int64_t rows);
  std::int64_t equation() const { return equation_; }

private:
  std::int64_t equation_;
};

class SparseCholesky {
public:
  explicit SparseCholesky(CholeskyOptions options = {});
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Orders the lower triangle of `A` (the upper triangle is not read) and predicts the
  /// factor. `groups`, if given, labels the group of every equation (any integers; e.g. the
  /// node a DOF belongs to): the ordering is then computed on the much smaller graph of the
  /// groups and each group's equations are kept together. Throws std::invalid_argument for a
  /// non-square matrix or a wrong number of group labels, std::runtime_error when CHOLMOD fails
  /// (e.g. out of memory).
  const CholeskyAnalysis& analyze(const Eigen::SparseMatrix<double>& A,
                                  const std::vector<int>& groups = {});

  /// Numeric factorisation of `A`, which must have the pattern given to `analyze`
  /// (std::invalid_argument otherwise). Throws std::runtime_error when the factor would not
  /// fit in the memory available (/proc/meminfo, cgroup limit) or CHOLMOD runs out of it,
  /// NotPositiveDefinite when A is not positive definite.
  void factorize(const Eigen::SparseMatrix<double>& A);

  /// x = A⁻¹ b for vectors of length rows(); b and x may not overlap.
  void solve(const double* b, double* x) const;

  /// X = A⁻¹ B for `columns` right-hand sides at once: B and X are column-major
  /// rows() × columns blocks (leading dimension rows()) that may not overlap. One pass over
  /// the factor for the whole block (CHOLMOD's, or ours on every core from
  /// `own_solve_columns` on), so the factor is read once per block instead of once per column.
  void solve(const double* b, double* x, std::int64_t columns) const;

  /// X = A⁻¹ B for an n × k block B (k ≥ 0), by the block solve above.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

  /// Changes CholeskyOptions::own_solve_columns of this factorisation (e.g. to time both
  /// solves on one factor).
  void set_own_solve_columns(int columns);

  std::int64_t rows() const;
  const CholeskyAnalysis& analysis() const;
  /// Peak memory CHOLMOD held so far, bytes.
  double peak_memory_bytes() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Bytes the system reports available to a new allocation (Linux: MemAvailable, and the room
/// under a cgroup v2 memory limit if tighter); < 0 when unknown.
double available_memory_bytes();

} // namespace jointid::fem
