// Harmonic balance against the exact linear solution and against time integration.
#include "frf/continuation.hpp"

#include "frf/harmonic_balance.hpp"
#include "frf/hb_equations.hpp" // the small LU of the Newton steps
#include "support/numbers.hpp"

#include "fem/damping.hpp"
#include "fem/time_integration.hpp"
#include "support/beam_models.hpp"
#include "support/error_of.hpp"
#include "support/synthesised_cantilever.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <vector>

using namespace jointid;
using fem::Dof;
using frf::Complex;
using joints::Term;

namespace {

using jointid::test::harmonic;

using jointid::test::two_pi;

joints::Joint make(std::string name, int node, int node_b, std::vector<Term> terms,
                   std::vector<double> values) {
  joints::Joint j{std::move(name),   node, node_b, Dof::uy, std::move(terms),
                  std::move(values), {},   {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

using PaperCantilever = test::SynthesisedCantilever;

} // namespace

TEST(HarmonicBalance, LinearJointToGroundEqualsTheExactSolution) {
  // g = k y + c ẏ at the tip: X_tip = H_tt F / (1 + H_tt (k + iωc)), and any other output
  // X_o = H_ot F / (1 + H_tt (k + iωc)), with F = −i F0 for F0 sin ωt. The problem is linear, so
  // Newton converges to its 1e-12 residual tolerance in a couple of steps: 1e-10 asserted.
  const PaperCantilever c;
  const double k = 4800.0, cv = 20.0, F0 = 80.0;
  const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k, Term::c}, {k, cv})};
  const std::vector<int> outputs{c.eq(7), c.eq(4)};
  const std::vector<int> tip{c.eq(7)};
  for (double f : {1.0, 3.0, 19.0}) {
    const double w = two_pi * f;
    const frf::HarmonicBalanceResult r =
        frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs);
    ASSERT_TRUE(r.status.ok()) << f;
    const Complex Htt = c.H.receptance(w, tip, tip)(0, 0);
    const Complex Hmt = c.H.receptance(w, std::vector<int>{c.eq(4)}, tip)(0, 0);
    const Complex denominator = 1.0 + Htt * Complex(k, w * cv);
    const Complex X_tip = Htt * Complex(0.0, -F0) / denominator;
    const Complex X_mid = Hmt * Complex(0.0, -F0) / denominator;
    EXPECT_LE(std::abs(r.X(1, 0) - X_tip), 1e-10 * std::abs(X_tip)) << f;
    EXPECT_LE(std::abs(r.X(1, 1) - X_mid), 1e-10 * std::abs(X_tip)) << f;
    EXPECT_LE(std::abs(r.Y(1, 0) - X_tip), 1e-10 * std::abs(X_tip)) << f;
    // A linear system responds at the excitation frequency only.
    for (int h = 0; h < r.X.rows(); ++h) {
      if (h == 1) continue;
      EXPECT_LE(std::abs(r.X(h, 0)), 1e-10 * std::abs(X_tip)) << "harmonic " << h;
    }
  }
}

TEST(HarmonicBalance, LinearJointBetweenNodesEqualsTheDirectSolveOfTheJoinedStructure) {
  // A joint between nodes 3 and 6 with g = k y + c ẏ is a spring and a dashpot between them:
  // solving (K + kbbᵀ − ω²M + iω(C + cbbᵀ)) X = F directly (UMFPACK) is an independent route.
  // Modal synthesis and the direct solve agree to ≈1e-10 for this model (see receptance tests),
  // so 1e-8 relative.
  const PaperCantilever c;
  const double k = 2e5, cv = 150.0, F0 = 40.0, f = 7.5, w = two_pi * f;
  const std::vector<joints::Joint> js{make("link", 3, 6, {Term::k, Term::c}, {k, cv})};
  const std::vector<int> outputs{c.eq(7), c.eq(3), c.eq(6)};
  const frf::HarmonicBalanceResult r =
      frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs);
  ASSERT_TRUE(r.status.ok());

  fem::Model joined = c.model;
  joined.springs.push_back({3, 6, Dof::uy, k});
  const fem::Assembled s = fem::assemble(joined);
  fem::SparseMatrix C = fem::damping_matrix(c.system, c.model.damping, &c.modes);
  const int a = c.eq(3), b = c.eq(6);
  C.coeffRef(a, a) += cv;
  C.coeffRef(b, b) += cv;
  C.coeffRef(a, b) -= cv;
  C.coeffRef(b, a) -= cv;
  const std::vector<int> force{c.eq(7)};
  const frf::CMatrix H = frf::direct_receptance(s, C, w, outputs, force).value;
  for (int o = 0; o < 3; ++o) {
    const Complex expected = H(o, 0) * Complex(0.0, -F0);
    EXPECT_LE(std::abs(r.X(1, o) - expected), 1e-8 * std::abs(H(0, 0) * F0)) << "output " << o;
  }
  EXPECT_LE(std::abs(r.Y(1, 0) - (r.X(1, 1) - r.X(1, 2))), 1e-12 * std::abs(r.X(1, 0)));
}

TEST(HarmonicBalance, CubicJointAgreesWithTimeIntegration) {
  // The paper's cantilever with k3 = 1.6e8 N/m³ from the tip to ground, 80 N at 3 Hz (at the
  // first resonance, so the hardening matters: the third harmonic is ≈7 % of the first).
  // Time integration (average acceleration, 4096 steps per period) is an independent method;
  // its error is the period error (ωh)²/12 ≈ 2e-7 amplified by the response's sensitivity to
  // frequency, ≤ 1/(2ζ) = 50 near resonance: ≲ 1e-5 for the fundamental, and (3ωh)²/12 · 50 ≈
  // 1e-4 relative for the third harmonic. HB with 9 harmonics neglects |X_11| ≈ 2e-6 |X_1|,
  // which enters the low harmonics only through the cubic's products (≲ 1e-8 |X_1|).
  // The remaining difference must be the integrator's O(h²): halving the steps multiplies
  // it by ≈ 4.
  const PaperCantilever c;
  const double F0 = 80.0, f = 3.0, w = two_pi * f;
  const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k3}, {1.6e8})};
  const std::vector<int> outputs{c.eq(7)};
  const frf::HarmonicBalanceResult hb =
      frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs);
  ASSERT_TRUE(hb.status.ok());
  const Complex X1 = hb.X(1, 0), X3 = hb.X(3, 0);
  ASSERT_GT(std::abs(X3), 0.01 * std::abs(X1)); // genuinely non-linear

  const fem::SparseMatrix C = fem::damping_matrix(c.system, c.model.damping, &c.modes);
  const joints::JointForces forces(js, c.system.dofs);
  auto integrate = [&](int steps) {
    fem::SteadyStateOptions o;
    o.steps_per_period = steps;
    o.output_periods = 1;
    o.tolerance = 1e-9; // transient left ≈ 1e-9 / (1 − e^{−2πζ}) ≈ 2e-8 relative
    const fem::SteadyState s =
        fem::steady_state(c.system, C, &forces, {c.eq(7), F0, f}, outputs, o);
    EXPECT_TRUE(s.status.ok());
    return s;
  };
  const fem::SteadyState fine = integrate(4096);
  const Complex T1 = harmonic(fine.u.col(0), fine.t, w, 1),
                T3 = harmonic(fine.u.col(0), fine.t, w, 3);
  const double error1 = std::abs(T1 - X1) / std::abs(X1);
  EXPECT_LT(error1, 1e-5);
  EXPECT_LT(std::abs(T3 - X3) / std::abs(X3), 1e-4);
  // Odd joint law, symmetric structure: no even harmonics (up to the transient left).
  for (int k : {0, 2}) {
    EXPECT_LT(std::abs(harmonic(fine.u.col(0), fine.t, w, k)), 1e-7 * std::abs(X1)) << k;
  }
  // The time signals agree, displacement and velocity (reconstructed from the harmonics).
  double du = 0.0, dv = 0.0;
  for (Eigen::Index i = 0; i < fine.t.size(); ++i) {
    du = std::max(du, std::abs(fine.u(i, 0) - hb.displacement(0, fine.t(i))));
    dv = std::max(dv, std::abs(fine.v(i, 0) - hb.velocity(0, fine.t(i))));
  }
  // Here the HB side dominates: it omits harmonics 11, 13, … With the odd harmonics falling
  // by q = |X9/X7| ≈ 1/12 per step, |X11| ≈ q|X9| ≈ 2e-6 |X1| — the displacement difference —
  // and the velocity weights it by 11: ≈ 2e-5 ω|X1|. Asserted with a factor 5.
  EXPECT_LT(du, 1e-5 * std::abs(X1));
  EXPECT_LT(dv, 1e-4 * w * std::abs(X1));

  const fem::SteadyState coarse = integrate(2048);
  const double error1_coarse =
      std::abs(harmonic(coarse.u.col(0), coarse.t, w, 1) - X1) / std::abs(X1);
  EXPECT_GT(error1_coarse / error1, 3.0);
  EXPECT_LT(error1_coarse / error1, 5.0);
}

TEST(HarmonicBalance, NonConvergenceSaysWhy) {
  // Two Newton iterations cannot solve the strongly non-linear k3 case at 80 N, 3 Hz (it takes
  // ≈ 8): the result is marked not converged, with the residual reached and how the solve went.
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k3}, {1.6e8})};
  frf::HarmonicBalanceOptions o;
  o.max_iterations = 2;
  o.continuation_steps = 2;
  const frf::HarmonicBalanceResult r = frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 80.0,
                                                             3.0, std::vector<int>{c.eq(7)}, o);
  ASSERT_FALSE(r.status.ok());
  EXPECT_GT(r.residual, o.tolerance);
  EXPECT_NE(r.status.reason.find("no convergence: relative residual"), std::string::npos)
      << r.status.reason;
  EXPECT_NE(r.status.reason.find("from the linear response"), std::string::npos) << r.status.reason;
  EXPECT_NE(r.status.reason.find("of 2"), std::string::npos) << r.status.reason;
  const frf::HarmonicBalanceResult ok =
      frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 80.0, 3.0, std::vector<int>{c.eq(7)});
  ASSERT_TRUE(ok.status.ok());
  EXPECT_TRUE(ok.status.reason.empty());
}

TEST(HarmonicBalance, BadOptionsThrow) {
  const PaperCantilever c;
  const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k3}, {1.6e8})};
  const std::vector<int> outputs{c.eq(7)};
  frf::HarmonicBalanceOptions o;
  o.harmonics = 0;
  EXPECT_THROW(frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 1.0, 3.0, outputs, o),
               std::invalid_argument);
  EXPECT_THROW(frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 1.0, 0.0, outputs),
               std::invalid_argument);
  o = {};
  o.friction_width = 0.0;
  EXPECT_THROW(frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 1.0, 3.0, outputs, o),
               std::invalid_argument);
}

namespace {

// A steady state of the FE model with its joints by time integration (Newmark, exact
// stick–slip), the last `periods` periods at the tip.
fem::SteadyState integrate(const PaperCantilever& c, const std::vector<joints::Joint>& js,
                           double F0, double f, int steps, int periods = 1) {
  const fem::SparseMatrix C = fem::damping_matrix(c.system, c.model.damping, &c.modes);
  const joints::JointForces forces(js, c.system.dofs);
  fem::SteadyStateOptions o;
  o.steps_per_period = steps;
  o.output_periods = periods;
  const std::vector<int> outputs{c.eq(7)};
  const fem::SteadyState s = fem::steady_state(c.system, C, &forces, {c.eq(7), F0, f}, outputs, o);
  EXPECT_TRUE(s.status.ok());
  return s;
}

} // namespace

TEST(HarmonicBalance, EvenTermAgreesWithTimeIntegration) {
  // k y + c ẏ + k2 y² at the tip, 40 N at 3 Hz: the even term makes a mean (harmonic 0, ≈ 2 %
  // of |X1|) and harmonic 2 (≈ 1.7 % of |X1|); no other test has an even term. Time
  // integration (Newmark, 2048 steps a period) is independent. Its period error (ωh)²/12 =
  // 7.8e-7, amplified near resonance by ≤ 1/(2ζ) ≈ 12, gives ≲ 1e-5 on X1; X0 and X2 are driven
  // by X1² (twice X1's relative error) plus their own period error (4 × 7.8e-7 at 2ω, not
  // resonant): bound 3e-5 relative for X0, X1, X2 (measured 3.3e-6, 1.7e-6, 9.9e-6). A mean
  // joint force off by a factor 2 moves X0 by ≈ 100 %. Harmonic balance with 9 harmonics
  // neglects |X10| ~ (|X2|/|X1|)^9 |X1|: nothing. The difference must be the integrator's
  // O(h²): halving the step divides it by 4 (asserted within 3 … 5).
  const PaperCantilever c;
  const double F0 = 40.0, f = 3.0, w = two_pi * f;
  const std::vector<joints::Joint> js{
      make("tip", 7, 0, {Term::k, Term::c, Term::k2}, {4800.0, 20.0, 5e4})};
  const std::vector<int> outputs{c.eq(7)};
  const frf::HarmonicBalanceResult hb =
      frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs);
  ASSERT_TRUE(hb.status.ok());
  ASSERT_GT(std::abs(hb.X(0, 0)), 0.01 * std::abs(hb.X(1, 0))); // the even term matters
  ASSERT_GT(std::abs(hb.X(2, 0)), 0.01 * std::abs(hb.X(1, 0)));
  // The mean is a static deflection against the joint: the joint pulls towards −y (k2 > 0).
  EXPECT_LT(hb.X(0, 0).real(), 0.0);
  EXPECT_NEAR(hb.Y(0, 0).real(), hb.X(0, 0).real(), 1e-12 * std::abs(hb.X(1, 0)));

  const fem::SteadyState fine = integrate(c, js, F0, f, 2048);
  const fem::SteadyState finer = integrate(c, js, F0, f, 4096);
  for (int k : {0, 1, 2}) {
    const Complex X = hb.X(k, 0);
    const double e = std::abs(harmonic(fine.u.col(0), fine.t, w, k) - X) / std::abs(X);
    const double e_finer = std::abs(harmonic(finer.u.col(0), finer.t, w, k) - X) / std::abs(X);
    EXPECT_LT(e, 3e-5) << "harmonic " << k;
    EXPECT_GT(e / e_finer, 3.0) << "harmonic " << k;
    EXPECT_LT(e / e_finer, 5.0) << "harmonic " << k;
  }
  // The joint force's harmonics: G = k Y + iωc Y + k2 (y²)_k, with (y²)_0 = |Y1|²/2 + … by
  // Parseval: G_0 = k Y_0 + k2 (Y_0² + ½ Σ_{k≥1} |Y_k|²).
  double mean_square = std::norm(hb.Y(0, 0));
  for (int k = 1; k < hb.Y.rows(); ++k)
    mean_square += 0.5 * std::norm(hb.Y(k, 0));
  EXPECT_NEAR(hb.G(0, 0).real(), 4800.0 * hb.Y(0, 0).real() + 5e4 * mean_square,
              1e-9 * std::abs(hb.G(1, 0)));
}

TEST(HarmonicBalance, ExactFrictionConvergesTowardsTimeIntegration) {
  // k y + c ẏ + fc sign(ẏ) (fc = 3 N) at the tip against time integration with exact
  // stick–slip (4096 steps a period; its own error, measured against 32768 steps, is ≤ 1.3e-5
  // of |X1| for these tests). The friction force jumps by 2 fc at each reversal, so its
  // harmonics decay like 1/k and the harmonic balance converges slowly in K, roughly like 1/K
  // where the joint slides; a stick phase shorter than a period over K is not resolved at all.
  // Measured relative error of the fundamental (K = 15 → 31 → 63):
  //   80 N, 5 Hz (always sliding):           2.1e-4 → 8.9e-5 → 5.7e-5
  //   80 N, 2.5 Hz (sticks 0.12 % a period):  1.5e-4 → 1.7e-4 → 1.4e-4 (the 1.2 ms stick needs
  //                                            K ≳ 800: no fall yet, so none is asserted)
  //   10 N, 3 Hz (sticks 1.5 % a period):     1.8e-2 → 1.1e-2 → 5.4e-3
  // Bounds: about 1.6 × the measured error, and a fall by at least 25 % from K = 15 to 31 where
  // the stick phase (if any) is resolved.
  const PaperCantilever c;
  const std::vector<joints::Joint> js{
      make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0})};
  const std::vector<int> outputs{c.eq(7)};
  struct Case {
    double F0, f, bound15, bound31;
    bool falls;
    double bound_tanh;
  };
  for (const Case& t :
       {Case{80.0, 5.0, 3.5e-4, 1.5e-4, true, 4e-4}, Case{80.0, 2.5, 2.5e-4, 2.8e-4, false, 1e-3},
        Case{10.0, 3.0, 3e-2, 1.7e-2, true, 1.3e-2}}) {
    SCOPED_TRACE(std::to_string(t.F0) + " N at " + std::to_string(t.f) + " Hz");
    const double w = two_pi * t.f;
    const fem::SteadyState s = integrate(c, js, t.F0, t.f, 4096);
    const Complex T1 = harmonic(s.u.col(0), s.t, w, 1);
    double error[2];
    for (int i = 0; i < 2; ++i) {
      frf::HarmonicBalanceOptions o;
      o.harmonics = i == 0 ? 15 : 31;
      const frf::HarmonicBalanceResult hb =
          frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), t.F0, t.f, outputs, o);
      ASSERT_TRUE(hb.status.ok()) << "K = " << o.harmonics;
      error[i] = std::abs(hb.X(1, 0) - T1) / std::abs(T1);
      // The joint force obeys the friction law: |G − k Y − c Ẏ| ≤ fc in the time domain, so
      // each harmonic of the friction part is at most 2 fc... its fundamental at most 4 fc/π
      // (a square wave, reached when always sliding).
      const Complex friction1 = hb.G(1, 0) - Complex(4800.0, w * 20.0) * hb.Y(1, 0);
      EXPECT_LE(std::abs(friction1), 4.0 * 3.0 / std::numbers::pi * (1.0 + 1e-9));
      EXPECT_GT(std::abs(friction1), 0.5 * 4.0 * 3.0 / std::numbers::pi);
    }
    EXPECT_LT(error[0], t.bound15);
    EXPECT_LT(error[1], t.bound31);
    if (t.falls) {
      EXPECT_LT(error[1], 0.75 * error[0]);
    }
    // Regularised friction (exact_friction = false, tanh(ẏ/1e-4 m/s)) still converges, with an
    // error of the same kind (measured at K = 15: 2.6e-4, 6.2e-4, 7.9e-3; bounds 1.6 × that).
    frf::HarmonicBalanceOptions o;
    o.harmonics = 15;
    o.exact_friction = false;
    const frf::HarmonicBalanceResult hb =
        frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), t.F0, t.f, outputs, o);
    ASSERT_TRUE(hb.status.ok());
    EXPECT_LT(std::abs(hb.X(1, 0) - T1) / std::abs(T1), t.bound_tanh);
  }
}

TEST(HarmonicBalance, HalfWaveSymmetricSolveEqualsTheFullOne) {
  // With odd joint laws and a sine force the steady state is half-wave symmetric; solving the
  // odd harmonics on half a period (the default) must give what all harmonics over the whole
  // period give: the same Newton iterates (the full solve's even harmonics stay at rounding
  // from the default start), hence the same iterations and the same solution to the 1e-12
  // residual (1e-10 of |X1| asserted, as for a reused problem), with the even harmonics
  // exactly 0. Cases: a hardening cubic near resonance, model I (quadratic damping c2 too),
  // exact friction with sticking (10 N at 3 Hz) and a second joint between nodes.
  const PaperCantilever c;
  const std::vector<int> outputs{c.eq(7), c.eq(5)};
  struct Case {
    const char* name;
    std::vector<joints::Joint> joints;
    double F0, f;
  };
  const std::vector<Case> cases{
      {"k + c + k3",
       {make("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})},
       80.0,
       4.0},
      {"model I",
       {make("tip", 7, 0, {Term::k, Term::c, Term::c2, Term::k3}, {4800.0, 20.0, 500.0, 1.6e8})},
       80.0,
       19.0},
      {"friction and a joint between nodes",
       {make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0}),
        make("mid", 4, 5, {Term::k, Term::k3}, {2e5, 1e9})},
       10.0,
       3.0}};
  for (const Case& t : cases) {
    SCOPED_TRACE(t.name);
    frf::HarmonicBalanceOptions half, full;
    half.harmonics = full.harmonics = 11;
    full.half_wave_symmetry = false;
    const frf::HarmonicBalanceResult a =
        frf::harmonic_balance(c.H, t.joints, c.system.dofs, c.eq(7), t.F0, t.f, outputs, half);
    const frf::HarmonicBalanceResult b =
        frf::harmonic_balance(c.H, t.joints, c.system.dofs, c.eq(7), t.F0, t.f, outputs, full);
    ASSERT_TRUE(a.status.ok()) << a.status.reason;
    ASSERT_TRUE(b.status.ok()) << b.status.reason;
    EXPECT_EQ(a.iterations, b.iterations);
    ASSERT_EQ(a.X.rows(), 12);
    const double scale = std::abs(b.X(1, 0));
    EXPECT_GT(std::abs(b.X(3, 0)), 1e-4 * scale); // non-linear enough to matter
    EXPECT_LE((a.X - b.X).cwiseAbs().maxCoeff(), 1e-10 * scale);
    EXPECT_LE((a.Y - b.Y).cwiseAbs().maxCoeff(), 1e-10 * scale);
    EXPECT_LE((a.G - b.G).cwiseAbs().maxCoeff(), 1e-10 * std::abs(b.G(1, 0)));
    for (int k = 0; k <= 11; k += 2) {
      EXPECT_EQ(a.X.row(k).cwiseAbs().maxCoeff(), 0.0) << "harmonic " << k;
      EXPECT_EQ(a.G.row(k).cwiseAbs().maxCoeff(), 0.0) << "harmonic " << k;
      EXPECT_LT(b.X.row(k).cwiseAbs().maxCoeff(), 1e-12 * scale) << "harmonic " << k;
    }
  }
  // A mean force breaks the symmetry: all harmonics are solved. 30 N static plus 80 N at 4 Hz
  // on the cubic: the mean shifts the operating point, so the cubic makes harmonic 2 (against
  // the exact 0 a symmetric solve would give) and the mean deflection follows the static force.
  const std::vector<joints::Joint> cubic{
      make("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8})};
  frf::HarmonicBalanceOptions o;
  const frf::HarmonicBalance problem(c.H, cubic, c.system.dofs, {c.eq(7)}, outputs, 4.0, o);
  Eigen::MatrixXcd F = frf::sine_force(80.0);
  F(0, 0) = 30.0;
  const frf::HarmonicBalanceResult m = problem.solve(cubic, F);
  ASSERT_TRUE(m.status.ok()) << m.status.reason;
  EXPECT_GT(m.X(0, 0).real(), 0.0);
  EXPECT_GT(std::abs(m.X(2, 0)), 1e-3 * std::abs(m.X(1, 0)));
  EXPECT_GT(std::abs(m.G(2, 0)), 1e-3 * std::abs(m.G(1, 0)));
}

TEST(HarmonicBalance, ProblemIsReusableForManyValuesAndLevels) {
  // One HarmonicBalance (receptances at the harmonics computed once) solved for several joint
  // values and force levels gives what separate harmonic_balance() calls give: the same
  // equations from the same start, so agreement to the solver's 1e-12 residual (1e-10 of |X1|
  // asserted, amplified by the conditioning of the joined structure).
  const PaperCantilever c;
  const double f = 3.5;
  frf::HarmonicBalanceOptions o;
  o.harmonics = 11;
  const std::vector<int> outputs{c.eq(7), c.eq(4)};
  auto joint = [](double k3, double fc) {
    return std::vector<joints::Joint>{
        make("tip", 7, 0, {Term::k, Term::c, Term::fc, Term::k3}, {4800.0, 20.0, fc, k3})};
  };
  const frf::HarmonicBalance problem(c.H, joint(1.6e8, 3.0), c.system.dofs, {c.eq(7)}, outputs, f,
                                     o);
  for (double k3 : {1.6e8, 4e7})
    for (double fc : {3.0, 0.5})
      for (double F0 : {20.0, 80.0}) {
        SCOPED_TRACE("k3 " + std::to_string(k3) + " fc " + std::to_string(fc) + " F0 " +
                     std::to_string(F0));
        const frf::HarmonicBalanceResult a = problem.solve(joint(k3, fc), frf::sine_force(F0));
        const frf::HarmonicBalanceResult b =
            frf::harmonic_balance(c.H, joint(k3, fc), c.system.dofs, c.eq(7), F0, f, outputs, o);
        ASSERT_TRUE(a.status.ok());
        ASSERT_TRUE(b.status.ok());
        const double scale = std::abs(b.X(1, 0));
        EXPECT_LE((a.X - b.X).cwiseAbs().maxCoeff(), 1e-10 * scale);
        EXPECT_LE((a.Y - b.Y).cwiseAbs().maxCoeff(), 1e-10 * scale);
        EXPECT_LE((a.G - b.G).cwiseAbs().maxCoeff(), 1e-10 * std::abs(b.G(1, 0)));
      }
  // A start: the solution itself is accepted at once; another level's solution leads to the
  // same solution as the default start (Newton's 1e-12 residual: 1e-9 of |X1|).
  const frf::HarmonicBalanceResult cold = problem.solve(joint(1.6e8, 3.0), frf::sine_force(80.0));
  const frf::HarmonicBalanceResult again =
      problem.solve(joint(1.6e8, 3.0), frf::sine_force(80.0), &cold.Y);
  ASSERT_TRUE(again.status.ok());
  EXPECT_LE(again.iterations, 2);
  EXPECT_LE((again.X - cold.X).cwiseAbs().maxCoeff(), 1e-9 * std::abs(cold.X(1, 0)));
  const frf::HarmonicBalanceResult low = problem.solve(joint(1.6e8, 3.0), frf::sine_force(60.0));
  const frf::HarmonicBalanceResult warm =
      problem.solve(joint(1.6e8, 3.0), frf::sine_force(80.0), &low.Y);
  ASSERT_TRUE(warm.status.ok());
  EXPECT_LE((warm.X - cold.X).cwiseAbs().maxCoeff(), 1e-9 * std::abs(cold.X(1, 0)));
  const Eigen::MatrixXcd wrong_shape = Eigen::MatrixXcd::Zero(3, 1);
  EXPECT_THROW(problem.solve(joint(1.6e8, 3.0), frf::sine_force(80.0), &wrong_shape),
               std::invalid_argument);
  // A joint elsewhere than the layout, and a friction limit that gives energy, are refused.
  std::vector<joints::Joint> moved = joint(1.6e8, 3.0);
  moved[0].node = 6;
  EXPECT_THROW(problem.solve(moved, frf::sine_force(80.0)), std::invalid_argument);
  try {
    problem.solve(joint(1.6e8, -1.0), frf::sine_force(80.0));
    FAIL() << "negative fc accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fc"), std::string::npos) << e.what();
  }
}

TEST(HarmonicBalance, RegularisedFrictionFollowsItsLaw) {
  // exact_friction = false: the joint force is k y + c ẏ + fc tanh(ẏ/width). With a wide
  // width (0.1 m/s against a velocity amplitude ≈ 0.5 m/s) the law is smooth, its harmonics
  // decay exponentially, and the 256-sample AFT is exact to rounding; so the solution's force
  // harmonics G must equal those of the law evaluated independently on the solution's own
  // motion, finely sampled (4096 samples): 1e-10 of |G1|. (Accuracy against time integration
  // with the narrow default width is asserted above.)
  const PaperCantilever c;
  const double fc = 3.0, width = 0.1, f = 5.0, w = two_pi * f;
  const std::vector<joints::Joint> js{
      make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, fc})};
  const std::vector<int> outputs{c.eq(7)};
  frf::HarmonicBalanceOptions o;
  o.harmonics = 15;
  o.exact_friction = false;
  o.friction_width = width;
  const frf::HarmonicBalanceResult hb =
      frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), 80.0, f, outputs, o);
  ASSERT_TRUE(hb.status.ok());
  const int N = 4096;
  Eigen::VectorXd t(N), g(N);
  for (int n = 0; n < N; ++n) {
    t(n) = n / (f * N);
    const double y = hb.displacement(0, t(n)), v = hb.velocity(0, t(n));
    g(n) = 4800.0 * y + 20.0 * v + fc * std::tanh(v / width);
  }
  for (int k = 0; k <= 15; ++k)
    EXPECT_LE(std::abs(harmonic(g, t, w, k) - hb.G(k, 0)), 1e-10 * std::abs(hb.G(1, 0)))
        << "harmonic " << k;
  // Odd law: no even harmonics.
  EXPECT_LE(std::abs(hb.G(2, 0)), 1e-10 * std::abs(hb.G(1, 0)));
  // A negative fc is only refused when friction is exact (regularised, it is a coefficient).
  std::vector<joints::Joint> negative = js;
  negative[0].values[2] = -1.0;
  EXPECT_NO_THROW(
      frf::harmonic_balance(c.H, negative, c.system.dofs, c.eq(7), 80.0, f, outputs, o));
  o.exact_friction = true;
  EXPECT_THROW(frf::harmonic_balance(c.H, negative, c.system.dofs, c.eq(7), 80.0, f, outputs, o),
               std::invalid_argument);
}

// The Newton steps' small LU (frf/hb_equations.hpp): the solution of a system that needs row
// exchanges equals Eigen's to rounding, real and complex, and a singular matrix shows in its
// least pivot (Newton then takes the least-norm step).
TEST(HarmonicBalance, SmallLUSolvesLikeEigensAndShowsASingularMatrix) {
  std::srand(7);
  for (const int n : {1, 3, 11, 30}) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
    A(0, 0) = 0.0; // row exchange needed at the first column
    const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
    frf::detail::SmallLU<double> lu;
    lu.compute(A);
    Eigen::VectorXd x = b;
    lu.solve_in_place(x);
    const Eigen::VectorXd reference = A.partialPivLu().solve(b);
    if (n == 1) { // a 1 × 1 zero: singular, nothing to solve
      EXPECT_EQ(lu.min_pivot, 0.0);
      continue;
    }
    EXPECT_GT(lu.min_pivot, 0.0);
    EXPECT_LT((x - reference).norm(), 1e-12 * reference.norm()) << "n = " << n;
    EXPECT_LT((A * x - b).norm(), 1e-12 * A.norm() * x.norm()) << "n = " << n;
  }
  const Eigen::MatrixXcd C = Eigen::MatrixXcd::Random(4, 4);
  const Eigen::VectorXcd c = Eigen::VectorXcd::Random(4);
  frf::detail::SmallLU<Complex> clu;
  clu.compute(C);
  Eigen::VectorXcd y = c;
  clu.solve_in_place(y);
  EXPECT_LT((C * y - c).norm(), 1e-12 * C.norm() * y.norm());
  // Rank 5 of 6: the least pivot is at rounding level against the matrix's size.
  const Eigen::MatrixXd U = Eigen::MatrixXd::Random(6, 5), V = Eigen::MatrixXd::Random(5, 6);
  frf::detail::SmallLU<double> singular;
  singular.compute(U * V);
  EXPECT_LT(singular.min_pivot, 1e-13 * (U * V).lpNorm<Eigen::Infinity>());
}

TEST(HarmonicBalance, AnAsymmetricStartFindsTheSymmetryBreakingSteadyState) {
  // The paper's cantilever with k + c + k3 at the tip (4700 N/m, 43 N·s/m, 1.62e8 N/m³), 100 N
  // at 3 Hz: the half-wave symmetric steady state exists but is unstable (largest Floquet
  // multiplier 1.011, measured), and a pair of mirror-image asymmetric ones, x(t) and
  // −x(t + T/2), with a mean and even harmonics (|X0| 3 %, |X2| 11 % of |X1|), is stable (0.973).
  // From the default start the solve stays symmetric; from a start with even harmonics it must
  // solve all harmonics (the symmetric subspace cannot hold the answer) and find the asymmetric
  // one, as a solve with half_wave_symmetry off does. Time integration from rest (independent)
  // settles on one of the pair: its harmonics equal the solution's, or the mirror's (−X_k for even
  // k), to the integrator's O(h²) error: (ωh)²/12 = 7.8e-7 at 2048 steps a period, amplified near
  // the bifurcation (the asymmetry is sensitive to the frequency): measured 5.1e-5 of |X1| over
  // harmonics 0 … 3 (1.3e-5 at 4096 steps); bound 1e-4, and the error quartered at 4096 steps
  // (3 … 5).
  const PaperCantilever c;
  const std::vector<int> outputs{c.eq(7)};
  const std::vector<joints::Joint> js{
      make("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4700.0, 43.0, 1.62e8})};
  const double f = 3.0, F0 = 100.0, w = two_pi * f;
  frf::HarmonicBalanceOptions o, full;
  o.harmonics = full.harmonics = 15;
  full.half_wave_symmetry = false;
  const frf::HarmonicBalance problem(c.H, js, c.system.dofs, {c.eq(7)}, outputs, f, o);
  const frf::HarmonicBalance all(c.H, js, c.system.dofs, {c.eq(7)}, outputs, f, full);
  const frf::HarmonicBalanceResult sym = problem.solve(js, frf::sine_force(F0));
  ASSERT_TRUE(sym.status.ok()) << sym.status.reason;
  EXPECT_EQ(sym.X(0, 0), 0.0);
  EXPECT_EQ(sym.X(2, 0), 0.0);
  Eigen::MatrixXcd start = sym.Y;
  start(0, 0) = 0.03 * std::abs(sym.Y(1, 0));
  start(2, 0) = 0.09 * std::abs(sym.Y(1, 0));
  const frf::HarmonicBalanceResult asym = problem.solve(js, frf::sine_force(F0), &start);
  const frf::HarmonicBalanceResult reference = all.solve(js, frf::sine_force(F0), &start);
  ASSERT_TRUE(asym.status.ok()) << asym.status.reason;
  ASSERT_TRUE(reference.status.ok()) << reference.status.reason;
  const double X1 = std::abs(asym.X(1, 0));
  EXPECT_GT(std::abs(asym.X(0, 0)), 0.01 * X1);
  EXPECT_GT(std::abs(asym.X(2, 0)), 0.05 * X1);
  EXPECT_LE((asym.X - reference.X).cwiseAbs().maxCoeff(), 1e-10 * X1);
  const frf::Stability s_sym = frf::floquet_stability(c.H, js, c.system.dofs, sym, o);
  const frf::Stability s_asym = frf::floquet_stability(c.H, js, c.system.dofs, asym, o);
  ASSERT_TRUE(s_sym.stable.has_value() && s_asym.stable.has_value());
  EXPECT_FALSE(*s_sym.stable);
  EXPECT_TRUE(*s_asym.stable);

  double error[2];
  for (int i = 0; i < 2; ++i) {
    const fem::SteadyState s = integrate(c, js, F0, f, i == 0 ? 2048 : 4096);
    const double mirror =
        harmonic(s.u.col(0), s.t, w, 0).real() * asym.X(0, 0).real() < 0.0 ? -1.0 : 1.0;
    error[i] = 0.0;
    for (int k = 0; k <= 3; ++k) {
      const Complex X = (k % 2 == 0 ? mirror : 1.0) * asym.X(k, 0);
      error[i] = std::max(error[i], std::abs(harmonic(s.u.col(0), s.t, w, k) - X) / X1);
    }
  }
  EXPECT_LT(error[0], 1e-4);
  EXPECT_GT(error[0] / error[1], 3.0);
  EXPECT_LT(error[0] / error[1], 5.0);
}

TEST(HarmonicBalance, ResidualSplitsByTheTermsDegree) {
  // Every term of the library is positively homogeneous, g(s y, s ẏ) = s^d g(y, ẏ); the first
  // guess's scaling relies on r(s z) = s z − pack(H_yf F) + Σ_d s^d h_d. Checked against the
  // residual itself at several s (rounding: 1e-13 of |r|), for every smooth term at once (k2
  // makes the problem non-symmetric: all harmonics) and for the odd ones (half-wave symmetric).
  // Friction unknowns or regularised friction have no such split: refused.
  const PaperCantilever c;
  const std::vector<int> outputs{c.eq(7)};
  for (const bool with_even : {true, false}) {
    SCOPED_TRACE(with_even ? "all terms" : "odd terms");
    std::vector<Term> terms{Term::k, Term::c, Term::k3, Term::c2, Term::c3};
    std::vector<double> values{4800.0, 20.0, 1.6e8, 500.0, 3e3};
    if (with_even) terms.push_back(Term::k2), values.push_back(5e4);
    const std::vector<joints::Joint> js{make("tip", 7, 0, terms, values),
                                        make("mid", 4, 5, {Term::k, Term::k3}, {2e5, 1e9})};
    frf::HarmonicBalanceOptions o;
    o.harmonics = 5;
    const frf::HarmonicBalance problem(c.H, js, c.system.dofs, {c.eq(7)}, outputs, 4.0, o);
    const auto P = problem.equations(js, frf::sine_force(80.0));
    ASSERT_EQ(P->symmetric(), !with_even);
    const Eigen::VectorXd z = problem.first_guess(*P, nullptr);
    Eigen::MatrixXd h;
    ASSERT_TRUE(P->homogeneous_parts(z, h));
    Eigen::VectorXd b(P->size());
    P->pack(P->HyF_F, b);
    for (const double s : {0.25, 1.0, 3.0}) {
      const Eigen::VectorXd r = P->residual(s * z, 1.0, nullptr);
      Eigen::VectorXd split = s * z - b;
      for (int d = 0; d <= 3; ++d)
        split += std::pow(s, d) * h.col(d);
      EXPECT_LE((r - split).norm(), 1e-13 * r.norm()) << "s = " << s;
    }
    EXPECT_GT(h.col(3).norm(), 0.01 * z.norm()); // the cubic terms matter at 80 N near resonance
    EXPECT_EQ(h.col(0).norm(), 0.0);             // no term of degree 0 but friction
  }
  const std::vector<joints::Joint> friction{
      make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0})};
  for (const bool exact : {true, false}) {
    frf::HarmonicBalanceOptions o;
    o.exact_friction = exact;
    const frf::HarmonicBalance problem(c.H, friction, c.system.dofs, {c.eq(7)}, outputs, 4.0, o);
    const auto P = problem.equations(friction, frf::sine_force(80.0));
    Eigen::MatrixXd h;
    EXPECT_FALSE(P->homogeneous_parts(problem.first_guess(*P, nullptr), h));
  }
}

namespace {

// A joint with the paper's k and c and one parametric term with its parameters (fixed).
joints::Joint parametric(Term term, std::vector<double> parameters) {
  joints::Joint j = make("tip", 7, 0, {Term::k, Term::c, term}, {4800.0, 20.0, 1.0});
  j.set_parameters(2, parameters);
  return j;
}

} // namespace

TEST(HarmonicBalance, ParametricTermsAgreeWithTimeIntegration) {
  // k y + c ẏ (the paper's 4800 N/m, 20 N s/m) and one parametric term at the tip, at the first
  // resonance (3 Hz): a Jenkins element and an Iwan (microslip, and macroslip), each solved with
  // its exact steady loop, and a clearance (contact beyond ±5 mm). Time integration (Newmark,
  // exact slider states and contact, from rest) is independent. The fundamentals must agree to
  //   tol = 2 · |X1|/F0 · 2L · (|X_K| K/2 + a (π/Nt)²/2) + 2 |T(2048) − T(1024)| / 3,
  // the harmonic balance's own error bounded through the structure's response to the joint
  // force (|X1|/F0) times the change of that force's fundamental under a change δy of the
  // deformation (at most 2 L max|δy|, L the term's largest slope: kt or kg). δy: the harmonics
  // beyond K (falling at least like k⁻² past the last one kept, odd ones only: their sum is at
  // most |X_K| K/2) and the peaks the AFT samples miss (a (1 − cos π/Nt)); doubled for the
  // aliasing of the force's harmonics of the same order. The integrator's error is its O(h²)
  // (Richardson from two step sizes, doubled). The time integration's mean may differ (sliders
  // left where the transient moved them, stuck since: their forces' mean only), so the
  // fundamentals are compared, and a term left out must not agree.
  const PaperCantilever c;
  struct Case {
    const char* name;
    joints::Joint joint;
    double F0, L;
  };
  const double f = 3.0, w = two_pi * f;
  const std::vector<Case> cases{
      {"jenkins", parametric(Term::jenkins, {1.0e4, 3.0}), 20.0, 1.0e4},
      {"iwan, microslip", parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}), 2.0, 1.0e4},
      {"iwan, macroslip", parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}), 20.0, 1.0e4},
      {"gap", parametric(Term::gap, {5e-3, 2e4}), 40.0, 2e4},
  };
  for (const Case& t : cases) {
    SCOPED_TRACE(t.name);
    const std::vector<joints::Joint> js{t.joint};
    frf::HarmonicBalanceOptions o;
    o.harmonics = 15;
    const frf::HarmonicBalanceResult hb = frf::harmonic_balance(
        c.H, js, c.system.dofs, c.eq(7), t.F0, f, std::vector<int>{c.eq(7)}, o);
    ASSERT_TRUE(hb.status.ok()) << hb.status.reason;
    const Complex X1 = hb.X(1, 0);
    const fem::SteadyState fine = integrate(c, js, t.F0, f, 2048),
                           coarse = integrate(c, js, t.F0, f, 1024);
    const Complex T1 = harmonic(fine.u.col(0), fine.t, w, 1),
                  T1_coarse = harmonic(coarse.u.col(0), coarse.t, w, 1);
    const int Nt = 16 * (o.harmonics + 1);
    const double a = std::abs(X1), XK = std::abs(hb.X(o.harmonics, 0));
    const double tol = 2.0 * a / t.F0 * 2.0 * t.L *
                           (XK * o.harmonics / 2.0 + a * std::pow(std::numbers::pi / Nt, 2) / 2.0) +
                       2.0 * std::abs(T1 - T1_coarse) / 3.0;
    EXPECT_LT(std::abs(X1 - T1), tol);
    EXPECT_LT(tol, 1e-2 * a); // a meaningful bound (the differences met: 4e-5 |X1| at most)
    // the term matters here: without it the response differs by far more than the bound
    const std::vector<joints::Joint> linear{make("tip", 7, 0, {Term::k, Term::c}, {4800.0, 20.0})};
    const frf::HarmonicBalanceResult without = frf::harmonic_balance(
        c.H, linear, c.system.dofs, c.eq(7), t.F0, f, std::vector<int>{c.eq(7)}, o);
    EXPECT_GT(std::abs(without.X(1, 0) - T1), 10.0 * tol);
  }
}

TEST(HarmonicBalance, HysteresisHalfWaveSymmetricSolveEqualsTheFullOne) {
  // The steady loop over half the period (y(t + T/2) = −y(t), the second half's samples the
  // first's negated) and over the whole period give one steady state: the exact derivative's
  // sign-turned entries included (else Newton would stall or converge slowly, not to 1e-12).
  const PaperCantilever c;
  const std::vector<joints::Joint> js{parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1})};
  frf::HarmonicBalanceOptions o;
  o.harmonics = 9;
  const frf::HarmonicBalanceResult half = frf::harmonic_balance(
      c.H, js, c.system.dofs, c.eq(7), 6.0, 3.0, std::vector<int>{c.eq(7)}, o);
  o.half_wave_symmetry = false;
  const frf::HarmonicBalanceResult full = frf::harmonic_balance(
      c.H, js, c.system.dofs, c.eq(7), 6.0, 3.0, std::vector<int>{c.eq(7)}, o);
  ASSERT_TRUE(half.status.ok() && full.status.ok());
  EXPECT_LE(half.iterations, 6);
  EXPECT_LE(full.iterations, 6);
  for (int k = 0; k <= o.harmonics; ++k)
    EXPECT_LE(std::abs(half.X(k, 0) - full.X(k, 0)), 1e-9 * std::abs(full.X(1, 0))) << k;
  // odd loop, odd load: no even harmonics, none in the full solve either
  EXPECT_LE(std::abs(full.X(2, 0)), 1e-9 * std::abs(full.X(1, 0)));
}

TEST(HarmonicBalance, ManyHarmonicsGiveTheSameEquationsByFftAsByTheTables) {
  // From Equations::fft_from unknowns a block, the transforms between samples and harmonics
  // (and the hysteretic loop's derivative) run by FFT instead of the tables: the same residual
  // and Jacobian to rounding (1e-12 of their size), for a Jenkins and an Iwan element, a gap
  // and a cubic stiffness with a velocity-squared damping (both of ∂g/∂y and ∂g/∂ẏ's weights),
  // half-wave symmetric and not, at 60 harmonics (121 and 60 unknowns a block), at the solution
  // at 40 N near resonance (the sliders slip, the gap is closed for part of the period), and off
  // it (1.3 times the solution).
  // (The dense Newton's route, tabulated: Equations::matrix_free_from out of reach.)
  const PaperCantilever c;
  const int saved = frf::detail::Equations::fft_from;
  const int saved_free = frf::detail::Equations::matrix_free_from;
  frf::detail::Equations::matrix_free_from = 1 << 30;
  joints::Joint smooth =
      make("tip", 7, 0, {Term::k, Term::c, Term::k3, Term::c2}, {4800.0, 20.0, 1.6e8, 500.0});
  for (const bool symmetric : {false, true})
    for (const auto& j :
         {parametric(Term::jenkins, {1.0e4, 3.0}), parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}),
          parametric(Term::gap, {5e-3, 2e4}), smooth}) {
      if (symmetric && j.term_index(Term::c2) >= 0) continue; // even in ẏ: not symmetric
      SCOPED_TRACE(std::string(symmetric ? "symmetric, " : "") +
                   std::string(joints::term_name(j.terms[2])));
      frf::detail::Equations::fft_from = saved;
      frf::HarmonicBalanceOptions o;
      o.harmonics = 60;
      o.half_wave_symmetry = symmetric;
      const std::vector<joints::Joint> js{j};
      const frf::HarmonicBalance problem(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7)}, 3.0, o);
      const frf::HarmonicBalanceResult solved = problem.solve(js, frf::sine_force(40.0));
      ASSERT_TRUE(solved.status.ok()) << solved.status.reason;
      const auto P = problem.equations(js, frf::sine_force(40.0));
      ASSERT_EQ(P->symmetric(), symmetric);
      Eigen::VectorXd z = Eigen::VectorXd::Zero(P->size());
      P->pack(solved.Y, z);
      Eigen::MatrixXd by_fft, by_table;
      frf::detail::Equations::fft_from = 1;
      const Eigen::VectorXd r_fft = P->residual(z, 1.0, &by_fft);
      frf::detail::Equations::fft_from = 1 << 30;
      const Eigen::VectorXd r_table = P->residual(z, 1.0, &by_table);
      frf::detail::Equations::fft_from = saved;
      EXPECT_LE((by_fft - by_table).norm(), 1e-12 * by_table.norm());
      // the residual at the solution is ~0: at a point off it as well
      EXPECT_LE((r_fft - r_table).norm(), 1e-12 * z.norm());
      const Eigen::VectorXd off = 1.3 * z;
      frf::detail::Equations::fft_from = 1;
      const Eigen::VectorXd o_fft = P->residual(off, 1.0, nullptr);
      frf::detail::Equations::fft_from = 1 << 30;
      const Eigen::VectorXd o_table = P->residual(off, 1.0, nullptr);
      frf::detail::Equations::fft_from = saved;
      EXPECT_GT(o_table.norm(), 1e-3 * off.norm());
      EXPECT_LE((o_fft - o_table).norm(), 1e-12 * o_table.norm());
      // the non-linear part is there: the elements slip (beyond fs / kt = 0.3 mm), the gap
      // closes (beyond 5 mm)
      EXPECT_GT(std::abs(solved.Y(1, 0)), j.term_index(Term::gap) >= 0 ? 5e-3 : 3e-4);
    }
  frf::detail::Equations::matrix_free_from = saved_free;
}

namespace {

// The joints of the matrix-free tests: each kind of force the Jacobian has (smooth with ∂g/∂y
// and ∂g/∂ẏ, a hysteretic loop, a gap, exact Coulomb friction), and two joints coupled through
// the structure, one of them with friction.
std::vector<std::pair<std::string, std::vector<joints::Joint>>> matrix_free_cases() {
  const joints::Joint smooth =
      make("tip", 7, 0, {Term::k, Term::c, Term::k3, Term::c2}, {4800.0, 20.0, 1.6e8, 500.0});
  return {{"cubic", {smooth}},
          {"jenkins", {parametric(Term::jenkins, {1.0e4, 3.0})}},
          {"iwan", {parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1})}},
          {"gap", {parametric(Term::gap, {5e-3, 2e4})}},
          {"friction", {make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 20.0, 3.0})}},
          {"two joints",
           {make("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8}),
            make("mid", 4, 0, {Term::k, Term::c, Term::fc}, {2.0e4, 10.0, 4.0})}}};
}

struct SavedRoutes {
  int fft = frf::detail::Equations::fft_from, free = frf::detail::Equations::matrix_free_from;
  ~SavedRoutes() {
    frf::detail::Equations::fft_from = fft, frf::detail::Equations::matrix_free_from = free;
  }
};

} // namespace

TEST(HarmonicBalance, TheMatrixFreeJacobianIsTheFormedOne) {
  // jacobian_times() (products by FFT from the residual's samples) against the Jacobian that
  // jacobian() forms, on random directions, at the steady state of 40 N at 3 Hz (the sliders
  // slip, the gap closes, the friction sticks and slips) and off it (1.3 times): equal to
  // rounding, 1e-12 of |J| |v|. And the line preconditioner: exact for linear joints (k, c):
  // preconditioned, J v comes back as v. (The dense route, so that jacobian() can form J.)
  const SavedRoutes saved;
  frf::detail::Equations::matrix_free_from = 1 << 30;
  const PaperCantilever c;
  for (const auto& [name, js] : matrix_free_cases()) {
    SCOPED_TRACE(name);
    frf::HarmonicBalanceOptions o;
    o.harmonics = 60;
    o.half_wave_symmetry = false;
    const frf::HarmonicBalance problem(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7)}, 3.0, o);
    const frf::HarmonicBalanceResult solved = problem.solve(js, frf::sine_force(40.0));
    ASSERT_TRUE(solved.status.ok()) << solved.status.reason;
    const auto P = problem.equations(js, frf::sine_force(40.0));
    ASSERT_TRUE(P->by_fft());
    Eigen::VectorXd z = problem.first_guess(*P, &solved.Y);
    for (const double scale : {1.0, 1.3}) {
      const Eigen::VectorXd at = scale * z;
      Eigen::MatrixXd J;
      P->residual(at, 1.0, &J);
      std::srand(7);
      for (int trial = 0; trial < 3; ++trial) {
        const Eigen::VectorXd v = Eigen::VectorXd::Random(P->size());
        Eigen::VectorXd Jv;
        P->jacobian_times(v, Jv);
        EXPECT_LE((Jv - J * v).norm(), 1e-12 * J.norm() * v.norm()) << scale;
      }
      // A matrix-free problem still forms J when asked (the continuation's), by its products.
      frf::detail::Equations::matrix_free_from = 1;
      const frf::HarmonicBalance free(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7)}, 3.0, o);
      const auto Pf = free.equations(js, frf::sine_force(40.0));
      frf::detail::Equations::matrix_free_from = 1 << 30;
      ASSERT_TRUE(Pf->matrix_free());
      Eigen::MatrixXd Jf;
      Pf->residual(at, 1.0, &Jf);
      EXPECT_LE((Jf - J).norm(), 1e-12 * J.norm()) << scale;
    }
  }
  const std::vector<joints::Joint> linear{make("tip", 7, 0, {Term::k, Term::c}, {4800.0, 20.0})};
  frf::HarmonicBalanceOptions o;
  o.harmonics = 60;
  const frf::HarmonicBalance problem(c.H, linear, c.system.dofs, {c.eq(7)}, {c.eq(7)}, 3.0, o);
  const auto P = problem.equations(linear, frf::sine_force(40.0));
  const Eigen::VectorXd z = problem.first_guess(*P, nullptr);
  P->residual(z, 1.0, nullptr);
  P->prepare_preconditioner();
  const Eigen::VectorXd v = Eigen::VectorXd::Random(P->size());
  Eigen::VectorXd Jv, back;
  P->jacobian_times(v, Jv);
  P->precondition(Jv, back);
  EXPECT_LE((back - v).norm(), 1e-12 * v.norm());
}

TEST(HarmonicBalance, NewtonKrylovSolvesAsTheDenseNewton) {
  // The matrix-free route (Equations::matrix_free_from lowered to every size, so that both run
  // at 60 harmonics) against the dense one: the same steady state, to the solves' tolerance
  // (1e-12 of |Y|: 1e-9 asserted), half-wave symmetric and not; and the same output
  // derivatives (implicit differentiation by GMRES to 1e-10 against the factorisation: 1e-7).
  const SavedRoutes saved;
  const PaperCantilever c;
  for (const bool symmetric : {false, true})
    for (const auto& [name, js] : matrix_free_cases()) {
      SCOPED_TRACE(name + std::string(symmetric ? ", symmetric" : ""));
      frf::HarmonicBalanceOptions o;
      o.harmonics = 60;
      o.half_wave_symmetry = symmetric;
      std::vector<frf::HarmonicBalanceResult> solved;
      std::vector<std::vector<Eigen::MatrixXcd>> derivatives;
      // k (a coefficient), and the third term's first parameter, or its value (k3: a
      // coefficient; fc: re-simulated equations)
      std::vector<std::vector<joints::Joint>> moved(2, js);
      std::vector<double> steps{js[0].values[0] * 1e-6};
      moved[0][0].values[0] += steps[0];
      if (js[0].has_parametric_terms()) {
        steps.push_back(js[0].parameters[2][0].value * 1e-6);
        moved[1][0].parameters[2][0].value += steps[1];
      } else {
        steps.push_back(js[0].values[2] * 1e-6);
        moved[1][0].values[2] += steps[1];
      }
      for (const bool free : {false, true}) {
        frf::detail::Equations::fft_from = 1;
        frf::detail::Equations::matrix_free_from = free ? 1 : 1 << 30;
        const frf::HarmonicBalance problem(c.H, js, c.system.dofs, {c.eq(7)}, {c.eq(7), c.eq(4)},
                                           3.0, o);
        ASSERT_EQ(problem.equations(js, frf::sine_force(40.0))->matrix_free(), free);
        solved.push_back(problem.solve(js, frf::sine_force(40.0)));
        ASSERT_TRUE(solved.back().status.ok()) << solved.back().status.reason;
        derivatives.push_back(
            problem.output_derivatives(js, frf::sine_force(40.0), solved.back().Y, moved, steps));
      }
      const auto& [dense, free] = std::pair{solved[0], solved[1]};
      EXPECT_LE((free.X - dense.X).norm(), 1e-9 * dense.X.norm());
      EXPECT_GT(dense.X.bottomRows(50).norm(), 1e-6 * dense.X.norm()); // harmonics are there
      ASSERT_EQ(derivatives[0].size(), 2u);
      ASSERT_EQ(derivatives[1].size(), 2u);
      for (std::size_t p = 0; p < 2; ++p) {
        if (derivatives[0][p].size() == 0) continue; // (a move the dense route re-simulates)
        ASSERT_EQ(derivatives[1][p].size(), derivatives[0][p].size());
        // (as changes of the outputs over the step: a derivative that is zero to rounding, the
        // kt of a Jenkins element in macroslip, compared at rounding level, 1e-13 of |X|)
        EXPECT_LE((derivatives[1][p] - derivatives[0][p]).norm() * steps[p],
                  1e-7 * derivatives[0][p].norm() * steps[p] + 1e-13 * dense.X.norm())
            << p;
      }
    }
}

TEST(HarmonicBalance, ParametricTermsOutOfRangeAreRefusedNamingTheKey) {
  const PaperCantilever c;
  joints::Joint j = parametric(Term::iwan, {3.0, 1.0e4, 0.5, 0.1});
  const std::string message = test::error_of([&] {
    frf::harmonic_balance(c.H, {j}, c.system.dofs, c.eq(7), 6.0, 3.0, std::vector<int>{c.eq(7)});
  });
  EXPECT_NE(message.find("'iwan.chi'"), std::string::npos) << message;
  EXPECT_NE(message.find("in (-1, 0]"), std::string::npos) << message;
  j.parameters[2][0].given = false; // fs not given
  const std::string missing = test::error_of([&] {
    frf::harmonic_balance(c.H, {j}, c.system.dofs, c.eq(7), 6.0, 3.0, std::vector<int>{c.eq(7)});
  });
  EXPECT_NE(missing.find("'iwan.fs' has no value"), std::string::npos) << missing;
}

TEST(HarmonicBalance, OutputDerivativesAreThoseOfTheSolvedSteadyStates) {
  // Implicit differentiation at a steady state (one factorisation for every move) against
  // central differences of steady states solved to 1e-12: coefficients (k, c, exact friction
  // fc, k3) and an iwan's four parameters, in microslip and in macroslip. The implicit
  // derivative over a step h = 1e-6 of the value is first order, good to about h of the
  // derivative (plus the solve's 1e-12 over h); the central difference over 1e-4 to (1e-4)²
  // and 1e-12/1e-4: 1e-3 of the largest derivative asserted leaves room for the generalised
  // Jacobian of friction's stick–slip samples, which a step can switch.
  const PaperCantilever c;
  const double f = 3.5;
  frf::HarmonicBalanceOptions o;
  o.harmonics = 9;
  const std::vector<int> outputs{c.eq(7), c.eq(4)};
  struct Case {
    const char* name;
    std::vector<joints::Joint> joints;
    double F0;
  };
  std::vector<Case> cases{
      {"k, c, fc, k3",
       {make("tip", 7, 0, {Term::k, Term::c, Term::fc, Term::k3}, {4800.0, 20.0, 3.0, 1.6e8})},
       40.0},
      {"iwan, microslip", {parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1})}, 2.0},
      {"iwan, macroslip", {parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1})}, 20.0},
      // Two joints (a coefficient of one moves the other's rows through H_yy), one with an
      // even term (no half-wave symmetry: the mean is solved for).
      {"iwan at the tip, k, k2, k3 at node 4",
       {parametric(Term::iwan, {3.0, 1.0e4, -0.5, 0.1}),
        make("mid", 4, 0, {Term::k, Term::k2, Term::k3}, {2000.0, 4e5, 5e7})},
       10.0},
  };
  // Each coefficient, and each parameter of a parametric term, moved by `relative` of itself.
  auto moves = [](const std::vector<joints::Joint>& js, double relative) {
    std::vector<std::vector<joints::Joint>> out;
    std::vector<double> steps;
    for (std::size_t i = 0; i < js.size(); ++i) {
      const joints::Joint& j = js[i];
      for (std::size_t t = 0; t < j.terms.size(); ++t) {
        if (joints::has_parameters(j.terms[t])) {
          for (std::size_t q = 0; q < j.parameters[t].size(); ++q) {
            std::vector<joints::Joint> m = js;
            const double h = relative * std::abs(j.parameters[t][q].value);
            m[i].parameters[t][q].value += h;
            out.push_back(m), steps.push_back(h);
          }
          continue;
        }
        std::vector<joints::Joint> m = js;
        const double h = relative * std::abs(j.values[t]);
        m[i].values[t] += h;
        out.push_back(m), steps.push_back(h);
      }
    }
    return std::pair{out, steps};
  };
  for (const Case& t : cases) {
    SCOPED_TRACE(t.name);
    const frf::HarmonicBalance problem(c.H, t.joints, c.system.dofs, {c.eq(7)}, outputs, f, o);
    const Eigen::MatrixXcd F = frf::sine_force(t.F0);
    const frf::HarmonicBalanceResult at = problem.solve(t.joints, F);
    ASSERT_TRUE(at.status.ok()) << at.status.reason;
    const auto [moved, steps] = moves(t.joints, 1e-6);
    const std::vector<Eigen::MatrixXcd> D =
        problem.output_derivatives(t.joints, F, at.Y, moved, steps);
    ASSERT_EQ(D.size(), moved.size());
    const auto [up, h_up] = moves(t.joints, 1e-4);
    const auto [down, h_down] = moves(t.joints, -1e-4);
    for (std::size_t p = 0; p < moved.size(); ++p) {
      SCOPED_TRACE("move " + std::to_string(p));
      const frf::HarmonicBalanceResult a = problem.solve(up[p], F, &at.Y),
                                       b = problem.solve(down[p], F, &at.Y);
      ASSERT_TRUE(a.status.ok() && b.status.ok());
      const Eigen::MatrixXcd central = (a.X - b.X) / (h_up[p] - h_down[p]);
      ASSERT_EQ(D[p].rows(), central.rows());
      ASSERT_EQ(D[p].cols(), central.cols());
      const double scale = central.cwiseAbs().maxCoeff();
      ASSERT_GT(scale, 0.0);
      EXPECT_LE((D[p] - central).cwiseAbs().maxCoeff(), 1e-3 * scale);
    }
  }
  // A move that changes the unknowns (an even term from 0: no half-wave symmetry) is left to
  // the caller, the others are formed.
  std::vector<joints::Joint> even{
      make("tip", 7, 0, {Term::k, Term::c, Term::k2, Term::k3}, {4800.0, 20.0, 0.0, 1.6e8})};
  const frf::HarmonicBalance problem(c.H, even, c.system.dofs, {c.eq(7)}, outputs, f, o);
  const frf::HarmonicBalanceResult at = problem.solve(even, frf::sine_force(20.0));
  ASSERT_TRUE(at.status.ok());
  std::vector<joints::Joint> with_k2 = even, stiffer = even;
  with_k2[0].values[2] = 1e3, stiffer[0].values[0] += 1e-2;
  const std::vector<double> steps{1e3, 1e-2};
  const auto D =
      problem.output_derivatives(even, frf::sine_force(20.0), at.Y, {with_k2, stiffer}, steps);
  ASSERT_EQ(D.size(), 2u);
  EXPECT_EQ(D[0].size(), 0);
  EXPECT_GT(D[1].size(), 0);
}
