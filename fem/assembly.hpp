#pragma once
/// Assembly of the substructure's sparse stiffness K (N/m) and mass M (kg) over the free DOFs.
#include "fem/dof_map.hpp"
#include "fem/model.hpp"

#include <Eigen/SparseCore>

namespace jointid::fem {

using SparseMatrix = Eigen::SparseMatrix<double>;

struct Assembled {
  DofMap dofs;
  SparseMatrix K; ///< n_eq × n_eq, symmetric
  SparseMatrix M; ///< n_eq × n_eq, symmetric
};

/// Validates the model, then assembles elements, point masses and springs.
Assembled assemble(const Model& model);

} // namespace jointid::fem
