// Identification round trips with known truth: responses simulated by time integration (an
// independent method: the identification never sees the joint model's equations) or by
// harmonic balance, then identified from the records and the substructure's modal FRFs.
#include "identify/fit.hpp"

#include "fem/damping.hpp"
#include "fem/time_integration.hpp"
#include "frf/harmonic_balance.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"
#include "support/failing_substructure.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <numbers>

using namespace jointid;
using joints::Term;

namespace {

using jointid::test::two_pi;

joints::Joint make_joint(std::string name, int node, int node_b, std::vector<Term> terms,
                         std::vector<double> values) {
  joints::Joint j{std::move(name),   node, node_b, fem::Dof::uy, std::move(terms),
                  std::move(values), {},   {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

class FitTest : public ::testing::Test {
protected:
  void SetUp() override {
    model = test::paper_cantilever();
    system = fem::assemble(model);
    modes = fem::modal_analysis(system, {.num_modes = 0});
    std::vector<int> all(system.dofs.num_equations());
    for (int i = 0; i < system.dofs.num_equations(); ++i)
      all[i] = i;
    synthesis.emplace(system, modes, model.damping, all);
    H = [this](double w, std::span<const int> r, std::span<const int> c) {
      return synthesis->receptance(w, r, c);
    };
  }
  int eq(int node) const { return system.dofs.equation({node, fem::Dof::uy}); }

  // Spectra built by hand, one per frequency, for a joint with two terms at the tip: the
  // fundamental only, a force of 80 N, X2 = 1e-3 - 2e-3 i, the first term's basis harmonic that
  // of a viscous damper (i ω X2) and the second's `second(f, first)`.
  std::vector<identify::TestSpectrum> two_term_spectra(
      const std::vector<double>& frequencies,
      const std::function<Eigen::VectorXcd(double, const Eigen::VectorXcd&)>& second) const {
    std::vector<identify::TestSpectrum> tests;
    for (double f : frequencies) {
      identify::TestSpectrum t;
      t.source = "synthetic";
      t.frequency_hz = f;
      t.force_equations = {eq(7)};
      t.F = Eigen::MatrixXcd::Zero(2, 1);
      t.F(1, 0) = {0.0, -80.0};
      t.X2 = Eigen::MatrixXcd::Zero(2, 1);
      t.X2(1, 0) = {1e-3, -2e-3};
      Eigen::MatrixXcd G(2, 2);
      G.col(0) = std::complex<double>(0.0, two_pi * f) * t.X2.col(0);
      G.col(1) = second(f, G.col(0));
      t.G = {G};
      tests.push_back(t);
    }
    return tests;
  }

  // A steady-state record by time integration (the library's virtual sine test): force, x and v
  // at the joint DOFs and the force DOF.
  identify::Record time_record(const std::vector<joints::Joint>& js, int force_node, double f,
                               double amp, int steps = 1024) const {
    identify::SimulationOptions o;
    o.steps_per_period = steps;
    o.periods = 4;
    return simulated(js, force_node, f, amp, o);
  }

  // The same record from harmonic balance (15 harmonics), sampled 512 times a period.
  identify::Record hb_record(const std::vector<joints::Joint>& js, int force_node, double f,
                             double amp) const {
    identify::SimulationOptions o;
    o.method = identify::SimulationMethod::harmonic_balance;
    o.steps_per_period = 512;
    o.periods = 2;
    o.balance.harmonics = 15;
    return simulated(js, force_node, f, amp, o);
  }

  identify::Record simulated(const std::vector<joints::Joint>& js, int force_node, double f,
                             double amp, const identify::SimulationOptions& o) const {
    auto tests = identify::simulate_sine_tests(frf::Substructure(model), js,
                                               {force_node, fem::Dof::uy}, {{f, amp}}, o);
    EXPECT_TRUE(tests.front().warnings.empty());
    return std::move(tests.front().record);
  }

  fem::Model model;
  fem::Assembled system;
  fem::Modes modes;
  std::optional<frf::ModalSynthesis> synthesis;
  identify::ReceptanceFn H;
};

void expect_values(const identify::FitResult& r, const std::vector<joints::Joint>& truth,
                   double rel) {
  ASSERT_EQ(r.joints.size(), truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i)
    for (std::size_t t = 0; t < truth[i].terms.size(); ++t)
      EXPECT_NEAR(r.joints[i].terms[t].value, truth[i].values[t],
                  rel * std::abs(truth[i].values[t]))
          << truth[i].name << "." << joints::term_name(truth[i].terms[t]);
}

TEST_F(FitTest, PaperModelIFromTimeIntegrationFrequencySweep) {
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::c2, Term::k3}, {4800, 20, 500, 1.6e8})};
  std::vector<identify::Record> records;
  for (int i = 0; i < 10; ++i)
    records.push_back(time_record(truth, 7, 1.0 + 0.4 * i, 80.0));
  const identify::FitResult r = identify::fit(H, system.dofs, truth, records);
  // Newmark at 1024 steps a period leaves a dispersion error ≈ (ωh)²/12 ≈ 3e-6 in the
  // response; the issue's bar for model I is 0.05 %.
  expect_values(r, truth, 5e-4);
  EXPECT_EQ(r.equations, 20);
  EXPECT_EQ(r.unknowns, 4);
  EXPECT_LT(r.residual_relative, 1e-4);
  for (const auto& t : r.joints[0].terms) { // the interval must contain the truth
    EXPECT_GT(t.std, 0.0);
    EXPECT_LT(t.ci_low, t.ci_high);
  }
}

TEST_F(FitTest, CoulombFrictionFromTimeIntegrationAmplitudeSweep) {
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::fc, Term::k3}, {4800, 20, 3.0, 1.6e8})};
  std::vector<identify::Record> records;
  for (int i = 1; i <= 10; ++i)
    records.push_back(time_record(truth, 7, 3.0, 10.0 * i, 2048));
  const identify::FitResult r = identify::fit(H, system.dofs, truth, records);
  expect_values(r, truth, 1e-2); // the issue's bar for model II
}

TEST_F(FitTest, TwoJointsForceOffTheJointsHarmonicBalance) {
  // A joint to ground at the tip and one between nodes 3 and 4; force at node 5 (set 1), so
  // the right-hand side needs H21 F1. Both joints are identified at once.
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800, 20, 1.6e8}),
      make_joint("mid", 3, 4, {Term::k, Term::c2}, {2.0e5, 300.0})};
  std::vector<identify::Record> records;
  for (double f : {2.0, 3.5, 5.0, 12.0, 17.0, 19.0, 25.0})
    for (double a : {40.0, 120.0})
      records.push_back(hb_record(truth, 5, f, a));
  const identify::FitResult r =
      identify::fit(H, system.dofs, truth, records, {.harmonics = {1, 3}});
  // Harmonic balance and identification share only H; truncation at 15 harmonics and
  // sampling leave errors far below 1e-5.
  expect_values(r, truth, 1e-5);
  EXPECT_EQ(r.unknowns, 5);
  EXPECT_EQ(r.equations, 14 * 2 * 3 * 2); // tests × harmonics × set-2 DOFs × (re, im)
}

TEST_F(FitTest, FixedTermsAreHeldAndMovedToTheRightHandSide) {
  std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800, 20, 1.6e8})};
  std::vector<identify::Record> records;
  for (double f : {2.0, 3.0, 4.0})
    records.push_back(hb_record(truth, 7, f, 80.0));
  std::vector<joints::Joint> start = truth;
  start[0].fixed = {true, false, false};
  start[0].values = {4800, 1.0, 1.0}; // wrong starting values for the free terms
  const identify::FitResult r = identify::fit(H, system.dofs, start, records);
  EXPECT_EQ(r.unknowns, 2);
  EXPECT_TRUE(r.joints[0].terms[0].fixed);
  expect_values(r, truth, 1e-6);
  // A wrong fixed value must show: k held 10 % low biases the rest and the residual grows.
  start[0].values[0] = 4320;
  const identify::FitResult wrong = identify::fit(H, system.dofs, start, records);
  EXPECT_GT(wrong.residual_relative, 100 * r.residual_relative);
}

TEST_F(FitTest, TooFewEquationsIsAClearError) {
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800, 20, 1.6e8})};
  const std::vector<identify::Record> records{hb_record(truth, 7, 3.0, 80.0)};
  try {
    identify::fit(H, system.dofs, truth, records);
    FAIL() << "2 equations for 3 unknowns accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("2 equations for 3 unknowns"), std::string::npos)
        << e.what();
  }
}

TEST_F(FitTest, InseparableTermsAreAClearError) {
  // Two terms whose basis harmonics are exactly proportional in every test (here built by
  // hand: G_c3 = 2 G_c) cannot be told apart, however many tests there are.
  const std::vector<joints::Joint> js{make_joint("tip", 7, 0, {Term::c, Term::c3}, {20, 1.0})};
  const auto tests =
      two_term_spectra({2.0, 3.0, 4.0}, [](double, const Eigen::VectorXcd& g) -> Eigen::VectorXcd {
        return 2.0 * g;
      });
  // A numerical outcome, not bad input: a status with its reason, and no value is returned as
  // if it were determined.
  const identify::FitResult r = identify::fit(H, system.dofs, js, tests);
  EXPECT_EQ(r.status.code, fem::Status::Code::not_separable);
  EXPECT_NE(r.status.reason.find("cannot be separated"), std::string::npos) << r.status.reason;
  // Both are named, whichever the singular vector leans to.
  EXPECT_NE(r.status.reason.find("terms c of 'tip' and c3 of 'tip' act alike"), std::string::npos)
      << r.status.reason;
  EXPECT_GE(r.condition_number, 1e13);
  for (const auto& te : r.joints.at(0).terms) {
    EXPECT_TRUE(std::isnan(te.value));
    EXPECT_FALSE(te.determined);
  }
  ASSERT_FALSE(r.identifiability.empty());
  EXPECT_EQ(r.identifiability[0], r.status.reason);
  EXPECT_THROW(r.identified(js), std::invalid_argument);
}

// The whole set of terms that cannot be told apart is named, and only it: three terms of
// which the third's basis harmonics are a combination of the first two (all three named), and
// two twins beside a term of its own (only the twins named). Which single term a solver would
// pick depends on the rounding; the set does not.
TEST_F(FitTest, InseparableTermsAreNamedAsAWholeSet) {
  auto reason = [&](const std::vector<Term>& terms,
                    const std::function<Eigen::MatrixXcd(double, const Eigen::VectorXcd&)>& G) {
    std::vector<identify::TestSpectrum> tests;
    for (double f : {2.0, 3.0, 4.0, 5.0}) {
      identify::TestSpectrum t;
      t.source = "synthetic";
      t.frequency_hz = f;
      t.force_equations = {eq(7)};
      t.F = Eigen::MatrixXcd::Zero(2, 1);
      t.F(1, 0) = {0.0, -80.0};
      t.X2 = Eigen::MatrixXcd::Zero(2, 1);
      t.X2(1, 0) = {1e-3 * f, -2e-3};
      t.G = {G(f, t.X2.col(0))};
      tests.push_back(t);
    }
    const identify::FitResult r = identify::fit(
        H, system.dofs, {make_joint("tip", 7, 0, terms, std::vector<double>(terms.size(), 1.0))},
        tests);
    EXPECT_EQ(r.status.code, fem::Status::Code::not_separable);
    return r.status.reason;
  };
  // k: y; c: iω y; k3 (here): 3 y − 0.5 iω y, a combination of both.
  const std::string three =
      reason({Term::k, Term::c, Term::k3}, [](double f, const Eigen::VectorXcd& x) {
        const std::complex<double> iw(0.0, two_pi * f);
        Eigen::MatrixXcd G(2, 3);
        G << x, iw * x, 3.0 * x - 0.5 * iw * x;
        return G;
      });
  EXPECT_NE(three.find("terms k of 'tip', c of 'tip' and k3 of 'tip' act alike (a combination of "
                       "them has no effect in these tests)"),
            std::string::npos)
      << three;
  // k and k3 twins (k3's harmonics −2 k's), c a term of its own.
  const std::string twins =
      reason({Term::k, Term::c, Term::k3}, [](double f, const Eigen::VectorXcd& x) {
        const std::complex<double> iw(0.0, two_pi * f);
        Eigen::MatrixXcd G(2, 3);
        G << x, iw * x * x(1).real() * 1e3, -2.0 * x;
        return G;
      });
  EXPECT_NE(twins.find("terms k of 'tip' and k3 of 'tip' act alike"), std::string::npos) << twins;
  EXPECT_EQ(twins.find("c of 'tip'"), std::string::npos) << twins;
}

TEST_F(FitTest, ATermWithoutEffectOrEveryTermFixedIsRefused) {
  auto message = [&](const std::vector<joints::Joint>& js,
                     const std::vector<identify::TestSpectrum>& tests) {
    try {
      identify::fit(H, system.dofs, js, tests);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  // c3's basis harmonics are zero in every test: nothing to fit it to.
  const auto zero = two_term_spectra({2.0, 3.0, 4.0}, [](double, const Eigen::VectorXcd& g) {
    return Eigen::VectorXcd(Eigen::VectorXcd::Zero(g.size()));
  });
  std::vector<joints::Joint> js{make_joint("tip", 7, 0, {Term::c, Term::c3}, {20, 1.0})};
  EXPECT_EQ(message(js, zero),
            "identify: term c3 of 'tip' has no effect in these tests (its basis function is zero)");
  js[0].fixed = {true, true};
  EXPECT_EQ(message(js, zero), "identify: every joint term is fixed; nothing to identify");
}

TEST_F(FitTest, IllConditionedAndUnderdeterminedFitsWarn) {
  const std::vector<joints::Joint> js{make_joint("tip", 7, 0, {Term::c, Term::c3}, {20, 1.0})};
  auto has = [](const identify::FitResult& r, const std::string& what) {
    for (const auto& w : r.warnings)
      if (w.find(what) != std::string::npos) return true;
    return false;
  };
  // c3's basis nearly proportional to c's (1e-9 apart, differently at each frequency): the
  // condition number lies between the warning (1e8) and inseparable (1e13), and the
  // inconsistent data leave both terms with a std far above their values.
  const auto near = two_term_spectra({2.0, 3.0, 4.0}, [](double f, const Eigen::VectorXcd& g) {
    return Eigen::VectorXcd((2.0 + 1e-9 * (f - 3.0)) * g);
  });
  const identify::FitResult r = identify::fit(H, system.dofs, js, near);
  ASSERT_TRUE(r.status.ok()) << r.status.reason;
  EXPECT_GT(r.condition_number, 1e8);
  EXPECT_LT(r.condition_number, 1e13);
  EXPECT_TRUE(has(r, "Q is ill-conditioned (condition number "))
      << ::testing::PrintToString(r.warnings);
  EXPECT_TRUE(has(r, "): parameters may be poorly determined"))
      << ::testing::PrintToString(r.warnings);
  for (const std::string term : {"c", "c3"})
    EXPECT_TRUE(has(r, "joint 'tip', term '" + term + "': poorly determined (std "))
        << term << ": " << ::testing::PrintToString(r.warnings);
  // One test, its fundamental only: 2 equations (real and imaginary parts) for 2 unknowns.
  const auto one = two_term_spectra({3.0}, [](double, const Eigen::VectorXcd& g) {
    return Eigen::VectorXcd(std::complex<double>(0.5, 0.5) * g);
  });
  const identify::FitResult exact = identify::fit(H, system.dofs, js, one);
  ASSERT_TRUE(exact.status.ok()) << exact.status.reason;
  EXPECT_EQ(exact.equations, 2);
  EXPECT_TRUE(has(exact, "as many equations as unknowns: no uncertainty estimate"))
      << ::testing::PrintToString(exact.warnings);
}

TEST_F(FitTest, WarnsAboutUnsteadyAndClippedRecordsAndDerivedVelocity) {
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800, 20, 1.6e8})};
  std::vector<identify::Record> records;
  for (double f : {2.0, 3.0, 4.0})
    records.push_back(hb_record(truth, 7, f, 80.0));
  identify::Record growing = records[0];
  Eigen::VectorXd& x = growing.channels[1].samples;
  for (int i = 0; i < x.size(); ++i)
    x(i) *= 1.0 + 0.02 * i / x.size(); // 2 % growth
  identify::Record clipped = records[1];
  Eigen::VectorXd& xc = clipped.channels[1].samples;
  const double limit = 0.8 * xc.cwiseAbs().maxCoeff();
  xc = xc.cwiseMax(-limit).cwiseMin(limit);
  identify::Record no_velocity = records[2];
  no_velocity.channels.pop_back();
  const identify::FitResult r = identify::fit(
      H, system.dofs, truth, std::vector<identify::Record>{growing, clipped, no_velocity});
  auto warned = [&](const std::string& source, const std::string& what) {
    for (const auto& w : r.warnings)
      if (w.find(source) != std::string::npos && w.find(what) != std::string::npos) return true;
    return false;
  };
  // Its two periods differ by 1 %: the response does not repeat, and the record is left out.
  EXPECT_TRUE(warned(growing.source, "periods 1 and 2 differ beyond the noise"));
  EXPECT_TRUE(warned(growing.source, "left out"));
  EXPECT_TRUE(warned(clipped.source, "clipped"));
  EXPECT_TRUE(warned(no_velocity.source, "velocity derived"));
  EXPECT_FALSE(warned(no_velocity.source, "clipped"));
}

// Issue 31: one record of ten with a decaying transient — a free vibration at the first mode,
// 15 % of the response, time constant 1.5 s — moved c by 9 % with no word about that record.
// Its transient periods are now dropped, naming the record and the periods, and c stays within
// the interval of the clean identification (two of its standard deviations).
TEST_F(FitTest, ATransientOnOneRecordIsNamedAndDropped) {
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::c2, Term::k3}, {4800, 20, 500, 1.6e8})};
  identify::SimulationOptions o;
  o.steps_per_period = 256;
  o.periods = 16;
  std::vector<identify::Record> clean;
  for (int i = 0; i < 10; ++i) {
    clean.push_back(simulated(truth, 7, 1.0 + 0.4 * i, 80.0, o));
    identify::add_noise(clean.back(), 0.01, 100 + static_cast<std::uint64_t>(i));
  }
  std::vector<identify::Record> records = clean;
  identify::Record& hit = records[6]; // 3.4 Hz, near the first mode
  const double wd = two_pi * 3.3, tau = 1.5;
  double amplitude = 0.0;
  for (const auto& c : hit.channels)
    if (c.quantity == identify::Quantity::displacement)
      amplitude = 0.15 * c.samples.cwiseAbs().maxCoeff();
  for (auto& c : hit.channels)
    for (Eigen::Index i = 0; i < c.samples.size(); ++i) {
      const double t = hit.t(i), decay = amplitude * std::exp(-t / tau);
      if (c.quantity == identify::Quantity::displacement)
        c.samples(i) += decay * std::cos(wd * t);
      else if (c.quantity == identify::Quantity::velocity)
        c.samples(i) += decay * (-wd * std::sin(wd * t) - std::cos(wd * t) / tau);
    }
  const identify::FitResult reference = identify::fit(H, system.dofs, truth, clean);
  const identify::FitResult r = identify::fit(H, system.dofs, truth, records);
  ASSERT_TRUE(r.status.ok()) << r.status.reason;
  bool named = false;
  for (const auto& w : r.warnings)
    named = named ||
            (w.find(hit.source) != std::string::npos &&
             w.find("not steady: a transient") != std::string::npos &&
             w.find("periods 1 to") != std::string::npos &&
             (w.find("dropped") != std::string::npos || w.find("left out") != std::string::npos));
  EXPECT_TRUE(named);
  const identify::TermEstimate& c = r.joints[0].terms[1];
  const identify::TermEstimate& c_clean = reference.joints[0].terms[1];
  EXPECT_NEAR(c.value, c_clean.value, 2.0 * c_clean.std);
  // The clean records themselves are steady: nothing dropped there.
  for (const auto& w : reference.warnings)
    EXPECT_EQ(w.find("not steady"), std::string::npos) << w;
}

TEST_F(FitTest, DerivedVelocityStillIdentifies) {
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, Term::c2, Term::k3}, {4800, 20, 500, 1.6e8})};
  std::vector<identify::Record> records;
  for (double f : {1.5, 2.5, 3.5, 4.5}) {
    records.push_back(hb_record(truth, 7, f, 80.0));
    records.back().channels.pop_back(); // drop v@7:uy
  }
  const identify::FitResult r = identify::fit(H, system.dofs, truth, records);
  expect_values(r, truth, 1e-4);
}

TEST_F(FitTest, MissingJointChannelNamesTheRecordAndChannel) {
  const std::vector<joints::Joint> truth{make_joint("tip", 7, 0, {Term::k}, {4800})};
  identify::Record r = hb_record(truth, 7, 3.0, 80.0);
  ASSERT_EQ(r.channels[1].name(), "x@7:uy");
  ASSERT_EQ(r.channels[2].name(), "v@7:uy");
  // Velocity alone would do (the displacement is derived from it): drop both.
  r.channels.erase(r.channels.begin() + 1, r.channels.begin() + 3);
  try {
    identify::fit(H, system.dofs, truth, std::vector<identify::Record>{r});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(r.source), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("x@7:uy"), std::string::npos) << e.what();
  }
}

// Every term of the library, simulated and recovered: a tip joint k = 4800 N/m, c = 20 N s/m
// plus the term, sine tests at 2.0 … 5.0 Hz (around the joined structure's first resonance,
// ≈ 4.2 Hz) simulated by time integration of the FE model through
// identify::simulate_sine_tests (an independent method: the identification never sees the
// joint law's equations), identified from harmonics 1–3.
//
// The identification equations hold exactly for these joint laws; what remains is the
// integrator's O(h²) error of the responses, (ωh)²/12 = 3.1e-6 at 1024 steps a period, times
// the quality factor near resonance (≤ 12), ×4 at harmonic 2 and ×9 at harmonic 3. It enters
// each coefficient divided by that term's share of the joint force in the harmonics used, so
// the bound differs per term. Measured relative errors (k, c, term) at 1024 steps, and at 2048
// steps all four times smaller (checked when the test was written: the error is the
// integrator's):
//   k2  7.3e-6, 7.8e-7, 1.4e-4  (k2 shows in harmonic 2 only, where the error is 4× larger
//                                and the response small)
//   k3  4.1e-6, 1.1e-6, 2.7e-6
//   c2  7.3e-6, 7.7e-7, 3.5e-8
//   c3  7.5e-6, 6.8e-7, 1.3e-7
//   fc  6.2e-5, 3.5e-5, 4.2e-5  (the joint sticks up to 2 % of a period at 20 N, 2 Hz, where
//                                the basis sign(ẏ) says 0 while the force lies anywhere in
//                                [−fc, fc]; and stick–slip integration is only first order
//                                at the transitions)
// Bounds: about 4 times the measured error, at least 1e-5 (2e-5 for k).

struct TermCase {
  double value;               ///< the term's coefficient (SI)
  std::vector<double> levels; ///< force amplitudes, N
  double tol_k, tol_c, tol_term;
};

TermCase term_case(Term t) {
  switch (t) {
  case Term::k2: // k2 y²: keep y far from the saddle of k y + k2 y² at y = −(k + 4860)/k2 ≈ −0.19 m
    return {5e4, {20.0, 40.0}, 3e-5, 1e-5, 5e-4};
  case Term::k3:
    return {1.6e8, {40.0, 80.0}, 2e-5, 1e-5, 1.5e-5};
  case Term::c2:
    return {500.0, {40.0, 80.0}, 3e-5, 1e-5, 1e-5};
  case Term::c3:
    return {500.0, {40.0, 80.0}, 3e-5, 1e-5, 1e-5};
  case Term::fc: // mostly sliding at ≥ 20 N
    return {3.0, {20.0, 50.0, 80.0}, 3e-4, 2e-4, 2e-4};
  default:
    throw std::logic_error("no case for this term");
  }
}

std::string term_case_name(const ::testing::TestParamInfo<Term>& info) {
  return std::string(joints::term_name(info.param));
}

class EveryTermTest : public ::testing::TestWithParam<Term> {};

TEST_P(EveryTermTest, SimulatedByTimeIntegrationAndRecovered) {
  const Term T = GetParam();
  const TermCase tc = term_case(T);
  const fem::NodeDof tip{7, fem::Dof::uy};
  const std::vector<joints::Joint> truth{
      make_joint("tip", 7, 0, {Term::k, Term::c, T}, {4800.0, 20.0, tc.value})};
  const frf::Substructure sub(test::paper_cantilever());
  std::vector<identify::SineTestPlan> plans;
  for (double f : {2.0, 2.6, 3.2, 3.8, 4.4, 5.0})
    for (double a : tc.levels)
      plans.push_back({f, a});
  identify::SimulationOptions o;
  o.periods = 2;
  o.steps_per_period = 1024;
  const std::vector<identify::SimulatedTest> tests =
      identify::simulate_sine_tests(sub, truth, tip, plans, o);
  std::vector<identify::Record> records;
  for (const auto& t : tests) {
    EXPECT_TRUE(t.warnings.empty()) << t.record.source; // periodic steady state reached
    // Bounded, and small enough for the term to stay stable (≤ 3 cm measured).
    const auto* x = t.record.find(identify::Quantity::displacement, tip);
    ASSERT_NE(x, nullptr);
    EXPECT_LT(x->samples.cwiseAbs().maxCoeff(), 0.1) << t.record.source;
    records.push_back(t.record);
  }
  const frf::ModalSynthesis synthesis = sub.synthesis({sub.dofs().equation(tip)}, 100.0);
  const identify::ReceptanceFn H = [&](double w, std::span<const int> r, std::span<const int> c) {
    return synthesis.receptance(w, r, c);
  };
  const identify::FitResult r =
      identify::fit(H, sub.dofs(), truth, records, {.harmonics = {1, 2, 3}});
  ASSERT_EQ(r.joints.size(), 1u);
  ASSERT_EQ(r.joints[0].terms.size(), 3u);
  const double tol[3] = {tc.tol_k, tc.tol_c, tc.tol_term};
  for (std::size_t t = 0; t < 3; ++t) {
    EXPECT_EQ(r.joints[0].terms[t].term, truth[0].terms[t]);
    EXPECT_NEAR(r.joints[0].terms[t].value, truth[0].values[t], tol[t] * truth[0].values[t])
        << joints::term_name(truth[0].terms[t]);
  }
  // The term matters: leaving it out makes the residual at least 100 times larger.
  joints::Joint linear = truth[0];
  linear.terms.resize(2), linear.values.resize(2), linear.fixed.resize(2);
  const identify::FitResult without =
      identify::fit(H, sub.dofs(), {linear}, records, {.harmonics = {1, 2, 3}});
  EXPECT_GT(without.residual_relative, 100.0 * r.residual_relative);
  // Friction: the identification says that the joint sticks where it does (20 N at 2 Hz).
  if (T == Term::fc) {
    bool warned = false;
    for (const auto& w : r.warnings)
      warned = warned ||
               (w.rfind("sine_f2Hz_F20N.csv: joint 'tip' sticks for ", 0) == 0 &&
                w.find(" % of the record; the Coulomb basis sign(ydot) does not describe the force "
                       "while stuck") != std::string::npos);
    EXPECT_TRUE(warned) << ::testing::PrintToString(r.warnings);
  }
}

INSTANTIATE_TEST_SUITE_P(Library, EveryTermTest,
                         ::testing::ValuesIn(std::vector<Term>(joints::coefficient_terms.begin() +
                                                                   2,
                                                               joints::coefficient_terms.end())),
                         term_case_name);

// The parameterised test covers every coefficient term but k and c (present in every case); the
// parametric terms (jenkins, iwan, gap) are identified by output error, each in
// ParametricIdentification.EachTermSimulatedByTimeIntegrationIsIdentifiedBack.
TEST(EveryTermCases, CoverTheWholeLibrary) {
  ASSERT_EQ(joints::coefficient_terms[0], Term::k);
  ASSERT_EQ(joints::coefficient_terms[1], Term::c);
  for (std::size_t i = 2; i < joints::coefficient_terms.size(); ++i)
    EXPECT_NO_THROW(term_case(joints::coefficient_terms[i]))
        << joints::term_name(joints::coefficient_terms[i]);
  for (Term t : joints::all_terms)
    EXPECT_TRUE(joints::has_parameters(t) ||
                std::find(joints::coefficient_terms.begin(), joints::coefficient_terms.end(), t) !=
                    joints::coefficient_terms.end())
        << joints::term_name(t);
}

// The 95 % intervals hold what they say: Monte Carlo over the measurement noise (white Gaussian
// on force and response channels, fixed seeds) of sine tests made by time integration. 200
// repetitions: a true coverage of 95 % gives 95 ± 1.5 % (one standard deviation), so [90, 98] %
// fails a method that under- or over-states the uncertainty by about 20 % (doubling every
// standard deviation gives 100 %; the residual intervals of ordinary least squares, 10–25 %).
// The bias is reported and must stay well inside the scatter.
struct Coverage {
  std::string name;
  std::vector<joints::Joint> truth;
  std::vector<identify::SineTestPlan> plans;
  double level;
};

class IntervalCoverage : public ::testing::TestWithParam<Coverage> {};

TEST_P(IntervalCoverage, HoldsForEveryParameter) {
  const Coverage& c = GetParam();
  const frf::Substructure sub(test::paper_cantilever());
  identify::SimulationOptions so;
  so.steps_per_period = 1024;
  so.samples_per_period = 256;
  so.periods = 8;
  const auto clean = identify::simulate_sine_tests(sub, c.truth, {7, fem::Dof::uy}, c.plans, so);
  identify::FitOptions fo;
  fo.harmonics = {1, 2, 3};
  constexpr int reps = 200;
  std::vector<std::pair<std::size_t, std::size_t>> params;
  for (std::size_t j = 0; j < c.truth.size(); ++j)
    for (std::size_t t = 0; t < c.truth[j].terms.size(); ++t)
      params.push_back({j, t});
  std::vector<int> covered(params.size(), 0);
  std::vector<double> bias(params.size(), 0.0), square(params.size(), 0.0);
  for (int r = 0; r < reps; ++r) {
    std::vector<identify::SineTest> tests;
    for (std::size_t i = 0; i < clean.size(); ++i) {
      identify::Record rec = clean[i].record;
      identify::add_noise(rec, c.level, 104729ull * static_cast<unsigned long long>(r) + i);
      tests.emplace_back(std::move(rec));
    }
    const identify::FitResult fit =
        identify::fit(sub, c.truth, identify::measure(tests, identify::measure_options(fo)), fo);
    ASSERT_EQ(fit.interval_method, "propagated noise");
    for (std::size_t q = 0; q < params.size(); ++q) {
      const auto& te = fit.joints[params[q].first].terms[params[q].second];
      const double truth = c.truth[params[q].first].values[params[q].second];
      covered[q] += te.ci_low <= truth && truth <= te.ci_high;
      bias[q] += (te.value - truth) / truth / reps;
      square[q] += std::pow((te.value - truth) / truth, 2) / reps;
    }
  }
  for (std::size_t q = 0; q < params.size(); ++q) {
    const auto& j = c.truth[params[q].first];
    const std::string name =
        std::string(joints::term_name(j.terms[params[q].second])) + " of '" + j.name + "'";
    const double coverage = static_cast<double>(covered[q]) / reps;
    const double scatter = std::sqrt(square[q] - bias[q] * bias[q]);
    std::printf("  %-12s coverage %5.1f %%, bias %+.2e, scatter %.2e (relative)\n", name.c_str(),
                100.0 * coverage, bias[q], scatter);
    EXPECT_GE(coverage, 0.90) << name;
    EXPECT_LE(coverage, 0.98) << name;
    // The errors-in-variables bias (noise through the non-linear basis functions), reduced by
    // averaging the records' periods, stays below half the scatter.
    EXPECT_LT(std::abs(bias[q]), 0.5 * scatter) << name;
  }
}

std::vector<Coverage> coverage_cases() {
  using T = Term;
  auto tip = [](std::vector<T> terms, std::vector<double> values) {
    return make_joint("tip", 7, 0, std::move(terms), std::move(values));
  };
  std::vector<identify::SineTestPlan> case_I; // the paper's case I: 80 N at 1.0 … 4.6 Hz
  for (int i = 0; i < 10; ++i)
    case_I.push_back({1.0 + 0.4 * i, 80.0});
  std::vector<identify::SineTestPlan> grid; // two joints: 2 … 7 Hz at 10, 40, 80 N
  for (double f : {2.0, 3.0, 4.0, 5.0, 6.0, 7.0})
    for (double a : {10.0, 40.0, 80.0})
      grid.push_back({f, a});
  const auto model_I = tip({T::k, T::c, T::c2, T::k3}, {4800.0, 20.0, 500.0, 1.6e8});
  const std::vector<joints::Joint> two{
      tip({T::k, T::c}, {4800.0, 20.0}),
      make_joint("mid", 4, 0, {T::k, T::c, T::k3}, {2e4, 10.0, 2e9})};
  return {{"ModelI_1pc", {model_I}, case_I, 0.01},
          {"ModelI_5pc", {model_I}, case_I, 0.05},
          {"TwoJoints_1pc", two, grid, 0.01},
          {"TwoJoints_5pc", two, grid, 0.05}};
}

INSTANTIATE_TEST_SUITE_P(MonteCarlo, IntervalCoverage, ::testing::ValuesIn(coverage_cases()),
                         [](const auto& info) { return info.param.name; });

// What the tests cannot determine is said in words, and flagged, not returned as a confident
// number.
TEST(Identifiability, ACubicTermTooSmallAtTheseAmplitudesIsNamed) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto truth = make_joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8});
  // At 0.2 N the tip moves ~20 µm: the cubic force is ~1e-5 of the linear one.
  std::vector<identify::SineTestPlan> plans;
  for (double f : {2.0, 3.0, 4.0, 5.0})
    plans.push_back({f, 0.2});
  identify::SimulationOptions so;
  so.steps_per_period = 512;
  so.samples_per_period = 128;
  auto tests = identify::simulate_sine_tests(sub, {truth}, {7, fem::Dof::uy}, plans, so);
  std::vector<identify::SineTest> noisy;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    identify::add_noise(tests[i].record, 0.01, 11 + i);
    noisy.emplace_back(tests[i].record);
  }
  identify::FitOptions fo;
  fo.harmonics = {1, 2, 3};
  const auto r =
      identify::fit(sub, {truth}, identify::measure(noisy, identify::measure_options(fo)), fo);
  EXPECT_TRUE(r.joints[0].terms[0].determined);  // k
  EXPECT_FALSE(r.joints[0].terms[2].determined); // k3
  ASSERT_FALSE(r.identifiability.empty());
  const std::string& s = r.identifiability.front();
  EXPECT_NE(s.find("k3 of 'tip' is not determined"), std::string::npos) << s;
  EXPECT_NE(s.find("its force is"), std::string::npos) << s;
  EXPECT_NE(s.find("larger amplitudes"), std::string::npos) << s;
}

TEST(Identifiability, DampingAndFrictionAtOneVelocityAmplitudeAreNotSeparated) {
  // Every test at the same frequency and force: the same velocity amplitude, so viscous and dry
  // friction damping give the same fundamental (the joint slides throughout at 80 N).
  const frf::Substructure sub(test::paper_cantilever());
  const auto truth = make_joint("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0});
  identify::SimulationOptions so;
  so.steps_per_period = 512;
  so.samples_per_period = 128;
  const auto clean =
      identify::simulate_sine_tests(sub, {truth}, {7, fem::Dof::uy}, {{3.0, 80.0}}, so);
  std::vector<identify::SineTest> noisy;
  for (int i = 0; i < 4; ++i) {
    identify::Record r = clean.front().record;
    identify::add_noise(r, 0.01, 31 + i);
    r.source = "repeat " + std::to_string(i);
    noisy.emplace_back(std::move(r));
  }
  identify::FitOptions fo;
  fo.harmonics = {1};
  const auto r =
      identify::fit(sub, {truth}, identify::measure(noisy, identify::measure_options(fo)), fo);
  std::string all;
  for (const auto& s : r.identifiability)
    all += s + "\n";
  EXPECT_NE(all.find("not separated"), std::string::npos) << all;
  EXPECT_NE(all.find("c of 'tip'"), std::string::npos) << all;
  EXPECT_NE(all.find("fc of 'tip'"), std::string::npos) << all;
  EXPECT_NE(all.find("same velocity amplitude"), std::string::npos) << all;
  EXPECT_FALSE(r.joints[0].terms[1].determined && r.joints[0].terms[2].determined);
}

TEST(FitWithSubstructure, AModalAnalysisThatFailsIsTheFitsStatus) {
  // tests/support/failing_substructure.hpp: its dense modal analysis fails, so there
  // is no receptance to fit with: the status and its reason, no estimates.
  const frf::Substructure failing = test::failing_substructure();
  joints::Joint j{"a", 2, 0, fem::Dof::ux, {Term::k}, {1.0}, {false}, {}};
  identify::Measurement m;
  m.source = "test.csv";
  m.frequency_hz = 1.0;
  m.force_at = {{3, fem::Dof::ux}};
  const identify::FitResult r = identify::fit(failing, {j}, {m});
  EXPECT_EQ(r.status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(r.status.reason, "the modal analysis failed: " + test::failing_modes_reason);
  EXPECT_TRUE(r.joints.empty());
  EXPECT_THROW(r.identified({j}), std::invalid_argument);
}

} // namespace
