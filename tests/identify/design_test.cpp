// Experiment design: the standard deviations it predicts are the scatter fit() shows on noisy
// tests (Monte Carlo), and its choice is the best set (exhaustive search).
#include "identify/design.hpp"

#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/parametric.hpp"
#include "identify/random_tests.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"
#include "support/failing_substructure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

using namespace jointid;
using joints::Term;

namespace {

joints::Joint tip_joint(std::vector<Term> terms, std::vector<double> values) {
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

using jointid::test::tip;

// The paper's model I.
std::vector<joints::Joint> model_I() {
  return {tip_joint({Term::k, Term::c, Term::c2, Term::k3}, {4800.0, 20.0, 500.0, 1.6e8})};
}

// fit() on the clean records with fresh noise: test i with seed `seed` + i.
identify::FitResult noisy_fit(const frf::Substructure& sub,
                              const std::vector<joints::Joint>& joints,
                              const std::vector<identify::SimulatedTest>& clean, double noise,
                              unsigned long long seed, const identify::FitOptions& fo) {
  std::vector<identify::SineTest> tests;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    identify::Record rec = clean[i].record;
    identify::add_noise(rec, noise, seed + i);
    tests.emplace_back(std::move(rec));
  }
  return identify::fit(sub, joints, identify::measure(tests, identify::measure_options(fo)), fo);
}

} // namespace

// The predicted standard deviation of every term is the scatter of the estimates over noisy
// repetitions of the same tests (records by harmonic balance, 1 % noise on force, displacement
// and velocity, 8 periods averaged). 400 repetitions estimate a standard deviation to ±3.5 % (one
// standard deviation of the estimate): the ratio must lie in [0.85, 1.17] (±4.5 of those), which
// fails a prediction that misstates the noise by a fifth, or miscounts the averaged periods (a
// factor √8). Measured: 0.97–1.02.
TEST(Design, PredictedStdIsTheMonteCarloScatter) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto joints = model_I();
  const std::vector<identify::SineTestPlan> plans{{2.0, 20.0}, {2.8, 80.0}, {3.4, 40.0},
                                                  {4.2, 80.0}, {5.0, 10.0}, {6.0, 60.0}};
  identify::DesignOptions d;
  d.harmonics = {1, 2, 3};
  d.noise = 0.01;
  d.periods = 8;
  d.samples_per_period = 256;
  const auto candidates = identify::predict_candidates(sub, joints, tip, plans, d);
  std::vector<int> all;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    ASSERT_TRUE(candidates[i].usable) << candidates[i].reason;
    all.push_back(static_cast<int>(i));
  }
  const Eigen::VectorXd predicted = identify::predicted_std(candidates, all);

  identify::SimulationOptions so;
  so.method = identify::SimulationMethod::harmonic_balance;
  so.periods = 8;
  so.steps_per_period = 256;
  const auto clean = identify::simulate_sine_tests(sub, joints, tip, plans, so);
  identify::FitOptions fo;
  fo.harmonics = {1, 2, 3};
  constexpr int reps = 400;
  const auto nu = predicted.size();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(nu), square = sum, reported = sum;
  for (int r = 0; r < reps; ++r) {
    const identify::FitResult fit =
        noisy_fit(sub, joints, clean, d.noise, 7919ull * static_cast<unsigned long long>(r), fo);
    for (Eigen::Index u = 0; u < nu; ++u) {
      const double v = fit.joints[0].terms[static_cast<std::size_t>(u)].value;
      sum(u) += v / reps;
      square(u) += v * v / reps;
      reported(u) += fit.joints[0].terms[static_cast<std::size_t>(u)].std / reps;
    }
  }
  for (Eigen::Index u = 0; u < nu; ++u) {
    const double scatter =
        std::sqrt(std::max(0.0, square(u) - sum(u) * sum(u)) * reps / (reps - 1));
    const std::string name(joints::term_name(joints[0].terms[static_cast<std::size_t>(u)]));
    std::printf("  %-3s predicted std %.4g, Monte Carlo %.4g (ratio %.3f), fit's mean std %.4g\n",
                name.c_str(), predicted(u), scatter, scatter / predicted(u), reported(u));
    EXPECT_GT(scatter / predicted(u), 0.85) << name;
    EXPECT_LT(scatter / predicted(u), 1.17) << name;
  }
}

// Greedy choice and exchanges find the best set: every 4 of 12 candidates searched.
TEST(Design, ChoiceIsTheBestSubsetOfAnExhaustiveSearch) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto joints = model_I();
  std::vector<identify::SineTestPlan> plans;
  for (double f : {1.0, 2.5, 3.2, 4.0, 5.5, 17.0})
    for (double a : {10.0, 80.0})
      plans.push_back({f, a});
  identify::DesignOptions options;
  std::vector<double> progress; // two passes over the 12 candidates: 24 calls up to 1
  options.progress = [&](double fraction) { progress.push_back(fraction); };
  const auto candidates = identify::predict_candidates(sub, joints, tip, plans, options);
  ASSERT_EQ(progress.size(), 24u);
  for (std::size_t i = 0; i < progress.size(); ++i)
    EXPECT_DOUBLE_EQ(progress[i], (i + 1.0) / 24.0);
  const auto unknowns = identify::design_unknowns(joints);
  ASSERT_EQ(unknowns.size(), 4u);
  const identify::Design design = identify::choose_tests(candidates, unknowns, 4);
  ASSERT_EQ(design.chosen.size(), 4u);
  Eigen::VectorXd scale(4);
  for (std::size_t u = 0; u < 4; ++u)
    scale(static_cast<Eigen::Index>(u)) = unknowns[u].prior;
  double best = -std::numeric_limits<double>::infinity();
  int worse = 0, subsets = 0;
  const int n = static_cast<int>(plans.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c)
        for (int e = c + 1; e < n; ++e) {
          const double v = identify::log_det_information(candidates, {a, b, c, e}, scale);
          best = std::max(best, v);
          worse += v < design.log_det - 1e-9;
          ++subsets;
        }
  EXPECT_EQ(subsets, 495);
  EXPECT_NEAR(design.log_det, best, 1e-9 * std::abs(best));
  EXPECT_GT(worse, 400); // the criterion does discriminate
  // The standard deviations it reports are those of its tests.
  const Eigen::VectorXd s = identify::predicted_std(candidates, design.chosen);
  EXPECT_TRUE(s.isApprox(design.std, 1e-12));
}

// Candidates too small to show the cubic term: the design says so, naming the term.
TEST(Design, UndeterminedTermIsNamed) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto joints = model_I();
  std::vector<identify::SineTestPlan> plans;
  for (double f : {1.0, 2.0, 4.0, 5.0, 6.0})
    plans.push_back({f, 0.01}); // 0.01 N: micrometres, the cubic force ~1e-9 of the linear
  const auto candidates = identify::predict_candidates(sub, joints, tip, plans);
  const identify::Design design =
      identify::choose_tests(candidates, identify::design_unknowns(joints), 5);
  bool named = false;
  for (const auto& w : design.warnings)
    named = named || (w.rfind("k3 of 'tip'", 0) == 0);
  EXPECT_TRUE(named);
  EXPECT_GT(design.std(3), 0.05 * 1.6e8);
  EXPECT_LT(design.std(0), 0.05 * 4800.0); // k is determined
}

TEST(Design, BadOptionsAreNamed) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto joints = model_I();
  const std::vector<identify::SineTestPlan> plans{{2.0, 10.0}, {3.0, 10.0}};
  auto message = [&](identify::DesignOptions o) {
    try {
      identify::predict_candidates(sub, joints, tip, plans, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  identify::DesignOptions o;
  o.noise = 0.0;
  EXPECT_NE(message(o).find("noise"), std::string::npos);
  o = {};
  o.periods = 1;
  EXPECT_NE(message(o).find("periods"), std::string::npos);
  o = {};
  o.harmonics = {1, 12};
  EXPECT_NE(message(o).find("harmonics"), std::string::npos);
  const auto candidates = identify::predict_candidates(sub, joints, tip, plans);
  try {
    identify::choose_tests(candidates, identify::design_unknowns(joints), 3);
    ADD_FAILURE() << "3 of 2 candidates accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("-n"), std::string::npos);
  }
}

// Samples of a period unless told otherwise: max(256, 8 (K + 1)) for the prediction's harmonics
// 0 … K: 256 at K = 9, 568 at K = 70 (where 256 is too few: fewer than 4 (K + 1) = 284).
TEST(Design, SamplesPerPeriodFollowTheHarmonicBalance) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto joints = model_I();
  const std::vector<identify::SineTestPlan> plans{{3.0, 40.0}};
  for (const auto& [K, samples] : {std::pair{9, 256}, std::pair{70, 568}}) {
    identify::DesignOptions automatic;
    automatic.balance.harmonics = K;
    identify::DesignOptions given = automatic;
    given.samples_per_period = samples;
    const auto a = identify::predict_candidates(sub, joints, tip, plans, automatic);
    const auto b = identify::predict_candidates(sub, joints, tip, plans, given);
    ASSERT_TRUE(a[0].usable) << a[0].reason;
    EXPECT_EQ(a[0].information, b[0].information) << K; // the same computation, bit for bit
  }
  identify::DesignOptions too_few;
  too_few.balance.harmonics = 70;
  too_few.samples_per_period = 256;
  EXPECT_THROW(identify::predict_candidates(sub, joints, tip, plans, too_few),
               std::invalid_argument);
}

// A test in which a friction joint sticks is left out, and says why: there the Coulomb basis
// sign(ẏ) does not describe the force, and the equations miss at the true values. On a smooth
// joint (model I) every candidate's misfit is the harmonic balance's truncation, nothing more.
TEST(Design, TestsWhereFrictionSticksAreLeftOut) {
  const frf::Substructure sub(test::paper_cantilever());
  const std::vector<joints::Joint> joints{
      tip_joint({Term::k, Term::c, Term::fc, Term::k3}, {4800.0, 20.0, 3.0, 1.6e8})};
  const std::vector<identify::SineTestPlan> plans{{1.0, 10.0}, {19.0, 80.0}};
  const auto candidates = identify::predict_candidates(sub, joints, tip, plans);
  ASSERT_EQ(candidates.size(), 2u);
  std::printf("  misfit: %.3g at 1 Hz, 10 N (sticks); %.3g at 19 Hz, 80 N\n", candidates[0].misfit,
              candidates[1].misfit);
  EXPECT_FALSE(candidates[0].usable);
  EXPECT_NE(candidates[0].reason.find("noise standard deviations"), std::string::npos)
      << candidates[0].reason;
  EXPECT_TRUE(candidates[1].usable) << candidates[1].reason;
  // Stuck for part of the period by exact time integration.
  identify::SimulationOptions ti;
  ti.periods = 2;
  const auto integrated = identify::simulate_sine_tests(sub, joints, tip, {plans[0]}, ti);
  const auto* v = integrated[0].record.find(identify::Quantity::velocity, tip);
  ASSERT_NE(v, nullptr);
  const double vmax = v->samples.cwiseAbs().maxCoeff();
  EXPECT_GT((v->samples.array().abs() <= 1e-9 * vmax).cast<double>().mean(), 0.01);

  std::vector<identify::SineTestPlan> grid;
  for (double f : {1.0, 3.0, 5.0, 19.0})
    for (double a : {10.0, 80.0})
      grid.push_back({f, a});
  for (const auto& c : identify::predict_candidates(sub, model_I(), tip, grid)) {
    EXPECT_TRUE(c.usable) << c.reason;
    EXPECT_LT(c.misfit, 0.01) << c.plan.frequency_hz << " Hz " << c.plan.amplitude << " N";
  }
}

TEST(Design, AModalAnalysisThatFailsLeavesEveryCandidateOutWithTheReason) {
  // tests/support/failing_substructure.hpp: its dense modal analysis fails, so no
  // candidate can be predicted; each says why.
  const frf::Substructure failing = test::failing_substructure();
  joints::Joint j{"a", 2, 0, fem::Dof::ux, {Term::k}, {1.0}, {false}, {}};
  const auto candidates =
      identify::predict_candidates(failing, {j}, {3, fem::Dof::ux}, {{1.0, 1.0}, {2.0, 1.0}});
  ASSERT_EQ(candidates.size(), 2u);
  for (const auto& c : candidates) {
    EXPECT_FALSE(c.usable);
    EXPECT_NE(c.reason.find("the modal analysis failed: " + test::failing_modes_reason),
              std::string::npos)
        << c.reason;
  }
}

// The predicted bias is the mean error of repeated identifications. A friction joint that
// sticks for part of each period (1 Hz, 10 N and 3 Hz, 20 N: TestsWhereFrictionSticksAreLeftOut)
// has equations that miss at the true values — sign(ẏ) does not describe the stuck force — so
// fit() is biased, by (Σ Iᵢ)⁻¹ Σ scoreᵢ to first order. Kept here (max_misfit infinite), the
// tests are simulated by harmonic balance as the design predicts them and identified 60 times
// with 0.1 % noise (at 1 %, the noise's own second-order bias of c and fc was as large as the
// misfit's): the mean error of each term must have the predicted sign and lie within 25 % of the
// predicted bias plus four standard errors of the mean (σ/√60). Measured: k 64.69 predicted,
// 65.04 mean error; c −0.928, −0.921; fc 0.507, 0.506. Flipping the bias's sign or leaving out a
// test's score fails.
TEST(Design, PredictedBiasIsTheMeanErrorOfRepeatedIdentifications) {
  const frf::Substructure sub(test::paper_cantilever());
  const std::vector<joints::Joint> joints{
      tip_joint({Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0})};
  const std::vector<identify::SineTestPlan> plans{
      {1.0, 10.0}, {3.0, 20.0}, {5.0, 40.0}, {19.0, 80.0}};
  identify::DesignOptions d;
  d.harmonics = {1, 2, 3};
  d.noise = 1e-3;
  d.periods = 8;
  d.samples_per_period = 256;
  d.max_misfit = std::numeric_limits<double>::infinity();
  const auto candidates = identify::predict_candidates(sub, joints, tip, plans, d);
  std::vector<int> all;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    ASSERT_TRUE(candidates[i].usable) << candidates[i].reason;
    all.push_back(static_cast<int>(i));
  }
  const Eigen::VectorXd bias = identify::predicted_bias(candidates, all);
  const Eigen::VectorXd std = identify::predicted_std(candidates, all);
  ASSERT_TRUE(bias.allFinite());

  identify::SimulationOptions so;
  so.method = identify::SimulationMethod::harmonic_balance;
  so.periods = d.periods;
  so.steps_per_period = d.samples_per_period;
  so.balance = d.balance;
  const auto clean = identify::simulate_sine_tests(sub, joints, tip, plans, so);
  identify::FitOptions fo;
  fo.harmonics = d.harmonics;
  constexpr int reps = 60;
  const auto nu = bias.size();
  Eigen::VectorXd mean_error = Eigen::VectorXd::Zero(nu);
  for (int r = 0; r < reps; ++r) {
    const identify::FitResult fit =
        noisy_fit(sub, joints, clean, d.noise, 104729ull * static_cast<unsigned long long>(r), fo);
    ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
    for (Eigen::Index u = 0; u < nu; ++u)
      mean_error(u) += (fit.joints[0].terms[static_cast<std::size_t>(u)].value -
                        joints[0].values[static_cast<std::size_t>(u)]) /
                       reps;
  }
  int significant = 0;
  for (Eigen::Index u = 0; u < nu; ++u) {
    const std::string name(joints::term_name(joints[0].terms[static_cast<std::size_t>(u)]));
    const double standard_error = std(u) / std::sqrt(static_cast<double>(reps));
    std::printf("  %-3s predicted bias %.4g, mean error %.4g (standard error %.3g)\n", name.c_str(),
                bias(u), mean_error(u), standard_error);
    EXPECT_LE(std::abs(mean_error(u) - bias(u)), 0.25 * std::abs(bias(u)) + 4.0 * standard_error)
        << name;
    if (std::abs(bias(u)) > 8.0 * standard_error) {
      ++significant;
      EXPECT_GT(mean_error(u) * bias(u), 0.0) << name << ": the bias has the wrong sign";
    }
  }
  EXPECT_GE(significant, 1) << "no term is biased beyond the scatter: the test would not fail";
}

namespace {

TEST(Design, ParametricLevelsSayWhichForcesReachMacroslip) {
  // An iwan (fs 3 N, kt 1e4 N/m, chi -0.5, beta 0.1) not fixed beside k and c: its macroslip
  // starts at Segalman's φ_max = fs (1 + β) / (kt (β + (χ + 1)/(χ + 2))) = 3.3e-4 / (0.1 + 1/3)
  // = 7.6154e-4 m. The level reported at each frequency must be the smallest candidate force
  // whose predicted deformation reaches φ_max (the next smaller one stays below), and where no
  // candidate reaches it a linear guess above the largest.
  const frf::Substructure sub{test::paper_cantilever()};
  joints::Joint j = tip_joint({Term::k, Term::c, Term::iwan}, {4800.0, 20.0, 1.0});
  j.set_parameters(2, {3.0, 1.0e4, -0.5, 0.1}, false);
  const std::vector<joints::Joint> joints{j};
  const double phi_max = 3.0 * 1.1 / (1.0e4 * (0.1 + 1.0 / 3.0));
  std::vector<identify::SineTestPlan> plans;
  for (double f : {1.0, 3.0})
    for (double a : {0.5, 2.0, 8.0})
      plans.push_back({f, a});
  identify::DesignOptions o;
  o.max_misfit = std::numeric_limits<double>::infinity();
  const auto candidates =
      identify::predict_candidates(sub, identify::with_parametric_fixed(joints), tip, plans, o);
  const auto levels = identify::parametric_levels(joints, candidates);
  ASSERT_EQ(levels.size(), 1u);
  const identify::ParametricLevel& l = levels[0];
  EXPECT_EQ(l.regime, "macroslip");
  EXPECT_NEAR(l.threshold, phi_max, 1e-12 * phi_max);
  ASSERT_EQ(l.frequency_hz.size(), 2u);
  for (std::size_t f = 0; f < 2; ++f) {
    double lowest = std::numeric_limits<double>::quiet_NaN(), below = 0.0;
    for (const auto& c : candidates)
      if (c.plan.frequency_hz == l.frequency_hz[f] && c.usable) {
        if (c.joint_amplitude[0] >= phi_max && !(c.plan.amplitude >= lowest))
          lowest = c.plan.amplitude;
      }
    for (const auto& c : candidates)
      if (c.plan.frequency_hz == l.frequency_hz[f] && c.usable && c.plan.amplitude < lowest)
        below = std::max(below, c.joint_amplitude[0]);
    if (std::isnan(lowest)) {
      EXPECT_TRUE(std::isnan(l.lowest_force[f]));
      EXPECT_GT(l.guess_force[f], 8.0);
    } else {
      EXPECT_EQ(l.lowest_force[f], lowest);
      EXPECT_LT(below, phi_max);
    }
  }
  // At 1 Hz, well below the resonance, 0.5 N deforms the joint by about 0.5 N over the joint's
  // and the beam's static stiffness (4800 + 1e4 + 3EI/L³ ≈ 4900 N/m), 2.5e-5 m: 30 times below
  // φ_max, never the level.
  EXPECT_NE(l.lowest_force[0], 0.5);
  EXPECT_NE(l.sentence.find("iwan.fs apart from iwan.beta"), std::string::npos) << l.sentence;
}

} // namespace

// A periodic candidate (a multisine over 1-4 Hz at 40 N RMS, period 4 s, 8 periods averaged,
// 1 % noise on force, displacement and velocity): the standard deviations predicted from its
// information are those identify reports for such a record (the mean of its std over 200
// repetitions of fresh noise on the same steady record, by time integration, its transient cut
// off as the prediction cuts it): within [0.95, 1.15] of them (measured 1.06-1.07), which fails a
// prediction that miscounts the averaged periods (a factor √8) or the lines. Against the scatter
// of the estimates themselves (±5 % from 200 repetitions) the ratio lies in [0.8, 1.35]: measured
// 1.02 for c and c2, but 1.17 for k and 1.23 for k3, whose scatter identify's own intervals for
// periodic records understate by a fifth to a quarter (its reported std: 6.83 N/m against a
// scatter of 8.50; k3 2.15e5 against 2.80e5; 32 periods do not close it). The bias is not
// predicted for periodic candidates (NaN), never a number.
TEST(Design, APeriodicCandidatesPredictedStdIsTheMonteCarloScatter) {
  const frf::Substructure sub(test::paper_cantilever());
  const auto joints = model_I();
  const identify::PeriodicPlan plan{1.0, 4.0, 40.0, 4.0, 256.0};
  identify::DesignOptions d;
  d.harmonics = {1, 2, 3};
  d.noise = 0.01;
  d.periods = 8;
  const auto candidates = identify::predict_periodic_candidates(sub, joints, tip, {plan}, d);
  ASSERT_EQ(candidates.size(), 1u);
  ASSERT_TRUE(candidates[0].usable) << candidates[0].reason;
  ASSERT_TRUE(candidates[0].periodic.has_value());
  EXPECT_EQ(candidates[0].plan.frequency_hz, 0.25);
  EXPECT_EQ(candidates[0].plan.amplitude, 40.0);
  ASSERT_EQ(candidates[0].joint_amplitude.size(), 1u);
  EXPECT_GT(candidates[0].joint_amplitude[0], 0.0);
  const Eigen::VectorXd predicted = identify::predicted_std(candidates, {0});
  EXPECT_TRUE(identify::predicted_bias(candidates, {0}).array().isNaN().all());

  // The steady record, independently: 3 transient periods simulated and cut off.
  const identify::ForceInput force = identify::generated_force(
      {identify::Excitation::multisine, 1.0, 4.0, 40.0, 1, 11 * 4.0, 256.0, 4.0}, tip);
  identify::ForcedOptions fo;
  fo.fade_in_s = 4.0;
  identify::ForcedTest run = identify::simulate_forced(sub, joints, force, fo);
  ASSERT_TRUE(run.status.ok()) << run.status.reason;
  identify::Record clean = run.record;
  const Eigen::Index keep = clean.t.size() - 3 * 1024;
  clean.t = Eigen::VectorXd(clean.t.tail(keep));
  for (auto& ch : clean.channels)
    ch.samples = Eigen::VectorXd(ch.samples.tail(keep));
  clean.period_s = 4.0;
  identify::FitOptions fit_options;
  fit_options.harmonics = {1, 2, 3};
  identify::MeasureOptions mo = identify::measure_options(fit_options);
  mo.band_from_hz = 1.0;
  mo.band_to_hz = 4.0;
  constexpr int reps = 200;
  const auto nu = predicted.size();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(nu), square = sum, reported = sum;
  for (int r = 0; r < reps; ++r) {
    identify::Record rec = clean;
    identify::add_noise(rec, d.noise, 104729ull + 31ull * static_cast<unsigned long long>(r));
    const identify::FitResult fit = identify::fit(
        sub, joints, {identify::measure(identify::SineTest(std::move(rec)), mo)}, fit_options);
    ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
    for (Eigen::Index u = 0; u < nu; ++u) {
      const double v = fit.joints[0].terms[static_cast<std::size_t>(u)].value;
      sum(u) += v / reps;
      square(u) += v * v / reps;
      reported(u) += fit.joints[0].terms[static_cast<std::size_t>(u)].std / reps;
    }
  }
  for (Eigen::Index u = 0; u < nu; ++u) {
    const double scatter =
        std::sqrt(std::max(0.0, square(u) - sum(u) * sum(u)) * reps / (reps - 1));
    const std::string name(joints::term_name(joints[0].terms[static_cast<std::size_t>(u)]));
    std::printf("  %-3s predicted std %.4g, Monte Carlo %.4g (ratio %.3f), fit's mean std %.4g\n",
                name.c_str(), predicted(u), scatter, scatter / predicted(u), reported(u));
    EXPECT_GT(predicted(u) / reported(u), 0.95) << name;
    EXPECT_LT(predicted(u) / reported(u), 1.15) << name;
    EXPECT_GT(scatter / predicted(u), 0.8) << name;
    EXPECT_LT(scatter / predicted(u), 1.35) << name;
  }
}
