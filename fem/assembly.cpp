#include "fem/assembly.hpp"

#include "fem/elements.hpp"

#include <stdexcept>

namespace jointid::fem {

Assembled assemble(const Model& model) {
  model.validate();
  Assembled out{DofMap(model), {}, {}};
  const DofMap& dofs = out.dofs;
  const int n = dofs.num_equations();
  if (n == 0) throw std::invalid_argument("the model has no free DOFs");
  std::vector<Eigen::Triplet<double>> k_entries, m_entries;
  const std::unordered_map<int, int> index = model.node_positions();

  for (const auto& e : model.elements) {
    const ElementMatrices em = element_matrices(model, e, model.nodes[index.at(e.node_a)].x,
                                                model.nodes[index.at(e.node_b)].x);
    const auto local = element_dofs(e.type);
    const int per_node = static_cast<int>(local.size());
    std::vector<int> eq(2 * per_node);
    for (int i = 0; i < per_node; ++i) {
      eq[i] = dofs.node_equations(e.node_a)[static_cast<int>(local[i])];
      eq[per_node + i] = dofs.node_equations(e.node_b)[static_cast<int>(local[i])];
    }
    for (int i = 0; i < 2 * per_node; ++i) {
      if (eq[i] < 0) continue;
      for (int j = 0; j < 2 * per_node; ++j) {
        if (eq[j] < 0) continue;
        if (em.K(i, j) != 0.0) k_entries.emplace_back(eq[i], eq[j], em.K(i, j));
        if (em.M(i, j) != 0.0) m_entries.emplace_back(eq[i], eq[j], em.M(i, j));
      }
    }
  }
  for (const auto& pm : model.masses) {
    const auto eq = dofs.node_equations(pm.node);
    for (int d = 0; d < 6; ++d) {
      if (eq[d] < 0) continue;
      const double value = d < 3 ? pm.mass : pm.inertia[d - 3];
      if (value != 0.0) m_entries.emplace_back(eq[d], eq[d], value);
    }
  }
  for (const auto& s : model.springs) {
    const int a = dofs.node_equations(s.node)[static_cast<int>(s.dof)];
    const int b = s.node_b != 0 ? dofs.node_equations(s.node_b)[static_cast<int>(s.dof)] : -1;
    if (a >= 0) k_entries.emplace_back(a, a, s.stiffness);
    if (b >= 0) k_entries.emplace_back(b, b, s.stiffness);
    if (a >= 0 && b >= 0) {
      k_entries.emplace_back(a, b, -s.stiffness);
      k_entries.emplace_back(b, a, -s.stiffness);
    }
  }
  out.K.resize(n, n);
  out.M.resize(n, n);
  out.K.setFromTriplets(k_entries.begin(), k_entries.end());
  out.M.setFromTriplets(m_entries.begin(), m_entries.end());
  return out;
}

} // namespace jointid::fem
