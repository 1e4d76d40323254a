// Frames against hand-derived frequencies. A frame whose girder (or table top) is rigid and
// carries large lumped masses M at its corners moves in two rigid-top coordinates: the sway δ
// and the rotation θ of the top about the horizontal axis across the sway. Each column is
// clamped at the foot; at its top it has [12, 6h; 6h, 4h²]·EI/h³ for (δ, θ) (Hermite beams are
// exact for end loads), and θ stretches and shortens the columns by θ·a (a: distance from the
// rotation axis), adding EA·a²/h. The columns' own mass adds 13/35 of itself to the sway and
// 1/3 of itself (axial) to the rotation; the neglected mass couplings are O(m/M).
#include "fem/assembly.hpp"
#include "fem/modal.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace jointid::fem;

namespace {

constexpr double E = 210e9, rho = 7850.0, nu = 0.3;

// Materials: 0 steel, 1 a massless, very stiff material for the rigid members.
void add_materials(Model& m) {
  m.materials.push_back({"steel", E, rho, nu});
  m.materials.push_back({"rigid", E * 1e4, 0.0, nu});
}

int add_node(Model& m, const Eigen::Vector3d& x) {
  const int id = static_cast<int>(m.nodes.size()) + 1;
  m.nodes.push_back({id, x});
  return id;
}

// A member from node a to b in `n` elements.
void add_member(Model& m, int a, int b, int n, ElementType type, int material, int section,
                const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ()) {
  const Eigen::Vector3d xa = m.nodes[a - 1].x, xb = m.nodes[b - 1].x;
  int previous = a;
  for (int i = 1; i <= n; ++i) {
    const int next = i == n ? b : add_node(m, xa + (xb - xa) * i / n);
    m.elements.push_back(
        {static_cast<int>(m.elements.size()) + 1, previous, next, type, material, section, up});
    previous = next;
  }
}

} // namespace

// Lowest ω of the 2-DOF (δ, θ) model of n columns (each EI, EA, height h, at distance a from
// the top's rotation axis) under a rigid top of sway mass m_sway and rotary inertia j_rot.
double sway_omega(int n, double EI, double EA, double h, double a, double m_sway, double j_rot) {
  Eigen::Matrix2d K, M;
  K << n * 12 * EI / (h * h * h), n * 6 * EI / (h * h), //
      n * 6 * EI / (h * h), n * (4 * EI / h + EA * a * a / h);
  M << m_sway, 0, 0, j_rot;
  return std::sqrt(
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d>(K, M).eigenvalues()(0));
}

TEST(FrameModes, PortalSwayWithRigidGirder) {
  const double h = 3.0, span = 4.0, A = 5.38e-3, I = 8.356e-5, M = 5000.0;
  Model m;
  m.dimension = 2;
  add_materials(m);
  m.sections.push_back({"IPE300", A, I, 0.0, 0.0});
  m.sections.push_back({"girder", 1.0, 1.0, 0.0, 0.0}); // 12 000 × the columns' I
  const int foot_l = add_node(m, {0, 0, 0}), top_l = add_node(m, {0, h, 0});
  const int top_r = add_node(m, {span, h, 0}), foot_r = add_node(m, {span, 0, 0});
  add_member(m, foot_l, top_l, 6, ElementType::frame2d, 0, 0);
  add_member(m, top_r, foot_r, 6, ElementType::frame2d, 0, 0);
  add_member(m, top_l, top_r, 1, ElementType::frame2d, 1, 1); // massless: no inner nodes
  for (int foot : {foot_l, foot_r})
    m.supports.push_back({foot, {Dof::ux, Dof::uy, Dof::rz}});
  for (int top : {top_l, top_r})
    m.masses.push_back({top, M, Eigen::Vector3d::Zero()});
  const Modes modes = modal_analysis(assemble(m), {.num_modes = 1});
  ASSERT_TRUE(modes.status.ok());
  const double column = rho * A * h, a = span / 2;
  const double expected = sway_omega(2, E * I, E * A, h, a, 2 * M + 2 * 13.0 / 35.0 * column,
                                     (2 * M + 2 * column / 3.0) * a * a);
  // Without the column's axial strain the sway would be 0.6 % stiffer in ω: the model matters.
  const double no_overturning =
      std::sqrt(2 * 12 * E * I / (h * h * h) / (2 * M + 2 * 13.0 / 35.0 * column));
  EXPECT_GT(std::abs(no_overturning / expected - 1.0), 5e-3);
  // Neglected: mass couplings O(m/M) ≈ 2.5 % of the columns' small share; girder flexibility.
  EXPECT_NEAR(modes.omega(0), expected, 5e-4 * expected);
}

TEST(FrameModes, TableSwayAndTorsionWithRigidTop) {
  // Four legs of height H with different bending stiffness about the two section axes, under a
  // (nearly) rigid top frame Lx × Ly with mass M at each corner.
  const double H = 0.75, Lx = 1.2, Ly = 0.8, M = 200.0;
  const double A = 4.21e-4, Iz = 9.32e-8, Iy = 4.0e-8, J = 1.55e-7;
  Model m;
  m.dimension = 3;
  add_materials(m);
  m.sections.push_back({"leg", A, Iz, Iy, J});
  // Stiff but not extreme (1000 × the legs' I): a larger contrast would only cost the dense
  // eigensolver accuracy (its error is about eps · λ_max).
  m.sections.push_back({"top", 1e-2, 1e-4, 1e-4, 1e-4});
  const double xs[4] = {0, Lx, Lx, 0}, ys[4] = {0, 0, Ly, Ly};
  int tops[4];
  for (int c = 0; c < 4; ++c) {
    const int foot = add_node(m, {xs[c], ys[c], 0.0});
    tops[c] = add_node(m, {xs[c], ys[c], H});
    // up = x: the leg's local y axis is global x, so Iz resists sway in x and Iy sway in y.
    add_member(m, foot, tops[c], 4, ElementType::frame3d, 0, 0, Eigen::Vector3d::UnitX());
    m.supports.push_back({foot, {Dof::ux, Dof::uy, Dof::uz, Dof::rx, Dof::ry, Dof::rz}});
    m.masses.push_back({tops[c], M, Eigen::Vector3d::Zero()});
  }
  // The top is massless (material 1, rho = 0): one element per side, no inner nodes.
  for (int c = 0; c < 4; ++c)
    add_member(m, tops[c], tops[(c + 1) % 4], 1, ElementType::frame3d, 1, 1);
  m.materials[1].E = E;
  const Modes modes = modal_analysis(assemble(m), {.num_modes = 3});
  ASSERT_TRUE(modes.status.ok());

  const double leg = rho * A * H, H3 = H * H * H, G = E / (2 * (1 + nu));
  const double m_sway = 4 * M + 4 * 13.0 / 35.0 * leg;
  const double sway_x =
      sway_omega(4, E * Iz, E * A, H, Lx / 2, m_sway, (4 * M + 4 * leg / 3.0) * Lx * Lx / 4);
  const double sway_y =
      sway_omega(4, E * Iy, E * A, H, Ly / 2, m_sway, (4 * M + 4 * leg / 3.0) * Ly * Ly / 4);
  // Torsion about the vertical axis through the centre: each leg top moves θ·r tangentially
  // (θ·ry along x, θ·rx along y) with its top held from rotating, and twists by θ (GJ/H).
  const double rx = Lx / 2, ry = Ly / 2, r2 = rx * rx + ry * ry;
  const double k_theta =
      4.0 * (12.0 * E * Iz / H3 * ry * ry + 12.0 * E * Iy / H3 * rx * rx + G * J / H);
  const double torsion = std::sqrt(k_theta / (4.0 * (M + 13.0 / 35.0 * leg) * r2));
  std::vector<double> expected{sway_y, sway_x, torsion};
  std::sort(expected.begin(), expected.end());
  // Tolerance: the top's flexibility (its rotational restraint is ~1600 × the legs') and mass
  // couplings O(m/M) of the legs' small share.
  for (int r = 0; r < 3; ++r)
    EXPECT_NEAR(modes.omega(r), expected[r], 1e-3 * expected[r]) << "mode " << r + 1;
}
