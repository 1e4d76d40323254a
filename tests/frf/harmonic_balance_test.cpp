// Harmonic balance against the exact linear solution and against time integration.
#include "frf/harmonic_balance.hpp"

#include "fem/damping.hpp"
#include "fem/time_integration.hpp"
#include "support/beam_models.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

using namespace jointid;
using fem::Dof;
using frf::Complex;
using joints::Term;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

joints::Joint make(std::string name, int node, int node_b, std::vector<Term> terms,
                   std::vector<double> values) {
  joints::Joint j{std::move(name), node, node_b, Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

// The METHOD.md cantilever: steel, L = 2 m, 0.25 m × 14.3623 mm, 6 beam elements, clamped at
// node 1, 1 % modal damping. Every mode kept, so the synthesis is exact for the FE model.
struct PaperCantilever {
  fem::Model model = [] {
    fem::Model m = test::cantilever(6, {});
    m.damping.kind = fem::Damping::Kind::modal;
    m.damping.modal_ratio = 0.01;
    return m;
  }();
  fem::Assembled system = fem::assemble(model);
  fem::Modes modes =
      fem::modal_analysis(system, {.num_modes = 0, .engine = fem::ModalEngine::dense});
  frf::ModalSynthesis H{system, modes, model.damping, test::all_equations(system)};
  int eq(int node) const { return system.dofs.equation({node, Dof::uy}); }
};

// Harmonic k of a periodic record sampled over whole periods: x = Re Σ X_k e^{ikωt}.
Complex harmonic(const Eigen::VectorXd& x, const Eigen::VectorXd& t, double omega, int k) {
  Complex sum = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    sum += x(i) * std::polar(1.0, -k * omega * t(i));
  return (k == 0 ? 1.0 : 2.0) / static_cast<double>(x.size()) * sum;
}

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
    ASSERT_TRUE(r.converged) << f;
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
  ASSERT_TRUE(r.converged);

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
  const frf::CMatrix H = frf::direct_receptance(s, C, w, outputs, force);
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
  ASSERT_TRUE(hb.converged);
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
    EXPECT_EQ(s.status, fem::SteadyStateStatus::converged);
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
  EXPECT_EQ(s.status, fem::SteadyStateStatus::converged);
  return s;
}

} // namespace

TEST(HarmonicBalance, Explore2) {
  const PaperCantilever c;
  const double F0 = 80, f = 2.5, w = two_pi * f;
  const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800, 20, 3.0})};
  const std::vector<int> outputs{c.eq(7)};
  const auto s = integrate(c, js, F0, f, 16384);
  const Complex T1 = harmonic(s.u.col(0), s.t, w, 1), T0 = harmonic(s.u.col(0), s.t, w, 0), T3 = harmonic(s.u.col(0), s.t, w, 3);
  const auto s2 = integrate(c, js, F0, f, 8192);
  std::cout << "TI 8192 vs 16384 " << std::abs(harmonic(s2.u.col(0), s2.t, w, 1) - T1) / std::abs(T1) << " X0 " << T0 << " X3/X1 " << std::abs(T3)/std::abs(T1) << "\n";
  for (int K : {15, 31, 63, 127})
    for (int Nt : {0, 4096}) {
      frf::HarmonicBalanceOptions o;
      o.harmonics = K; o.time_samples = Nt;
      const auto hb = frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs, o);
      std::cout << "  K " << K << " Nt " << Nt << " conv " << hb.converged << " it " << hb.iterations << " err1 " << std::abs(hb.X(1, 0) - T1) / std::abs(T1) << " err0 " << std::abs(hb.X(0,0) - T0)/std::abs(T1) << " err3 " << std::abs(hb.X(3,0) - T3)/std::abs(T1) << "\n";
    }
}

TEST(HarmonicBalance, Explore) {
  const PaperCantilever c;
  {
    const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k, Term::c, Term::k2}, {4800, 20, 5e4})};
    const double F0 = 40, f = 3.0, w = two_pi * f;
    const std::vector<int> outputs{c.eq(7)};
    const auto hb = frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs);
    for (int steps : {1024, 2048, 4096}) {
      const auto s = integrate(c, js, F0, f, steps);
      std::cout << "k2 steps " << steps << " periods " << s.periods_run;
      for (int k = 0; k <= 3; ++k) {
        const Complex T = harmonic(s.u.col(0), s.t, w, k);
        std::cout << " | k" << k << " |X|=" << std::abs(hb.X(k, 0)) << " rel " << std::abs(T - hb.X(k, 0)) / std::abs(hb.X(k, 0));
      }
      std::cout << "\n";
    }
  }
  for (auto [F0, f] : {std::pair{80.0, 2.5}, std::pair{80.0, 5.0}, std::pair{10.0, 3.0}, std::pair{10.0, 2.5}}) {
    const std::vector<joints::Joint> js{make("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800, 20, 3.0})};
    const double w = two_pi * f;
    const std::vector<int> outputs{c.eq(7)};
    std::vector<Complex> T1;
    for (int steps : {2048, 4096, 8192}) {
      const auto s = integrate(c, js, F0, f, steps);
      int stuck = 0;
      const double vmax = s.v.col(0).cwiseAbs().maxCoeff();
      for (int i = 0; i < s.v.rows(); ++i) if (std::abs(s.v(i, 0)) < 1e-9 * vmax) ++stuck;
      T1.push_back(harmonic(s.u.col(0), s.t, w, 1));
      std::cout << "fc F0 " << F0 << " f " << f << " steps " << steps << " periods " << s.periods_run << " stuck " << double(stuck) / s.v.rows() << " |X1| " << std::abs(T1.back()) << "\n";
    }
    std::cout << "  TI 2048 vs 8192 " << std::abs(T1[0] - T1[2]) / std::abs(T1[2]) << " 4096 vs 8192 " << std::abs(T1[1] - T1[2]) / std::abs(T1[2]) << "\n";
    for (int K : {7, 15, 31, 63}) {
      frf::HarmonicBalanceOptions o;
      o.harmonics = K;
      const auto hb = frf::harmonic_balance(c.H, js, c.system.dofs, c.eq(7), F0, f, outputs, o);
      std::cout << "  K " << K << " conv " << hb.converged << " it " << hb.iterations << " err1 " << std::abs(hb.X(1, 0) - T1[2]) / std::abs(T1[2]) << "\n";
    }
  }
}
