#pragma once
// The paper's 6-element cantilever (METHOD.md), built in code for tests that must not depend
// on the model-file reader: steel, L = 2 m, width 0.25 m, thickness 14.3623 mm (first mode
// 3.000 Hz), clamped at node 1, 1 % modal damping.
#include "fem/dof.hpp"
#include "fem/model.hpp"

namespace jointid::test {

inline fem::Model paper_cantilever(int elements = 6) {
  fem::Model m;
  m.dimension = 2;
  const double L = 2.0, b = 0.25, t = 0.0143622750907616;
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"strip", b * t, b * t * t * t / 12.0, 0.0, 0.0});
  for (int i = 0; i <= elements; ++i)
    m.nodes.push_back({i + 1, Eigen::Vector3d(L * i / elements, 0.0, 0.0)});
  for (int i = 0; i < elements; ++i)
    m.elements.push_back({i + 1, i + 1, i + 2, fem::ElementType::beam, 0, 0});
  m.supports.push_back({1, {fem::Dof::ux, fem::Dof::uy, fem::Dof::rz}});
  m.damping.kind = fem::Damping::Kind::modal;
  m.damping.modal_ratio = 0.01;
  return m;
}

// Its tip and mid-span deflections.
inline const fem::NodeDof tip{7, fem::Dof::uy}, mid{4, fem::Dof::uy};

} // namespace jointid::test
