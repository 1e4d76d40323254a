#include "fem/zero_modes.hpp"

#include <gtest/gtest.h>

using namespace jointid::fem;

namespace {

// A straight chain of `n` elements of the given type along x (or along a skew line in 3D).
Model chain(ElementType type, int n, int dimension) {
  Model m;
  m.dimension = dimension;
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"s", 1e-3, 1e-6, 1e-6, 2e-6});
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector3d x = dimension == 3 ? Eigen::Vector3d(0.5 * i, 0.3 * i, 0.2 * i)
                                             : Eigen::Vector3d(0.5 * i, 0.0, 0.0);
    m.nodes.push_back({i + 1, x});
  }
  for (int i = 0; i < n; ++i)
    m.elements.push_back({i + 1, i + 1, i + 2, type, 0, 0});
  return m;
}

ZeroModes analyse(const Model& m) {
  const Assembled s = assemble(m);
  return zero_modes(m, s, modal_analysis(s, {.num_modes = 0}));
}

} // namespace

TEST(ZeroModes, FreeBodiesHaveTheirRigidBodyModes) {
  const ZeroModes beam = analyse(chain(ElementType::beam, 4, 2));
  EXPECT_EQ(beam.count, 2); // uy translation and rz rotation
  const ZeroModes frame2d = analyse(chain(ElementType::frame2d, 4, 2));
  EXPECT_EQ(frame2d.count, 3);
  const ZeroModes frame3d = analyse(chain(ElementType::frame3d, 4, 3));
  EXPECT_EQ(frame3d.count, 6);
  for (const ZeroModes& z : {beam, frame2d, frame3d}) {
    EXPECT_FALSE(z.mechanism);
    EXPECT_NE(z.describe().find("rigid-body"), std::string::npos) << z.describe();
  }
}

TEST(ZeroModes, ClampedStructureHasNone) {
  Model m = chain(ElementType::frame3d, 3, 3);
  m.supports.push_back({1, {Dof::ux, Dof::uy, Dof::uz, Dof::rx, Dof::ry, Dof::rz}});
  const ZeroModes z = analyse(m);
  EXPECT_EQ(z.count, 0);
  EXPECT_TRUE(z.describe().empty());
}

TEST(ZeroModes, PinnedBarIsAMechanismAndSaysWhere) {
  // One planar frame member pinned at node 1 (ux, uy held, rotation free): it can swing
  // about the pin without straining, a mechanism with the largest motion at the free end.
  Model m = chain(ElementType::frame2d, 1, 2);
  m.supports.push_back({1, {Dof::ux, Dof::uy}});
  const ZeroModes z = analyse(m);
  EXPECT_EQ(z.count, 1);
  EXPECT_TRUE(z.supported);
  EXPECT_TRUE(z.mechanism);
  EXPECT_NE(z.describe().find("mechanism"), std::string::npos);
  EXPECT_NE(z.describe().find("2:uy"), std::string::npos) << z.describe();
}
