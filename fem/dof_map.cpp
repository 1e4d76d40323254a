#include "fem/dof_map.hpp"

#include "fem/elements.hpp"

#include <algorithm>
#include <stdexcept>

namespace jointid::fem {

namespace {
constexpr int absent = -2, fixed = -1;

// Node ids as sorted ranges, "1–7, 10, 12–15", at most `shown` ranges ("…, 120 nodes in all").
std::string node_ranges(std::vector<int> ids) {
  std::sort(ids.begin(), ids.end());
  std::string out;
  constexpr int shown = 6;
  int ranges = 0;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1)
      ++j;
    if (ranges == shown) {
      out += ", … (" + std::to_string(ids.size()) + " nodes in all)";
      break;
    }
    out += (out.empty() ? "" : ", ") + std::to_string(ids[i]);
    if (j > i) out += (j == i + 1 ? ", " : "–") + std::to_string(ids[j]);
    ++ranges;
    i = j + 1;
  }
  return out.empty() ? std::string("none") : out;
}
} // namespace

DofMap::DofMap(const Model& model) {
  const std::size_t n = model.nodes.size();
  node_ids_.reserve(n);
  for (const auto& node : model.nodes)
    node_ids_.push_back(node.id);
  eq_.assign(n, {absent, absent, absent, absent, absent, absent});
  index_ = model.node_positions();
  auto use = [&](int node_id, Dof dof) { eq_[index_.at(node_id)][static_cast<int>(dof)] = 0; };
  for (const auto& e : model.elements)
    for (Dof d : element_dofs(e.type)) {
      use(e.node_a, d);
      use(e.node_b, d);
    }
  for (const auto& s : model.springs) {
    use(s.node, s.dof);
    if (s.node_b != 0) use(s.node_b, s.dof);
  }
  for (const auto& s : model.supports)
    for (Dof d : s.fixed) {
      int& slot = eq_[index_.at(s.node)][static_cast<int>(d)];
      if (slot != absent) slot = fixed;
    }
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < num_dof_kinds; ++d)
      if (eq_[i][d] == 0) {
        eq_[i][d] = static_cast<int>(by_equation_.size());
        by_equation_.push_back({node_ids_[i], static_cast<Dof>(d)});
      }
}

DofMap DofMap::from_dofs(const std::vector<NodeDof>& dofs) {
  DofMap map;
  map.listed_ = true;
  for (const NodeDof& nd : dofs) {
    auto [it, added] = map.index_.emplace(nd.node, static_cast<int>(map.node_ids_.size()));
    if (added) {
      map.node_ids_.push_back(nd.node);
      map.eq_.push_back({absent, absent, absent, absent, absent, absent});
    }
    int& slot = map.eq_[it->second][static_cast<int>(nd.dof)];
    if (slot != absent)
      throw std::invalid_argument("DOF " + to_string(nd) + " is listed twice (as equations " +
                                  std::to_string(slot) + " and " +
                                  std::to_string(map.by_equation_.size()) + ")");
    slot = static_cast<int>(map.by_equation_.size());
    map.by_equation_.push_back(nd);
  }
  return map;
}

int DofMap::index_of(int node_id) const {
  const auto it = index_.find(node_id);
  return it == index_.end() ? -1 : it->second;
}

DofMap::State DofMap::state(const NodeDof& nd) const {
  const int i = index_of(nd.node);
  if (i < 0) return State::absent;
  const int e = eq_[i][static_cast<int>(nd.dof)];
  return e == absent ? State::absent : e == fixed ? State::fixed : State::free;
}

int DofMap::equation(const NodeDof& nd) const {
  const int i = index_of(nd.node);
  if (i < 0) throw std::invalid_argument("node " + std::to_string(nd.node) + " does not exist");
  const int e = eq_[i][static_cast<int>(nd.dof)];
  if (e == absent)
    throw std::invalid_argument("node " + std::to_string(nd.node) + " has no DOF " +
                                std::string(dof_name(nd.dof)) +
                                (listed_ ? " (it is not among the substructure's DOFs)"
                                         : " (no element or spring at the node uses it)"));
  if (e == fixed) throw std::invalid_argument("DOF " + to_string(nd) + " is fixed by a support");
  return e;
}

std::string DofMap::why_not_free(const NodeDof& nd) const {
  const int i = index_of(nd.node);
  // The DOFs node i has, with `which` (absent: every DOF it has; fixed: the free ones).
  const auto dofs_of = [&](bool free_only) {
    std::string list;
    for (Dof d : all_dofs) {
      const int e = eq_[i][static_cast<int>(d)];
      if (e == absent || (free_only && e == fixed)) continue;
      list += (list.empty() ? "" : ", ") + std::string(dof_name(d));
    }
    return list;
  };
  if (i < 0) {
    if (!listed_)
      return "the model has no node " + std::to_string(nd.node) +
             " (its nodes: " + node_ranges(node_ids_) + ")";
    std::string list;
    for (std::size_t e = 0; e < by_equation_.size() && e < 8; ++e)
      list += (list.empty() ? "" : ", ") + to_string(by_equation_[e]);
    if (by_equation_.size() > 8)
      list += ", … (" + std::to_string(by_equation_.size()) + " DOFs in all)";
    return "the substructure has no DOF at node " + std::to_string(nd.node) +
           " (it is known at its listed DOFs only: " + (list.empty() ? "none" : list) + ")";
  }
  const int e = eq_[i][static_cast<int>(nd.dof)];
  if (e == absent) {
    const std::string has = dofs_of(false);
    return "node " + std::to_string(nd.node) + " has no DOF " + std::string(dof_name(nd.dof)) +
           (listed_ ? " among the substructure's DOFs (" : " in the model (") +
           (has.empty() ? "it has none" : "its DOFs: " + has) + ")";
  }
  if (e == fixed) {
    const std::string free = dofs_of(true);
    return "a support of the model holds " + to_string(nd) + " fixed (" +
           (free.empty() ? "node " + std::to_string(nd.node) + " has no free DOF"
                         : "the free DOFs of node " + std::to_string(nd.node) + ": " + free) +
           ")";
  }
  return "";
}

std::array<int, 6> DofMap::node_equations(int node_id) const {
  const int i = index_of(node_id);
  if (i < 0) throw std::invalid_argument("node " + std::to_string(node_id) + " does not exist");
  std::array<int, 6> out;
  for (int d = 0; d < 6; ++d)
    out[d] = eq_[i][d] >= 0 ? eq_[i][d] : -1;
  return out;
}

std::vector<int> DofMap::equation_nodes() const {
  std::vector<int> out(by_equation_.size());
  for (std::size_t e = 0; e < by_equation_.size(); ++e)
    out[e] = index_of(by_equation_[e].node);
  return out;
}

} // namespace jointid::fem
