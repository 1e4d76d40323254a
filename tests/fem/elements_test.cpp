// Element kernels against closed-form beam theory and rigid-body kinematics.
#include "fem/elements.hpp"

#include "fem/assembly.hpp"
#include "support/beam_models.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>

using namespace jointid;
using fem::Matrix12;
using fem::Matrix4;
using fem::Matrix6;

namespace {

using jointid::test::eps;

// A null-space check that is scale aware: for an exact null vector u, K u is a sum of terms
// |K_ij u_j| that cancel, so the rounding is a few eps times ‖K‖‖u‖ (100 eps is generous for
// a 12 × 12 matrix, a genuine stiffness would give ‖K u‖ of order ‖K‖‖u‖).
template <class M, class V> double null_residual(const M& K, const V& u) {
  return (K * u).norm() / (K.norm() * u.norm());
}
constexpr double null_tolerance = 100 * eps;

// Skew matrix of a rotation vector: θ × r.
Eigen::Vector3d rotate(const Eigen::Vector3d& theta, const Eigen::Vector3d& r) {
  return theta.cross(r);
}

} // namespace

TEST(BeamElement, StiffnessAndMassAreSymmetric) {
  const Matrix4 K = fem::beam_stiffness(3.7e5, 0.45);
  const Matrix4 M = fem::beam_consistent_mass(12.3, 0.45);
  // The matrices are built symmetric; any asymmetry is a typo in an entry (order 1 relative).
  EXPECT_LE((K - K.transpose()).norm(), eps * K.norm());
  EXPECT_LE((M - M.transpose()).norm(), eps * M.norm());
  // Positive semidefinite stiffness (2 rigid modes), positive definite mass.
  // Dynamic-size solvers: fixed-size ones unroll into thousands of template instances (with
  // them this file took 86 s of CPU to compile at -O3, without them 31 s).
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ek(K), em(M);
  EXPECT_GT(ek.eigenvalues()(2), 0.0);
  EXPECT_GE(ek.eigenvalues()(0), -1e3 * eps * K.norm());
  EXPECT_GT(em.eigenvalues()(0), 0.0);
}

TEST(BeamElement, RigidBodyModesAreInTheNullSpace) {
  const double L = 0.45;
  const Matrix4 K = fem::beam_stiffness(3.7e5, L);
  const Eigen::Vector4d translation(1.0, 0.0, 1.0, 0.0);
  // Rotation θ = 1 about node a: uy = θ x, rz = θ.
  const Eigen::Vector4d rotation(0.0, 1.0, L, 1.0);
  EXPECT_LE(null_residual(K, translation), null_tolerance);
  EXPECT_LE(null_residual(K, rotation), null_tolerance);
  // A bending shape is far outside the null space (so the check above can fail).
  EXPECT_GT(null_residual(K, Eigen::Vector4d(0.0, 1.0, 0.0, -1.0)), 1e6 * null_tolerance);
}

TEST(BeamElement, ConsistentAndLumpedMassCarryTheTotalMass) {
  const double rho_A = 28.18, L = 0.37;
  const Eigen::Vector4d translation(1.0, 0.0, 1.0, 0.0);
  // Kinetic energy of a unit rigid translation: uᵀ M u = ρ A L, to rounding.
  EXPECT_NEAR(translation.dot(fem::beam_consistent_mass(rho_A, L) * translation), rho_A * L,
              10 * eps * rho_A * L);
  EXPECT_NEAR(translation.dot(fem::beam_lumped_mass(rho_A, L) * translation), rho_A * L,
              10 * eps * rho_A * L);
  // Rigid rotation about the element centre: consistent mass gives the exact ρAL³/12 (the
  // interpolation reproduces linear fields).
  const Eigen::Vector4d spin(-L / 2, 1.0, L / 2, 1.0);
  EXPECT_NEAR(spin.dot(fem::beam_consistent_mass(rho_A, L) * spin), rho_A * L * L * L / 12.0,
              10 * eps * rho_A * L * L * L);
}

TEST(BeamElement, LumpedMassIsTheHRZScaledConsistentDiagonal) {
  // HRZ rule: keep the consistent matrix's diagonal, scaled so that the translational entries
  // sum to the element mass ρAL; off-diagonals dropped. Built here from the consistent matrix.
  const double rho_A = 28.18, L = 0.37;
  const Matrix4 consistent = fem::beam_consistent_mass(rho_A, L);
  const double scale = rho_A * L / (consistent(0, 0) + consistent(2, 2));
  const Eigen::Vector4d expected = scale * consistent.diagonal();
  const Matrix4 lumped = fem::beam_lumped_mass(rho_A, L);
  EXPECT_LE((lumped.diagonal() - expected).norm(), 10 * eps * expected.norm());
  EXPECT_EQ((lumped - Matrix4(lumped.diagonal().asDiagonal())).norm(), 0.0);
}

TEST(BeamElement, CantileverTipDeflectionIsExactForAnyElementCount) {
  // Hermite cubics contain the exact static solution for end loads (the moment is linear), so
  // the FE tip deflection equals P L³ / 3EI and the rotation P L² / 2EI up to rounding. The
  // solve's rounding is of order cond(K) eps ≈ n⁴ eps; 1e-9 relative is far above that and far
  // below any discretisation error (a wrong element is off by percent).
  const test::BeamProperties p;
  const double P = 1234.5, EI = p.E * p.I(), L = p.length;
  for (int n : {1, 2, 3, 7, 16}) {
    const fem::Assembled s = fem::assemble(test::cantilever(n, p));
    Eigen::VectorXd f = Eigen::VectorXd::Zero(s.dofs.num_equations());
    f(s.dofs.equation({n + 1, fem::Dof::uy})) = P;
    const Eigen::VectorXd u = Eigen::MatrixXd(s.K).ldlt().solve(f);
    const double tip = u(s.dofs.equation({n + 1, fem::Dof::uy}));
    const double rot = u(s.dofs.equation({n + 1, fem::Dof::rz}));
    EXPECT_NEAR(tip, P * L * L * L / (3 * EI), 1e-9 * P * L * L * L / (3 * EI)) << n << " elements";
    EXPECT_NEAR(rot, P * L * L / (2 * EI), 1e-9 * P * L * L / (2 * EI)) << n << " elements";
    // Mid-span deflection of the end-loaded cantilever, P x² (3L − x) / 6EI, also exact at nodes.
    if (n % 2 == 0) {
      const double x = L / 2;
      const double mid = u(s.dofs.equation({n / 2 + 1, fem::Dof::uy}));
      EXPECT_NEAR(mid, P * x * x * (3 * L - x) / (6 * EI), 1e-9 * P * L * L * L / EI) << n;
    }
  }
}

namespace {

// Local planar frame stiffness built here from its definition: bar EA/L on the axial DOFs and
// the beam matrix on the transverse DOFs, order [u_a, v_a, θ_a, u_b, v_b, θ_b].
Matrix6 local_frame2d(double EA, double EI, double L) {
  Matrix6 k = Matrix6::Zero();
  k(0, 0) = k(3, 3) = EA / L;
  k(0, 3) = k(3, 0) = -EA / L;
  const Matrix4 kb = fem::beam_stiffness(EI, L);
  const int map[4] = {1, 2, 4, 5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      k(map[i], map[j]) = kb(i, j);
  return k;
}

} // namespace

TEST(Frame2dElement, RotatedElementEqualsTransformedLocalMatrix) {
  const double EA = 2.1e9, EI = 3.3e5, L = 1.7, angle = 0.7;
  const double c = std::cos(angle), s = std::sin(angle);
  const Eigen::Vector2d xa(0.3, -0.2), xb = xa + L * Eigen::Vector2d(c, s);
  Matrix6 T = Matrix6::Zero();
  Eigen::Matrix3d r;
  r << c, s, 0, -s, c, 0, 0, 0, 1; // local components = r · global components
  T.block<3, 3>(0, 0) = r;
  T.block<3, 3>(3, 3) = r;
  const Matrix6 expected = T.transpose() * local_frame2d(EA, EI, L) * T;
  const Matrix6 K = fem::frame2d_stiffness(EA, EI, xa, xb);
  // Same arithmetic up to the rounding of the rotation (a few eps of ‖K‖).
  EXPECT_LE((K - expected).norm(), 1e-13 * expected.norm());
  EXPECT_LE((K - K.transpose()).norm(), 1e-14 * K.norm());
}

TEST(Frame2dElement, AxialBarGivesEAOverL) {
  const double EA = 2.1e9, EI = 3.3e5, L = 1.7, angle = -2.1;
  const Eigen::Vector2d e(std::cos(angle), std::sin(angle)), xa(1.0, 2.0), xb = xa + L * e;
  const Matrix6 K = fem::frame2d_stiffness(EA, EI, xa, xb);
  // Stretch the bar by δ = 1 along its axis at node b: the nodal forces are ∓(EA/L) e and there
  // are no moments nor transverse forces.
  Eigen::Matrix<double, 6, 1> u = Eigen::Matrix<double, 6, 1>::Zero();
  u(3) = e.x();
  u(4) = e.y();
  const Eigen::Matrix<double, 6, 1> f = K * u;
  const double tol = 1e-12 * EA / L;
  EXPECT_NEAR(f(3), EA / L * e.x(), tol);
  EXPECT_NEAR(f(4), EA / L * e.y(), tol);
  EXPECT_NEAR(f(0), -EA / L * e.x(), tol);
  EXPECT_NEAR(f(1), -EA / L * e.y(), tol);
  EXPECT_NEAR(f(2), 0.0, tol);
  EXPECT_NEAR(f(5), 0.0, tol);
}

TEST(Frame2dElement, RigidModesAndTranslationMass) {
  const double EA = 2.1e9, EI = 3.3e5, L = 1.7, angle = 2.5, rho_A = 39.0;
  const Eigen::Vector2d xa(0.5, 0.1),
      xb = xa + L * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  const Matrix6 K = fem::frame2d_stiffness(EA, EI, xa, xb);
  using V6 = Eigen::Matrix<double, 6, 1>;
  V6 tx, ty, rot;
  tx << 1, 0, 0, 1, 0, 0;
  ty << 0, 1, 0, 0, 1, 0;
  // Rotation θ = 1 about the origin: (ux, uy) = (−y, x), rz = 1.
  rot << -xa.y(), xa.x(), 1, -xb.y(), xb.x(), 1;
  EXPECT_LE(null_residual(K, tx), null_tolerance);
  EXPECT_LE(null_residual(K, ty), null_tolerance);
  EXPECT_LE(null_residual(K, rot), null_tolerance);
  for (bool lumped : {false, true}) {
    const Matrix6 M = fem::frame2d_mass(rho_A, xa, xb, lumped);
    EXPECT_NEAR(tx.dot(M * tx), rho_A * L, 10 * eps * rho_A * L) << lumped;
    EXPECT_NEAR(ty.dot(M * ty), rho_A * L, 10 * eps * rho_A * L) << lumped;
    EXPECT_NEAR(tx.dot(M * ty), 0.0, 10 * eps * rho_A * L) << lumped;
  }
}

namespace {

struct Frame3dCase {
  fem::Material material{"steel", 210e9, 7850.0, 0.3};
  fem::Section section{"box", 3.1e-3, 4.2e-6, 2.5e-6, 5.0e-6};
  Eigen::Vector3d xa{0.3, -1.2, 0.8};
  Eigen::Vector3d xb{1.4, 0.1, -0.4}; // arbitrary orientation
  Eigen::Vector3d up{0.2, 0.9, 0.4};
  double L() const { return (xb - xa).norm(); }
  // Local axes built here from the header's definition: ex along the element, ey in the plane
  // of ex and `up`, ez = ex × ey.
  Eigen::Vector3d ex() const { return (xb - xa).normalized(); }
  Eigen::Vector3d ez() const { return ex().cross(up).normalized(); }
  Eigen::Vector3d ey() const { return ez().cross(ex()); }
};

using V12 = Eigen::Matrix<double, 12, 1>;

V12 rigid_translation(const Eigen::Vector3d& t) {
  V12 u = V12::Zero();
  u.segment<3>(0) = t;
  u.segment<3>(6) = t;
  return u;
}

V12 rigid_rotation(const Eigen::Vector3d& theta, const Eigen::Vector3d& xa,
                   const Eigen::Vector3d& xb) {
  V12 u;
  u.segment<3>(0) = rotate(theta, xa);
  u.segment<3>(3) = theta;
  u.segment<3>(6) = rotate(theta, xb);
  u.segment<3>(9) = theta;
  return u;
}

} // namespace

TEST(Frame3dElement, SymmetricWithSixRigidModesForAnyOrientation) {
  const Frame3dCase c;
  const Matrix12 K = fem::frame3d_stiffness(c.material, c.section, c.xa, c.xb, c.up);
  EXPECT_LE((K - K.transpose()).norm(), 1e-14 * K.norm());
  for (int d = 0; d < 3; ++d) {
    EXPECT_LE(null_residual(K, rigid_translation(Eigen::Vector3d::Unit(d))), null_tolerance) << d;
    EXPECT_LE(null_residual(K, rigid_rotation(Eigen::Vector3d::Unit(d), c.xa, c.xb)),
              null_tolerance)
        << d;
  }
  // Exactly six: the seventh eigenvalue is a genuine stiffness.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(K);
  EXPECT_LE(es.eigenvalues().head<6>().cwiseAbs().maxCoeff(), 1e3 * eps * K.norm());
  EXPECT_GT(es.eigenvalues()(6), 1e-6 * K.norm());
}

TEST(Frame3dElement, ClampedElementTipFlexibilityMatchesBeamTheory) {
  // Clamp node a, load node b along each local axis: δ = PL/EA (axial), PL³/3EIz (local y),
  // PL³/3EIy (local z), and a torque gives φ = TL/GJ. Hermite beams are exact here, so rounding
  // (cond ≈ 1e4) is all that separates the values: 1e-9 relative.
  const Frame3dCase c;
  const Matrix12 K = fem::frame3d_stiffness(c.material, c.section, c.xa, c.xb, c.up);
  const Eigen::Matrix<double, 6, 6> Kbb = K.bottomRightCorner<6, 6>();
  const Eigen::Matrix<double, 6, 6> flex = Eigen::MatrixXd(Kbb).inverse();
  const double E = c.material.E, G = E / (2 * (1 + c.material.nu)), L = c.L();
  const auto& s = c.section;
  auto translation_along = [&](const Eigen::Vector3d& e) {
    Eigen::Matrix<double, 6, 1> f = Eigen::Matrix<double, 6, 1>::Zero();
    f.head<3>() = e;
    return (flex * f).head<3>().dot(e);
  };
  auto rotation_about = [&](const Eigen::Vector3d& e) {
    Eigen::Matrix<double, 6, 1> f = Eigen::Matrix<double, 6, 1>::Zero();
    f.tail<3>() = e;
    return (flex * f).tail<3>().dot(e);
  };
  auto near = [](double a, double b) { EXPECT_NEAR(a, b, 1e-9 * std::abs(b)); };
  near(translation_along(c.ex()), L / (E * s.A));
  near(translation_along(c.ey()), L * L * L / (3 * E * s.Iz));
  near(translation_along(c.ez()), L * L * L / (3 * E * s.Iy));
  near(rotation_about(c.ex()), L / (G * s.J));
  // End moments: bending about local z with EIz, about local y with EIy: θ = ML/EI.
  near(rotation_about(c.ez()), L / (E * s.Iz));
  near(rotation_about(c.ey()), L / (E * s.Iy));
}

TEST(Frame3dElement, TranslationMassIsRhoAL) {
  const Frame3dCase c;
  const double total = c.material.rho * c.section.A * c.L();
  for (bool lumped : {false, true}) {
    const Matrix12 M = fem::frame3d_mass(c.material, c.section, c.xa, c.xb, c.up, lumped);
    EXPECT_LE((M - M.transpose()).norm(), 1e-14 * M.norm());
    for (int d = 0; d < 3; ++d) {
      const V12 u = rigid_translation(Eigen::Vector3d::Unit(d));
      EXPECT_NEAR(u.dot(M * u), total, 1e-13 * total) << d << " lumped " << lumped;
      const V12 w = rigid_translation(Eigen::Vector3d::Unit((d + 1) % 3));
      EXPECT_NEAR(u.dot(M * w), 0.0, 1e-13 * total) << d << " lumped " << lumped;
    }
  }
}

TEST(Frame3dElement, UpParallelToAxisThrows) {
  const Frame3dCase c;
  EXPECT_THROW(fem::frame3d_stiffness(c.material, c.section, c.xa, c.xb, c.xb - c.xa),
               std::invalid_argument);
}

TEST(Frame3dElement, DefaultUpIsVerticalExceptForVerticalMembers) {
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  EXPECT_EQ(fem::frame3d_default_up(o, {2.0, 1.0, 0.5}), Eigen::Vector3d::UnitZ());
  EXPECT_EQ(fem::frame3d_default_up(o, {0.0, 0.0, 3.0}), Eigen::Vector3d::UnitX());
  EXPECT_EQ(fem::frame3d_default_up({1.0, 1.0, 2.0}, {1.0, 1.0, -1.0}), Eigen::Vector3d::UnitX());
  // Tilted by 1e-3 rad: +z still fixes the section axes (|ex × z| = 1e-3 ≫ 1e-6).
  EXPECT_EQ(fem::frame3d_default_up(o, {1e-3, 0.0, 1.0}), Eigen::Vector3d::UnitZ());
}

TEST(ElementMatrices, AVerticalFrame3dMemberWithoutUpGetsTheDefault) {
  // A column along z, no `up`: accepted, and equal to the same column with up = +x given.
  fem::Model m;
  m.dimension = 3;
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"tube", 1e-3, 2e-6, 3e-6, 4e-6});
  m.nodes = {{1, Eigen::Vector3d::Zero()}, {2, Eigen::Vector3d(0.0, 0.0, 3.0)}};
  m.elements.push_back({1, 1, 2, fem::ElementType::frame3d, 0, 0, std::nullopt});
  const auto by_default = fem::element_matrices(m, m.elements[0]);
  m.elements[0].up = Eigen::Vector3d::UnitX();
  const auto given = fem::element_matrices(m, m.elements[0]);
  EXPECT_EQ((by_default.K - given.K).norm(), 0.0);
  EXPECT_EQ((by_default.M - given.M).norm(), 0.0);
  // With up = +x the local y axis is global x: a tip force along global x bends the column in
  // its local x–y plane (EIz), one along y in the x–z plane (EIy). Clamped at node 1, the tip
  // compliances are L³/(3EIz) and L³/(3EIy).
  const Eigen::Matrix<double, 6, 6> tip = Eigen::MatrixXd(by_default.K.block<6, 6>(6, 6)).inverse();
  const double L3 = 27.0, E = 210e9;
  EXPECT_NEAR(tip(0, 0), L3 / (3.0 * E * 2e-6), 1e-9 * L3 / (3.0 * E * 2e-6));
  EXPECT_NEAR(tip(1, 1), L3 / (3.0 * E * 3e-6), 1e-9 * L3 / (3.0 * E * 3e-6));
}

TEST(ElementMatrices, BeamMustRunAlongPositiveX) {
  fem::Model m = test::uniform_beam(1);
  m.nodes[1].x = Eigen::Vector3d(1.0, 1.0, 0.0);
  EXPECT_THROW(fem::element_matrices(m, m.elements[0]), std::invalid_argument);
  // The same geometry is valid as a frame2d element and equals the kernel.
  m.elements[0].type = fem::ElementType::frame2d;
  const auto em = fem::element_matrices(m, m.elements[0]);
  const auto& mat = m.materials[0];
  const auto& sec = m.sections[0];
  const Matrix6 K = fem::frame2d_stiffness(mat.E * sec.A, mat.E * sec.Iz, Eigen::Vector2d(0, 0),
                                           Eigen::Vector2d(1, 1));
  EXPECT_LE((em.K - Eigen::MatrixXd(K)).norm(), 1e-14 * K.norm());
}

TEST(ElementMatrices, ElementDofsPerType) {
  using fem::Dof;
  const auto beam = fem::element_dofs(fem::ElementType::beam);
  ASSERT_EQ(beam.size(), 2u);
  EXPECT_EQ(beam[0], Dof::uy);
  EXPECT_EQ(beam[1], Dof::rz);
  const auto f2 = fem::element_dofs(fem::ElementType::frame2d);
  ASSERT_EQ(f2.size(), 3u);
  EXPECT_EQ(f2[0], Dof::ux);
  EXPECT_EQ(f2[1], Dof::uy);
  EXPECT_EQ(f2[2], Dof::rz);
  EXPECT_EQ(fem::element_dofs(fem::ElementType::frame3d).size(), 6u);
}
