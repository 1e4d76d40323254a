// Assembly: global K and M against hand-assembled element matrices and rigid-body kinematics.
#include "fem/assembly.hpp"

#include "fem/elements.hpp"
#include "support/beam_models.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>

using namespace jointid;
using fem::Dof;

namespace {
using jointid::test::eps;
}

TEST(Assembly, CantileverEqualsHandAssembledBeamWithSupportRowsRemoved) {
  // Hand assembly over all 2(n+1) DOFs [uy_1, rz_1, uy_2, …], then delete node 1's rows and
  // columns: an independent route to the same matrices (sums of the same numbers, so equal to
  // a few eps).
  const test::BeamProperties p;
  const int n = 5;
  const double h = p.length / n;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(2 * n + 2, 2 * n + 2), M = K;
  for (int e = 0; e < n; ++e) {
    K.block<4, 4>(2 * e, 2 * e) += fem::beam_stiffness(p.E * p.I(), h);
    M.block<4, 4>(2 * e, 2 * e) += fem::beam_consistent_mass(p.rho * p.A(), h);
  }
  const fem::Assembled s = fem::assemble(test::cantilever(n, p));
  ASSERT_EQ(s.dofs.num_equations(), 2 * n);
  const Eigen::MatrixXd Ks(s.K), Ms(s.M);
  EXPECT_LE((Ks - K.bottomRightCorner(2 * n, 2 * n)).norm(), 10 * eps * K.norm());
  EXPECT_LE((Ms - M.bottomRightCorner(2 * n, 2 * n)).norm(), 10 * eps * M.norm());
  EXPECT_LE((Ks - Ks.transpose()).norm(), 10 * eps * Ks.norm());
  EXPECT_LE((Ms - Ms.transpose()).norm(), 10 * eps * Ms.norm());
}

TEST(Assembly, TotalMassIncludesPointMasses) {
  // Unit rigid translation of a free beam in y: uᵀ M u = ρ A L + Σ point masses (rotational
  // inertia does not enter a translation).
  const test::BeamProperties p;
  fem::Model m = test::uniform_beam(4, p);
  m.masses.push_back({3, 1.5, Eigen::Vector3d(0.0, 0.0, 0.2)});
  m.masses.push_back({5, 0.25, Eigen::Vector3d::Zero()});
  for (bool lumped : {false, true}) {
    m.mass_options.lumped = lumped;
    const fem::Assembled s = fem::assemble(m);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(s.dofs.num_equations());
    for (int node = 1; node <= 5; ++node)
      u(s.dofs.equation({node, Dof::uy})) = 1.0;
    const double total = p.rho * p.A() * p.length + 1.5 + 0.25;
    EXPECT_NEAR(u.dot(s.M * u), total, 100 * eps * total) << lumped;
    // The rotary inertia 0.2 sits on node 3's rz diagonal.
    const int rz3 = s.dofs.equation({3, Dof::rz});
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(s.dofs.num_equations());
    unit(rz3) = 1.0;
    fem::Model bare = m;
    bare.masses.clear();
    const fem::Assembled sb = fem::assemble(bare);
    EXPECT_NEAR(unit.dot(s.M * unit) - unit.dot(sb.M * unit), 0.2, 1e-12) << lumped;
  }
}

TEST(Assembly, SpringBetweenNodesAndToGround) {
  fem::Model m = test::oscillator(1.0, 300.0);
  m.nodes.push_back({2, Eigen::Vector3d(1.0, 0.0, 0.0)});
  m.masses.push_back({2, 2.0, Eigen::Vector3d::Zero()});
  m.springs.push_back({1, 2, Dof::ux, 50.0});
  const fem::Assembled s = fem::assemble(m);
  ASSERT_EQ(s.dofs.num_equations(), 2);
  Eigen::Matrix2d K_expected, M_expected;
  K_expected << 300.0 + 50.0, -50.0, -50.0, 50.0;
  M_expected << 1.0, 0.0, 0.0, 2.0;
  EXPECT_EQ(Eigen::MatrixXd(s.K), Eigen::MatrixXd(K_expected));
  EXPECT_EQ(Eigen::MatrixXd(s.M), Eigen::MatrixXd(M_expected));
}

TEST(Assembly, RowRangesTogetherGiveTheWholeMatrices) {
  // A distributed assembly: each range's entries lie in its rows, and the three ranges summed
  // give assemble()'s K and M (elements, point masses and a spring between two nodes).
  const test::BeamProperties p;
  fem::Model m = test::uniform_beam(6, p);
  m.masses.push_back({4, 1.5, Eigen::Vector3d(0.0, 0.0, 0.2)});
  m.springs.push_back({2, 6, Dof::uy, 800.0});
  const fem::Assembled whole = fem::assemble(m);
  const int n = whole.dofs.num_equations();
  std::vector<Eigen::Triplet<double>> k, mass;
  for (auto [first, last] : {std::pair{0, 3}, std::pair{3, 7}, std::pair{7, n}}) {
    const fem::Entries part = fem::assemble_rows(m, whole.dofs, first, last);
    for (const auto* list : {&part.K, &part.M})
      for (const auto& t : *list) {
        EXPECT_GE(t.row(), first);
        EXPECT_LT(t.row(), last);
      }
    k.insert(k.end(), part.K.begin(), part.K.end());
    mass.insert(mass.end(), part.M.begin(), part.M.end());
  }
  fem::SparseMatrix K(n, n), M(n, n);
  K.setFromTriplets(k.begin(), k.end());
  M.setFromTriplets(mass.begin(), mass.end());
  EXPECT_EQ(Eigen::MatrixXd(K), Eigen::MatrixXd(whole.K));
  EXPECT_EQ(Eigen::MatrixXd(M), Eigen::MatrixXd(whole.M));
}

TEST(Assembly, FreeLShapedFrameHasThreeRigidModes) {
  // Two frame2d members at a right angle: the assembled K must annihilate the planar rigid
  // motions expressed in global coordinates (this fails if element rotation or DOF scatter is
  // wrong), and nothing else.
  fem::Model m = test::uniform_beam(1, {}, fem::ElementType::frame2d);
  m.nodes.push_back({3, Eigen::Vector3d(2.0, 1.5, 0.0)});
  m.elements.push_back({2, 2, 3, fem::ElementType::frame2d, 0, 0});
  const fem::Assembled s = fem::assemble(m);
  const Eigen::MatrixXd K(s.K);
  ASSERT_EQ(K.rows(), 9);
  Eigen::MatrixXd rigid = Eigen::MatrixXd::Zero(9, 3);
  for (const auto& node : m.nodes) {
    const auto eq = s.dofs.node_equations(node.id);
    rigid(eq[0], 0) = 1.0;
    rigid(eq[1], 1) = 1.0;
    rigid(eq[0], 2) = -node.x.y(); // rotation about the origin: (−y, x), rz = 1
    rigid(eq[1], 2) = node.x.x();
    rigid(eq[5], 2) = 1.0;
  }
  // ‖K r‖ is rounding of cancelling terms of size ‖K‖‖r‖.
  EXPECT_LE((K * rigid).norm(), 100 * eps * K.norm() * rigid.norm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(K);
  EXPECT_GT(es.eigenvalues()(3), 1e-9 * es.eigenvalues()(8));
}

TEST(Assembly, InvalidModelsThrow) {
  fem::Model m = test::cantilever(2);
  m.elements[1].material = 3;
  EXPECT_THROW(fem::assemble(m), std::invalid_argument);
  m = test::cantilever(2);
  m.nodes[2].x = m.nodes[1].x;
  EXPECT_THROW(fem::assemble(m), std::invalid_argument);
  m = test::oscillator(1.0, 1.0);
  m.supports.push_back({1, {Dof::ux}});
  EXPECT_THROW(fem::assemble(m), std::invalid_argument); // no free DOFs
}
