#pragma once
/// Forward and back substitution, X = A⁻¹ B = Pᵀ L⁻ᵀ L⁻¹ P B, with a supernodal Cholesky factor
/// A = Pᵀ L Lᵀ P held as CHOLMOD holds it, for a block of right-hand sides on every core.
///
/// Why not CHOLMOD's own solve: for a block of b columns it calls the BLAS on each supernode
/// (dtrsm on the diagonal block, dgemm of the rows below by the b columns). With b small (8)
/// those calls pack their operands, so on the 10⁶-DOF lattice 8 columns cost 3.9× one column,
/// where reading the factor, which bounds a single-column solve, is the same.
///
/// How it is done here:
/// - The right-hand sides are held row-major, a row's (up to) 8 values in one cache line, so
///   that gathering a supernode's rows reads one line per row instead of one per column.
/// - The elimination tree is cut below its top: the subtrees under the cut are shared among
///   the cores whole (a core forward-solves its subtrees alone; the updates its subtrees make
///   to the rows of the top go to a buffer of its own, added up when all are done), the top
///   supernodes (the large separators) are each shared: their columns in panels of 256, the
///   panel's triangle with the right-hand sides shared, then the rows below it (forward) or
///   the panel's columns (backward). The cut is chosen to balance the cores' work (the factor
///   values each reads) with least work left in the top's small supernodes, which one core does.
/// - The kernels read the factor column by column, G columns at a time (4 with AVX2, 8 with
///   AVX-512), each value once for all the right-hand sides, the rows they update held in the
///   L1 cache: the hardware prefetchers follow such streams.
///
/// Measured: docs/benchmarks.md, "Own block solve".
///
/// The layout (CHOLMOD's `cholmod_factor` with `is_super`): supernode s holds columns
/// first_column[s] … first_column[s + 1] − 1 of L, its row indices are
/// rows[row_pointer[s] …  row_pointer[s + 1] − 1] (the supernode's own columns first, ascending),
/// and its values a column-major block of those rows by those columns, starting at
/// values[value_pointer[s]], the diagonal block's upper part not read.
#include <cstdint>
#include <memory>

namespace jointid::fem {

struct SupernodalFactorView {
  std::int64_t n = 0;
  std::int64_t supernodes = 0;
  const std::int64_t* first_column = nullptr;  ///< supernodes + 1 entries
  const std::int64_t* row_pointer = nullptr;   ///< supernodes + 1 entries, into rows
  const std::int64_t* value_pointer = nullptr; ///< supernodes + 1 entries, into values
  const std::int64_t* rows = nullptr;
  const double* values = nullptr;
  /// Row k of L is equation permutation[k] of A; null for the identity.
  const std::int64_t* permutation = nullptr;
};

/// A factor's substitution plan (its elimination tree, cut and shared among `threads` cores)
/// and work space, kept for repeated solves. The factor's arrays must outlive it and keep
/// their structure (new values in the same structure are fine).
class SupernodalSolver {
public:
  /// `threads` ≤ 1 runs on the calling thread alone.
  SupernodalSolver(const SupernodalFactorView& factor, int threads);
  ~SupernodalSolver();
  SupernodalSolver(const SupernodalSolver&) = delete;
  SupernodalSolver& operator=(const SupernodalSolver&) = delete;

  /// X = A⁻¹ B for `columns` right-hand sides: B and X column-major n × columns (leading
  /// dimension n), which may not overlap.
  void solve(const double* B, double* X, std::int64_t columns);

private:
  struct Plan;
  std::unique_ptr<Plan> plan_;
};

} // namespace jointid::fem
