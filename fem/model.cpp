#include "fem/model.hpp"

#include <set>
#include <stdexcept>

namespace jointid::fem {

double Damping::ratio(double omega) const {
  switch (kind) {
  case Kind::none:
    return 0.0;
  case Kind::modal:
    return modal_ratio;
  case Kind::rayleigh:
    return omega > 0.0 ? alpha / (2.0 * omega) + beta * omega / 2.0 : 0.0;
  }
  return 0.0;
}

int Model::node_index(int id) const {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].id == id) return static_cast<int>(i);
  throw std::out_of_range("node " + std::to_string(id) + " does not exist");
}

std::unordered_map<int, int> Model::node_positions() const {
  std::unordered_map<int, int> index;
  index.reserve(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!index.emplace(nodes[i].id, static_cast<int>(i)).second)
      throw std::invalid_argument("duplicate node id " + std::to_string(nodes[i].id));
  return index;
}

bool Model::has_node(int id) const {
  for (const auto& n : nodes)
    if (n.id == id) return true;
  return false;
}

void Model::validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
  if (dimension != 2 && dimension != 3) fail("dimension must be 2 or 3");
  const std::unordered_map<int, int> index = node_positions(); // also rejects duplicate ids
  const auto exists = [&](int id) { return index.count(id) > 0; };
  for (const auto& m : materials) {
    if (!(m.E > 0.0)) fail("material '" + m.name + "': E must be > 0 Pa");
    if (!(m.rho >= 0.0)) fail("material '" + m.name + "': rho must be >= 0 kg/m^3");
  }
  for (const auto& s : sections)
    if (!(s.A > 0.0) || !(s.Iz > 0.0)) fail("section '" + s.name + "': A and Iz must be > 0");
  std::set<int> element_ids;
  for (const auto& e : elements) {
    const std::string which = "element " + std::to_string(e.id);
    if (!element_ids.insert(e.id).second) fail("duplicate element id " + std::to_string(e.id));
    if (!exists(e.node_a) || !exists(e.node_b))
      fail(which + " refers to a node that does not exist");
    if (e.node_a == e.node_b)
      fail(which + " connects node " + std::to_string(e.node_a) + " to itself");
    if (e.material < 0 || e.material >= static_cast<int>(materials.size()))
      fail(which + " has no material");
    if (e.section < 0 || e.section >= static_cast<int>(sections.size()))
      fail(which + " has no section");
    const double length = (nodes[index.at(e.node_b)].x - nodes[index.at(e.node_a)].x).norm();
    if (!(length > 0.0)) fail(which + " has zero length");
    if (e.type == ElementType::frame3d) {
      const auto& s = sections[e.section];
      if (!(s.Iy > 0.0) || !(s.J > 0.0))
        fail(which + ": frame3d needs section '" + s.name + "' with Iy > 0 and J > 0");
    }
    if (dimension == 2 && e.type == ElementType::frame3d)
      fail(which + ": frame3d element in a 2D model (set [model] dimension = 3)");
  }
  for (const auto& s : supports)
    if (!exists(s.node)) fail("support at node " + std::to_string(s.node) + ": no such node");
  for (const auto& m : masses) {
    if (!exists(m.node)) fail("point mass at node " + std::to_string(m.node) + ": no such node");
    if (!(m.mass >= 0.0) || !(m.inertia.minCoeff() >= 0.0))
      fail("point mass at node " + std::to_string(m.node) + ": mass and inertia must be >= 0");
  }
  for (const auto& s : springs) {
    if (!exists(s.node) || (s.node_b != 0 && !exists(s.node_b)))
      fail("spring at node " + std::to_string(s.node) + ": no such node");
    if (!(s.stiffness >= 0.0))
      fail("spring at node " + std::to_string(s.node) + ": stiffness must be >= 0");
  }
  if (damping.kind == Damping::Kind::modal &&
      !(damping.modal_ratio >= 0.0 && damping.modal_ratio < 1.0))
    fail("damping: modal ratio must be in [0, 1)");
  if (damping.kind == Damping::Kind::rayleigh && !(damping.alpha >= 0.0 && damping.beta >= 0.0))
    fail("damping: rayleigh alpha and beta must be >= 0");
}

} // namespace jointid::fem
