#include "fem/assembly.hpp"

#include "fem/elements.hpp"

#include <algorithm>
#include <stdexcept>

namespace jointid::fem {

Entries assemble_rows(const Model& model, const DofMap& dofs, int first_row, int last_row) {
  Entries out;
  auto& k_entries = out.K;
  auto& m_entries = out.M;
  const auto owned = [&](int eq) { return eq >= first_row && eq < last_row; };
  const std::unordered_map<int, int> index = model.node_positions();

  std::vector<int> eq;
  for (const auto& e : model.elements) {
    const auto local = element_dofs(e.type);
    const int per_node = static_cast<int>(local.size());
    eq.resize(2 * per_node);
    for (int i = 0; i < per_node; ++i) {
      eq[i] = dofs.node_equations(e.node_a)[static_cast<int>(local[i])];
      eq[per_node + i] = dofs.node_equations(e.node_b)[static_cast<int>(local[i])];
    }
    if (std::none_of(eq.begin(), eq.end(), owned)) continue;
    const ElementMatrices em = element_matrices(model, e, model.nodes[index.at(e.node_a)].x,
                                                model.nodes[index.at(e.node_b)].x);
    for (int i = 0; i < 2 * per_node; ++i) {
      if (!owned(eq[i])) continue;
      for (int j = 0; j < 2 * per_node; ++j) {
        if (eq[j] < 0) continue;
        if (em.K(i, j) != 0.0) k_entries.emplace_back(eq[i], eq[j], em.K(i, j));
        if (em.M(i, j) != 0.0) m_entries.emplace_back(eq[i], eq[j], em.M(i, j));
      }
    }
  }
  for (const auto& pm : model.masses) {
    const auto node_eq = dofs.node_equations(pm.node);
    for (int d = 0; d < 6; ++d) {
      if (node_eq[d] < 0 || !owned(node_eq[d])) continue;
      const double value = d < 3 ? pm.mass : pm.inertia[d - 3];
      if (value != 0.0) m_entries.emplace_back(node_eq[d], node_eq[d], value);
    }
  }
  for (const auto& s : model.springs) {
    const int a = dofs.node_equations(s.node)[static_cast<int>(s.dof)];
    const int b = s.node_b != 0 ? dofs.node_equations(s.node_b)[static_cast<int>(s.dof)] : -1;
    if (a >= 0 && owned(a)) k_entries.emplace_back(a, a, s.stiffness);
    if (b >= 0 && owned(b)) k_entries.emplace_back(b, b, s.stiffness);
    if (a >= 0 && b >= 0) {
      if (owned(a)) k_entries.emplace_back(a, b, -s.stiffness);
      if (owned(b)) k_entries.emplace_back(b, a, -s.stiffness);
    }
  }
  return out;
}

Assembled assemble(const Model& model) {
  model.validate();
  Assembled out{DofMap(model), {}, {}};
  const int n = out.dofs.num_equations();
  if (n == 0) throw std::invalid_argument("the model has no free DOFs");
  const Entries entries = assemble_rows(model, out.dofs, 0, n);
  out.K.resize(n, n);
  out.M.resize(n, n);
  out.K.setFromTriplets(entries.K.begin(), entries.K.end());
  out.M.setFromTriplets(entries.M.begin(), entries.M.end());
  return out;
}

} // namespace jointid::fem
