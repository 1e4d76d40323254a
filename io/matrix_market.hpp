#pragma once
/// MatrixMarket files (NIST's exchange format, `.mtx`) for stiffness and mass matrices exported
/// by other finite element programs, and a DOF table that names their rows.
///
/// Read: `%%MatrixMarket matrix coordinate real|integer general|symmetric`, `%` comment lines,
/// the size line `rows cols entries`, then `entries` lines `i j value` (1-based). `symmetric`
/// files hold one triangle (either; an entry on both sides of the diagonal is an error); a
/// `general` file must be square for K and M, and is checked for symmetry by the caller.
/// Repeated entries are added (as element-by-element exports write them). `array`, `complex`,
/// `pattern` and `hermitian` files are refused with the reason.
#include "fem/dof.hpp"

#include <Eigen/SparseCore>

#include <filesystem>
#include <vector>

namespace jointid::io {

/// Throws io::Error naming the file, the line and what was expected; sizes above 10^7 rows or
/// columns are refused (the largest models jointid is sized for, docs/scaling.md).
Eigen::SparseMatrix<double> read_matrix_market(const std::filesystem::path& path);

/// Writes A (square) as `coordinate real symmetric` (the lower triangle; A must be symmetric to
/// 1e-12 of its largest entry, else io::Error), each value as the shortest text that reads back
/// to the same double, atomically.
void write_matrix_market(const std::filesystem::path& path, const Eigen::SparseMatrix<double>& A);

/// A DOF table: one `NODE:DOF` (e.g. `7:uy`) per line naming the matrix rows in order; blank
/// lines and `#` comments are skipped. Throws io::Error naming the file and line for a bad
/// entry, a node id ≤ 0, or a DOF listed twice.
std::vector<fem::NodeDof> read_dof_table(const std::filesystem::path& path);

} // namespace jointid::io
