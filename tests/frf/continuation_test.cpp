// Response curves by continuation: against fixed-frequency harmonic balance, the exact linear
// FRF, time integration from rest, and the Floquet multipliers of the bare structure.
#include "frf/continuation.hpp"

#include "frf/modal_model.hpp"
#include "frf/substructure.hpp"
#include "support/numbers.hpp"

#include "fem/damping.hpp"
#include "fem/time_integration.hpp"
#include "support/beam_models.hpp"
#include "support/failing_substructure.hpp"
#include "support/synthesised_cantilever.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

using namespace jointid;
using fem::Dof;
using frf::Complex;
using joints::Term;

namespace {

using jointid::test::harmonic;

using jointid::test::two_pi;

joints::Joint make(std::string name, int node, std::vector<Term> terms,
                   std::vector<double> values) {
  joints::Joint j{std::move(name), node, 0, Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

using PaperCantilever = test::SynthesisedCantilever;

frf::ResponseBranch trace(const PaperCantilever& c, const std::vector<joints::Joint>& js, double F0,
                          double f0, double f1, frf::ContinuationOptions o = {}) {
  return frf::trace_response(c.H, js, c.system.dofs, {c.eq(7)}, frf::sine_force(F0), {c.eq(7)}, f0,
                             f1, o);
}

// Where the branch's frequency moves forwards (+1) or backwards (−1) at point i.
double heading(const frf::ResponseBranch& b, std::size_t i) {
  return b.points[i + 1].hb.frequency_hz > b.points[i].hb.frequency_hz ? 1.0 : -1.0;
}

// The point of segment [from, to) of the branch that crosses frequency f, linearly interpolated
// in the harmonics of the joint deformation.
Eigen::MatrixXcd crossing(const frf::ResponseBranch& b, int from, int to, double f) {
  for (int i = from; i + 1 < to; ++i) {
    const double fa = b.points[i].hb.frequency_hz, fb = b.points[i + 1].hb.frequency_hz;
    if ((fa - f) * (fb - f) <= 0.0 && fa != fb) {
      const double x = (f - fa) / (fb - fa);
      return (1.0 - x) * b.points[i].hb.Y + x * b.points[i + 1].hb.Y;
    }
  }
  ADD_FAILURE() << "no crossing of " << f << " Hz in points " << from << " … " << to;
  return {};
}

} // namespace

TEST(Continuation, LinearJointFollowsTheExactFrf) {
  // g = k y + c ẏ at the tip: X = H_tt F / (1 + H_tt (k + iωc)) exactly (see the harmonic
  // balance tests). Over 1 … 25 Hz (two resonances) the branch must go forwards only, end at
  // 25 Hz, have no folds, and every point must be the exact solution (Newton's tolerance 1e-10
  // on the linear problem).
  const PaperCantilever c;
  const double k = 4800.0, cv = 20.0, F0 = 80.0;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k, Term::c}, {k, cv})};
  const frf::ResponseBranch b = trace(c, js, F0, 1.0, 25.0);
  ASSERT_TRUE(b.complete);
  EXPECT_TRUE(b.folds.empty());
  EXPECT_DOUBLE_EQ(b.points.front().hb.frequency_hz, 1.0);
  EXPECT_DOUBLE_EQ(b.points.back().hb.frequency_hz, 25.0);
  EXPECT_GT(b.points.size(), 50u);
  const std::vector<int> tip{c.eq(7)};
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    const frf::ResponsePoint& p = b.points[i];
    if (i + 1 < b.points.size()) {
      EXPECT_GT(heading(b, i), 0.0) << i;
    }
    const double w = two_pi * p.hb.frequency_hz;
    const Complex Htt = c.H.receptance(w, tip, tip)(0, 0);
    const Complex X = Htt * Complex(0.0, -F0) / (1.0 + Htt * Complex(k, w * cv));
    EXPECT_LE(std::abs(p.hb.X(1, 0) - X), 1e-9 * std::abs(X)) << p.hb.frequency_hz;
    ASSERT_TRUE(p.stable.has_value());
    EXPECT_TRUE(*p.stable);
  }
}

TEST(Continuation, WithoutJointsTheBranchIsTheLinearFrf) {
  // No joints (jointid response on a model without [[joints]]): the branch is the bare
  // structure's receptance times the force, and stable. The stability check bounded its time
  // step by the largest joint stiffness of an empty set of joints and crashed.
  const PaperCantilever c;
  const double F0 = 10.0;
  const frf::ResponseBranch b = trace(c, {}, F0, 2.0, 4.0);
  ASSERT_TRUE(b.complete);
  EXPECT_TRUE(b.folds.empty());
  EXPECT_GT(b.points.size(), 10u);
  const std::vector<int> tip{c.eq(7)};
  for (const frf::ResponsePoint& p : b.points) {
    const Complex X =
        c.H.receptance(two_pi * p.hb.frequency_hz, tip, tip)(0, 0) * Complex(0.0, -F0);
    EXPECT_LE(std::abs(p.hb.X(1, 0) - X), 1e-9 * std::abs(X)) << p.hb.frequency_hz;
    ASSERT_TRUE(p.stable.has_value()) << p.hb.frequency_hz;
    EXPECT_TRUE(*p.stable) << p.hb.frequency_hz;
  }
}

TEST(Continuation, FloquetMultipliersOfTheBareStructure) {
  // At a vanishing amplitude the joint (k3 only) adds nothing: the multipliers are those of the
  // damped modes over one period, |μ_r| = exp(−ζ ω_r T) (ζ = 1 %), the largest from mode 1. The
  // classical Runge–Kutta method with h ω_1 ≤ 0.5 ω_1/ω_max is accurate to ≪ 1e-6 for mode 1.
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k3}, {1.6e8})};
  for (double f : {1.0, 3.0, 7.0}) {
    const frf::HarmonicBalanceResult r =
        frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 1e-9, f, std::vector<int>{c.eq(7)});
    ASSERT_TRUE(r.status.ok());
    const frf::Stability s = frf::floquet_stability(c.H, js, c.system.dofs, r, {});
    ASSERT_TRUE(s.stable.has_value()) << s.note;
    EXPECT_TRUE(*s.stable);
    EXPECT_GE(s.modes, 3);
    const double w1 = c.H.natural_frequencies().minCoeff();
    EXPECT_NEAR(s.multipliers.cwiseAbs().maxCoeff(), std::exp(-0.01 * w1 / f), 1e-6) << f;
  }
}

TEST(Continuation, HardeningCubicFoldsAndStability) {
  // k3 = 1.6e8 N/m³ at the tip, 0.5 N: the first resonance (3.0 Hz) bends to the right and
  // overhangs. Checked: two folds (upper, then lower; 3 solutions between their frequencies);
  // every point a steady state of the fixed-frequency harmonic balance; the branch goes
  // backwards exactly between the folds, and exactly those points are unstable (a saddle-node:
  // one multiplier through +1 at each fold, so |μ|max = 1 there up to the modes the check leaves
  // out); time integration from rest between the folds ends on a stable branch, not the middle.
  const PaperCantilever c;
  const double F0 = 0.5;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k3}, {1.6e8})};
  const frf::ResponseBranch b = trace(c, js, F0, 2.5, 4.5);
  ASSERT_TRUE(b.complete);
  ASSERT_EQ(b.folds.size(), 2u);
  const int up = b.folds[0], down = b.folds[1];
  const double f_up = b.points[up].hb.frequency_hz, f_down = b.points[down].hb.frequency_hz;
  EXPECT_GT(f_up, f_down + 0.1);
  EXPECT_GT(f_down, 3.0); // hardening: both folds above the linear resonance
  EXPECT_GT(std::abs(b.points[up].hb.X(1, 0)), 2.0 * std::abs(b.points[down].hb.X(1, 0)));

  for (std::size_t i = 0; i < b.points.size(); ++i) {
    const frf::ResponsePoint& p = b.points[i];
    // Fixed-frequency Newton started at the point stays there.
    const frf::HarmonicBalance at(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7)}, p.hb.frequency_hz);
    const frf::HarmonicBalanceResult r = at.solve(js, frf::sine_force(F0), &p.hb.Y);
    ASSERT_TRUE(r.status.ok()) << i;
    EXPECT_LE((r.Y - p.hb.Y).norm(), 1e-9 * p.hb.Y.norm()) << i;
    const bool between = static_cast<int>(i) > up && static_cast<int>(i) < down;
    const bool at_fold = static_cast<int>(i) == up || static_cast<int>(i) == down;
    if (i + 1 < b.points.size() && !at_fold && static_cast<int>(i + 1) != up &&
        static_cast<int>(i + 1) != down) {
      EXPECT_EQ(heading(b, i), between ? -1.0 : 1.0) << i;
    }
    ASSERT_TRUE(p.stable.has_value()) << i;
    if (at_fold) { // computed at every fold
      ASSERT_TRUE(p.stability_checked) << i;
      EXPECT_NEAR(p.max_multiplier, 1.0, 1e-3) << i;
    } else if (!p.stability_checked || std::abs(p.max_multiplier - 1.0) > 1e-3) { // off the folds
      EXPECT_EQ(*p.stable, !between) << i << " at " << p.hb.frequency_hz << " Hz";
    }
  }

  // Between the folds: three distinct steady states, and time integration from rest lands on
  // one of the stable ones (the lower branch: it starts from small amplitudes), to its 1e-4.
  const double f = 0.5 * (f_up + f_down), w = two_pi * f;
  const Eigen::MatrixXcd lower = crossing(b, down, static_cast<int>(b.points.size()), f),
                         middle = crossing(b, up, down + 1, f), upper = crossing(b, 0, up + 1, f);
  const frf::HarmonicBalance at(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7)}, f);
  std::vector<frf::HarmonicBalanceResult> three;
  for (const Eigen::MatrixXcd* start : {&lower, &middle, &upper}) {
    three.push_back(at.solve(js, frf::sine_force(F0), start));
    ASSERT_TRUE(three.back().status.ok());
  }
  EXPECT_GT(std::abs(three[1].X(1, 0)), 1.3 * std::abs(three[0].X(1, 0)));
  EXPECT_GT(std::abs(three[2].X(1, 0)), 1.02 * std::abs(three[1].X(1, 0)));
  EXPECT_TRUE(frf::floquet_stability(c.H, js, c.system.dofs, three[0], {}).stable.value());
  EXPECT_FALSE(frf::floquet_stability(c.H, js, c.system.dofs, three[1], {}).stable.value());
  EXPECT_TRUE(frf::floquet_stability(c.H, js, c.system.dofs, three[2], {}).stable.value());

  const fem::SparseMatrix C = fem::damping_matrix(c.system, c.model.damping, &c.modes);
  const joints::JointForces forces(js, c.system.dofs);
  fem::SteadyStateOptions o;
  o.steps_per_period = 2048;
  o.output_periods = 1;
  o.tolerance = 1e-9;
  const std::vector<int> outputs{c.eq(7)};
  const fem::SteadyState s = fem::steady_state(c.system, C, &forces, {c.eq(7), F0, f}, outputs, o);
  ASSERT_TRUE(s.status.ok());
  const Complex T1 = harmonic(s.u.col(0), s.t, w, 1);
  EXPECT_LT(std::abs(T1 - three[0].X(1, 0)), 1e-4 * std::abs(three[0].X(1, 0)));
}

TEST(Continuation, ProgressRisesToTheEndThroughTracingAndThenTheStabilityChecks) {
  // With stability, tracing reports the first half of the fraction and the Floquet checks the
  // second: the fraction never falls, passes 0.5 once the band is covered, is reported once for
  // each point whose multipliers are computed after that, and ends at 1. Without stability the
  // band's coverage is the fraction (it reaches 1 when the branch ends).
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k3}, {1.6e8})};
  for (const bool stability : {true, false}) {
    frf::ContinuationOptions o;
    o.stability = stability;
    std::vector<double> seen;
    const frf::ResponseBranch b =
        frf::trace_response(c.H, js, c.system.dofs, {c.eq(7)}, frf::sine_force(0.5), {c.eq(7)}, 2.5,
                            4.5, o, [&](double fraction) { seen.push_back(fraction); });
    ASSERT_TRUE(b.complete);
    ASSERT_FALSE(seen.empty());
    for (std::size_t i = 1; i < seen.size(); ++i)
      EXPECT_GE(seen[i], seen[i - 1]) << i;
    EXPECT_EQ(seen.back(), 1.0);
    std::size_t computed = 0;
    for (const auto& p : b.points)
      computed += p.stability_checked ? 1 : 0;
    // Reports after tracing ended at the half: one per point computed, and the final 1.
    const auto first_after = std::find(seen.begin(), seen.end(), 0.5);
    if (stability) {
      ASSERT_NE(first_after, seen.end());
      EXPECT_EQ(static_cast<std::size_t>(seen.end() - first_after) - 1, computed + 1);
      EXPECT_GT(computed, 0u);
    } else {
      EXPECT_EQ(computed, 0u);
    }
  }
}

TEST(Continuation, SofteningTracedUpAndDownAlike) {
  // k = 4800 N/m with k3 = −2e8 N/m³ at the tip, 0.3 N: the resonance (≈4.2 Hz with the joint's
  // k) bends to the left. Traced upwards and downwards the branch is the same curve: the same
  // two folds (in reverse order) at the same frequencies, to the location's accuracy (the secant
  // stops at |t_ω| < 1e-8; a fold is quadratic in the arclength, so the frequency is exact to
  // far below 1e-8 relative; 1e-6 asserted), both below the linear resonance.
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k, Term::k3}, {4800.0, -2e8})};
  const frf::ResponseBranch up = trace(c, js, 0.3, 3.0, 5.0), down = trace(c, js, 0.3, 5.0, 3.0);
  ASSERT_TRUE(up.complete);
  ASSERT_TRUE(down.complete);
  ASSERT_EQ(up.folds.size(), 2u);
  ASSERT_EQ(down.folds.size(), 2u);
  for (int i : {0, 1}) {
    const double fu = up.points[up.folds[i]].hb.frequency_hz;
    const double fd = down.points[down.folds[1 - i]].hb.frequency_hz;
    EXPECT_NEAR(fu, fd, 1e-6 * fu) << i;
  }
  // Upwards the branch turns back first at the higher frequency (the end of the lower branch,
  // the jump up of a rising sweep), then forwards again at the lower one, where the upper
  // branch begins: the amplitude is larger there.
  const frf::ResponsePoint &a = up.points[up.folds[0]], &b = up.points[up.folds[1]];
  EXPECT_GT(a.hb.frequency_hz, b.hb.frequency_hz);
  EXPECT_GT(std::abs(b.hb.X(1, 0)), 1.3 * std::abs(a.hb.X(1, 0)));
  // The linear resonance with the joint's k: ω² = eigenvalue of the tip-stiffened structure,
  // above both folds. From the linear FRF's peak: scan |X| on a fine grid.
  const std::vector<int> tip{c.eq(7)};
  double f_peak = 0.0, peak = 0.0;
  for (double f = 3.0; f <= 5.0; f += 1e-4) {
    const double w = two_pi * f;
    const Complex Htt = c.H.receptance(w, tip, tip)(0, 0);
    const double x = std::abs(Htt / (1.0 + Htt * 4800.0));
    if (x > peak) peak = x, f_peak = f;
  }
  EXPECT_LT(a.hb.frequency_hz, f_peak);
}

TEST(Continuation, ExactFrictionPointsAreFixedFrequencySteadyStates) {
  // k y + c ẏ + fc sign(ẏ) with fc = 3 N at the tip, 10 N, 2 … 4.5 Hz. Every point must be the
  // steady state an independent fixed-frequency solve finds from the linear guess (1e-8), and
  // stability is reported as not determined (set-valued friction), never guessed.
  const PaperCantilever c;
  const std::vector<joints::Joint> js{
      make("tip", 7, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0})};
  const frf::ResponseBranch b = trace(c, js, 10.0, 2.0, 4.5);
  for (const auto& n : b.notes)
    std::printf("note: %s\n", n.c_str());
  ASSERT_TRUE(b.complete);
  ASSERT_FALSE(b.notes.empty());
  EXPECT_NE(b.notes.front().find("not determined"), std::string::npos);
  for (std::size_t i = 0; i < b.points.size(); i += 3) {
    const frf::ResponsePoint& p = b.points[i];
    EXPECT_FALSE(p.stable.has_value());
    const frf::HarmonicBalanceResult r = frf::harmonic_balance(
        c.H, js, c.system.dofs, c.eq(7), 10.0, p.hb.frequency_hz, std::vector<int>{c.eq(7)});
    ASSERT_TRUE(r.status.ok()) << i;
    EXPECT_LE((r.X - p.hb.X).norm(), 1e-8 * r.X.norm()) << i << " at " << p.hb.frequency_hz;
  }
}

TEST(Continuation, IncompleteBranchesSayWhereAndWhy) {
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k3}, {1.6e8})};
  // The point limit: a branch of 5 points stops short of the band's end.
  frf::ContinuationOptions few;
  few.max_points = 5;
  const frf::ResponseBranch b = trace(c, js, 0.5, 2.5, 4.5, few);
  EXPECT_FALSE(b.complete);
  ASSERT_EQ(b.points.size(), 5u);
  ASSERT_EQ(b.notes.size(), 1u);
  std::ostringstream at;
  at.precision(6);
  at << b.points.back().hb.frequency_hz;
  EXPECT_EQ(b.notes[0], "stopped after 5 points at " + at.str() + " Hz (max_points)");
  // No start: two Newton iterations (and two load steps) cannot solve 80 N at 3 Hz.
  frf::ContinuationOptions weak;
  weak.hb.max_iterations = 2;
  weak.hb.continuation_steps = 2;
  const frf::ResponseBranch none = trace(c, js, 80.0, 3.0, 4.0, weak);
  EXPECT_FALSE(none.complete);
  EXPECT_TRUE(none.points.empty());
  ASSERT_EQ(none.notes.size(), 1u);
  EXPECT_EQ(none.notes[0].rfind("no steady state found at the start, 3 Hz (residual ", 0), 0u)
      << none.notes[0];
  // A stall: at 10 N the branch climbs towards its upper fold, where steps of at least 0.02
  // (scaled arclength) with 4 Newton iterations no longer converge.
  frf::ContinuationOptions coarse;
  coarse.hb.max_iterations = 4;
  coarse.initial_step = coarse.min_step = 0.02;
  coarse.max_step = 0.05;
  const frf::ResponseBranch stalled = trace(c, js, 10.0, 2.0, 4.5, coarse);
  EXPECT_FALSE(stalled.complete);
  ASSERT_FALSE(stalled.points.empty());
  ASSERT_EQ(stalled.notes.size(), 1u);
  std::ostringstream where;
  where.precision(6);
  where << stalled.points.back().hb.frequency_hz;
  EXPECT_EQ(stalled.notes[0],
            "continuation stalled at " + where.str() + " Hz: no step down to 0.02 converged");
  EXPECT_GT(stalled.points.back().hb.frequency_hz, 3.0);
}

TEST(Continuation, BadArgumentsThrow) {
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, {Term::k3}, {1.6e8})};
  EXPECT_THROW(trace(c, js, 1.0, 3.0, 3.0), std::invalid_argument);
  EXPECT_THROW(trace(c, js, 1.0, -1.0, 3.0), std::invalid_argument);
  frf::ContinuationOptions o;
  o.max_step = 1e-3; // below the initial step
  EXPECT_THROW(trace(c, js, 1.0, 2.0, 3.0, o), std::invalid_argument);
}

TEST(Continuation, FloquetOfAJenkinsOscillatorMatchesTheDecayInTime) {
  // A mass (1 kg) on a spring (1e4 N/m, 1 % modal damping: c = 2 N s/m) with a Jenkins joint
  // (kt = 1e4 N/m, fs = 1 N) under F0 sin ωt at 12 Hz. Stuck all the time (0.5 N) it is a linear
  // oscillator of stiffness 2e4 N/m: |μ| = exp(−c T / 2m) exactly (to the check's Runge–Kutta,
  // ≪ 1e-6). Sliding part of the period (3 N, 10 N) the multipliers must be those the
  // time integrator shows: two integrations from rest, one of them nudged (1e-6 of the
  // amplitude) at period 60, differ afterwards by M^p times the nudge, so their difference's
  // norm falls by |μ|max a period (its fluctuation, the pair's rotation, is averaged by a
  // least-squares fit of its logarithm over periods 3 … 12, the difference still ≫ rounding:
  // ±2 % met, 4 % asserted).
  // A check that took the stuck elements' stiffness alone (δg = K_st δy, forgetting where the
  // stick phase began) would find the linear 0.920 at every level — far outside.
  fem::Model model = test::oscillator(1.0, 1.0e4);
  model.damping.kind = fem::Damping::Kind::modal;
  model.damping.modal_ratio = 0.01;
  const fem::Assembled system = fem::assemble(model);
  const fem::Modes modes =
      fem::modal_analysis(system, {.num_modes = 0, .engine = fem::ModalEngine::dense});
  const frf::ModalSynthesis H(system, modes, model.damping, test::all_equations(system));
  const fem::SparseMatrix C = fem::damping_matrix(system, model.damping, &modes);
  const double f = 12.0, T = 1.0 / f;
  joints::Joint j{"j", 1, 0, Dof::ux, {Term::jenkins}, {1.0}, {true}, {}};
  j.set_parameters(0, {1.0e4, 1.0});
  const std::vector<joints::Joint> js{j};
  const joints::JointForces forces(js, system.dofs);
  frf::HarmonicBalanceOptions ho;
  ho.harmonics = 31;
  for (double F0 : {0.5, 3.0, 10.0}) {
    SCOPED_TRACE(std::to_string(F0) + " N");
    const frf::HarmonicBalanceResult r =
        frf::harmonic_balance(H, js, system.dofs, 0, F0, f, std::vector<int>{0}, ho);
    ASSERT_TRUE(r.status.ok());
    const frf::Stability s = frf::floquet_stability(H, js, system.dofs, r, ho);
    ASSERT_TRUE(s.stable.has_value()) << s.note;
    EXPECT_TRUE(*s.stable);
    const double mu = s.multipliers.cwiseAbs().maxCoeff();
    if (F0 == 0.5) {
      EXPECT_NEAR(mu, std::exp(-2.0 * T / 2.0), 1e-6);
      continue;
    }
    const int N = 1024;
    fem::Newmark a(system, C, &forces, T / N), b(system, C, &forces, T / N);
    Eigen::VectorXd load = Eigen::VectorXd::Zero(1);
    a.set_state(load, load, load);
    b.set_state(load, load, load);
    long step = 0;
    auto advance = [&](int count) {
      for (int i = 1; i <= count; ++i) {
        load(0) = F0 * std::sin(two_pi * f * static_cast<double>(step + i) * T / N);
        ASSERT_TRUE(a.step(load).ok());
        ASSERT_TRUE(b.step(load).ok());
      }
      step += count;
    };
    advance(60 * N);
    Eigen::VectorXd u = b.u();
    u(0) += 1e-4 * std::abs(r.X(1, 0));
    b.set_state(u, b.v(), load);
    std::vector<double> p, logs;
    for (int period = 1; period <= 12; ++period) {
      advance(N);
      const double du = b.u()(0) - a.u()(0), dv = (b.v()(0) - a.v()(0)) / 100.0;
      if (period > 2) p.push_back(period), logs.push_back(0.5 * std::log(du * du + dv * dv));
    }
    const Eigen::Map<const Eigen::VectorXd> x(p.data(), static_cast<Eigen::Index>(p.size())),
        l(logs.data(), static_cast<Eigen::Index>(logs.size()));
    const double xm = x.mean(), lm = l.mean();
    const double slope =
        ((x.array() - xm) * (l.array() - lm)).sum() / (x.array() - xm).square().sum();
    EXPECT_NEAR(mu, std::exp(slope), 0.04 * mu);
    EXPECT_LT(mu, 0.85); // the sliding dissipates: well below the linear 0.920
  }
}

TEST(Continuation, IwanResponseCurveIsTracedWithItsStability) {
  // The paper's cantilever with k, c and an iwan at the tip, 2 N (microslip) across the first
  // resonance: the branch is complete, every point a fixed-frequency steady state, and every
  // point's stability determined (a passive joint under a harmonic force: stable).
  const PaperCantilever c;
  joints::Joint j = make("tip", 7, {Term::k, Term::c, Term::iwan}, {4800.0, 20.0, 1.0});
  j.set_parameters(2, {3.0, 1.0e4, -0.5, 0.1});
  const std::vector<joints::Joint> js{j};
  frf::ContinuationOptions o;
  o.hb.harmonics = 7;
  const frf::ResponseBranch b = trace(c, js, 2.0, 2.5, 3.5, o);
  ASSERT_TRUE(b.complete);
  ASSERT_GE(b.points.size(), 10u);
  for (std::size_t i = 0; i < b.points.size(); i += 5) {
    const frf::ResponsePoint& p = b.points[i];
    const frf::HarmonicBalance at(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7)}, p.hb.frequency_hz,
                                  o.hb);
    const frf::HarmonicBalanceResult r = at.solve(js, frf::sine_force(2.0), &p.hb.Y);
    ASSERT_TRUE(r.status.ok()) << i;
    EXPECT_LE((r.Y - p.hb.Y).norm(), 1e-8 * p.hb.Y.norm()) << i;
  }
  int checked = 0;
  for (const frf::ResponsePoint& p : b.points) {
    ASSERT_TRUE(p.stable.has_value()) << p.hb.frequency_hz;
    EXPECT_TRUE(*p.stable) << p.hb.frequency_hz;
    if (p.stability_checked) {
      EXPECT_LT(p.max_multiplier, 1.0);
      ++checked;
    }
  }
  EXPECT_TRUE(b.points.front().stability_checked && b.points.back().stability_checked);
  EXPECT_GE(checked, static_cast<int>(b.points.size()) / o.stability_stride);
}

TEST(Continuation, AModalAnalysisThatFailsIsTheCurvesStatus) {
  // tests/support/failing_substructure.hpp: its dense modal analysis fails. No curve
  // is traced; the status says why.
  const frf::Substructure sub = test::failing_substructure();
  joints::Joint j{"a", 2, 0, Dof::ux, {Term::k3}, {1e6}, {true}, {}};
  const frf::ResponseCurves curves = frf::response_curves(sub, {j}, {3, Dof::ux}, {1.0}, 1.0, 2.0);
  EXPECT_EQ(curves.status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(curves.status.reason, "the modal analysis failed: " + test::failing_modes_reason);
  EXPECT_TRUE(curves.curves.empty());
}

// An undamped mode where the harmonics reach (issue 31): the curves' notes name it and the
// missing damping, and whether a joint's damping can bound its resonance; a damped one is not
// mentioned. One mode at 10 Hz; band 4–4.5 Hz with 3 harmonics: they reach 4–13.5 Hz, and no
// harmonic lands on 10 Hz (the points stay finite).
TEST(Continuation, AnUndampedModeInReachIsNamedWithTheMissingDamping) {
  frf::ModalModel m;
  m.dofs = {{7, Dof::uy}};
  m.frequencies_hz = Eigen::VectorXd::Constant(1, 10.0);
  m.damping = Eigen::VectorXd::Zero(1);
  m.shapes = Eigen::MatrixXd::Constant(1, 1, 1.0);
  frf::ContinuationOptions o;
  o.hb.harmonics = 3;
  auto notes = [&](const frf::ModalModel& model, const joints::Joint& j) {
    const frf::ResponseCurves c =
        frf::response_curves(frf::Substructure(model), {j}, {7, Dof::uy}, {0.1}, 4.0, 4.5, o);
    EXPECT_TRUE(c.status.ok()) << c.status.reason;
    std::string all;
    for (const auto& n : c.notes)
      all += n + "\n";
    return all;
  };
  const std::string undamped = notes(m, make("tip", 7, {Term::k3}, {1e6}));
  EXPECT_NE(undamped.find("mode 1 (10 Hz) has no damping (modal damping 0) and lies where the "
                          "harmonics reach (4 Hz to 13.5 Hz): no joint term dissipates either, so "
                          "its resonance is unbounded and the points near it are the arithmetic's "
                          "limits, not a response; give the model damping ([damping])"),
            std::string::npos)
      << undamped;
  const std::string joint_damped = notes(m, make("tip", 7, {Term::k3, Term::c}, {1e6, 2.0}));
  EXPECT_NE(joint_damped.find("mode 1 (10 Hz) has no damping (modal damping 0) and lies where the "
                              "harmonics reach (4 Hz to 13.5 Hz): only the joints' damping bounds "
                              "its resonance"),
            std::string::npos)
      << joint_damped;
  m.damping(0) = 0.01;
  EXPECT_EQ(notes(m, make("tip", 7, {Term::k3}, {1e6})).find("no damping"), std::string::npos);
}

TEST(Continuation, StabilityAtSomePointsIsThatOfEveryPoint) {
  // The symmetry-breaking case of HarmonicBalance.AnAsymmetricStartFindsTheSymmetryBreaking
  // SteadyState (k + c + k3 at the tip, 100 N): around 3 Hz the half-wave symmetric branch is
  // unstable without a fold (a multiplier through +1 with an asymmetric perturbation). With the
  // multipliers computed only at the ends, the folds and where the even block's determinant
  // changes sign (a stride longer than the branch), every point's verdict must be the one
  // computed at every point: the unstable stretch is found by the sign change alone.
  const PaperCantilever c;
  const std::vector<joints::Joint> js{
      make("tip", 7, {Term::k, Term::c, Term::k3}, {4700.0, 43.0, 1.62e8})};
  frf::ContinuationOptions every, few;
  every.hb.harmonics = few.hb.harmonics = 9;
  every.stability_stride = 1;
  few.stability_stride = 100000;
  const frf::ResponseBranch all = trace(c, js, 100.0, 2.0, 4.0, every);
  const frf::ResponseBranch some = trace(c, js, 100.0, 2.0, 4.0, few);
  ASSERT_TRUE(all.complete && some.complete);
  ASSERT_EQ(all.points.size(), some.points.size());
  int unstable = 0, checked = 0;
  for (std::size_t i = 0; i < all.points.size(); ++i) {
    ASSERT_TRUE(all.points[i].stable.has_value()) << i;
    EXPECT_TRUE(all.points[i].stability_checked);
    EXPECT_EQ(some.points[i].stable, all.points[i].stable)
        << i << " at " << all.points[i].hb.frequency_hz << " Hz";
    unstable += !*all.points[i].stable;
    checked += some.points[i].stability_checked;
  }
  // No fold: the unstable stretch (3 points near 3 Hz, measured) is the symmetry breaking's,
  // found from a handful of computed points (6 of 70, measured).
  EXPECT_TRUE(all.folds.empty());
  EXPECT_GE(unstable, 2);
  EXPECT_LE(checked, 10);
}
