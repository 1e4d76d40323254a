#pragma once
/// Map between (node id, DOF) and equation numbers. A node has only the DOFs that an element
/// or spring at it uses; supported (fixed) DOFs get no equation. Equations are numbered node by
/// node in the order of Model::nodes, DOFs in the order ux uy uz rx ry rz (from_dofs: in the
/// order of a given list, for a substructure known only at a few DOFs).
#include "fem/model.hpp"

#include <array>
#include <string>
#include <unordered_map>
#include <vector>

namespace jointid::fem {

class DofMap {
public:
  enum class State { absent, fixed, free };

  DofMap() = default;
  explicit DofMap(const Model& model);
  /// The DOFs of a substructure known only at these DOFs (e.g. given by its modes): equation e
  /// is dofs[e]; node_ids() in order of first appearance; every other DOF of those nodes is
  /// absent. Throws std::invalid_argument naming a DOF listed twice.
  static DofMap from_dofs(const std::vector<NodeDof>& dofs);

  int num_equations() const { return static_cast<int>(by_equation_.size()); }
  State state(const NodeDof& nd) const;
  /// Equation of a free DOF; throws std::invalid_argument saying whether the node does not
  /// exist, does not have that DOF, or has it fixed by a support.
  int equation(const NodeDof& nd) const;
  /// Why `nd` is not a free DOF, saying what the model has instead ("" when it is free), for
  /// messages that blame what refers to it (a record's channel, an option), not the model:
  /// "the model has no node 99 (its nodes: 1–7)", "node 7 has no DOF uz in the model (its
  /// DOFs: ux, uy, rz)", "a support of the model holds 1:uy fixed (node 1 has no free DOF)".
  std::string why_not_free(const NodeDof& nd) const;
  const NodeDof& node_dof(int equation) const { return by_equation_.at(equation); }
  /// Node ids in model order, and every node's equation numbers (-1 where absent or fixed).
  const std::vector<int>& node_ids() const { return node_ids_; }
  std::array<int, 6> node_equations(int node_id) const;
  /// For every equation, the position in node_ids() of its node (groups the DOFs of a node,
  /// e.g. for a node-wise fill-reducing ordering).
  std::vector<int> equation_nodes() const;

private:
  int index_of(int node_id) const;
  std::vector<int> node_ids_;
  std::unordered_map<int, int> index_; // node id → position in node_ids_
  std::vector<std::array<int, 6>> eq_; // -2 absent, -1 fixed, >= 0 equation
  std::vector<NodeDof> by_equation_;
  bool listed_ = false; // from_dofs: an absent DOF is one the list lacks
};

} // namespace jointid::fem
