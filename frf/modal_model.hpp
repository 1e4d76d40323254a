#pragma once
/// A linear substructure given by its modes at a few DOFs (from a modal test or another FE
/// program) instead of a finite element model: DESIGN.md's "[modal]" contract. SI units.
#include "fem/dof.hpp"

#include <Eigen/Core>
#include <vector>

namespace jointid::frf {

/// H(ω)_ij = Σ_r φ_ri φ_rj / (ω_r² − ω² + 2iζ_r ω_r ω) + R_ij with ω_r = 2π f_r
/// (frf::ModalSynthesis evaluates it). Equation e of the substructure is dofs[e]
/// (fem::DofMap::from_dofs).
struct ModalModel {
  std::vector<fem::NodeDof> dofs;       ///< the DOFs that tests and joints use
  Eigen::VectorXd frequencies_hz;       ///< natural frequencies f_r, Hz (n_modes)
  Eigen::VectorXd damping;              ///< modal damping ratios ζ_r (n_modes)
  Eigen::MatrixXd shapes;               ///< n_modes × n_dofs, mass-normalised, 1/sqrt(kg)
  Eigen::MatrixXd residual_flexibility; ///< n_dofs × n_dofs, m/N, symmetric; or empty

  int num_modes() const { return static_cast<int>(frequencies_hz.size()); }
  int num_dofs() const { return static_cast<int>(dofs.size()); }
  /// Throws std::invalid_argument naming what is wrong: no DOFs or no modes, sizes that do not
  /// match, a node id <= 0 (0 means ground), a DOF listed twice, a non-finite value, a negative
  /// frequency or damping ratio, a residual flexibility not symmetric to 1e-9 (relative to its
  /// largest entry).
  void validate() const;
};

} // namespace jointid::frf
