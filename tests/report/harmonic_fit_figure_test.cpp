// The records-and-harmonic-fits figure of `jointid identify --fit-png`: its data, checked without
// drawing. A harmonic-balance record holds harmonics 0 … 9 exactly, so a fit of 9 harmonics
// leaves only rounding; a fit of the fundamental alone leaves the cubic joint's harmonics.
#include "report/harmonic_fit_figure.hpp"

#include "frf/substructure.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

using namespace jointid;

namespace {

double residual_percent(const std::string& title) {
  const auto at = title.find("residual ");
  return std::stod(title.substr(at + 9));
}

TEST(HarmonicFitFigure, ResidualIsRoundingWithEveryHarmonicAndNotWithTheFundamentalAlone) {
  const frf::Substructure sub(test::paper_cantilever());
  joints::Joint j{"tip",           7,  0, fem::Dof::uy, {joints::Term::k, joints::Term::k3},
                  {4800.0, 1.6e8}, {}, {}};
  j.fixed.assign(2, true);
  identify::SimulationOptions o;
  o.method = identify::SimulationMethod::harmonic_balance;
  o.periods = 2;
  o.steps_per_period = 256;
  const auto simulated =
      identify::simulate_sine_tests(sub, {j}, {7, fem::Dof::uy}, {{1.0, 80.0}, {4.0, 80.0}}, o);
  std::vector<identify::SineTest> tests;
  for (const auto& s : simulated)
    tests.emplace_back(s.record);
  const std::vector<fem::NodeDof> shown{{7, fem::Dof::uy}};
  identify::MeasureOptions all;
  all.harmonics = 9;
  const report::Figure exact = report::harmonic_fit_figure(identify::measure(tests, all), shown);
  ASSERT_EQ(exact.charts.size(), 2u);
  for (const auto& chart : exact.charts) {
    ASSERT_EQ(chart.series.size(), 2u);        // samples, fit
    EXPECT_EQ(chart.series[0].x.size(), 256u); // one averaged period
    EXPECT_LT(residual_percent(chart.title), 1e-8) << chart.title;
  }
  identify::MeasureOptions fundamental;
  fundamental.harmonics = 1;
  const report::Figure rough =
      report::harmonic_fit_figure(identify::measure(tests, fundamental), shown);
  EXPECT_GT(residual_percent(rough.charts[0].title), 1.0) << rough.charts[0].title; // 1 Hz
  // A DOF without a displacement channel: nothing to draw.
  EXPECT_THROW(report::harmonic_fit_figure(identify::measure(tests, all), {{4, fem::Dof::uy}}),
               std::invalid_argument);
}

// The DOFs shown: every joint's DOF at both its nodes, each once, in the joints' order.
TEST(HarmonicFitFigure, ShowsEveryJointDofOnce) {
  using fem::Dof;
  auto joint = [](int node, int node_b, Dof dof) {
    return joints::Joint{"j", node, node_b, dof, {joints::Term::k}, {1.0}, {false}, {}};
  };
  const std::vector<fem::NodeDof> shown = report::harmonic_fit_dofs(
      {joint(7, 0, Dof::uy), joint(3, 5, Dof::uy), joint(3, 0, Dof::ux), joint(5, 7, Dof::uy)});
  const std::vector<fem::NodeDof> expected{{7, Dof::uy}, {3, Dof::uy}, {5, Dof::uy}, {3, Dof::ux}};
  EXPECT_EQ(shown, expected);
  EXPECT_TRUE(report::harmonic_fit_dofs({}).empty());
}

TEST(ParameterFigure, RatiosAndIntervalsOfTheTermsTheModelGives) {
  joints::Joint model{"tip",
                      7,
                      0,
                      fem::Dof::uy,
                      {joints::Term::k, joints::Term::c, joints::Term::k3},
                      {4800.0, 20.0, 0.0},
                      {false, true, false},
                      {true, true, false}};
  identify::FitResult r;
  r.joints.push_back({"tip",
                      {{joints::Term::k, {}, 4896.0, 24.0, 4848.0, 4944.0, false, true},
                       {joints::Term::c, {}, 20.0, 0.0, 20.0, 20.0, true, true},
                       {joints::Term::k3, {}, 1.7e8, 1e6, 1.68e8, 1.72e8, false, true}}});
  const report::Figure f = report::parameter_figure(r, {model});
  ASSERT_EQ(f.charts.size(), 1u);
  const report::Chart& c = f.charts[0];
  // c is fixed and k3 has no value in the model: k alone, at 1.02 with [1.01, 1.03].
  ASSERT_EQ(c.x_categories, std::vector<std::string>{"tip k"});
  ASSERT_EQ(c.series.size(), 3u); // the line at 1, k's interval, the values
  EXPECT_EQ(c.series[0].y, (std::vector<double>{1.0, 1.0}));
  EXPECT_DOUBLE_EQ(c.series[1].y[0], 1.01);
  EXPECT_DOUBLE_EQ(c.series[1].y[1], 1.03);
  EXPECT_DOUBLE_EQ(c.series[2].y[0], 1.02);
  model.given = {false, true, false};
  EXPECT_THROW(report::parameter_figure(r, {model}), std::invalid_argument);
}

} // namespace
