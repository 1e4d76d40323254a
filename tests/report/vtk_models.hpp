#pragma once
// Frames built in code for the VTK output tests and the picture demo (SI units): a 3D steel
// portal frame in the x–z plane (z up, clamped feet) and a 2D cantilever of beam elements.
#include "fem/model.hpp"

namespace jointid::test {

/// Portal frame: columns of height 3 m at x = 0 and x = 4 m, a beam across the top, each member
/// split into `per_member` elements, feet clamped. Node ids are multiples of 10 (10, 20, …) so
/// that tests notice an id used as an index.
inline fem::Model portal_frame(int per_member = 1) {
  fem::Model m;
  m.dimension = 3;
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"box", 2.0e-3, 3.0e-6, 2.0e-6, 4.0e-6}); // A, Iz, Iy, J
  const Eigen::Vector3d corners[4] = {{0, 0, 0}, {0, 0, 3}, {4, 0, 3}, {4, 0, 0}};
  int id = 0;
  auto add_node = [&](const Eigen::Vector3d& x) {
    id += 10;
    m.nodes.push_back({id, x});
    return id;
  };
  int previous = add_node(corners[0]);
  for (int member = 0; member < 3; ++member) {
    const Eigen::Vector3d a = corners[member], b = corners[member + 1];
    // Columns (along z) take x as their section's "up"; the beam (along x) takes z.
    const Eigen::Vector3d up = member == 1 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    for (int k = 1; k <= per_member; ++k) {
      const int next = add_node(a + (b - a) * k / per_member);
      m.elements.push_back({static_cast<int>(m.elements.size()) + 1, previous, next,
                            fem::ElementType::frame3d, 0, 0, up});
      previous = next;
    }
  }
  const std::vector<fem::Dof> all(fem::all_dofs.begin(), fem::all_dofs.end());
  m.supports.push_back({m.nodes.front().id, all});
  m.supports.push_back({m.nodes.back().id, all});
  return m;
}

/// Planar cantilever along x of `elements` beam elements (uy and rz only), 2 m long, steel
/// strip 50 mm × 10 mm, clamped at node 1.
inline fem::Model beam_cantilever(int elements = 10) {
  fem::Model m;
  m.dimension = 2;
  const double b = 0.05, t = 0.01;
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"strip", b * t, b * t * t * t / 12.0, 0.0, 0.0});
  for (int i = 0; i <= elements; ++i)
    m.nodes.push_back({i + 1, Eigen::Vector3d(2.0 * i / elements, 0.0, 0.0)});
  for (int i = 0; i < elements; ++i)
    m.elements.push_back({i + 1, i + 1, i + 2, fem::ElementType::beam, 0, 0});
  m.supports.push_back({1, {fem::Dof::ux, fem::Dof::uy, fem::Dof::rz}});
  return m;
}

} // namespace jointid::test
