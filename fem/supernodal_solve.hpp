#pragma once
/// Forward and back substitution, X = A⁻¹ B = Pᵀ L⁻ᵀ L⁻¹ P B, with a supernodal Cholesky factor
/// A = Pᵀ L Lᵀ P held as CHOLMOD holds it, for a block of right-hand sides on every core.
///
/// Why not CHOLMOD's own solve: for a block of b columns it calls the BLAS on each supernode
/// (dtrsm on the diagonal block, dgemm of the rows below by the b columns). With b small (8)
/// those calls pack their operands, so on the 10⁵ lattice 8 columns cost 3.1× one column,
/// where reading the factor, which bounds a single-column solve, is the same. Here each
/// supernode's columns are taken in panels of 256: the panel's triangle with the right-hand
/// sides shared among the cores, then the rows below it (forward) or the panel's columns
/// (backward) shared, with register-blocked kernels that read each factor value once and use
/// it for every right-hand side. Supernodes under 2¹⁶ values are done by one core.
///
/// Measured (docs/benchmarks.md, "Own block solve"), 8 columns: 2.79 s against CHOLMOD's 3.93 s
/// on the 10⁶-DOF lattice, 3–10 % faster on the 10⁵ one, slower on the 10⁴ one; so it is used
/// for large factors only (CholeskyOptions::own_solve_columns). Its forward kernel reads 8
/// rows of each of 256 columns at a time, which streams the factor badly: the next thing to
/// change.
///
/// The layout (CHOLMOD's `cholmod_factor` with `is_super`): supernode s holds columns
/// first_column[s] … first_column[s + 1] − 1 of L, its row indices are
/// rows[row_pointer[s] …  row_pointer[s + 1] − 1] (the supernode's own columns first, ascending),
/// and its values a column-major block of those rows by those columns, starting at
/// values[value_pointer[s]], the diagonal block's upper part not read.
#include <cstdint>

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

/// X = A⁻¹ B for `columns` right-hand sides: B and X column-major n × columns (leading dimension
/// n), which may not overlap. `threads` ≤ 1 runs on the calling thread alone.
void supernodal_solve(const SupernodalFactorView& factor, const double* B, double* X,
                      std::int64_t columns, int threads);

} // namespace jointid::fem
