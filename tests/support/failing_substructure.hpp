#pragma once
// A substructure whose modal analysis fails: K and M given for three DOFs (nodes 1, 2, 3, ux), a
// chain of springs of 1e10 N/m, unit masses but for node 1's, 1e-300 kg. The dense generalised
// eigensolver reduces K to L⁻¹KL⁻ᵀ with M = LLᵀ, which overflows there (1e10 / 1e-300), and its
// eigenvalues are NaN: the modal analysis' status is numerical_issue (checked by
// Substructure.ADenseModalAnalysisThatFailsIsAStatus). Modal damping, so that the damping matrix
// needs those modes too. A numerical failure, not bad input: K and M are finite, symmetric, and
// M is positive definite.
#include "fem/assembly.hpp"
#include "fem/dof.hpp"
#include "frf/substructure.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <string>

namespace jointid::test {

/// The reason its modal analysis gives.
inline const std::string failing_modes_reason =
    "the dense generalised eigensolver (K, M) gave eigenvalues that are not finite (a mass too "
    "small for its stiffness?)";

inline frf::Substructure failing_substructure() {
  fem::Assembled s;
  s.dofs = fem::DofMap::from_dofs({{1, fem::Dof::ux}, {2, fem::Dof::ux}, {3, fem::Dof::ux}});
  Eigen::MatrixXd K(3, 3);
  K << 2e10, -1e10, 0.0, -1e10, 2e10, -1e10, 0.0, -1e10, 1e10;
  s.K = K.sparseView();
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(3, 3);
  M(0, 0) = 1e-300;
  s.M = M.sparseView(0.0, 0.0); // keep 1e-300 (the default view drops it as zero)
  fem::Damping damping;
  damping.kind = fem::Damping::Kind::modal;
  damping.modal_ratio = 0.01;
  return frf::Substructure(std::move(s), damping);
}

} // namespace jointid::test
