// The problem discovery works on, on a substructure whose response is known in closed form: the
// re-simulation of every test against the exact receptance, its gap and criterion, and the
// set-up's refusals.
#include "discover/problem.hpp"
#include "discover/selection.hpp"

#include "one_mode.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid {
namespace {

using namespace discover::detail;

TEST(Problem, ReSimulatesEveryTestAsTheClosedForm) {
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  const auto tests = m.tests({2.5, 3.0, 3.5, 4.0}, 10.0);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  EXPECT_EQ(problem.compared().values, 8);
  EXPECT_TRUE(problem.compared().noise_known);
  // The true joint: every fundamental as the closed form, the gap at rounding.
  const discover::State truth = problem.evaluate({m.joint(m.k, m.c)}, problem.simulator(1.0));
  ASSERT_TRUE(truth.converged);
  EXPECT_EQ(truth.parameters, 2);
  for (std::size_t i = 0; i < tests.size(); ++i)
    EXPECT_LT(std::abs(truth.X[i](1, 0) - tests[i].X(1, 0)), 1e-9 * std::abs(tests[i].X(1, 0)))
        << tests[i].source;
  EXPECT_LT(truth.gap, 1e-9);
  // Another stiffness: its gap is the closed form's relative difference.
  const discover::State stiffer = problem.evaluate({m.joint(500.0, m.c)}, problem.simulator(1.0));
  double S = 0.0, S0 = 0.0;
  for (const auto& t : tests) {
    const std::complex<double> X = m.receptance(t.frequency_hz, 500.0, m.c) * t.F(1, 0);
    S += std::norm(t.X(1, 0) - X), S0 += std::norm(t.X(1, 0));
  }
  EXPECT_NEAR(stiffer.gap, std::sqrt(S / S0), 1e-9 * std::sqrt(S / S0));
  // χ² weighs each squared difference by its variance over its 2 real values.
  EXPECT_NEAR(stiffer.chi2, 2.0 * S / 1e-16, 1e-8 * 2.0 * S / 1e-16);
  // Held terms are not parameters; a damping scale is one.
  EXPECT_EQ(problem.parameters({m.joint(m.k, m.c, true)}, 1.0), 0);
  EXPECT_EQ(problem.parameters({m.joint(m.k, m.c)}, 1.5), 3);
}

TEST(Problem, ADampingScaleScalesTheSubstructuresDamping) {
  // The substructure's damping doubled is the closed form with ζ doubled.
  test::OneMode m;
  const frf::Substructure sub = m.substructure();
  const auto tests = m.tests({2.5, 3.0, 3.5}, 10.0);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const auto sim = problem.make_simulator(2.0, false);
  const discover::State s = problem.evaluate({m.joint(m.k, m.c)}, *sim);
  EXPECT_EQ(s.damping_scale, 2.0);
  m.zeta *= 2.0;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const std::complex<double> X = m.receptance(tests[i].frequency_hz, m.k, m.c) * tests[i].F(1, 0);
    EXPECT_LT(std::abs(s.X[i](1, 0) - X), 1e-9 * std::abs(X));
  }
}

TEST(Problem, RefusesWhatCannotBeCompared) {
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  const auto tests = m.tests({3.0}, 10.0);
  auto refused = [&](const std::vector<identify::Measurement>& t,
                     const std::vector<joints::Joint>& start, const discover::Options& o) {
    try {
      Problem problem(sub, start, t, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const discover::Options o = test::fundamental_only();
  EXPECT_EQ(refused({}, {m.joint(0.0, 0.0)}, o), "discover: no tests");
  EXPECT_EQ(refused(tests, {}, o), "discover: the model has no joints");
  discover::Options few = o;
  few.harmonics = {1, 2, 3, 4};
  EXPECT_EQ(refused(tests, {m.joint(0.0, 0.0)}, few),
            "discover: the harmonic balance needs at least as many harmonics as are compared");
  few.balance.harmonics = 15;
  EXPECT_NE(refused(tests, {m.joint(0.0, 0.0)}, few)
                .find("measured to harmonic 1, but 4 are "
                      "compared"),
            std::string::npos);
  // A force or response channel the substructure lacks is the test's fault: named with its
  // channel and what the substructure has (its [modal] DOFs here).
  auto foreign = tests;
  foreign[0].force_at[0] = {99, fem::Dof::uy};
  EXPECT_EQ(refused(foreign, {m.joint(0.0, 0.0)}, o),
            tests[0].source + ": force channel f@99:uy: the substructure has no DOF at node 99 (it "
                              "is known at its listed DOFs only: 7:uy)");
  foreign = tests;
  foreign[0].response_at.push_back({7, fem::Dof::rz});
  foreign[0].measured_as.push_back(identify::Quantity::displacement);
  EXPECT_EQ(refused(foreign, {m.joint(0.0, 0.0)}, o),
            tests[0].source + ": channel x@7:rz: node 7 has no DOF rz among the substructure's "
                              "DOFs (its DOFs: uy)");
  auto silent = tests;
  silent[0].X.setZero();
  EXPECT_EQ(refused(silent, {m.joint(0.0, 0.0)}, o), "discover: every response is zero");
}

} // namespace
} // namespace jointid

namespace jointid {
namespace {

using namespace discover::detail;

// Rule 1's stability: the one mode's static stiffness at 7:uy is ω₀²/φ² (3 Hz, φ = 0.25 /√kg:
// 5685 N/m). A joint to ground whose linear stiffness is below minus that has no stable state
// at rest — with a Jenkins element beside it too, once that slips — whatever the harmonic
// balance finds at the tests; above it, the model stands.
TEST(Problem, AModelWithoutAStableStateAtRestIsNotPhysical) {
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  const auto tests = m.tests({2.5, 3.0, 3.5, 4.0}, 10.0);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const double w0 = 2.0 * std::numbers::pi * m.f0, held = w0 * w0 / (m.phi * m.phi);
  EXPECT_EQ(problem.stability_problem({m.joint(-0.99 * held, m.c)}), "");
  EXPECT_EQ(problem.stability_problem({m.joint(1e6, m.c)}), "");
  const std::string why = problem.stability_problem({m.joint(-1.01 * held, m.c)});
  EXPECT_EQ(why.rfind("not physical: with its friction slipping and its gaps open, 'tip' keeps "
                      "k = -5742 N/m where the substructure holds 5685 N/m",
                      0),
            0u)
      << why;
  // A Jenkins element that holds it while stuck does not: it slips.
  joints::Joint slipping{"tip",
                         7,
                         0,
                         fem::Dof::uy,
                         {joints::Term::k, joints::Term::c, joints::Term::jenkins},
                         {-2.0 * held, m.c, 1.0},
                         {false, false, false},
                         {}};
  slipping.parameters.resize(3);
  slipping.set_parameters(2, {3.0 * held, 1.0});
  EXPECT_NE(problem.stability_problem({slipping}), "");
  // The state carries it, and rule 1 rejects a candidate with it.
  const discover::State s = problem.evaluate({m.joint(-2.0 * held, m.c)}, problem.simulator(1.0));
  EXPECT_EQ(s.unstable, problem.stability_problem({m.joint(-2.0 * held, m.c)}));
  discover::Candidate c;
  c.joint = "tip";
  c.refit = true;
  judge(c, s);
  EXPECT_EQ(c.rejected, s.unstable);
}

} // namespace
} // namespace jointid
