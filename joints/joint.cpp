#include "joints/joint.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace jointid::joints {

double Joint::force(double y, double ydot) const {
  double g = 0.0;
  for (std::size_t j = 0; j < terms.size(); ++j)
    g += values[j] * basis(terms[j], y, ydot);
  return g;
}

int Joint::term_index(Term t) const {
  for (std::size_t j = 0; j < terms.size(); ++j)
    if (terms[j] == t) return static_cast<int>(j);
  return -1;
}

void validate_joints(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  std::set<std::string> names;
  for (const auto& j : joints) {
    const std::string which = "joint '" + j.name + "'";
    if (j.name.empty()) throw std::invalid_argument("a joint has no name");
    if (!names.insert(j.name).second)
      throw std::invalid_argument("duplicate joint name '" + j.name + "'");
    if (j.terms.empty()) throw std::invalid_argument(which + " has no terms");
    if (j.values.size() != j.terms.size() || j.fixed.size() != j.terms.size() ||
        (!j.given.empty() && j.given.size() != j.terms.size()))
      throw std::invalid_argument(which + ": values and terms differ in number");
    std::set<Term> seen;
    for (Term t : j.terms)
      if (!seen.insert(t).second)
        throw std::invalid_argument(which + " lists term '" + std::string(term_name(t)) +
                                    "' twice");
    if (j.node == j.node_b)
      throw std::invalid_argument(which + " connects node " + std::to_string(j.node) +
                                  " to itself");
    try {
      dofs.equation({j.node, j.dof});
      if (!j.to_ground()) dofs.equation({j.node_b, j.dof});
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(which + ": " + e.what());
    }
  }
}

fem::SparseMatrix joint_coordinates(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto& j = joints[i];
    entries.emplace_back(dofs.equation({j.node, j.dof}), static_cast<int>(i), 1.0);
    if (!j.to_ground())
      entries.emplace_back(dofs.equation({j.node_b, j.dof}), static_cast<int>(i), -1.0);
  }
  fem::SparseMatrix B(dofs.num_equations(), static_cast<int>(joints.size()));
  B.setFromTriplets(entries.begin(), entries.end());
  return B;
}

std::vector<int> joint_dof_set(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  std::vector<int> set2;
  auto add = [&](int eq) {
    if (std::find(set2.begin(), set2.end(), eq) == set2.end()) set2.push_back(eq);
  };
  for (const auto& j : joints) {
    add(dofs.equation({j.node, j.dof}));
    if (!j.to_ground()) add(dofs.equation({j.node_b, j.dof}));
  }
  return set2;
}

Eigen::MatrixXd joint_coordinates_on(const std::vector<Joint>& joints, const fem::DofMap& dofs,
                                     const std::vector<int>& set2) {
  auto position = [&](int node, fem::Dof dof) {
    const auto it = std::find(set2.begin(), set2.end(), dofs.equation({node, dof}));
    if (it == set2.end())
      throw std::invalid_argument("joint DOF " + fem::to_string({node, dof}) + " is not in set 2");
    return static_cast<int>(it - set2.begin());
  };
  Eigen::MatrixXd B =
      Eigen::MatrixXd::Zero(static_cast<int>(set2.size()), static_cast<int>(joints.size()));
  for (std::size_t i = 0; i < joints.size(); ++i) {
    B(position(joints[i].node, joints[i].dof), i) = 1.0;
    if (!joints[i].to_ground()) B(position(joints[i].node_b, joints[i].dof), i) = -1.0;
  }
  return B;
}

JointForces::JointForces(std::vector<Joint> joints, const fem::DofMap& dofs)
    : joints_(std::move(joints)) {
  validate_joints(joints_, dofs);
  for (const auto& j : joints_) {
    const int i = j.term_index(Term::fc);
    if (i >= 0 && j.values[i] < 0.0)
      throw std::invalid_argument("joint '" + j.name +
                                  "': Coulomb friction fc must be >= 0 N to simulate");
  }
  B_ = joint_coordinates(joints_, dofs);
}

void JointForces::evaluate(const Eigen::VectorXd& y, const Eigen::VectorXd& ydot,
                           Eigen::VectorXd& g, Eigen::VectorXd& dg_dy,
                           Eigen::VectorXd& dg_dydot) const {
  const int n = static_cast<int>(joints_.size());
  g.setZero(n);
  dg_dy.setZero(n);
  dg_dydot.setZero(n);
  for (int i = 0; i < n; ++i) {
    const auto& j = joints_[i];
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      if (is_dry_friction(j.terms[t])) continue; // set-valued: handled by the integrator
      g(i) += j.values[t] * basis(j.terms[t], y(i), ydot(i));
      dg_dy(i) += j.values[t] * basis_dy(j.terms[t], y(i), ydot(i));
      dg_dydot(i) += j.values[t] * basis_dydot(j.terms[t], y(i), ydot(i));
    }
  }
}

Eigen::VectorXd JointForces::friction_limits() const {
  Eigen::VectorXd F = Eigen::VectorXd::Zero(static_cast<int>(joints_.size()));
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const int t = joints_[i].term_index(Term::fc);
    if (t >= 0) F(i) = joints_[i].values[t];
  }
  return F;
}

} // namespace jointid::joints
