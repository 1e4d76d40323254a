// Model discovery on data in which effects are hidden. The "measurements" are made by implicit
// time integration of the finite element model with the true joints (exact stick–slip for dry
// friction) — never by the harmonic balance that discovery itself uses — with white noise
// added to every channel, force included. Discovery is told only the linear joint terms (k, c,
// without values) and must name what is missing at the right joint, identify it, and stop at
// the noise level; with nothing hidden it must add nothing, and a linear model error must be
// reported as linear.
#include "discover/discover.hpp"

#include "constructed.hpp"
#include "identify/random_tests.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace jointid {
namespace {

using joints::Term;

joints::Joint joint(std::string name, int node, std::vector<Term> terms,
                    std::vector<double> values) {
  joints::Joint j{std::move(name),   node, 0, fem::Dof::uy, std::move(terms),
                  std::move(values), {},   {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

// The starting model discovery is given: k and c at the joint, values unknown.
joints::Joint linear_start(const std::string& name, int node) {
  joints::Joint j = joint(name, node, {Term::k, Term::c}, {0.0, 0.0});
  j.given.assign(2, false);
  return j;
}

struct Data {
  fem::Model model = test::paper_cantilever(); ///< the truth's substructure
  std::vector<joints::Joint> truth;
  std::vector<double> frequencies{2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0};
  std::vector<double> levels{10.0, 40.0, 80.0};
  double noise = 0.01;
  std::vector<identify::Quantity> channels{identify::Quantity::displacement,
                                           identify::Quantity::velocity};
  bool table = false; ///< keep the fundamentals only (a stepped-sine table's content)
};

// Time integration of the truth to steady state, 1024 steps a period, 8 periods of 256 samples
// recorded (a data acquisition's record), noise added with a fixed seed per test.
std::vector<identify::Measurement> measure(const Data& d, int harmonics = 3) {
  std::vector<identify::SineTestPlan> plans;
  for (double f : d.frequencies)
    for (double a : d.levels)
      plans.push_back({f, a});
  identify::SimulationOptions o;
  o.steps_per_period = 1024;
  o.samples_per_period = 256;
  o.periods = 8;
  o.quantities = d.channels;
  std::vector<identify::SimulatedTest> tests = identify::simulate_sine_tests(
      frf::Substructure(d.model), d.truth, {7, fem::Dof::uy}, plans, o);
  std::vector<identify::Measurement> out;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    EXPECT_TRUE(tests[i].warnings.empty()) << tests[i].warnings.front();
    identify::add_noise(tests[i].record, d.noise, 1000 + i);
    identify::Measurement m = identify::measure(tests[i].record, {.harmonics = harmonics});
    if (d.table) { // a stepped-sine table keeps the fundamental of each channel only
      const int K = m.harmonics;
      for (int k = 0; k <= K; ++k)
        if (k != 1) m.X.row(k).setZero(), m.F.row(k).setZero();
      m.fundamental_only = true;
      m.X_variance.setConstant(std::numeric_limits<double>::quiet_NaN());
      m.F_variance.setConstant(std::numeric_limits<double>::quiet_NaN());
      std::fill(m.has_mean.begin(), m.has_mean.end(), false);
      // The basis functions then see the fundamental's sinusoid only, as for a table row.
      const double w = 2.0 * std::numbers::pi * m.frequency_hz;
      for (Eigen::Index j = 0; j < m.X.cols(); ++j)
        for (Eigen::Index n = 0; n < m.t.size(); ++n) {
          const std::complex<double> e = std::polar(1.0, w * m.t(n));
          m.x(n, j) = (m.X(1, j) * e).real();
          m.v(n, j) = (std::complex<double>(0.0, w) * m.X(1, j) * e).real();
        }
    }
    out.push_back(std::move(m));
  }
  return out;
}

// The terms each joint has at the end, by joint name.
std::map<std::string, std::set<Term>> final_terms(const discover::Result& r) {
  std::map<std::string, std::set<Term>> out;
  for (const auto& j : r.states.back().joints)
    out[j.name].insert(j.terms.begin(), j.terms.end());
  return out;
}

double value_of(const discover::Result& r, const std::string& joint, Term term) {
  for (const auto& j : r.states.back().joints)
    if (j.name == joint && j.term_index(term) >= 0) return j.values[j.term_index(term)];
  return std::numeric_limits<double>::quiet_NaN();
}

double std_of(const discover::Result& r, const std::string& joint, Term term) {
  for (const auto& je : r.states.back().fit.joints)
    if (je.name == joint)
      for (const auto& te : je.terms)
        if (te.term == term) return te.std;
  return std::numeric_limits<double>::quiet_NaN();
}

// The final gap against the floor it is judged by: the noise and the simulation's own error.
void expect_at_noise_level(const discover::Result& r) {
  ASSERT_GT(r.noise_gap, 0.0);
  EXPECT_TRUE(r.at_noise_level) << "gap " << r.gap.back() << ", noise " << r.noise_gap
                                << ", simulation " << r.simulation_gap << ", chi2/value "
                                << r.chi2_per_value;
  // The weighted test above is the criterion. The unweighted gap follows the largest tests; it
  // may exceed the floor's own aggregate when the simulation's error sits in a few tests (dry
  // friction sticking at the lowest level), which the weighted identification discounts: 1.5.
  EXPECT_LT(r.gap.back(), 1.5 * std::hypot(r.noise_gap, r.simulation_gap));
}

std::string describe(const discover::Result& r) {
  std::ostringstream s;
  s << "steps:";
  for (const auto& step : r.steps)
    s << ' ' << step.added.name();
  s << "; gaps:";
  for (double g : r.gap)
    s << ' ' << g;
  s << "; stop: " << r.stop_reason;
  return s.str();
}

// One hidden term at the cantilever's tip: named, valued, nothing else added, at the noise level.
struct Hidden {
  Term term;
  double value;
  std::vector<double> levels;
  double tolerance; ///< relative, on the identified value
  discover::Result run() const {
    Data d;
    d.truth = {joint("tip", 7, {Term::k, Term::c, term}, {4800.0, 20.0, value})};
    d.levels = levels;
    return discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d));
  }
};

class HiddenTerm : public ::testing::TestWithParam<Hidden> {};

TEST_P(HiddenTerm, IsNamedIdentifiedAndTheGapFallsToTheNoise) {
  const Hidden h = GetParam();
  const discover::Result r = h.run();
  SCOPED_TRACE(describe(r));
  ASSERT_EQ(r.steps.size(), 1u);
  ASSERT_TRUE(r.steps[0].added.term.has_value());
  EXPECT_EQ(*r.steps[0].added.term, h.term);
  EXPECT_EQ(r.steps[0].added.joint, "tip");
  EXPECT_EQ(r.states.back().damping_scale, 1.0);
  EXPECT_NEAR(value_of(r, "tip", h.term), h.value, h.tolerance * h.value);
  // Output-error estimates of smooth terms are unbiased: within 4 standard deviations of the
  // truth (dry friction's harmonic balance has its own, larger, truncation bias).
  if (h.term != Term::fc) {
    EXPECT_LT(std::abs(value_of(r, "tip", h.term) - h.value), 4.0 * std_of(r, "tip", h.term));
  }
  EXPECT_NEAR(value_of(r, "tip", Term::k), 4800.0, 0.005 * 4800.0);
  EXPECT_NEAR(value_of(r, "tip", Term::c), 20.0, 0.01 * 20.0);
  expect_at_noise_level(r);
  // The gap shrinks by far more than an order of magnitude.
  EXPECT_LT(r.gap.back(), 0.02 * r.gap.front());
  // The diagnosis: non-linear, at the tip, of the right nature.
  ASSERT_TRUE(r.diagnosis.level_dependent.has_value());
  EXPECT_TRUE(*r.diagnosis.level_dependent);
  EXPECT_EQ(r.diagnosis.joint, "tip");
  EXPECT_EQ(r.diagnosis.nature, joints::term_info(h.term).nature == joints::Nature::conservative
                                    ? "conservative"
                                    : "dissipative");
  EXPECT_EQ(r.diagnosis.asymmetric, joints::term_info(h.term).even);
  if (h.term == Term::k2) {
    EXPECT_TRUE(r.diagnosis.even_harmonics);
  }
}

// Values that matter at these levels and stay stable; friction at levels where it mostly slides
// (its basis sign(ẏ) does not describe a stuck joint, and its harmonic balance converges slowly
// with the harmonics: 2 % on fc).
INSTANTIATE_TEST_SUITE_P(AtTheTip, HiddenTerm,
                         ::testing::Values(Hidden{Term::k3, 1.6e8, {10.0, 40.0, 80.0}, 0.005},
                                           Hidden{Term::c2, 500.0, {10.0, 40.0, 80.0}, 0.01},
                                           Hidden{Term::c3, 500.0, {10.0, 40.0, 80.0}, 0.01},
                                           Hidden{Term::fc, 3.0, {20.0, 50.0, 100.0}, 0.02},
                                           Hidden{Term::k2, 5e4, {10.0, 40.0, 80.0}, 0.01}),
                         [](const auto& info) {
                           return std::string(joints::term_name(info.param.term));
                         });

TEST(Discover, AWrongGivenValueIsCorrectedByTheRefit) {
  // k, c and k3 all given, k3 with the wrong sign and size (-5e8, truth 1.6e8), on a 21-row
  // stepped-sine table. The model now predicts held-out tests with the values it was given (they
  // were fitted to none), so the refit, identified per fold, predicts them far better and is
  // made; its finding says from what to what. (Refitting the model now per fold as well made
  // both held-out gaps equal and the refit never passed: "not in the library".)
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  d.table = true;
  joints::Joint start = joint("tip", 7, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, -5e8});
  start.given.assign(3, true);
  const discover::Result r = discover::discover(frf::Substructure(d.model), {start}, measure(d));
  SCOPED_TRACE(describe(r));
  ASSERT_FALSE(r.steps.empty());
  EXPECT_TRUE(r.steps[0].added.refit);
  EXPECT_LT(r.steps[0].cv_after, r.steps[0].cv_before);
  EXPECT_NE(r.steps[0].finding.find("Refitted the starting values"), std::string::npos)
      << r.steps[0].finding;
  EXPECT_NE(r.steps[0].finding.find("k3 at 'tip' -5e+08 \u2192"), std::string::npos)
      << r.steps[0].finding;
  // The refit's k3: the truth within 1 % (the 1 % noise gives 0.5 % for the hidden k3 above).
  EXPECT_NEAR(value_of(r, "tip", Term::k3), 1.6e8, 0.01 * 1.6e8);
  EXPECT_EQ(r.stop_reason.find("not in the library"), std::string::npos);
}

// A term with named parameters hidden at the tip beside k and c: discovery, told only k and c,
// must name it (nothing else added), give its parameters with intervals that hold the truth
// where the tests determine them, and say in words what the data show of the joint.
struct HiddenParametric {
  Term term;
  std::vector<double> parameters; ///< in the table's order
  std::vector<double> levels;
  bool table;            ///< stepped-sine fundamentals (noise unknown), else records
  std::string behaviour; ///< what the diagnosis must say of the tip
};

class HiddenParametricTerm : public ::testing::TestWithParam<HiddenParametric> {};

TEST_P(HiddenParametricTerm, IsNamedWithItsParametersAndTheDiagnosisSaysWhatItDoes) {
  const HiddenParametric h = GetParam();
  Data d;
  joints::Joint truth = joint("tip", 7, {Term::k, Term::c, h.term}, {4800.0, 20.0, 1.0});
  truth.parameters.resize(3);
  truth.set_parameters(2, h.parameters);
  d.truth = {truth};
  d.levels = h.levels;
  d.table = h.table;
  discover::Options o;
  if (h.table) o.harmonics = {1};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d), o);
  SCOPED_TRACE(describe(r));
  ASSERT_EQ(r.steps.size(), 1u);
  ASSERT_TRUE(r.steps[0].added.term.has_value());
  EXPECT_EQ(*r.steps[0].added.term, h.term);
  EXPECT_EQ(r.steps[0].added.joint, "tip");
  EXPECT_EQ(r.states.back().damping_scale, 1.0);
  EXPECT_LT(r.gap.back(), 0.1 * r.gap.front());
  // Its parameters: every determined one's 95 % interval holds the truth, within a margin for
  // the harmonic balance's truncation of the loop's corners (1 %); some are determined.
  const auto& params = r.steps[0].added.parameters;
  ASSERT_EQ(params.size(), h.parameters.size());
  int determined = 0;
  for (std::size_t p = 0; p < params.size(); ++p) {
    if (!params[p].determined) {
      EXPECT_TRUE(std::isnan(params[p].value)) << params[p].name; // never a value then
      continue;
    }
    ++determined;
    const double truth_p = h.parameters[p], margin = 0.01 * std::abs(truth_p);
    EXPECT_LE(params[p].ci_low - margin, truth_p) << params[p].name << " = " << params[p].value;
    EXPECT_GE(params[p].ci_high + margin, truth_p) << params[p].name << " = " << params[p].value;
  }
  EXPECT_GT(determined, 0);
  if (std::isfinite(std_of(r, "tip", Term::k))) {
    EXPECT_NEAR(value_of(r, "tip", Term::k), 4800.0, 0.05 * 4800.0);
  } else { // an iwan in microslip: k apart from kt is not determined, their sum is
    ASSERT_EQ(h.term, Term::iwan);
    const auto& tip = r.states.back().joints.front();
    const double kt = tip.parameter(static_cast<std::size_t>(tip.term_index(Term::iwan)), "kt");
    EXPECT_NEAR(value_of(r, "tip", Term::k) + kt, 4800.0 + h.parameters[1], 0.02 * 7800.0);
  }
  // The diagnosis, from the equivalent stiffness and damping of each test alone.
  EXPECT_EQ(r.diagnosis.nature, joints::is_hysteretic(h.term) ? "hysteretic" : "conservative");
  ASSERT_FALSE(r.diagnosis.behaviour.empty());
  const discover::JointBehaviour& b = r.diagnosis.behaviour.front();
  EXPECT_EQ(b.joint, "tip");
  EXPECT_EQ(b.behaviour, h.behaviour) << b.finding << [&] {
    std::ostringstream o;
    o << "\nslope " << b.slope << " share " << b.hysteretic_share << "\n";
    for (std::size_t i = 0; i < b.amplitude.size(); ++i)
      o << b.frequency_hz[i] << " " << b.amplitude[i] << " D " << b.dissipation[i] << " k "
        << b.stiffness[i] << "\n";
    return o.str();
  }();
  EXPECT_FALSE(b.model_amplitude.empty());
}

// Jenkins: slips at 1 mm (fs / kt), below every test's amplitude: Coulomb sliding. Iwan: its
// largest slip displacement phi_max = 8.5 cm beyond every amplitude: microslip. Gap: contact at
// ±1 cm, inside the tests' span (1 mm … 5 cm).
INSTANTIATE_TEST_SUITE_P(
    AtTheTip, HiddenParametricTerm,
    ::testing::Values(
        HiddenParametric{Term::jenkins, {5000.0, 5.0}, {10.0, 40.0, 80.0}, true, "macroslip"},
        HiddenParametric{
            Term::iwan, {100.0, 3000.0, -0.5, 0.1}, {10.0, 40.0, 80.0}, false, "microslip"},
        HiddenParametric{Term::gap, {0.01, 5000.0}, {10.0, 40.0, 80.0}, true, "clearance"}),
    [](const auto& info) { return std::string(joints::term_name(info.param.term)); });

TEST(Discover, ACoefficientTermIsTriedBesideAParametricTermOfTheStart) {
  // A starting joint that carries a parametric term (the true jenkins, given with its
  // parameters) and lacks a cubic stiffness: every coefficient candidate is added beside the
  // jenkins, its parameters kept in step with the terms. (Until a411160 each such candidate
  // threw "parameters and terms differ in number" and the run stopped before any step.)
  Data d;
  d.frequencies = {2.0, 3.0, 4.0, 5.0};
  d.table = true;
  joints::Joint truth =
      joint("tip", 7, {Term::k, Term::c, Term::jenkins, Term::k3}, {4800.0, 20.0, 1.0, 1.6e8});
  truth.parameters.resize(4);
  truth.set_parameters(2, {5000.0, 5.0});
  d.truth = {truth};
  joints::Joint start = joint("tip", 7, {Term::k, Term::c, Term::jenkins}, {4800.0, 20.0, 1.0});
  start.parameters.resize(3);
  start.set_parameters(2, {5000.0, 5.0});
  start.given.assign(3, true);
  discover::Options o;
  o.harmonics = {1};
  const discover::Result r = discover::discover(frf::Substructure(d.model), {start}, measure(d), o);
  SCOPED_TRACE(describe(r));
  ASSERT_FALSE(r.steps.empty());
  ASSERT_TRUE(r.steps[0].added.term.has_value());
  EXPECT_EQ(*r.steps[0].added.term, Term::k3);
  EXPECT_EQ(r.steps[0].added.joint, "tip");
  // The 1 % noise on 12 fundamentals: k3 within a few per cent.
  EXPECT_NEAR(value_of(r, "tip", Term::k3), 1.6e8, 0.05 * 1.6e8);
  const auto& tip = r.states.back().joints.front();
  EXPECT_EQ(tip.parameters.size(), tip.terms.size());
}

TEST(Discover, ThroughMeasuredFrfsAsThroughTheModel) {
  // The substructure given by its measured FRF at the tip (sampled from the model every
  // 0.005 Hz up to 80 Hz: the tests at 2–5 Hz lie on the lines), the cubic stiffness hidden.
  // Discovery names and values it as through the model; its re-simulations keep to the 8
  // harmonics whose doubles stay in the band (said in a warning), the model's use 15.
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  const std::vector<identify::Measurement> tests = measure(d);
  const frf::Substructure model(d.model);
  const int tip = model.dofs().equation({7, fem::Dof::uy});
  const frf::ModalSynthesis H = model.synthesis({tip}, 100.0);
  frf::MeasuredFrf frf;
  frf.dofs = {{7, fem::Dof::uy}};
  frf::MeasuredFunction f{{7, fem::Dof::uy}, {7, fem::Dof::uy}, {}, {}, "sampled from the model"};
  for (int i = 0; i <= 16000; ++i) {
    const int e[] = {tip};
    f.frequencies_hz.push_back(0.005 * i);
    f.receptance.push_back(H.receptance(2.0 * std::numbers::pi * 0.005 * i, e, e)(0, 0));
  }
  frf.functions.push_back(f);
  const discover::Result a = discover::discover(model, {linear_start("tip", 7)}, tests);
  const discover::Result b =
      discover::discover(frf::Substructure(frf), {linear_start("tip", 7)}, tests);
  SCOPED_TRACE(describe(b));
  ASSERT_EQ(b.steps.size(), 1u);
  ASSERT_TRUE(b.steps[0].added.term.has_value());
  EXPECT_EQ(*b.steps[0].added.term, Term::k3);
  EXPECT_NEAR(value_of(b, "tip", Term::k3), 1.6e8, 0.005 * 1.6e8);
  EXPECT_LT(std::abs(value_of(b, "tip", Term::k3) - value_of(a, "tip", Term::k3)),
            std_of(a, "tip", Term::k3));
  expect_at_noise_level(b);
  EXPECT_NE(std::find_if(b.warnings.begin(), b.warnings.end(),
                         [](const std::string& w) {
                           return w.find("the re-simulations use 8 harmonics (not 15)") !=
                                  std::string::npos;
                         }),
            b.warnings.end());
  // A band too short for the harmonics compared is refused, saying how far to measure.
  frf.functions[0].frequencies_hz.resize(4001); // to 20 Hz
  frf.functions[0].receptance.resize(4001);
  try {
    (void)discover::discover(frf::Substructure(frf), {linear_start("tip", 7)}, tests);
    ADD_FAILURE() << "a band to 20 Hz was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "discover: the measured FRFs reach 20 Hz; the re-simulations need "
                           "harmonic 6 (twice the 3 compared, to estimate their own error) of "
                           "the highest test frequency, 5 Hz: 30 Hz. Measure to that, or compare "
                           "fewer harmonics");
  }
}

// The checkpoint (Options::checkpoint) is called as the run goes, and an exception thrown from
// it — on whichever thread the candidates run — stops the run and leaves discover() (the Python
// module's Ctrl-C, python/src/common.hpp).
TEST(Discover, AnExceptionFromTheCheckpointStopsTheRun) {
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  d.frequencies = {2.5, 3.5, 4.5};
  d.levels = {20.0, 80.0};
  const std::vector<identify::Measurement> tests = measure(d);
  struct Stop {};
  for (const int stop_at : {1, 40}) {
    std::atomic<int> calls{0};
    discover::Options o;
    o.terms = {Term::k3, Term::c2};
    o.substructure_damping = false;
    o.curve_points = 0;
    o.checkpoint = [&calls, stop_at] {
      if (++calls >= stop_at) throw Stop{};
    };
    EXPECT_THROW(discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, tests, o),
                 Stop)
        << "stop at call " << stop_at;
    EXPECT_GE(calls.load(), stop_at);
  }
}

TEST(Discover, NothingHiddenAddsNothing) {
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c}, {4800.0, 20.0})};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d));
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.steps.empty());
  expect_at_noise_level(r);
  EXPECT_NEAR(value_of(r, "tip", Term::k), 4800.0, 4.0 * std_of(r, "tip", Term::k));
  EXPECT_NEAR(value_of(r, "tip", Term::c), 20.0, 4.0 * std_of(r, "tip", Term::c));
}

TEST(Discover, TwoEffectsAtOnceCubicStiffnessAndVelocitySquaredDamping) {
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3, Term::c2}, {4800.0, 20.0, 1.6e8, 500.0})};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d));
  SCOPED_TRACE(describe(r));
  EXPECT_EQ(final_terms(r)["tip"], (std::set<Term>{Term::k, Term::c, Term::k3, Term::c2}));
  EXPECT_EQ(r.steps.size(), 2u);
  EXPECT_NEAR(value_of(r, "tip", Term::k3), 1.6e8, 0.005 * 1.6e8);
  EXPECT_NEAR(value_of(r, "tip", Term::c2), 500.0, 0.01 * 500.0);
  expect_at_noise_level(r);
}

TEST(Discover, TwoEffectsAtOnceCubicStiffnessAndDryFriction) {
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3, Term::fc}, {4800.0, 20.0, 1.6e8, 3.0})};
  d.levels = {20.0, 50.0, 100.0};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d));
  SCOPED_TRACE(describe(r));
  EXPECT_EQ(final_terms(r)["tip"], (std::set<Term>{Term::k, Term::c, Term::k3, Term::fc}));
  EXPECT_EQ(r.steps.size(), 2u);
  EXPECT_NEAR(value_of(r, "tip", Term::k3), 1.6e8, 0.01 * 1.6e8);
  EXPECT_NEAR(value_of(r, "tip", Term::fc), 3.0, 0.02 * 3.0);
  expect_at_noise_level(r);
  EXPECT_LT(r.gap.back(), 0.01 * r.gap.front());
}

TEST(Discover, TheEffectHidesAtOneOfTwoJointsAndTheOtherStaysLinear) {
  // A second joint at mid-span (node 4), stiffer, hides a cubic stiffness; the tip is linear.
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c}, {4800.0, 20.0}),
             joint("mid", 4, {Term::k, Term::c, Term::k3}, {2e4, 10.0, 2e9})};
  d.frequencies = {2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0};
  const discover::Result r = discover::discover(
      frf::Substructure(d.model), {linear_start("tip", 7), linear_start("mid", 4)}, measure(d));
  SCOPED_TRACE(describe(r));
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_EQ(r.steps[0].added.joint, "mid");
  EXPECT_EQ(r.steps[0].added.term, Term::k3);
  EXPECT_EQ(final_terms(r)["tip"], (std::set<Term>{Term::k, Term::c}));
  EXPECT_NEAR(value_of(r, "mid", Term::k3), 2e9, 0.005 * 2e9);
  EXPECT_EQ(r.diagnosis.joint, "mid");
  // The wrong location must lose: the same term at the tip explains less.
  const auto& ranking = r.steps[0].ranking;
  const auto at = [&](const std::string& j) {
    return std::find_if(ranking.begin(), ranking.end(), [&](const discover::Candidate& c) {
      return c.joint == j && c.term == Term::k3;
    });
  };
  ASSERT_NE(at("tip"), ranking.end());
  EXPECT_LT(at("mid")->gap, 0.1 * at("tip")->gap);
  expect_at_noise_level(r);
}

TEST(Discover, ALinearModelErrorIsReportedAsLinear) {
  // The substructure's damping is twice what the model says; the joint is linear. Tests span
  // the first two modes, so that the substructure's damping shows apart from the joint's.
  Data d;
  d.model.damping.modal_ratio = 0.02;
  d.truth = {joint("tip", 7, {Term::k, Term::c}, {4800.0, 20.0})};
  d.frequencies = {2.0, 3.0, 4.0, 5.0, 8.0, 17.0, 18.0, 19.0, 20.0};
  const discover::Result r = discover::discover(frf::Substructure(test::paper_cantilever()),
                                                {linear_start("tip", 7)}, measure(d));
  SCOPED_TRACE(describe(r));
  ASSERT_TRUE(r.diagnosis.level_dependent.has_value());
  EXPECT_FALSE(*r.diagnosis.level_dependent);
  for (const auto& step : r.steps) // no non-linear term "fixes" it
    EXPECT_TRUE(step.added.linear()) << step.added.name();
  EXPECT_EQ(final_terms(r)["tip"], (std::set<Term>{Term::k, Term::c}));
  EXPECT_NEAR(r.states.back().damping_scale, 2.0, 0.02 * 2.0);
  expect_at_noise_level(r);
}

// The same hidden cubic stiffness at 0.5 %, 1 % and 2 % noise: named, valued within 4 standard
// deviations, and the final gap at each noise level.
class NoiseLevel : public ::testing::TestWithParam<double> {};

TEST_P(NoiseLevel, CubicStiffnessIsFoundAndTheGapEndsAtTheNoise) {
  Data d;
  d.noise = GetParam();
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d));
  SCOPED_TRACE(describe(r));
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_EQ(r.steps[0].added.term, Term::k3);
  EXPECT_LT(std::abs(value_of(r, "tip", Term::k3) - 1.6e8), 4.0 * std_of(r, "tip", Term::k3));
  expect_at_noise_level(r);
  // The noise level follows the noise: the fundamental of a sinusoid of RMS A/√2 with white
  // noise of RMS level·A/√2 over n samples is off by level·√(2/n) (relative); the harmonics,
  // the mean and the force's noise driving the model add to it, by less than a factor 4.
  const double fundamental = GetParam() * std::sqrt(2.0 / (8 * 256));
  EXPECT_GT(r.noise_gap, fundamental);
  EXPECT_LT(r.noise_gap, 4.0 * fundamental);
}

// Named by the noise in per cent of each channel's RMS: Noise0_5pc, Noise1pc, Noise2pc.
INSTANTIATE_TEST_SUITE_P(Discover, NoiseLevel, ::testing::Values(0.005, 0.01, 0.02),
                         [](const auto& info) {
                           const long tenths = std::lround(info.param * 1000.0);
                           return "Noise" + std::to_string(tenths / 10) +
                                  (tenths % 10 ? "_" + std::to_string(tenths % 10) : "") + "pc";
                         });

TEST(Discover, FromStepSineFundamentalsOfAccelerationOnly) {
  // What many labs keep: the fundamental of force and drive-point acceleration per test. The
  // noise level is then unknown; the selection rule still adds what explains the gap, and stops.
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3, Term::fc}, {4800.0, 20.0, 1.6e8, 3.0})};
  d.levels = {20.0, 50.0, 100.0};
  d.frequencies = {2.0, 2.5, 3.0, 3.5, 4.0, 4.25, 4.5, 4.75, 5.0};
  d.channels = {identify::Quantity::acceleration};
  d.table = true;
  discover::Options o;
  o.harmonics = {1};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d, 1), o);
  SCOPED_TRACE(describe(r));
  EXPECT_LT(r.noise_gap, 0.0); // unknown
  EXPECT_EQ(final_terms(r)["tip"], (std::set<Term>{Term::k, Term::c, Term::k3, Term::fc}));
  EXPECT_NEAR(value_of(r, "tip", Term::k3), 1.6e8, 0.02 * 1.6e8);
  EXPECT_NEAR(value_of(r, "tip", Term::fc), 3.0, 0.03 * 3.0);
  EXPECT_LT(r.gap.back(), 0.05 * r.gap.front());
}

TEST(Discover, OnAOneModeModalModelWithDriftingLevels) {
  // The real-measurement case: the substructure a one-mode [modal] model of the joined structure
  // (its linear joint inside), stepped-sine tests at four levels whose linear stiffness drifts
  // by ±0.5 % from level to level, acceleration at the drive point. No model explains that to
  // the noise level; discovery must add the two effects that explain a real share, and stop.
  const fem::Model fe = test::paper_cantilever();
  std::vector<identify::Measurement> tests;
  const std::vector<std::pair<double, double>> levels{
      {5.0, 4830.0}, {20.0, 4790.0}, {50.0, 4815.0}, {100.0, 4780.0}};
  for (const auto& [level, k] : levels) {
    Data d;
    d.truth = {joint("tip", 7, {Term::k, Term::c, Term::k3, Term::fc}, {k, 20.0, 1.6e8, 3.0})};
    d.levels = {level};
    d.frequencies = {3.6, 3.8, 4.0, 4.2, 4.4, 4.6, 4.8};
    d.channels = {identify::Quantity::acceleration};
    d.table = true;
    for (auto& m : measure(d, 1))
      tests.push_back(std::move(m));
  }
  // The first mode of the cantilever with a 4800 N/m spring at the tip, at 7:uy: 4.1683 Hz,
  // φ = 0.2585 /√kg; damping 1 % plus the joint's c φ² / (2ω) = 2.55 %.
  frf::ModalModel modal;
  modal.dofs = {{7, fem::Dof::uy}};
  modal.frequencies_hz = Eigen::VectorXd::Constant(1, 4.168278);
  modal.damping = Eigen::VectorXd::Constant(1, 0.0355);
  modal.shapes = Eigen::MatrixXd::Constant(1, 1, 0.258487);
  discover::Options o;
  o.harmonics = {1};
  const discover::Result r =
      discover::discover(frf::Substructure(modal), {linear_start("tip", 7)}, tests, o);
  SCOPED_TRACE(describe(r));
  ASSERT_GE(r.steps.size(), 2u);
  EXPECT_LE(r.steps.size(), 4u);
  EXPECT_EQ(r.steps[0].added.term, Term::k3);
  const auto terms = final_terms(r)["tip"];
  EXPECT_TRUE(terms.count(Term::k3) && terms.count(Term::fc)) << describe(r);
  EXPECT_LT(r.gap.back(), 0.1 * r.gap.front());
  EXPECT_FALSE(r.stop_reason.find("maximum") != std::string::npos) << r.stop_reason;
}

TEST(Discover, AFrictionThatFallsWithTheAmplitudeIsNamedAsOutsideTheLibrary) {
  // The effect of the paper's experiment (examples/polyethylene) on the paper's cantilever: every
  // force level has its own Coulomb friction, the lower the larger the level (a contact whose
  // normal load falls as the vibration grows). No term of the library explains that; a friction
  // with a value per test does. Discovery must say so, at the tip, with the trend, and add
  // nothing to the model.
  std::vector<identify::Measurement> tests;
  // One frequency near the first mode, six levels: the amplitude grows with the level (at
  // several frequencies around a resonance it would not, and the friction here is set per level).
  const std::vector<std::pair<double, double>> levels{{20.0, 3.0}, {30.0, 2.7}, {40.0, 2.4},
                                                      {50.0, 2.1}, {60.0, 1.9}, {80.0, 1.5}};
  const std::vector<double> frequencies{3.2};
  for (const auto& [level, fc] : levels) {
    Data d;
    d.truth = {joint("tip", 7, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, fc})};
    d.levels = {level};
    d.frequencies = frequencies;
    for (auto& m : measure(d))
      tests.push_back(std::move(m));
  }
  // The linear part is known (k and c held: with one frequency a viscous c that changes per
  // test and a friction that does cannot be told apart); the friction's value is not given.
  joints::Joint start = joint("tip", 7, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 0.0});
  start.fixed = {true, true, false};
  start.given = {true, true, false};
  const discover::Result r =
      discover::discover(frf::Substructure(test::paper_cantilever()), {start}, tests);
  SCOPED_TRACE(describe(r));
  EXPECT_TRUE(r.steps.empty());
  EXPECT_NE(r.stop_reason.find("not in the library: fc at 'tip', a value per test"),
            std::string::npos)
      << r.stop_reason;
  ASSERT_FALSE(r.last_ranking.empty());
  const discover::Candidate& best = r.last_ranking.front();
  ASSERT_TRUE(best.varies.has_value()) << best.name();
  EXPECT_EQ(best.term, Term::fc);
  EXPECT_TRUE(best.rejected.empty()) << best.rejected;
  const discover::Variation& v = *best.varies;
  ASSERT_EQ(v.value.size(), tests.size());
  // Each test's own value is its level's friction, to the noise (k and c are right).
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const double truth = levels[i].second;
    EXPECT_NEAR(v.value[i], truth, 4.0 * v.std[i] + 0.01 * truth) << v.tests[i];
  }
  EXPECT_LT(v.amplitude_correlation, -0.99);
  EXPECT_GT(v.chi2, v.dof + 3.0 * std::sqrt(2.0 * v.dof));
  // It explains more than any addition of the library, and the diagnosis says so.
  for (const auto& c : r.last_ranking)
    if (!c.varies && std::isfinite(c.gap)) {
      EXPECT_GT(c.gap, best.gap) << c.name();
    }
  const std::string findings = [&] {
    std::string all;
    for (const auto& f : r.diagnosis.findings)
      all += f + "\n";
    return all;
  }();
  EXPECT_NE(findings.find("fc at 'tip' is not one number"), std::string::npos) << findings;
  EXPECT_NE(findings.find("it falls with the deformation amplitude"), std::string::npos)
      << findings;
}

// Periodic broadband tests (issue 30): multisine virtual tests of the cantilever, force at the
// tip, 1–4 Hz (Schroeder phases, every 0.25 Hz line), period 4 s, 256 Hz, `periods` periods from
// rest with a fade-in, by time integration in modal coordinates (never the harmonic balance
// discovery re-simulates with; 16 steps a sample: a period error (ωh)²/12 of 3e-5 at 12 Hz, the
// third harmonic of 4 Hz), each channel's noise `noise` of its RMS (force too), a seed per level.
std::vector<identify::Measurement> multisine_tests(const std::vector<joints::Joint>& truth,
                                                   const std::vector<double>& levels, double noise,
                                                   int periods = 8) {
  static const frf::Substructure cantilever(test::paper_cantilever());
  std::vector<identify::SineTest> records;
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const identify::ExcitationSpec spec{
        identify::Excitation::multisine, 1.0, 4.0, levels[i], 1, 4.0 * periods, 256.0, 4.0};
    identify::ForcedOptions o;
    o.fade_in_s = identify::default_fade_in_s(spec);
    o.substeps = 16;
    o.route = identify::TransientRoute::modal;
    o.quantities = {identify::Quantity::displacement, identify::Quantity::velocity};
    identify::ForcedTest test = identify::simulate_forced(
        cantilever, truth, identify::generated_force(spec, {7, fem::Dof::uy}), o);
    identify::add_noise(test, noise, 100 + i);
    test.record.source = "multisine_" + std::to_string(static_cast<int>(levels[i])) + "N.csv";
    records.push_back(std::move(test.record));
  }
  return identify::measure(records, {.harmonics = 3});
}

// A hidden cubic stiffness at the tip, multisine tests at four levels with 1 % noise: compared at
// their lines, re-simulated by the harmonic balance at 1/T, k3 is named and nothing else, within
// 4 standard deviations of the truth, and the gap falls from far above the noise to it.
TEST(Discover, PeriodicMultisineTestsNameAHiddenCubicStiffness) {
  const std::vector<identify::Measurement> tests =
      multisine_tests({joint("tip", 7, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})},
                      {10.0, 30.0, 60.0, 90.0}, 0.01);
  for (const auto& m : tests) {
    ASSERT_EQ(m.kind, identify::RecordKind::periodic) << m.source;
    EXPECT_TRUE(m.left_out.empty()) << m.left_out;
  }
  const discover::Result r = discover::discover(frf::Substructure(test::paper_cantilever()),
                                                {linear_start("tip", 7)}, tests);
  SCOPED_TRACE(describe(r));
  ASSERT_EQ(r.steps.size(), 1u);
  ASSERT_TRUE(r.steps[0].added.term.has_value());
  EXPECT_EQ(*r.steps[0].added.term, Term::k3);
  EXPECT_EQ(r.steps[0].added.joint, "tip");
  EXPECT_EQ(r.states.back().damping_scale, 1.0);
  EXPECT_LT(std::abs(value_of(r, "tip", Term::k3) - 1.6e8), 4.0 * std_of(r, "tip", Term::k3));
  EXPECT_LT(std::abs(value_of(r, "tip", Term::k) - 4800.0), 4.0 * std_of(r, "tip", Term::k));
  EXPECT_LT(std::abs(value_of(r, "tip", Term::c) - 20.0), 4.0 * std_of(r, "tip", Term::c));
  // Cross-validated (four tests: leave one out) and compared at the periodic tests' lines: the
  // 13 excited ones (4 … 16) at least, two real values each.
  EXPECT_GT(r.steps[0].cv_before, 0.0);
  EXPECT_LT(r.steps[0].cv_after, r.steps[0].cv_before);
  EXPECT_GT(r.compared_values, static_cast<int>(tests.size()) * 2 * 13);
  // The missing k3 stands far out of the noise at the start; the end is at the noise level.
  EXPECT_GT(r.gap.front(), 10.0 * r.noise_gap);
  expect_at_noise_level(r);
  EXPECT_EQ(r.diagnosis.joint, "tip");
  EXPECT_EQ(r.diagnosis.nature, "conservative");
  EXPECT_TRUE(r.curves.empty() || r.curves.back().empty()); // no sine sweep through a multisine
  // The report's comparisons: every excited line of every test (its FRF over them).
  ASSERT_EQ(r.comparisons.back().size(), tests.size() * 13);
  EXPECT_EQ(r.comparisons.back()[0].frequency_hz, 1.0);
  EXPECT_EQ(r.comparisons.back()[0].measured, tests[0].X(4, 0));
}

// A friction with its own stiffness and a clearance at the tip (issue 30's joint of a real
// structure): stuck at low levels, its stiffness falls as the Jenkins element slips (above fs/kt
// = 1 mm) and rises once the stop is met (delta 4 mm). Neither term alone follows that; the pair
// is started from one describing-function fit of both (each test at its deformation's peak: a
// multisine's slip and contact begin there) and refined by output error. Multisine tests at six
// levels, 1 % noise; discovery from k and c alone, the candidates jenkins and gap (to keep it
// short), one step: "jenkins and gap at 'tip'", every parameter within 5 % of the truth, and the
// gap at the noise level.
TEST(Discover, AFrictionAndAClearanceTogetherAreNamedTogether) {
  joints::Joint truth =
      joint("tip", 7, {Term::k, Term::c, Term::jenkins, Term::gap}, {4800.0, 20.0, 1.0, 1.0});
  truth.parameters.resize(4);
  truth.set_parameters(2, {5000.0, 5.0});
  truth.set_parameters(3, {4e-3, 2e4});
  const std::vector<identify::Measurement> tests =
      multisine_tests({truth}, {5.0, 10.0, 20.0, 40.0, 80.0, 120.0}, 0.01);
  discover::Options o;
  o.terms = {Term::jenkins, Term::gap};
  o.max_steps = 1;
  o.substructure_damping = false;
  const discover::Result r = discover::discover(frf::Substructure(test::paper_cantilever()),
                                                {linear_start("tip", 7)}, tests, o);
  SCOPED_TRACE(describe(r));
  ASSERT_EQ(r.steps.size(), 1u);
  const discover::Candidate& added = r.steps[0].added;
  EXPECT_EQ(added.name(), "jenkins and gap at 'tip'");
  ASSERT_EQ(added.parameters.size(), 2u);
  ASSERT_EQ(added.with_parameters.size(), 2u);
  const double truth_values[] = {5000.0, 5.0, 4e-3, 2e4};
  const identify::ParameterEstimate* found[] = {&added.parameters[0], &added.parameters[1],
                                                &added.with_parameters[0],
                                                &added.with_parameters[1]};
  for (int p = 0; p < 4; ++p)
    EXPECT_NEAR(found[p]->value, truth_values[p], 0.05 * truth_values[p]) << found[p]->name;
  EXPECT_NEAR(value_of(r, "tip", Term::k), 4800.0, 0.05 * 4800.0);
  EXPECT_GT(r.gap.front(), 10.0 * r.noise_gap);
  expect_at_noise_level(r);
}

// The same joint of a real structure under sine tests (35: 2-5 Hz at 10-80 N, time integration,
// 1 % noise), with a strong friction and a wide clearance (kt 1e4 N/m, fs 20 N: slip from 2 mm;
// delta 15 mm, kg 1e4 N/m): a case that one parametric term at a time never found (the Jenkins
// element's screening state, the other terms refitted around it, left a gap of 1.64 against 0.33
// before it). With every candidate of the library, the pair is named in one step, each parameter
// within 3 % of the truth, and the gap falls from 0.68 by more than 100 times, to within twice its
// floor (measured: 0.00138, the noise and the simulation's own error 0.00105 together; the
// harmonic balance's error for a friction and a stop at 15 harmonics is what is left).
TEST(Discover, AFrictionAndAWideClearanceUnderSineTestsAreNamedTogether) {
  Data d;
  joints::Joint truth =
      joint("tip", 7, {Term::k, Term::c, Term::jenkins, Term::gap}, {4800.0, 20.0, 1.0, 1.0});
  truth.parameters.resize(4);
  truth.set_parameters(2, {1.0e4, 20.0});
  truth.set_parameters(3, {15e-3, 1e4});
  d.truth = {truth};
  d.levels = {10.0, 20.0, 40.0, 60.0, 80.0};
  const discover::Result r =
      discover::discover(frf::Substructure(d.model), {linear_start("tip", 7)}, measure(d));
  SCOPED_TRACE(describe(r));
  ASSERT_GE(r.steps.size(), 1u);
  const discover::Candidate& added = r.steps[0].added;
  EXPECT_EQ(added.name(), "jenkins and gap at 'tip'");
  ASSERT_EQ(added.parameters.size(), 2u);
  ASSERT_EQ(added.with_parameters.size(), 2u);
  EXPECT_NEAR(added.parameters[0].value, 1.0e4, 0.03 * 1.0e4);
  EXPECT_NEAR(added.parameters[1].value, 20.0, 0.03 * 20.0);
  EXPECT_NEAR(added.with_parameters[0].value, 15e-3, 0.03 * 15e-3);
  EXPECT_NEAR(added.with_parameters[1].value, 1e4, 0.03 * 1e4);
  EXPECT_LT(r.gap.back(), 0.01 * r.gap.front());
  EXPECT_LT(r.gap.back(), 2.0 * std::hypot(r.noise_gap, r.simulation_gap));
}

namespace {

// The cantilever's tip receptance sampled every 0.05 Hz to 20 Hz, as a measured-FRF substructure.
frf::MeasuredFrf tip_frf_to_20_hz() {
  const frf::Substructure model(test::paper_cantilever());
  const int tip = model.dofs().equation({7, fem::Dof::uy});
  const frf::ModalSynthesis H = model.synthesis({tip}, 100.0);
  frf::MeasuredFrf frf;
  frf.dofs = {{7, fem::Dof::uy}};
  frf::MeasuredFunction f{{7, fem::Dof::uy}, {7, fem::Dof::uy}, {}, {}, "sampled from the model"};
  for (int i = 0; i <= 400; ++i) { // to 20 Hz
    const int e[] = {tip};
    f.frequencies_hz.push_back(0.05 * i);
    f.receptance.push_back(H.receptance(2.0 * std::numbers::pi * 0.05 * i, e, e)(0, 0));
  }
  frf.functions.push_back(f);
  return frf;
}

// A multisine test every 0.25 Hz, lines 4 and 6 excited by 10 N, `other` N at line 8 (not
// excited), its force's noise unknown.
identify::Measurement multisine_with_line_8(double other) {
  std::vector<std::complex<double>> X(9, 1e-4);
  identify::Measurement m =
      test::measurement("multisine.csv", 0.25, 0.0, X, std::vector<double>(9, 1e-12));
  m.kind = identify::RecordKind::periodic;
  m.F(4, 0) = 10.0, m.F(6, 0) = 10.0, m.F(8, 0) = other;
  m.lines = m.excited_lines = {4, 6};
  return m;
}

// The refusal of a periodic test whose balance reaches past the measured FRFs.
std::string refusal_at_20_hz(const identify::Measurement& m) {
  try {
    (void)discover::discover(frf::Substructure(tip_frf_to_20_hz()), {linear_start("tip", 7)}, {m});
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "a band to 20 Hz was accepted";
}

} // namespace

// A periodic test re-simulated through measured FRFs needs them to twice line max(K, 10) × its
// highest driven line: lines 4 and 6 every 0.25 Hz, K = 3: line 60, 15 Hz, doubled 30 Hz; FRFs to
// 20 Hz are refused, naming the test and saying how far to measure.
TEST(Discover, APeriodicTestBeyondTheMeasuredFrfsBandIsRefusedNamingIt) {
  EXPECT_EQ(refusal_at_20_hz(multisine_with_line_8(0.0)),
            "multisine.csv: the measured FRFs reach 20 Hz; this periodic test's "
            "re-simulation needs 30 Hz (twice line 60: the joints' response up to "
            "10 times its highest driven line, doubled to estimate the "
            "simulation's own error). Measure the FRFs to that, or use fewer of "
            "its lines (--band)");
}

// A line the periodic test does not excite drives its re-simulation (and sets how far its
// balance reaches) only above 1e-3 of its largest excited line, whatever its noise: 1 % of it
// at line 8 takes the balance to line 80 (twice: 40 Hz), 1e-4 of it leaves line 60 (30 Hz).
TEST(Discover, APeriodicTestsLineFarBelowItsExcitedOnesDoesNotDriveIt) {
  EXPECT_NE(refusal_at_20_hz(multisine_with_line_8(0.1)).find("needs 40 Hz (twice line 80"),
            std::string::npos);
  EXPECT_NE(refusal_at_20_hz(multisine_with_line_8(1e-3)).find("needs 30 Hz (twice line 60"),
            std::string::npos);
}

TEST(Discover, BadInputIsRefusedWithTheReason) {
  Data d;
  d.truth = {joint("tip", 7, {Term::k, Term::c}, {4800.0, 20.0})};
  d.frequencies = {3.0};
  d.levels = {10.0};
  const std::vector<identify::Measurement> tests = measure(d);
  const frf::Substructure sub(d.model);
  EXPECT_THROW(discover::discover(sub, {linear_start("tip", 7)}, {}), std::invalid_argument);
  EXPECT_THROW(discover::discover(sub, {}, tests), std::invalid_argument);
  // A joint whose DOF no test measures.
  try {
    discover::discover(sub, {linear_start("tip", 7), linear_start("mid", 4)}, tests);
    ADD_FAILURE() << "a joint at an unmeasured DOF was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("4:uy"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace jointid
