#pragma once
/// Element kernels: pure functions returning element matrices in global coordinates.
/// DOF order per node is the element's `element_dofs()` list, node a first, then node b.
#include "fem/model.hpp"

#include <Eigen/Core>
#include <span>

namespace jointid::fem {

using Matrix4 = Eigen::Matrix<double, 4, 4>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Matrix12 = Eigen::Matrix<double, 12, 12>;

/// Planar Euler–Bernoulli beam along x, DOFs [uy_a, rz_a, uy_b, rz_b].
Matrix4 beam_stiffness(double EI, double length);
Matrix4 beam_consistent_mass(double rho_A, double length);
/// HRZ lumping: ρAL/2 on each translation, ρAL³/78 on each rotation.
Matrix4 beam_lumped_mass(double rho_A, double length);

/// Planar frame element from node a at xa to node b at xb (x–y plane), global DOFs
/// [ux_a, uy_a, rz_a, ux_b, uy_b, rz_b].
Matrix6 frame2d_stiffness(double EA, double EI, const Eigen::Vector2d& xa,
                          const Eigen::Vector2d& xb);
Matrix6 frame2d_mass(double rho_A, const Eigen::Vector2d& xa, const Eigen::Vector2d& xb,
                     bool lumped);

/// The `up` vector of a frame3d element that gives none: global +z (the local y axis then points
/// upwards in the vertical plane through the member), or global +x for a member parallel to z
/// (within 1e-6 rad), where +z cannot serve — the rule of SAP2000 and other frame programs.
Eigen::Vector3d frame3d_default_up(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb);

/// Spatial frame element (axial EA, torsion GJ, bending EIz in the local x–y plane and EIy in
/// the local x–z plane). `up` lies in the local x–y plane. Global DOFs, 6 per node.
Matrix12 frame3d_stiffness(const Material& material, const Section& section,
                           const Eigen::Vector3d& xa, const Eigen::Vector3d& xb,
                           const Eigen::Vector3d& up);
Matrix12 frame3d_mass(const Material& material, const Section& section, const Eigen::Vector3d& xa,
                      const Eigen::Vector3d& xb, const Eigen::Vector3d& up, bool lumped);

/// The nodal DOFs an element type uses, in its matrix order.
std::span<const Dof> element_dofs(ElementType type);

/// Element stiffness and mass in global coordinates (size 2 * element_dofs(type).size()).
struct ElementMatrices {
  Eigen::MatrixXd K;
  Eigen::MatrixXd M;
};
/// Looks the nodes up by id (linear search; see the overload for loops).
ElementMatrices element_matrices(const Model& model, const Element& element);
/// Same, with the positions of node_a and node_b given.
ElementMatrices element_matrices(const Model& model, const Element& element,
                                 const Eigen::Vector3d& xa, const Eigen::Vector3d& xb);

} // namespace jointid::fem
