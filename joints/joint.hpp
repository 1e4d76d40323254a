#pragma once
/// Joints: a non-linear connection between one DOF and ground, or between the same DOF of two
/// nodes (translational or rotational). Its deformation is y = u(node) − u(node_b) (or u(node)
/// to ground), and its force g(y, ẏ) = Σ b_j g_j acts as −g on `node` and +g on `node_b`.
#include "fem/assembly.hpp"
#include "fem/time_integration.hpp"
#include "joints/basis.hpp"

#include <optional>
#include <string>
#include <vector>

namespace jointid::joints {

struct Joint {
  std::string name;
  int node = 0;
  int node_b = 0; ///< 0: the joint goes to ground
  fem::Dof dof = fem::Dof::uy;
  std::vector<Term> terms;
  std::vector<double> values; ///< b_j, same order as terms (known or starting values)
  std::vector<bool> fixed;    ///< true: b_j is known and held, not identified
  /// true where `values` holds a value given in the model file; false: unknown (starts at 0).
  /// Empty: every value is given.
  std::vector<bool> given;

  bool to_ground() const { return node_b == 0; }
  /// g(y, ẏ) with the joint's values.
  double force(double y, double ydot) const;
  /// Index of a term in `terms`, or -1.
  int term_index(Term t) const;
  bool has_value(std::size_t term) const { return given.empty() || given[term]; }
};

/// Checks the joints against the model's DOF map (nodes exist, DOFs present and free, names
/// unique, values consistent); throws std::invalid_argument naming the joint.
void validate_joints(const std::vector<Joint>& joints, const fem::DofMap& dofs);

/// The joints as local forces for the time integrator (coordinate i = joint i).
class JointForces final : public fem::LocalForces {
public:
  JointForces(std::vector<Joint> joints, const fem::DofMap& dofs);
  const fem::SparseMatrix& coordinates() const override { return B_; }
  void evaluate(const Eigen::VectorXd& y, const Eigen::VectorXd& ydot, Eigen::VectorXd& g,
                Eigen::VectorXd& dg_dy, Eigen::VectorXd& dg_dydot) const override;
  Eigen::VectorXd friction_limits() const override;
  const std::vector<Joint>& joints() const { return joints_; }

private:
  std::vector<Joint> joints_;
  fem::SparseMatrix B_;
};

/// B (n_eq × n_joints): +1 at a joint's node DOF, −1 at node_b's.
fem::SparseMatrix joint_coordinates(const std::vector<Joint>& joints, const fem::DofMap& dofs);

/// The joints' DOFs (set 2 of the partition), as equation numbers, each once, in joint order.
std::vector<int> joint_dof_set(const std::vector<Joint>& joints, const fem::DofMap& dofs);
/// B restricted to set 2 (|set2| × n_joints): y = Bᵀ x2, and the joints' forces on set 2 are −B g.
Eigen::MatrixXd joint_coordinates_on(const std::vector<Joint>& joints, const fem::DofMap& dofs,
                                     const std::vector<int>& set2);

} // namespace jointid::joints
