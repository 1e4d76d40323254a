// Virtual sine tests: time integration against harmonic balance (two independent methods),
// the sampling of the records, derived acceleration, measurement noise and errors.
#include "identify/sine_tests.hpp"

#include "fem/modal.hpp"
#include "frf/receptance.hpp"
#include "support/cantilever.hpp"
#include "support/cantilever_substructure.hpp"
#include "support/failing_substructure.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <numbers>
#include <string>

using namespace jointid;
using namespace jointid::identify;
using joints::Term;
using cd = std::complex<double>;

namespace {

using jointid::test::cantilever;
using jointid::test::tip;
using jointid::test::two_pi;

joints::Joint make_joint(std::vector<Term> terms, std::vector<double> values) {
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

// Harmonic k of samples over whole periods starting at t(0) (DFT; phase relative to t = 0).
cd harmonic(const Eigen::VectorXd& x, const Eigen::VectorXd& t, double omega, int k) {
  cd sum = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    sum += x(i) * std::polar(1.0, -k * omega * t(i));
  return (k == 0 ? 1.0 : 2.0) / static_cast<double>(x.size()) * sum;
}

const Channel& channel(const Record& r, Quantity q, const fem::NodeDof& at) {
  const Channel* c = r.find(q, at);
  if (!c) throw std::logic_error("test record lacks a channel");
  return *c;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(SimulateSineTests, TimeIntegrationAndHarmonicBalanceAgree) {
  // k, c, k3 at the tip; 40 N at 3 Hz (|X3| ≈ 2 % of |X1|) and 80 N at 4.5 Hz (near the joined
  // structure's resonance). Newmark's average-acceleration rule at 1024 steps a period has a
  // period error (ωh)²/12 = 3.1e-6, amplified near resonance by the quality factor of the
  // joined structure (≈ 1/(2ζ), ζ ≈ 4 % with the joint's damper: ≤ 12): ≲ 4e-5 of |X1|.
  // Measured: 2.8e-6 and 4.1e-6. The harmonic balance's truncation at 9 harmonics and its
  // 1e-12 residual are far below that. The third harmonic is driven by the fundamental's error
  // through the cubic and has its own period error 9 × 3.1e-6 of |X3|: measured ≤ 4e-6 |X1|.
  // Bound for both: 4e-5 |X1|, which also bounds the largest difference of the time signals
  // (x, and v relative to ω|X1|).
  const std::vector<joints::Joint> js{
      make_joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  const std::vector<SineTestPlan> plans{{3.0, 40.0}, {4.5, 80.0}};
  SimulationOptions o;
  o.periods = 2;
  o.steps_per_period = 1024;
  o.extra_outputs = {{4, fem::Dof::uy}};
  const auto ti = simulate_sine_tests(cantilever(), js, tip, plans, o);
  o.method = SimulationMethod::harmonic_balance;
  const auto hb = simulate_sine_tests(cantilever(), js, tip, plans, o);
  ASSERT_EQ(ti.size(), 2u);
  ASSERT_EQ(hb.size(), 2u);
  for (std::size_t p = 0; p < plans.size(); ++p) {
    SCOPED_TRACE(sine_test_name(plans[p]));
    EXPECT_TRUE(ti[p].warnings.empty());
    EXPECT_TRUE(hb[p].warnings.empty());
    const double w = two_pi * plans[p].frequency_hz;
    const Record &a = ti[p].record, &b = hb[p].record;
    ASSERT_EQ(a.t.size(), 2 * 1024);
    ASSERT_EQ(b.t.size(), 2 * 1024);
    for (const fem::NodeDof at : {tip, fem::NodeDof{4, fem::Dof::uy}}) {
      const Eigen::VectorXd &xa = channel(a, Quantity::displacement, at).samples,
                            &xb = channel(b, Quantity::displacement, at).samples,
                            &va = channel(a, Quantity::velocity, at).samples,
                            &vb = channel(b, Quantity::velocity, at).samples;
      const cd B1 = harmonic(xb, b.t, w, 1);
      const double scale = std::abs(B1);
      for (int k = 0; k <= 3; ++k)
        EXPECT_LE(std::abs(harmonic(xa, a.t, w, k) - harmonic(xb, b.t, w, k)), 4e-5 * scale)
            << fem::to_string(at) << " harmonic " << k;
      EXPECT_LE((xa - xb).cwiseAbs().maxCoeff(), 4e-5 * scale) << fem::to_string(at);
      EXPECT_LE((va - vb).cwiseAbs().maxCoeff(), 4e-5 * w * scale) << fem::to_string(at);
    }
    // Genuinely non-linear: the third harmonic (0.4 % and 2 % of |X1|) is 50 times the bound.
    const Eigen::VectorXd& x = channel(b, Quantity::displacement, tip).samples;
    EXPECT_GT(std::abs(harmonic(x, b.t, w, 3)), 50 * 4e-5 * std::abs(harmonic(x, b.t, w, 1)));
    // The force is F0 sin ωt in both.
    for (const Record* r : {&a, &b}) {
      const Eigen::VectorXd& f = channel(*r, Quantity::force, tip).samples;
      for (Eigen::Index i = 0; i < f.size(); i += 37)
        EXPECT_NEAR(f(i), plans[p].amplitude * std::sin(w * r->t(i)), 1e-9 * plans[p].amplitude);
    }
  }
}

// Every term of the library, harmonic balance against time integration: k = 4800, c = 20 and the
// term at the tip, 80 N at 3 Hz. Harmonics 0 … 3 of the tip displacement agree within the
// integrator's error (bound of the test above, 4e-5 |X1|), except dry friction, whose harmonic
// balance converges like 1/K where the joint sticks (README: 1e-4 where it slides, ~1 % at
// K = 15 where it sticks a good part of the period); here it slides except near the turning
// points: bound 1.5e-3 |X1| at K = 25. The even term k2 makes a mean (harmonic 0) and a second
// harmonic, both far above the bound, so an error in the harmonic balance's mean is caught.
// Measured (largest over harmonics 0-3, relative to |X1|): k2 8.9e-6 (its mean 9.1 % of |X1|,
// differing by 1.6e-6), k3 6.5e-6, c2 8.5e-6, c3 7.1e-6, fc 5.7e-4.
TEST(SimulateSineTests, EveryTermAgreesWithTimeIntegrationHarmonicByHarmonic) {
  const std::vector<std::pair<Term, double>> terms{
      {Term::k2, 1.0e5}, {Term::k3, 1.6e8}, {Term::c2, 400.0}, {Term::c3, 4000.0}, {Term::fc, 5.0}};
  const std::vector<SineTestPlan> plans{{3.0, 80.0}};
  const double w = two_pi * plans[0].frequency_hz;
  for (const auto& [term, value] : terms) {
    SCOPED_TRACE(std::string(joints::term_name(term)));
    const std::vector<joints::Joint> js{
        make_joint({Term::k, Term::c, term}, {4800.0, 20.0, value})};
    const bool friction = joints::is_dry_friction(term);
    SimulationOptions o;
    o.periods = 2;
    o.steps_per_period = 1024;
    const auto ti = simulate_sine_tests(cantilever(), js, tip, plans, o);
    o.method = SimulationMethod::harmonic_balance;
    o.balance.harmonics = friction ? 25 : 9;
    const auto hb = simulate_sine_tests(cantilever(), js, tip, plans, o);
    ASSERT_TRUE(ti[0].warnings.empty());
    ASSERT_TRUE(hb[0].warnings.empty());
    const Record &a = ti[0].record, &b = hb[0].record;
    const Eigen::VectorXd &xa = channel(a, Quantity::displacement, tip).samples,
                          &xb = channel(b, Quantity::displacement, tip).samples;
    const double scale = std::abs(harmonic(xb, b.t, w, 1));
    const double bound = (friction ? 1.5e-3 : 4e-5) * scale;
    for (int k = 0; k <= 3; ++k)
      EXPECT_LE(std::abs(harmonic(xa, a.t, w, k) - harmonic(xb, b.t, w, k)), bound)
          << "harmonic " << k;
    if (joints::term_info(term).even) {
      EXPECT_GT(std::abs(harmonic(xb, b.t, w, 0)), 100.0 * bound); // the mean
      EXPECT_GT(std::abs(harmonic(xb, b.t, w, 2)), 100.0 * bound);
    }
  }
}

TEST(SimulateSineTests, RecordLayout) {
  // Channels: the force, then every output (joint DOFs, the force DOF, the extra ones, each
  // once) with the quantities asked, in that order.
  const std::vector<joints::Joint> js{make_joint({Term::k, Term::c}, {4800.0, 20.0})};
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.periods = 3;
  o.steps_per_period = 64;
  o.quantities = {Quantity::velocity, Quantity::displacement};
  o.extra_outputs = {{3, fem::Dof::uy}, tip};
  const auto tests = simulate_sine_tests(cantilever(), js, tip, {{3.4, 80.0}}, o);
  ASSERT_EQ(tests.size(), 1u);
  const Record& r = tests[0].record;
  EXPECT_EQ(r.source, "sine_f3.4Hz_F80N.csv");
  ASSERT_TRUE(r.excitation_hz);
  EXPECT_EQ(*r.excitation_hz, 3.4);
  EXPECT_EQ(tests[0].plan.amplitude, 80.0);
  std::vector<std::string> names;
  for (const auto& c : r.channels)
    names.push_back(c.name());
  EXPECT_EQ(names, (std::vector<std::string>{"f@7:uy", "v@7:uy", "x@7:uy", "v@3:uy", "x@3:uy"}));
  EXPECT_EQ(r.t.size(), 3 * 64);
  EXPECT_FALSE(tests[0].comments.empty());
}

TEST(SimulateSineTests, SamplesPerPeriodKeepsEveryNthStep) {
  const std::vector<joints::Joint> js{
      make_joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  const SineTestPlan plan{3.0, 40.0};
  SimulationOptions o;
  o.periods = 3;
  o.steps_per_period = 1024;
  for (SimulationMethod method :
       {SimulationMethod::time_integration, SimulationMethod::harmonic_balance}) {
    o.method = method;
    o.samples_per_period = 0;
    const Record all = simulate_sine_tests(cantilever(), js, tip, {plan}, o)[0].record;
    o.samples_per_period = 128;
    const Record kept = simulate_sine_tests(cantilever(), js, tip, {plan}, o)[0].record;
    ASSERT_EQ(all.t.size(), 3 * 1024);
    ASSERT_EQ(kept.t.size(), 3 * 128);
    // Spacing: 8 steps, i.e. a period over 128 samples (rounding of t only).
    EXPECT_NEAR(kept.dt(), 1.0 / (plan.frequency_hz * 128), 1e-12 * kept.dt());
    ASSERT_EQ(kept.channels.size(), all.channels.size());
    // The same run, so the kept samples are the steps themselves, bit for bit.
    for (Eigen::Index i = 0; i < kept.t.size(); ++i) {
      ASSERT_EQ(kept.t(i), all.t(8 * i)) << i;
      for (std::size_t c = 0; c < kept.channels.size(); ++c)
        ASSERT_EQ(kept.channels[c].samples(i), all.channels[c].samples(8 * i))
            << kept.channels[c].name() << " sample " << i;
    }
  }
}

TEST(SimulateSineTests, AccelerationIsTheDerivativeOfTheVelocity) {
  // Harmonic balance with 9 harmonics, 64 samples a period: the sampled velocity holds
  // harmonics ≤ 9 < 32 (no aliasing), so its derivative from its harmonics is exact up to
  // rounding (≈ 1e-15 of max|a|); compared with Re Σ −(kω)² X_k e^{ikωt} from a separate
  // harmonic-balance solve (residual 1e-12): 1e-9 of max|a|.
  const std::vector<joints::Joint> js{
      make_joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  const SineTestPlan plan{3.0, 60.0};
  const double w = two_pi * plan.frequency_hz;
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.periods = 2;
  o.steps_per_period = 64;
  o.quantities = {Quantity::displacement, Quantity::velocity, Quantity::acceleration};
  const Record r = simulate_sine_tests(cantilever(), js, tip, {plan}, o)[0].record;
  const Eigen::VectorXd& a = channel(r, Quantity::acceleration, tip).samples;

  const int eq = cantilever().dofs().equation(tip);
  const std::vector<int> outputs{eq};
  const frf::ModalSynthesis H = cantilever().synthesis(outputs, 100.0);
  const frf::HarmonicBalanceResult hb = frf::harmonic_balance(
      H, js, cantilever().dofs(), eq, plan.amplitude, plan.frequency_hz, outputs, o.balance);
  ASSERT_TRUE(hb.status.ok());
  Eigen::VectorXd expected(r.t.size());
  for (Eigen::Index i = 0; i < r.t.size(); ++i) {
    expected(i) = 0.0;
    for (int k = 1; k < hb.X.rows(); ++k)
      expected(i) += (-(k * w) * (k * w) * hb.X(k, 0) * std::polar(1.0, k * w * r.t(i))).real();
  }
  const double scale = expected.cwiseAbs().maxCoeff();
  EXPECT_GT(scale, 0.0);
  EXPECT_LE((a - expected).cwiseAbs().maxCoeff(), 1e-9 * scale);
  // Not merely −ω² x: the third harmonic (9 ω² weight) makes a visible difference.
  const Eigen::VectorXd& x = channel(r, Quantity::displacement, tip).samples;
  EXPECT_GT((a + w * w * x).cwiseAbs().maxCoeff(), 1e-2 * scale);
}

TEST(SimulateSineTests, AddNoiseHasTheAskedLevelAndIsReproducible) {
  const std::vector<joints::Joint> js{
      make_joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.periods = 8;
  o.steps_per_period = 256;
  const Record clean = simulate_sine_tests(cantilever(), js, tip, {{3.0, 40.0}}, o)[0].record;
  const double level = 0.02;
  const Eigen::Index n = clean.t.size();
  ASSERT_EQ(n, 2048);

  Record noisy = clean;
  add_noise(noisy, level, 11);
  // Per channel: the added noise's RMS over n = 2048 samples estimates level × RMS(channel)
  // with a relative standard deviation 1/√(2n) = 1.6 %: 4.5 of them, 7 %. Its mean is within
  // 4.5 σ/√n of 0.
  for (std::size_t c = 0; c < clean.channels.size(); ++c) {
    const Eigen::VectorXd& s = clean.channels[c].samples;
    const double rms = std::sqrt((s.array() - s.mean()).square().mean());
    const Eigen::VectorXd added = noisy.channels[c].samples - s;
    const double sigma = level * rms;
    EXPECT_NEAR(std::sqrt(added.squaredNorm() / n) / sigma, 1.0, 0.07) << clean.channels[c].name();
    EXPECT_LE(std::abs(added.mean()), 4.5 * sigma / std::sqrt(n)) << clean.channels[c].name();
  }
  EXPECT_EQ(noisy.t, clean.t);
  // Channels get independent noise: the correlation of two channels' noise is ≈ N(0, 1/n);
  // 4.5/√n = 0.1.
  const Eigen::VectorXd n0 = noisy.channels[1].samples - clean.channels[1].samples,
                        n1 = noisy.channels[2].samples - clean.channels[2].samples;
  EXPECT_LT(std::abs(n0.dot(n1)) / (n0.norm() * n1.norm()), 0.1);

  Record again = clean;
  add_noise(again, level, 11);
  Record other = clean;
  add_noise(other, level, 12);
  for (std::size_t c = 0; c < clean.channels.size(); ++c) {
    EXPECT_EQ(again.channels[c].samples, noisy.channels[c].samples); // bit for bit
    EXPECT_NE(other.channels[c].samples, noisy.channels[c].samples);
  }
  Record quiet_force = clean;
  add_noise(quiet_force, level, 11, false);
  ASSERT_EQ(quiet_force.channels[0].quantity, Quantity::force);
  EXPECT_EQ(quiet_force.channels[0].samples, clean.channels[0].samples);
  for (std::size_t c = 1; c < clean.channels.size(); ++c)
    EXPECT_NE(quiet_force.channels[c].samples, clean.channels[c].samples);
  Record none = clean;
  add_noise(none, 0.0, 11);
  for (std::size_t c = 0; c < clean.channels.size(); ++c)
    EXPECT_EQ(none.channels[c].samples, clean.channels[c].samples);
  EXPECT_THROW(add_noise(none, -0.01, 1), std::invalid_argument);
  EXPECT_THROW(add_noise(none, std::nan(""), 1), std::invalid_argument);
}

// A series' noise: test i draws from seed + i (so two tests of one run never share their noise,
// and one seed repeats the run), and its comments say so; a table of the series keeps the lines
// on how the series was made, not those of one test alone.
TEST(SimulateSineTests, NoiseOnASeriesAndTheCommentsItsTableKeeps) {
  const joints::Joint joint = make_joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8});
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.periods = 2;
  o.steps_per_period = 64;
  const std::vector<SimulatedTest> clean =
      simulate_sine_tests(cantilever(), {joint}, tip, {{3.0, 10.0}, {4.0, 10.0}}, o);
  std::vector<SimulatedTest> noisy = clean;
  add_noise(noisy, 0.02, 7);
  for (std::size_t i = 0; i < clean.size(); ++i) {
    Record expected = clean[i].record;
    add_noise(expected, 0.02, 7 + i);
    for (std::size_t c = 0; c < expected.channels.size(); ++c)
      EXPECT_EQ(noisy[i].record.channels[c].samples, expected.channels[c].samples) << i << c;
    EXPECT_EQ(noisy[i].comments.back(), "noise: white Gaussian, RMS 0.02 of each channel's RMS, "
                                        "on every channel (seed " +
                                            std::to_string(7 + i) + ")");
  }
  std::vector<SimulatedTest> quiet = clean;
  add_noise(quiet, 0.0, 7);
  EXPECT_EQ(quiet[0].comments, clean[0].comments);
  EXPECT_EQ(quiet[1].record.channels[1].samples, clean[1].record.channels[1].samples);

  const std::vector<std::string> kept = stepped_sine_comments(noisy);
  ASSERT_EQ(kept.size(), 4u) << ::testing::PrintToString(kept);
  EXPECT_EQ(kept[0], "one sine test a row: fundamentals of the records");
  EXPECT_EQ(kept[1], joint_comment(joint));
  EXPECT_EQ(kept[2].rfind("method: hb (harmonic balance, harmonics 0 to 9", 0), 0u) << kept[2];
  EXPECT_EQ(kept[3], noisy[0].comments.back());
  for (const auto& line : noisy[0].comments) { // the lines of the first test alone are left out
    if (line.rfind("sine force", 0) == 0 || line.rfind("harmonic balance:", 0) == 0) {
      EXPECT_EQ(std::find(kept.begin(), kept.end(), line), kept.end()) << line;
    }
  }
  EXPECT_EQ(stepped_sine_comments({}).size(), 1u);
}

TEST(SimulateSineTests, ModalSubstructureByTimeIntegrationAgreesWithHarmonicBalance) {
  // The cantilever given by its 3 modes below 60 Hz at the tip and the middle (1 % damping,
  // mass-normalised shapes) and the exact residual flexibility of the 15 others there: one
  // model, simulated by both methods. Time integration in its modal coordinates with the
  // residual flexibility as a static correction, harmonic balance with it as a static term:
  // the same steady state to the bounds of the finite element tests above (4e-5 |X1| for the
  // smooth terms at 1024 steps a period; 1.5e-3 |X1| for dry friction at 25 harmonics), the
  // static part's velocity by backward differences adding (ωh)²/3 = 1.3e-5 of a small share.
  const fem::Model model = test::paper_cantilever();
  const fem::Assembled system = fem::assemble(model);
  fem::Modes modes =
      fem::modal_analysis(system, {.num_modes = 0, .engine = fem::ModalEngine::dense});
  modes.omega.conservativeResize(3);
  modes.phi.conservativeResize(Eigen::NoChange, 3);
  ASSERT_LT(modes.frequency_hz(2), 60.0);
  const fem::NodeDof mid{4, fem::Dof::uy};
  const std::vector<int> eq{system.dofs.equation(tip), system.dofs.equation(mid)};
  frf::ModalModel modal;
  modal.dofs = {tip, mid};
  modal.frequencies_hz = modes.omega / two_pi;
  modal.damping = Eigen::VectorXd::Constant(3, 0.01);
  modal.shapes.resize(3, 2);
  for (int i = 0; i < 2; ++i)
    modal.shapes.col(i) = modes.phi.row(eq[static_cast<std::size_t>(i)]).transpose();
  modal.residual_flexibility =
      frf::ModalSynthesis(system, modes, model.damping, eq).residual_flexibility(eq, eq);
  ASSERT_GT(modal.residual_flexibility(0, 0), 0.0);
  const frf::Substructure sub(modal);

  const std::vector<SineTestPlan> plans{{3.0, 40.0}};
  const double w = two_pi * plans[0].frequency_hz;
  for (const auto& [term, value] :
       std::vector<std::pair<Term, double>>{{Term::k3, 1.6e8}, {Term::fc, 5.0}}) {
    SCOPED_TRACE(std::string(joints::term_name(term)));
    const bool friction = joints::is_dry_friction(term);
    const std::vector<joints::Joint> js{
        make_joint({Term::k, Term::c, term}, {4800.0, 20.0, value})};
    SimulationOptions o;
    o.periods = 2;
    o.steps_per_period = 1024;
    o.extra_outputs = {mid};
    const auto ti = simulate_sine_tests(sub, js, tip, plans, o);
    o.method = SimulationMethod::harmonic_balance;
    o.balance.harmonics = friction ? 25 : 9;
    const auto hb = simulate_sine_tests(sub, js, tip, plans, o);
    ASSERT_TRUE(ti[0].status.ok()) << ti[0].status.reason;
    ASSERT_TRUE(ti[0].warnings.empty());
    ASSERT_TRUE(hb[0].status.ok()) << hb[0].status.reason;
    const Record &a = ti[0].record, &b = hb[0].record;
    for (const fem::NodeDof at : {tip, mid}) {
      const Eigen::VectorXd &xa = channel(a, Quantity::displacement, at).samples,
                            &xb = channel(b, Quantity::displacement, at).samples;
      const double scale =
          std::abs(harmonic(channel(b, Quantity::displacement, tip).samples, b.t, w, 1));
      const double bound = (friction ? 1.5e-3 : 4e-5) * scale;
      double largest = 0.0;
      for (int k = 0; k <= 3; ++k) {
        const double d = std::abs(harmonic(xa, a.t, w, k) - harmonic(xb, b.t, w, k));
        largest = std::max(largest, d / scale);
        EXPECT_LE(d, bound) << fem::to_string(at) << " harmonic " << k;
      }
      std::printf("[modal] time vs hb, %s at %s: %.3g of |X1|\n",
                  std::string(joints::term_name(term)).c_str(), fem::to_string(at).c_str(),
                  largest);
    }
    // The record says how it was made.
    EXPECT_NE(std::find(ti[0].comments.begin(), ti[0].comments.end(),
                        "method: time, 3 modes of its [modal] model, its residual flexibility at "
                        "2 DOFs as a static correction (Newmark, average acceleration, 1024 steps "
                        "per period)"),
              ti[0].comments.end());
  }
}

TEST(SimulateSineTests, BadPlansAndOptionsAreRefused) {
  const std::vector<joints::Joint> js{make_joint({Term::k, Term::c}, {4800.0, 20.0})};
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.steps_per_period = 1024;
  auto run = [&](const std::vector<SineTestPlan>& plans) {
    return error_of([&] { simulate_sine_tests(cantilever(), js, tip, plans, o); });
  };
  std::string e = run({{3.0, 80.0}, {4.0, 80.0}, {3.0, 80.0}});
  EXPECT_NE(e.find("listed twice"), std::string::npos) << e;
  EXPECT_NE(e.find("3 Hz"), std::string::npos) << e;
  e = run({{0.0, 80.0}});
  EXPECT_NE(e.find("frequencies > 0"), std::string::npos) << e;
  e = run({{3.0, -1.0}});
  EXPECT_NE(e.find("amplitudes > 0"), std::string::npos) << e;
  EXPECT_NE(run({}), "");
  o.samples_per_period = 100; // does not divide 1024
  e = run({{3.0, 80.0}});
  EXPECT_NE(e.find("divisor of the 1024 steps"), std::string::npos) << e;
  EXPECT_NE(e.find("got 100"), std::string::npos) << e;
  o.samples_per_period = 4; // divides, but too few
  EXPECT_NE(run({{3.0, 80.0}}), "");
  o.samples_per_period = 0;
  o.quantities = {Quantity::force};
  EXPECT_NE(run({{3.0, 80.0}}), "");
  o.quantities = {};
  EXPECT_NE(run({{3.0, 80.0}}), "");
  o.quantities = {Quantity::displacement};
  EXPECT_THROW(simulate_sine_tests(cantilever(), js, {9, fem::Dof::uy}, {{3.0, 80.0}}, o),
               std::invalid_argument);
  o.periods = 0;
  EXPECT_NE(run({{3.0, 80.0}}), "");
}

TEST(SimulateSineTests, HarmonicBalanceWithoutASolutionSaysWhichTestAndWhy) {
  // Two Newton iterations cannot solve the strongly non-linear k3 case at 80 N, 3 Hz (it takes
  // about 8; see HarmonicBalance.NonConvergenceSaysWhy).
  const std::vector<joints::Joint> js{make_joint({Term::k3}, {1.6e8})};
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.steps_per_period = 64;
  o.balance.max_iterations = 2;
  o.balance.continuation_steps = 2;
  // A numerical outcome: that test's status, with the reason and no record; the others are
  // simulated all the same.
  const auto tests = simulate_sine_tests(cantilever(), js, tip, {{3.0, 80.0}, {3.0, 1e-6}}, o);
  ASSERT_EQ(tests.size(), 2u);
  EXPECT_EQ(tests[0].status.code, fem::Status::Code::not_converging);
  const std::string& m = tests[0].status.reason;
  EXPECT_EQ(m.rfind("harmonic balance at 3 Hz, 80 N: no periodic solution found (no "
                    "convergence: relative residual ",
                    0),
            0u)
      << m;
  EXPECT_NE(m.find("); simulate this test by time integration"), std::string::npos) << m;
  EXPECT_EQ(tests[0].record.source, "sine_f3Hz_F80N.csv");
  EXPECT_TRUE(tests[0].record.channels.empty());
  EXPECT_TRUE(tests[1].status.ok()) << tests[1].status.reason;
  EXPECT_TRUE(tests[1].warnings.empty()) << ::testing::PrintToString(tests[1].warnings);
  EXPECT_EQ(tests[1].record.t.size(), o.periods * o.steps_per_period);
}

TEST(SimulateSineTests, TimeIntegrationWhoseJointIterationFailsSaysWhichTestAndWhen) {
  // A softening cubic (k3 < 0) driven hard: the tip runs away from rest, the joint force
  // overflows and its Newton iteration fails in the first period. That test's status says so,
  // naming the test, the period and the time; the gentle one beside it is simulated.
  const std::vector<joints::Joint> soft{
      make_joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, -1.6e8})};
  SimulationOptions o;
  o.periods = 2;
  o.steps_per_period = 64;
  const auto failed = simulate_sine_tests(cantilever(), soft, tip, {{3.0, 80.0}, {3.0, 1.0}}, o);
  ASSERT_EQ(failed.size(), 2u);
  EXPECT_EQ(failed[0].status.code, fem::Status::Code::not_converging);
  EXPECT_EQ(failed[0].status.reason.rfind("time integration at 3 Hz, 80 N: the joints' Newton "
                                          "iteration failed in period 1 (t = ",
                                          0),
            0u)
      << failed[0].status.reason;
  EXPECT_TRUE(failed[0].record.channels.empty());
  EXPECT_TRUE(failed[1].status.ok()) << failed[1].status.reason;
  EXPECT_FALSE(failed[1].record.channels.empty());
}

TEST(SimulateSineTests, ProgressCountsEveryTestOnceUpToOne) {
  // Five tests, both methods (time integration runs them in parallel): one call per test, the
  // fractions k/5 in increasing order, the last exactly 1.
  const std::vector<joints::Joint> js{make_joint({Term::k, Term::k3}, {4800.0, 1.6e8})};
  const std::vector<SineTestPlan> plans{
      {2.0, 10.0}, {2.5, 10.0}, {3.0, 10.0}, {3.5, 20.0}, {4.0, 20.0}};
  for (const SimulationMethod method :
       {SimulationMethod::time_integration, SimulationMethod::harmonic_balance}) {
    SimulationOptions o;
    o.method = method;
    o.periods = 2;
    o.steps_per_period = 128;
    std::vector<double> seen;
    o.progress = [&](double fraction) { seen.push_back(fraction); };
    simulate_sine_tests(cantilever(), js, tip, plans, o);
    ASSERT_EQ(seen.size(), plans.size());
    for (std::size_t i = 0; i < seen.size(); ++i)
      EXPECT_DOUBLE_EQ(seen[i], (i + 1.0) / plans.size());
  }
}

TEST(SimulateSineTests, TestNamesUseTheShortestExactNumbers) {
  EXPECT_EQ(sine_test_name({3.4, 80.0}), "sine_f3.4Hz_F80N.csv");
  EXPECT_EQ(sine_test_name({0.1 + 0.2, 12.5}), "sine_f0.30000000000000004Hz_F12.5N.csv");
  EXPECT_NE(sine_test_name({3.0, 80.0}), sine_test_name({3.0000000000000004, 80.0}));
}

TEST(SimulateSineTests, AModalAnalysisThatFailsIsEveryTestsStatus) {
  // tests/support/failing_substructure.hpp: its dense modal analysis fails. Harmonic
  // balance needs its synthesis, time integration its modal damping matrix: every test has
  // that status, naming the test, and no record.
  const frf::Substructure failing = test::failing_substructure();
  joints::Joint j{"a", 2, 0, fem::Dof::ux, {Term::k3}, {1e6}, {true}, {}};
  SimulationOptions o;
  o.method = SimulationMethod::harmonic_balance;
  o.steps_per_period = 64;
  const auto hb = simulate_sine_tests(failing, {j}, {3, fem::Dof::ux}, {{1.0, 1.0}, {2.0, 1.0}}, o);
  ASSERT_EQ(hb.size(), 2u);
  EXPECT_EQ(hb[1].status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(hb[1].status.reason, "harmonic balance at 2 Hz, 1 N: the modal analysis failed: " +
                                     test::failing_modes_reason);
  EXPECT_EQ(hb[1].record.source, "sine_f2Hz_F1N.csv");
  EXPECT_TRUE(hb[1].record.channels.empty());
  o.method = SimulationMethod::time_integration;
  const auto ti = simulate_sine_tests(failing, {j}, {3, fem::Dof::ux}, {{1.0, 1.0}}, o);
  ASSERT_EQ(ti.size(), 1u);
  EXPECT_EQ(ti[0].status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(ti[0].status.reason, "time integration at 1 Hz, 1 N: modal damping needs every mode, "
                                 "and the modal analysis failed: " +
                                     test::failing_modes_reason);
  EXPECT_TRUE(ti[0].record.channels.empty());
}
