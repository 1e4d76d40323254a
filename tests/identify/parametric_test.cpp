// The parametric terms' identification: the describing function against closed forms, and each
// term simulated by time integration (Newmark, exact slider states and contact: independent of
// the harmonic balance the output error fits with) and identified back; an iwan kept in
// microslip has kt apart from k and fs apart from beta said undetermined, never given a value.
#include "identify/parametric.hpp"

#include "identify/output_error.hpp"
#include "identify/sine_tests.hpp"
#include "joints/hysteresis.hpp"
#include "support/cantilever.hpp"
#include "support/failing_substructure.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>

namespace jointid {
namespace {

using jointid::test::pi;
using joints::Term;

// The paper's cantilever tip: k, c and one parametric term.
joints::Joint tip(Term term, const std::vector<double>& parameters, bool fixed = false) {
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, {Term::k, Term::c, term}, {4800.0, 20.0, 1.0}, {}, {}};
  j.fixed.assign(3, false);
  j.set_parameters(2, parameters, fixed);
  return j;
}

// The first harmonic of the steady loop sampled at N points of y = a cos θ: G₁/a, G₁ = (2/N) Σ
// g e^{−iθ} (a second method: the return map of every slider, or the gap's force, sample by
// sample).
std::complex<double> sampled_describing_function(const joints::Joint& j, double a, int N) {
  std::vector<double> y(static_cast<std::size_t>(N)), g(y.size());
  for (int s = 0; s < N; ++s)
    y[static_cast<std::size_t>(s)] = a * std::cos(2.0 * pi * s / N);
  if (j.terms[2] == Term::gap) {
    for (std::size_t s = 0; s < y.size(); ++s)
      g[s] = joints::gap_force(j.parameter(2, "delta"), j.parameter(2, "kg"), y[s]);
  } else {
    const joints::Sliders sliders =
        j.terms[2] == Term::jenkins
            ? joints::jenkins_sliders(j.parameter(2, "kt"), j.parameter(2, "fs"))
            : joints::iwan_sliders(j.parameter(2, "fs"), j.parameter(2, "kt"),
                                   j.parameter(2, "chi"), j.parameter(2, "beta"), j.iwan_sliders);
    joints::LoopWork work;
    EXPECT_TRUE(joints::steady_loop(sliders, y, false, g, nullptr, work));
  }
  std::complex<double> G1 = 0.0;
  for (int s = 0; s < N; ++s)
    G1 += g[static_cast<std::size_t>(s)] * std::polar(1.0, -2.0 * pi * s / N);
  return G1 * (2.0 / N) / a;
}

TEST(DescribingFunction, ClosedFormIsTheSampledSteadyLoopsFirstHarmonic) {
  // Jenkins (kt, fs) at a > fs/kt: the loop's area 4 fs (a − fs/kt) is π a² Im N; stuck, the
  // spring alone. Gap (δ, kg) at a > δ: N = kg (1 − (2/π)(asin(δ/a) + (δ/a)√(1 − (δ/a)²))),
  // real. Every term (an iwan's 100 sliders too) against its loop sampled at N points, which
  // integrates the loop's kinks with an error of order (2π/N)² relative.
  const int N = 4096;
  const double tol = 4.0 * std::pow(2.0 * pi / N, 2);
  const joints::Joint jenkins = tip(Term::jenkins, {1.0e4, 3.0}, true);
  for (double a : {5e-4, 2e-3, 1e-2}) {
    const auto n = identify::describing_function(jenkins, 2, a);
    const double area = 4.0 * 3.0 * (a - 3.0 / 1.0e4);
    EXPECT_NEAR(pi * a * a * n.imag(), area, 1e-12 * area) << a;
  }
  const auto stuck = identify::describing_function(jenkins, 2, 1e-4);
  EXPECT_NEAR(stuck.real(), 1.0e4, 1e-12 * 1.0e4);
  EXPECT_EQ(stuck.imag(), 0.0);
  const joints::Joint gap = tip(Term::gap, {5e-3, 2e4}, true);
  EXPECT_EQ(identify::describing_function(gap, 2, 4e-3), 0.0);
  const joints::Joint iwan = tip(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}, true);
  const double phi_max = joints::iwan_density(3.0, 1.0e4, -0.5, 0.1).phi_max;
  const std::vector<std::tuple<joints::Joint, double, std::vector<double>>> cases{
      {jenkins, 1.0e4, {1e-4, 3.1e-4, 5e-4, 2e-3, 1e-2}},
      {iwan, 1.0e4, {0.05 * phi_max, 0.3 * phi_max, 0.9 * phi_max, 1.5 * phi_max, 10 * phi_max}},
      {gap, 2e4, {4e-3, 5.1e-3, 6e-3, 1e-2, 5e-2}}};
  for (const auto& [joint, s, amplitudes] : cases)
    for (double a : amplitudes) {
      const auto closed = identify::describing_function(joint, 2, a);
      const auto sampled = sampled_describing_function(joint, a, N);
      const std::string name(joints::term_name(joint.terms[2]));
      EXPECT_NEAR(closed.real(), sampled.real(), tol * s) << name << " at " << a;
      EXPECT_NEAR(closed.imag(), sampled.imag(), tol * s) << name << " at " << a;
    }
}

TEST(DescribingFunction, OnAGridInLnAIsTheExactOneToTheInterpolationError) {
  // 300 amplitudes over a factor 49 around each term's onset (slip, the Dirac's slider, contact),
  // on a grid of h = 1/24 in ln a with the onset a node. Just past a slider's onset at φ its
  // in-phase part is k (1 − (16/3π) x^{3/2}), x = ln(a/φ), whose linear interpolation over the
  // first step errs by (4/27)(16/3π) k h^{3/2} = 2.1e-3 k at most; elsewhere by h²/8 |N''|, a
  // few 1e-4 of the stiffness s (kt, kg). A grid without the onset as a node errs by a quarter
  // step of the slope's jump, (4/π) s h/4 = 1.3e-2 s.
  const std::vector<std::tuple<joints::Joint, double, double>> terms{
      {tip(Term::jenkins, {1.0e4, 3.0}, true), 1.0e4, 3.0 / 1.0e4},
      {tip(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}, true), 1.0e4,
       joints::iwan_density(3.0, 1.0e4, -0.5, 0.1).phi_max},
      {tip(Term::gap, {5e-3, 2e4}, true), 2e4, 5e-3}};
  for (const auto& [joint, s, onset] : terms) {
    std::vector<double> a;
    for (int i = 0; i < 300; ++i)
      a.push_back(onset / 7.0 * std::pow(49.0, i / 299.0));
    const auto exact = identify::describing_functions(joint, 2, a);
    const auto grid = identify::describing_functions(joint, 2, a, 24);
    ASSERT_EQ(grid.size(), a.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(exact[i], identify::describing_function(joint, 2, a[i]));
      worst = std::max(worst, std::abs(grid[i] - exact[i]));
    }
    const std::string name(joints::term_name(joint.terms[2]));
    EXPECT_LT(worst, 2.5e-3 * s) << name;
    EXPECT_GT(worst, 0.0) << name << ": not interpolated";
  }
}

// Tests across the first resonance at several forces, made by time integration (512 steps a
// period, 4 periods kept once steady), 1e-4 noise on every channel (its variance known: the
// output error weighs by it).
std::vector<identify::Measurement> records(const frf::Substructure& sub,
                                           const std::vector<joints::Joint>& truth,
                                           const std::vector<double>& forces) {
  std::vector<identify::SineTestPlan> plans;
  for (double f : {2.6, 3.0, 3.4})
    for (double F : forces)
      plans.push_back({f, F});
  identify::SimulationOptions so;
  so.method = identify::SimulationMethod::time_integration;
  so.steps_per_period = 512;
  so.samples_per_period = 128;
  so.periods = 4;
  std::vector<identify::SimulatedTest> made =
      identify::simulate_sine_tests(sub, truth, {7, fem::Dof::uy}, plans, so);
  std::vector<identify::Measurement> out;
  for (std::size_t i = 0; i < made.size(); ++i) {
    identify::add_noise(made[i].record, 1e-4, 100 + i);
    out.push_back(identify::measure(made[i].record, {.harmonics = 3}));
  }
  return out;
}

const identify::ParameterEstimate& parameter(const identify::FitResult& r, const char* name) {
  for (const auto& p : r.joints.at(0).terms.at(2).parameters)
    if (p.name == name) return p;
  throw std::invalid_argument(name);
}

TEST(ParametricIdentification, AnIntervalThatDoesNotFixTheScaleIsNotAResult) {
  // iwan's kt (positive: a factor of 100 at most), chi (an exponent in (−1, 0]: half its range
  // at most), and a zero-width or infinite interval, never.
  const auto& iwan = joints::term_info(Term::iwan).parameters;
  const auto find = [&](const std::string& name) -> const joints::ParameterInfo& {
    for (const auto& p : iwan)
      if (p.name == name) return p;
    throw std::logic_error(name);
  };
  const joints::ParameterInfo &kt = find("kt"), &chi = find("chi");
  EXPECT_TRUE(identify::interval_determines(kt, 3000.0, 1000.0, 9000.0));
  EXPECT_TRUE(identify::interval_determines(kt, 3000.0, 300.0, 30000.0));
  EXPECT_FALSE(identify::interval_determines(kt, 5.177e8, 1.06e-10, 2.527e27));
  EXPECT_FALSE(identify::interval_determines(kt, 3000.0, 100.0, 30000.0));
  EXPECT_FALSE(identify::interval_determines(kt, 3000.0, 3000.0, 3000.0));
  EXPECT_FALSE(identify::interval_determines(kt, 3000.0, 0.0, 3000.0));
  EXPECT_FALSE(identify::interval_determines(kt, 3000.0, 1000.0, INFINITY));
  EXPECT_TRUE(identify::interval_determines(chi, -0.5, -0.7, -0.3));
  EXPECT_FALSE(identify::interval_determines(chi, -0.5, -0.95, -0.05));
}

TEST(ParametricIdentification, EachTermSimulatedByTimeIntegrationIsIdentifiedBack) {
  // From no given parameter: the describing-function start, then output error. The harmonic
  // balance it fits agrees with time integration to ~4e-5 of the response
  // (HarmonicBalance.ParametricTermsAgreeWithTimeIntegration), below the noise (1e-4): each
  // parameter must come back within its 95 % interval widened to 3 % (the start's and the
  // model's bias together stay below that; the interval alone is a few 1e-3).
  const frf::Substructure sub{test::paper_cantilever()};
  struct Case {
    Term term;
    std::vector<double> truth;
    std::vector<double> forces;
  };
  const std::vector<Case> cases{
      {Term::jenkins, {1.0e4, 3.0}, {2.0, 8.0, 20.0}},
      {Term::iwan, {3.0, 1.0e4, -0.5, 0.1}, {2.0, 8.0, 20.0}},
      {Term::gap, {5e-3, 2e4}, {10.0, 40.0}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(joints::term_name(c.term));
    const std::vector<joints::Joint> truth{tip(c.term, c.truth, true)};
    const auto tests = records(sub, truth, c.forces);
    joints::Joint unknown = truth[0];
    unknown.fixed.assign(3, false);
    unknown.parameters[2].assign(c.truth.size(), joints::Parameter{}); // none given
    unknown.values = {0.0, 0.0, 1.0};
    const identify::FitResult r =
        identify::output_error(sub, {unknown}, tests, {.harmonics = {1, 2, 3}});
    ASSERT_TRUE(r.status.ok()) << r.status.reason;
    const auto& info = joints::term_info(c.term).parameters;
    for (std::size_t p = 0; p < info.size(); ++p) {
      const auto& e = r.joints[0].terms[2].parameters[p];
      EXPECT_TRUE(e.determined) << info[p].name;
      const double t = c.truth[p];
      EXPECT_LT(std::abs(e.value - t), std::max(e.ci_high - e.ci_low, 0.03 * std::abs(t)))
          << info[p].name << " " << e.value << " [" << e.ci_low << ", " << e.ci_high << "]";
    }
    EXPECT_NEAR(r.joints[0].terms[0].value, 4800.0, 0.03 * 4800.0);
  }
}

TEST(ParametricIdentification, IwanInMicroslipSaysWhatTheTestsDoNotDetermine) {
  // Forces small enough that the iwan never reaches macroslip (φ_max ≈ 7.6e-4 m here): its force
  // depends on k + kt, chi and R only. kt, fs and beta must be said undetermined (no value, the
  // combination instead), k + kt must come back (5800 + … = 14800), chi too, and the term is
  // not blocked (the fit is ok).
  const frf::Substructure sub{test::paper_cantilever()};
  const std::vector<double> truth{3.0, 1.0e4, -0.5, 0.1};
  const std::vector<joints::Joint> model{tip(Term::iwan, truth, true)};
  const auto tests = records(sub, model, {0.5, 1.0});
  joints::Joint unknown = model[0];
  unknown.fixed.assign(3, false);
  unknown.parameters[2].assign(4, joints::Parameter{});
  unknown.values = {0.0, 0.0, 1.0};
  const identify::FitResult r =
      identify::output_error(sub, {unknown}, tests, {.harmonics = {1, 2, 3}});
  ASSERT_TRUE(r.status.ok()) << r.status.reason;
  for (const char* name : {"fs", "kt", "beta"}) {
    EXPECT_FALSE(parameter(r, name).determined) << name;
    EXPECT_TRUE(std::isnan(parameter(r, name).value)) << name;
  }
  EXPECT_TRUE(parameter(r, "chi").determined);
  EXPECT_NEAR(parameter(r, "chi").value, -0.5, 0.05);
  EXPECT_FALSE(r.joints[0].terms[0].determined); // k apart from kt
  ASSERT_FALSE(r.identifiability.empty());
  const std::string& said = r.identifiability.back();
  EXPECT_NE(said.find("microslip"), std::string::npos) << said;
  const auto at = said.find("k + iwan.kt = ");
  ASSERT_NE(at, std::string::npos) << said;
  const double sum = std::stod(said.substr(at + 14));
  EXPECT_NEAR(sum, 4800.0 + 1.0e4, 0.03 * (4800.0 + 1.0e4)) << said;
}

TEST(ParametricIdentification, EquationErrorTakesAParametricTermOnlyFixed) {
  // The route Q b = p cannot estimate parameters that enter non-linearly: a non-fixed one is
  // refused naming the joint, the term and its parameters; all fixed, it is a known force.
  joints::Joint j = tip(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}, false);
  try {
    identify::check_identifiable({j});
    FAIL() << "a non-fixed iwan was taken by the equation error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("joint 'tip'"), std::string::npos) << what;
    EXPECT_NE(what.find("'iwan' (fs, kt, chi, beta)"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(identify::check_identifiable({tip(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}, true)}));
}

TEST(DescribingFunction, AJointThatCorrectsASubstructureFittedAtLowLevelIsStartedFromItsPoints) {
  // A substructure fitted to a low-level test holds the stuck joint's stiffness: the joint is
  // k = -kt beside its Jenkins element (kt 4e4 N/m, fs 4 N), its equivalent stiffness 0 while
  // stuck (below 0.1 mm) and falling as it slips. Exact points at 0.05 … 0.4 mm recover kt and
  // fs to 1 %: the stuck points' Z of 0 must not weigh as relative misfits would (each point's
  // misfit is scaled by its |Z| but not below a tenth of the largest).
  joints::Joint truth{"mount",
                      10,
                      5,
                      fem::Dof::uy,
                      {Term::k, Term::c, Term::jenkins},
                      {-4.0e4, 0.0, 1.0},
                      {false, false, false},
                      {}};
  truth.parameters.resize(3);
  truth.set_parameters(2, {4.0e4, 4.0});
  std::vector<identify::EquivalentStiffness> points;
  const double w = 2.0 * pi * 21.0;
  for (int i = 0; i < 12; ++i) {
    const double a = 5e-5 * std::pow(8.0, i / 11.0);
    points.push_back({a, w, -4.0e4 + identify::describing_function(truth, 2, a)});
  }
  EXPECT_LT(std::abs(points.front().Z), 1e-6 * 4.0e4); // stuck
  joints::Joint model = truth;
  model.values[0] = 0.0;
  model.parameters[2].assign(2, joints::Parameter{});
  std::string note;
  const joints::Joint fitted =
      identify::fit_describing_function(model, 2, points, true, true, note);
  EXPECT_NEAR(fitted.parameter(2, "kt"), 4.0e4, 0.01 * 4.0e4) << note;
  EXPECT_NEAR(fitted.parameter(2, "fs"), 4.0, 0.01 * 4.0) << note;
}

TEST(DescribingFunction, AFrictionAndAClearanceTogetherAreStartedFromOneFit) {
  // The frame example's mount against its substructure fitted at low level: k = -kt beside a
  // Jenkins element (kt 4e4 N/m, fs 4 N) and a gap (delta 0.25 mm, kg 1.5e5 N/m). Its equivalent
  // stiffness is 0 while stuck, falls as the friction slips and rises once the stop is met: no
  // one term follows it. Exact points at 0.05 … 0.8 mm recover all four parameters and k to 2 %
  // (the describing functions are interpolated on a grid in ln a: about 2e-3 of the stiffness).
  joints::Joint truth{"mount",
                      10,
                      5,
                      fem::Dof::uy,
                      {Term::k, Term::c, Term::jenkins, Term::gap},
                      {-4.0e4, 2.0, 1.0, 1.0},
                      {false, false, false, false},
                      {}};
  truth.parameters.resize(4);
  truth.set_parameters(2, {4.0e4, 4.0}, false);
  truth.set_parameters(3, {2.5e-4, 1.5e5}, false);
  std::vector<identify::EquivalentStiffness> points;
  const double w = 2.0 * pi * 21.0;
  for (int i = 0; i < 14; ++i) {
    const double a = 5e-5 * std::pow(16.0, i / 13.0);
    points.push_back({a, w,
                      std::complex<double>(-4.0e4, 2.0 * w) +
                          identify::describing_function(truth, 2, a) +
                          identify::describing_function(truth, 3, a)});
  }
  joints::Joint model = truth;
  model.values[0] = model.values[1] = 0.0;
  model.parameters[2].assign(2, joints::Parameter{});
  model.parameters[3].assign(2, joints::Parameter{});
  std::string note;
  const joints::Joint fitted =
      identify::fit_describing_functions(model, {2, 3}, points, true, true, note);
  EXPECT_NEAR(fitted.parameter(2, "kt"), 4.0e4, 0.02 * 4.0e4) << note;
  EXPECT_NEAR(fitted.parameter(2, "fs"), 4.0, 0.02 * 4.0) << note;
  EXPECT_NEAR(fitted.parameter(3, "delta"), 2.5e-4, 0.02 * 2.5e-4) << note;
  EXPECT_NEAR(fitted.parameter(3, "kg"), 1.5e5, 0.02 * 1.5e5) << note;
  EXPECT_NE(note.find("jenkins and gap started from a describing-function fit"), std::string::npos)
      << note;
  // Either alone misses the turn: its best fit leaves a misfit many times the pair's.
  const auto misfit = [](const std::string& n) {
    const auto at = n.find("relative misfit ");
    return std::stod(n.substr(at + 16));
  };
  joints::Joint jenkins = model;
  jenkins.terms.pop_back(), jenkins.values.pop_back(), jenkins.fixed.pop_back();
  jenkins.parameters.pop_back();
  std::string alone;
  (void)identify::fit_describing_functions(jenkins, {2}, points, true, true, alone);
  EXPECT_GT(misfit(alone), 20.0 * misfit(note)) << alone << "\n" << note;
}

TEST(ParametricIdentification, AFailedDescribingFunctionFitIsAStatusNamingTheJointAndTerm) {
  // A substructure whose modal analysis fails (a numerical outcome, not bad input): no test gives
  // the joint's equivalent stiffness, so the start fails. That is a status whose reason names the
  // joint and the term and passes the per-test fits' own status up (the modal analysis' reason),
  // through the output-error pipeline too; nothing is thrown.
  const frf::Substructure sub = test::failing_substructure();
  joints::Joint j{"j", 3, 0, fem::Dof::ux, {Term::k, Term::c, Term::jenkins}, {0.0, 0.0, 1.0},
                  {},  {}};
  j.fixed.assign(3, false);
  j.parameters.resize(3);
  j.parameters[2].assign(2, joints::Parameter{});
  // A sine record at 2 Hz, 4 periods of 64 samples: force and displacement at node 3.
  identify::Record r;
  r.source = "r.csv";
  r.excitation_hz = 2.0;
  const int n = 256;
  r.t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / (64.0 * 2.0));
  const Eigen::VectorXd wt = 2.0 * pi * 2.0 * r.t;
  r.channels.push_back({identify::Quantity::force, {3, fem::Dof::ux}, wt.array().sin()});
  r.channels.push_back(
      {identify::Quantity::displacement, {3, fem::Dof::ux}, 1e-3 * wt.array().cos()});
  const identify::Measurement m = identify::measure(identify::SineTest{r}, {.harmonics = 1});
  const identify::DescribingFunctionStart start =
      identify::describing_function_start(sub, {j}, {m}, {});
  ASSERT_FALSE(start.status.ok());
  const std::string& why = start.status.reason;
  EXPECT_EQ(why.rfind("joint 'j': the describing-function fit of its jenkins", 0), 0u) << why;
  EXPECT_NE(why.find(test::failing_modes_reason), std::string::npos) << why;
  EXPECT_EQ(start.status.code, fem::Status::Code::numerical_issue) << why;
  const identify::FitResult r2 = identify::output_error(sub, {j}, {m}, {});
  EXPECT_EQ(r2.status.reason, why);
  EXPECT_TRUE(r2.joints.empty());
}

} // namespace
} // namespace jointid
