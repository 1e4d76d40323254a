// DOF map: which DOFs exist, which are fixed, and how equations are numbered.
#include "fem/dof_map.hpp"

#include "support/beam_models.hpp"

#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>
#include <vector>

using namespace jointid;
using fem::Dof;
using State = fem::DofMap::State;

namespace {

// The message of the std::invalid_argument thrown by dofs.equation(nd), or "" if none.
std::string equation_error(const fem::DofMap& dofs, fem::NodeDof nd) {
  try {
    dofs.equation(nd);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

} // namespace

TEST(DofMap, BeamNodesHaveOnlyUyAndRz) {
  const fem::DofMap dofs(test::uniform_beam(3));
  EXPECT_EQ(dofs.num_equations(), 4 * 2);
  for (int node = 1; node <= 4; ++node)
    for (Dof d : fem::all_dofs) {
      const bool used = d == Dof::uy || d == Dof::rz;
      EXPECT_EQ(dofs.state({node, d}), used ? State::free : State::absent)
          << "node " << node << " " << fem::dof_name(d);
    }
}

TEST(DofMap, FrameElementsUseTheirDofs) {
  fem::Model m = test::uniform_beam(2, {}, fem::ElementType::frame2d);
  const fem::DofMap planar(m);
  EXPECT_EQ(planar.num_equations(), 3 * 3);
  EXPECT_EQ(planar.state({2, Dof::ux}), State::free);
  EXPECT_EQ(planar.state({2, Dof::uz}), State::absent);
  m.dimension = 3;
  for (auto& e : m.elements)
    e.type = fem::ElementType::frame3d;
  m.sections[0].Iy = m.sections[0].J = 1e-6;
  const fem::DofMap spatial(m);
  EXPECT_EQ(spatial.num_equations(), 3 * 6);
}

TEST(DofMap, SupportsRemoveDofsAndEquationsAreContiguous) {
  fem::Model m = test::cantilever(3); // node 1 fixed (ux listed too, which it does not have)
  m.supports.push_back({4, {Dof::uy}});
  const fem::DofMap dofs(m);
  EXPECT_EQ(dofs.num_equations(), 4 * 2 - 2 - 1);
  EXPECT_EQ(dofs.state({1, Dof::uy}), State::fixed);
  EXPECT_EQ(dofs.state({1, Dof::rz}), State::fixed);
  EXPECT_EQ(dofs.state({1, Dof::ux}), State::absent); // a support does not create a DOF
  EXPECT_EQ(dofs.state({4, Dof::uy}), State::fixed);
  EXPECT_EQ(dofs.state({4, Dof::rz}), State::free);

  // Every equation 0 … n−1 appears exactly once, node by node in model order, DOFs in order
  // ux … rz; node_dof is the inverse of equation.
  int expected = 0;
  std::set<int> seen;
  for (int node : dofs.node_ids()) {
    const auto eqs = dofs.node_equations(node);
    for (int d = 0; d < fem::num_dof_kinds; ++d) {
      const fem::NodeDof nd{node, static_cast<Dof>(d)};
      if (dofs.state(nd) != State::free) {
        EXPECT_EQ(eqs[d], -1);
        continue;
      }
      EXPECT_EQ(eqs[d], expected);
      EXPECT_EQ(dofs.equation(nd), expected);
      EXPECT_EQ(dofs.node_dof(expected), nd);
      seen.insert(expected++);
    }
  }
  EXPECT_EQ(expected, dofs.num_equations());
  EXPECT_EQ(static_cast<int>(seen.size()), dofs.num_equations());
}

TEST(DofMap, AbsentOrFixedDofThrowsNamingNodeAndDof) {
  const fem::DofMap dofs(test::cantilever(2));
  const std::string fixed = equation_error(dofs, {1, Dof::uy});
  EXPECT_TRUE(contains(fixed, "1:uy") && contains(fixed, "fixed")) << fixed;
  const std::string absent = equation_error(dofs, {2, Dof::ux});
  EXPECT_TRUE(contains(absent, "node 2") && contains(absent, "ux")) << absent;
  const std::string missing = equation_error(dofs, {99, Dof::uy});
  EXPECT_TRUE(contains(missing, "node 99") && contains(missing, "does not exist")) << missing;
  EXPECT_THROW(dofs.node_equations(99), std::invalid_argument);
  EXPECT_EQ(dofs.state({99, Dof::uy}), State::absent);
}

TEST(DofMap, WhyNotFreeSaysWhatTheModelHas) {
  // A planar cantilever of beam elements: nodes 1–3, each with uy and rz; node 1 clamped.
  const fem::DofMap dofs(test::cantilever(2));
  EXPECT_EQ(dofs.why_not_free({2, Dof::uy}), "");
  EXPECT_EQ(dofs.why_not_free({99, Dof::uy}), "the model has no node 99 (its nodes: 1–3)");
  EXPECT_EQ(dofs.why_not_free({2, Dof::ux}),
            "node 2 has no DOF ux in the model (its DOFs: uy, rz)");
  EXPECT_EQ(dofs.why_not_free({1, Dof::uy}),
            "a support of the model holds 1:uy fixed (node 1 has no free DOF)");
  fem::Model pinned = test::cantilever(2);
  pinned.supports[0].fixed = {Dof::uy};
  EXPECT_EQ(fem::DofMap(pinned).why_not_free({1, Dof::uy}),
            "a support of the model holds 1:uy fixed (the free DOFs of node 1: rz)");
  // Node ids as sorted ranges, a pair as two ids, at most six ranges.
  fem::Model scattered = test::uniform_beam(9); // nodes 1–10
  for (int id : {22, 12, 20, 21, 14})
    scattered.nodes.push_back({id, Eigen::Vector3d(id, 1.0, 0.0)});
  EXPECT_EQ(fem::DofMap(scattered).why_not_free({11, Dof::uy}),
            "the model has no node 11 (its nodes: 1–10, 12, 14, 20–22)");
  for (int id : {30, 31, 40, 50, 60})
    scattered.nodes.push_back({id, Eigen::Vector3d(id, 1.0, 0.0)});
  EXPECT_EQ(fem::DofMap(scattered).why_not_free({11, Dof::uy}),
            "the model has no node 11 (its nodes: 1–10, 12, 14, 20–22, 30, 31, 40, … (20 nodes "
            "in all))");
  // A substructure known at a few DOFs only.
  const fem::DofMap listed = fem::DofMap::from_dofs({{4, Dof::uy}, {7, Dof::uy}});
  EXPECT_EQ(listed.why_not_free({5, Dof::uy}),
            "the substructure has no DOF at node 5 (it is known at its listed DOFs only: 4:uy, "
            "7:uy)");
  EXPECT_EQ(listed.why_not_free({4, Dof::rz}),
            "node 4 has no DOF rz among the substructure's DOFs (its DOFs: uy)");
}

TEST(DofMap, SpringsAddTheirDofs) {
  // A grounded spring on ux of a beam node gives that node an ux DOF; a spring between two
  // nodes gives both the DOF.
  fem::Model m = test::uniform_beam(2);
  m.springs.push_back({2, 0, Dof::ux, 1e3});
  m.nodes.push_back({10, Eigen::Vector3d(5, 0, 0)});
  m.springs.push_back({3, 10, Dof::uz, 1e3});
  const fem::DofMap dofs(m);
  EXPECT_EQ(dofs.state({2, Dof::ux}), State::free);
  EXPECT_EQ(dofs.state({1, Dof::ux}), State::absent);
  EXPECT_EQ(dofs.state({3, Dof::uz}), State::free);
  EXPECT_EQ(dofs.state({10, Dof::uz}), State::free);
  EXPECT_EQ(dofs.num_equations(), 3 * 2 + 1 + 2);
}

TEST(DofMap, SingleOscillatorWithoutElements) {
  const fem::Model m = test::oscillator(2.0, 800.0);
  const fem::DofMap dofs(m);
  ASSERT_EQ(dofs.num_equations(), 1);
  EXPECT_EQ(dofs.equation({1, Dof::ux}), 0);
  EXPECT_EQ(dofs.state({1, Dof::uy}), State::absent);
  // The assembled system is the 1 × 1 pair (k, m).
  const fem::Assembled s = fem::assemble(m);
  EXPECT_EQ(Eigen::MatrixXd(s.K)(0, 0), 800.0);
  EXPECT_EQ(Eigen::MatrixXd(s.M)(0, 0), 2.0);
}

TEST(DofMap, FromDofsNumbersInListOrder) {
  // A substructure known only at these DOFs (e.g. by its modes): equation e is the e-th entry,
  // nodes in order of first appearance, whatever the node ids and DOF kinds.
  const std::vector<fem::NodeDof> list{{4, Dof::uy}, {1, Dof::rz}, {4, Dof::ux}, {9, Dof::uz}};
  const fem::DofMap dofs = fem::DofMap::from_dofs(list);
  ASSERT_EQ(dofs.num_equations(), 4);
  for (int e = 0; e < 4; ++e) {
    EXPECT_EQ(dofs.equation(list[e]), e);
    EXPECT_EQ(dofs.node_dof(e), list[e]);
    EXPECT_EQ(dofs.state(list[e]), State::free);
  }
  EXPECT_EQ(dofs.node_ids(), (std::vector<int>{4, 1, 9}));
  EXPECT_EQ(dofs.node_equations(4), (std::array<int, 6>{2, 0, -1, -1, -1, -1}));
  EXPECT_EQ(dofs.node_equations(1), (std::array<int, 6>{-1, -1, -1, -1, -1, 1}));
  EXPECT_EQ(dofs.equation_nodes(), (std::vector<int>{0, 1, 0, 2}));
  // Every other DOF of a listed node is absent, never fixed.
  for (Dof d : {Dof::uz, Dof::rx, Dof::ry, Dof::rz})
    EXPECT_EQ(dofs.state({4, d}), State::absent) << fem::dof_name(d);
  EXPECT_EQ(dofs.state({1, Dof::uy}), State::absent);
  EXPECT_EQ(dofs.state({2, Dof::uy}), State::absent); // not a node of the list
  EXPECT_EQ(fem::DofMap::from_dofs({}).num_equations(), 0);
}

TEST(DofMap, FromDofsErrors) {
  const fem::DofMap dofs = fem::DofMap::from_dofs({{4, Dof::uy}, {7, Dof::uy}});
  const std::string absent = equation_error(dofs, {4, Dof::rz});
  EXPECT_TRUE(contains(absent, "node 4") && contains(absent, "rz") &&
              contains(absent, "not among the substructure's DOFs"))
      << absent;
  const std::string missing = equation_error(dofs, {5, Dof::uy});
  EXPECT_TRUE(contains(missing, "node 5") && contains(missing, "does not exist")) << missing;
  EXPECT_THROW(dofs.node_equations(5), std::invalid_argument);
  try {
    fem::DofMap::from_dofs({{4, Dof::uy}, {7, Dof::uy}, {4, Dof::uy}});
    FAIL() << "a DOF listed twice was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "4:uy") && contains(e.what(), "twice")) << e.what();
  }
}
