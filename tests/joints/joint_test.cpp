// Joints: force law, coordinates B, friction limits and validation against the DOF map.
#include "joints/joint.hpp"

#include "support/beam_models.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

using namespace jointid;
using fem::Dof;
using joints::Joint;
using joints::Term;

namespace {

Joint make(std::string name, int node, int node_b, std::vector<Term> terms,
           std::vector<double> values, Dof dof = Dof::uy) {
  Joint j{std::move(name), node, node_b, dof, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

std::string validation_error(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  try {
    joints::validate_joints(joints, dofs);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Cantilever of 4 elements clamped at node 1: nodes 2…5 have free uy and rz.
const fem::DofMap& cantilever_dofs() {
  static const fem::DofMap dofs(test::cantilever(4));
  return dofs;
}

} // namespace

TEST(Joint, ForceIsTheSumOfTermsTimesCoefficients) {
  // Paper model I: g = k y + c ẏ + c2 ẏ|ẏ| + k3 y³, written out.
  const Joint j = make("tip", 5, 0, {Term::k, Term::c, Term::c2, Term::k3}, {4800, 20, 500, 1.6e8});
  for (double y : {-0.02, 0.0, 0.013})
    for (double v : {-0.5, 0.0, 0.31}) {
      const double expected = 4800 * y + 20 * v + 500 * v * std::abs(v) + 1.6e8 * y * y * y;
      EXPECT_NEAR(j.force(y, v), expected, 1e-13 * (1 + std::abs(expected))) << y << " " << v;
    }
  EXPECT_EQ(j.term_index(Term::c2), 2);
  EXPECT_EQ(j.term_index(Term::fc), -1);
  EXPECT_TRUE(j.to_ground());
}

TEST(JointForces, CoordinatesArePlusOneAtNodeAndMinusOneAtNodeB) {
  const fem::DofMap& dofs = cantilever_dofs();
  const std::vector<Joint> js{make("between", 3, 5, {Term::k}, {1.0}),
                              make("ground", 4, 0, {Term::k}, {1.0}),
                              make("rot", 2, 4, {Term::k}, {1.0}, Dof::rz)};
  const joints::JointForces forces(js, dofs);
  const Eigen::MatrixXd B(forces.coordinates());
  ASSERT_EQ(B.rows(), dofs.num_equations());
  ASSERT_EQ(B.cols(), 3);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(dofs.num_equations(), 3);
  expected(dofs.equation({3, Dof::uy}), 0) = 1.0;
  expected(dofs.equation({5, Dof::uy}), 0) = -1.0;
  expected(dofs.equation({4, Dof::uy}), 1) = 1.0;
  expected(dofs.equation({2, Dof::rz}), 2) = 1.0;
  expected(dofs.equation({4, Dof::rz}), 2) = -1.0;
  EXPECT_EQ(B, expected);
  // y = Bᵀu is the relative displacement u(node) − u(node_b).
  Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(dofs.num_equations(), 0.1, 0.9);
  const Eigen::VectorXd y = B.transpose() * u;
  EXPECT_DOUBLE_EQ(y(0), u(dofs.equation({3, Dof::uy})) - u(dofs.equation({5, Dof::uy})));
  EXPECT_EQ(Eigen::MatrixXd(joints::joint_coordinates(js, dofs)), expected);
}

TEST(JointForces, EvaluateLeavesDryFrictionToTheIntegrator) {
  const fem::DofMap& dofs = cantilever_dofs();
  const joints::JointForces forces(
      {make("a", 5, 0, {Term::k, Term::fc, Term::k3, Term::c2}, {4800, 3, 1.6e8, 500}),
       make("b", 2, 3, {Term::c, Term::k2}, {20, 7e3})},
      dofs);
  Eigen::VectorXd y(2), v(2), g, gy, gv;
  y << 0.011, -0.004;
  v << -0.2, 0.05;
  forces.evaluate(y, v, g, gy, gv);
  // Smooth parts written out; fc excluded from g (it is the set-valued λ).
  EXPECT_NEAR(g(0), 4800 * 0.011 + 1.6e8 * std::pow(0.011, 3) - 500 * 0.04, 1e-12 * 300);
  EXPECT_NEAR(gy(0), 4800 + 3 * 1.6e8 * 0.011 * 0.011, 1e-9);
  EXPECT_NEAR(gv(0), 2 * 500 * 0.2, 1e-12);
  EXPECT_NEAR(g(1), 20 * 0.05 + 7e3 * 0.004 * 0.004, 1e-14);
  EXPECT_NEAR(gy(1), 2 * 7e3 * -0.004, 1e-12);
  EXPECT_NEAR(gv(1), 20.0, 1e-14);
  const Eigen::VectorXd F = forces.friction_limits();
  ASSERT_EQ(F.size(), 2);
  EXPECT_EQ(F(0), 3.0);
  EXPECT_EQ(F(1), 0.0);
}

TEST(JointForces, NegativeFrictionCannotBeSimulated) {
  EXPECT_THROW(joints::JointForces({make("a", 5, 0, {Term::fc}, {-1.0})}, cantilever_dofs()),
               std::invalid_argument);
}

TEST(ValidateJoints, NamesTheJointAndTheProblem) {
  const fem::DofMap& dofs = cantilever_dofs();
  EXPECT_EQ(validation_error(
                {make("ok", 5, 0, {Term::k}, {1.0}), make("ok2", 2, 5, {Term::c}, {1.0})}, dofs),
            "");

  std::string e = validation_error({make("clamp", 1, 0, {Term::k}, {1.0})}, dofs);
  EXPECT_TRUE(contains(e, "'clamp'") && contains(e, "fixed")) << e;
  e = validation_error({make("clamp_b", 5, 1, {Term::k}, {1.0})}, dofs);
  EXPECT_TRUE(contains(e, "'clamp_b'") && contains(e, "fixed")) << e;
  e = validation_error({make("twin", 5, 0, {Term::k}, {1.0}), make("twin", 4, 0, {Term::k}, {1.0})},
                       dofs);
  EXPECT_TRUE(contains(e, "duplicate") && contains(e, "'twin'")) << e;
  e = validation_error({make("again", 5, 0, {Term::k, Term::c, Term::k}, {1.0, 2.0, 3.0})}, dofs);
  EXPECT_TRUE(contains(e, "'again'") && contains(e, "'k' twice")) << e;
  e = validation_error({make("self", 3, 3, {Term::k}, {1.0})}, dofs);
  EXPECT_TRUE(contains(e, "'self'") && contains(e, "itself")) << e;
  e = validation_error({make("axial", 5, 0, {Term::k}, {1.0}, Dof::ux)}, dofs);
  EXPECT_TRUE(contains(e, "'axial'") && contains(e, "ux")) << e;
  e = validation_error({make("nowhere", 42, 0, {Term::k}, {1.0})}, dofs);
  EXPECT_TRUE(contains(e, "'nowhere'") && contains(e, "node 42")) << e;
  e = validation_error({make("empty", 5, 0, {}, {})}, dofs);
  EXPECT_TRUE(contains(e, "'empty'")) << e;
  Joint mismatched = make("short", 5, 0, {Term::k, Term::c}, {1.0});
  e = validation_error({mismatched}, dofs);
  EXPECT_TRUE(contains(e, "'short'")) << e;
  e = validation_error({make("", 5, 0, {Term::k}, {1.0})}, dofs);
  EXPECT_FALSE(e.empty());
  // JointForces validates too.
  EXPECT_THROW(joints::JointForces({make("clamp", 1, 0, {Term::k}, {1.0})}, dofs),
               std::invalid_argument);
}
