#pragma once
/// Assembly of the substructure's sparse stiffness K (N/m) and mass M (kg) over the free DOFs.
#include "fem/dof_map.hpp"
#include "fem/model.hpp"

#include <Eigen/SparseCore>

#include <vector>

namespace jointid::fem {

using SparseMatrix = Eigen::SparseMatrix<double>;

struct Assembled {
  DofMap dofs;
  SparseMatrix K; ///< n_eq × n_eq, symmetric
  SparseMatrix M; ///< n_eq × n_eq, symmetric
};

/// Validates the model, then assembles elements, point masses and springs.
Assembled assemble(const Model& model);

/// Triplets (row, column, value) of K and M, duplicates to be summed.
struct Entries {
  std::vector<Eigen::Triplet<double>> K, M;
};

/// The entries of K and M in rows first_row … last_row − 1 only (columns all), for a
/// distributed assembly where each process owns a range of rows: elements that touch none of
/// those rows are not computed. Does not validate the model (assemble() does).
Entries assemble_rows(const Model& model, const DofMap& dofs, int first_row, int last_row);

} // namespace jointid::fem
