// Newmark time integration: linear steady state against the exact receptance, dry friction
// against the analytic Coulomb oscillator, local (joint) forces against the same springs and
// dampers placed in the linear model.
#include "fem/time_integration.hpp"

#include "fem/damping.hpp"
#include "joints/joint.hpp"
#include "support/beam_models.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <vector>

using namespace jointid;
using fem::Dof;
using Complex = std::complex<double>;

namespace {

using jointid::test::eps;
using jointid::test::pi;

// Complex amplitude X of x(t) = Re(X e^{iωt}) by a DFT over whole periods (exact for a
// periodic signal sampled uniformly with no aliasing at the fundamental).
Complex fundamental(const Eigen::VectorXd& x, const Eigen::VectorXd& t, double omega) {
  Complex sum = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    sum += x(i) * std::polar(1.0, -omega * t(i));
  return 2.0 / static_cast<double>(x.size()) * sum;
}

joints::Joint joint(std::string name, int node, int node_b, Dof dof,
                    std::vector<joints::Term> terms, std::vector<double> values) {
  joints::Joint j{std::move(name), node, node_b, dof, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

} // namespace

TEST(Newmark, LinearOscillatorSteadyStateMatchesTheReceptance) {
  // m ẍ + c ẋ + k x = F0 sin ωt: X = −i F0 H(ω), H = 1/(k − mω² + icω). The average
  // acceleration rule is the trapezoidal rule, whose steady state is exactly H at the warped
  // frequency ω' = (2/h) tan(ωh/2) = ω (1 + (ωh)²/12 + …) — the period error. So
  //  (1) X equals −i F0 H(ω') to the steady-state convergence (≈1e-10, 1e-8 asserted);
  //  (2) |X| and arg X differ from the exact H(ω) by ≈ ω|H'/H| (ωh)²/12, the period error
  //      amplified near resonance; asserted with a factor 2 and checked to be non-trivial.
  const double m = 2.0, k = 800.0, zeta = 0.05, F0 = 3.0;
  const double wn = std::sqrt(k / m), c = 2 * zeta * std::sqrt(k * m);
  const fem::Assembled s = fem::assemble(test::oscillator(m, k));
  fem::Damping d;
  d.kind = fem::Damping::Kind::rayleigh;
  d.alpha = c / m; // C = αM = c
  const fem::SparseMatrix C = fem::damping_matrix(s, d);
  fem::SteadyStateOptions o;
  o.steps_per_period = 64; // coarse on purpose: the period error (ωh)²/12 ≈ 8e-4 is visible
  o.output_periods = 2;
  const std::vector<int> out{0};
  for (double ratio : {0.5, 0.98, 2.0}) {
    const double w = ratio * wn, h = 2 * pi / w / o.steps_per_period;
    const fem::SteadyState ss = fem::steady_state(s, C, nullptr, {0, F0, w / (2 * pi)}, out, o);
    ASSERT_TRUE(ss.status.ok()) << ratio;
    ASSERT_EQ(ss.u.rows(), o.output_periods * o.steps_per_period);
    const Complex X = fundamental(ss.u.col(0), ss.t, w);
    auto H = [&](double omega) { return 1.0 / Complex(k - m * omega * omega, c * omega); };
    const Complex exact = Complex(0.0, -F0) * H(w);
    const double w_warped = 2.0 / h * std::tan(w * h / 2.0);
    const Complex trapezoidal = Complex(0.0, -F0) * H(w_warped);
    EXPECT_LE(std::abs(X - trapezoidal), 1e-8 * std::abs(trapezoidal)) << ratio;

    const Complex dH = -H(w) * H(w) * Complex(-2 * m * w, c); // dH/dω
    const double predicted = w * std::abs(dH / H(w)) * std::pow(w * h, 2) / 12.0;
    const double tol = 2.0 * predicted;
    EXPECT_NEAR(std::abs(X), std::abs(exact), tol * std::abs(exact)) << ratio;
    EXPECT_NEAR(std::arg(X / exact), 0.0, tol) << ratio;
    // ... and the error really is the period error (first order in (ωh)², so > half of it).
    EXPECT_GT(std::abs(X / exact - 1.0), 0.5 * predicted) << ratio;
    // The sampled force is F0 sin ωt on the same time grid.
    EXPECT_NEAR(ss.force(5), F0 * std::sin(w * ss.t(5)), 1e-12 * F0);
  }
}

TEST(Newmark, SteadyStateReportsNotPeriodicWhenMaxPeriodsIsTooSmall) {
  // ζ = 0.001: the transient decays by e^{-2πζ} ≈ 0.994 per period, nowhere near 1e-10 in
  // 5 periods.
  const double m = 1.0, k = 100.0;
  const fem::Assembled s = fem::assemble(test::oscillator(m, k));
  fem::Damping d;
  d.kind = fem::Damping::Kind::rayleigh;
  d.alpha = 2 * 0.001 * std::sqrt(k / m);
  const fem::SparseMatrix C = fem::damping_matrix(s, d);
  fem::SteadyStateOptions o;
  o.steps_per_period = 32;
  o.output_periods = 1;
  o.max_periods = 5;
  const std::vector<int> out{0};
  const fem::SteadyState ss = fem::steady_state(s, C, nullptr, {0, 1.0, 1.3}, out, o);
  EXPECT_EQ(ss.status.code, fem::Status::Code::not_periodic);
  EXPECT_EQ(ss.status.reason.rfind("not a periodic steady state after 5 periods (last "
                                   "period-to-period change ",
                                   0),
            0u)
      << ss.status.reason;
  EXPECT_EQ(ss.periods_run, 5);
  EXPECT_GT(ss.period_change, o.tolerance);
  o.max_periods = 2; // fewer than output_periods + 2
  EXPECT_THROW(fem::steady_state(s, C, nullptr, {0, 1.0, 1.3}, out, o), std::invalid_argument);
}

namespace {

// Single-DOF oscillator with a Coulomb joint to ground, stepped by hand.
struct CoulombOscillator {
  double m = 1.0, k = 400.0, F = 2.0;
  fem::Assembled system = fem::assemble(test::oscillator(m, k));
  fem::SparseMatrix C = fem::SparseMatrix(1, 1); // no viscous damping
  joints::JointForces friction{{joint("dry", 1, 0, Dof::ux, {joints::Term::fc}, {F})}, system.dofs};
  double omega() const { return std::sqrt(k / m); }
};

} // namespace

TEST(Newmark, CoulombFreeDecayLosesFourFOverKPerCycleAndSticksInTheBand) {
  // Released from x0 at rest: half-cycles of the linear oscillator about ±F/k, so the extreme
  // values are x_n = (−1)ⁿ (x0 − 2nF/k) (4F/k per full cycle) until the first |x_n| ≤ F/k,
  // where the spring cannot overcome friction and the mass sticks for good. x0 is chosen so
  // that the final x_10 = x0 − 20F/k = 1.3 mm lies well inside the band |x| ≤ 5 mm.
  // Tolerance: between reversals the trapezoidal rule conserves the oscillator's energy exactly,
  // so the errors come from sampling the peaks (≤ A(ωh)²/8) and from the reversal steps (the
  // friction switches within a step where ẋ = O(h)): O(h²) overall; x0·(ωh)² is a safe bound
  // and still far below the 2F/k = 10 mm between consecutive peaks.
  const CoulombOscillator sys;
  const double x0 = 0.1013, F_k = sys.F / sys.k;
  const int N = 200; // steps per period of the linear oscillator
  const double h = 2 * pi / sys.omega() / N;
  fem::Newmark integrator(sys.system, sys.C, &sys.friction, h);
  Eigen::VectorXd u(1), v(1), f = Eigen::VectorXd::Zero(1);
  u << x0;
  v << 0.0;
  integrator.set_state(u, v, f);
  std::vector<double> x{x0};
  for (int i = 0; i < 8 * N; ++i) {
    ASSERT_TRUE(integrator.step(f).ok()) << "step " << i;
    x.push_back(integrator.u()(0));
  }
  // Extremes: where the sampled x stops increasing/decreasing.
  // Changes below 1e-12 x0 are rounding of a held position, not motion.
  auto motion = [&](double dx) { return std::abs(dx) <= 1e-12 * x0 ? 0.0 : dx; };
  std::vector<double> peaks{x0};
  for (std::size_t i = 1; i + 1 < x.size(); ++i) {
    const double before = motion(x[i] - x[i - 1]), after = motion(x[i + 1] - x[i]);
    if (before * after < 0.0 || (before != 0.0 && after == 0.0)) peaks.push_back(x[i]);
  }
  const double tol = x0 * std::pow(sys.omega() * h, 2);
  int expected_peaks = 1;
  while (x0 - 2 * (expected_peaks - 1) * F_k > F_k)
    ++expected_peaks;
  ASSERT_EQ(static_cast<int>(peaks.size()), expected_peaks);
  for (std::size_t n = 0; n < peaks.size(); ++n) {
    const double exact = (n % 2 == 0 ? 1.0 : -1.0) * (x0 - 2.0 * n * F_k);
    EXPECT_NEAR(peaks[n], exact, tol) << "extreme " << n;
    if (n >= 2) {
      EXPECT_NEAR(std::abs(peaks[n - 2]) - std::abs(peaks[n]), 4 * F_k, 2 * tol) << n;
    }
  }
  // Rest at the last extreme, inside the band.
  const int last = expected_peaks - 1;
  EXPECT_LE(std::abs(x.back()), F_k);
  EXPECT_NEAR(x.back(), (last % 2 == 0 ? 1.0 : -1.0) * (x0 - 2.0 * last * F_k), tol);
}

TEST(Newmark, StickPhaseIsHeld) {
  // After the decay above, the mass sticks: ẋ = 0 to rounding (ẋ is a difference of terms of
  // size a1·|x| ≈ (2/h)|x|), x constant up to that rounding velocity integrated over the
  // elapsed time, ẍ = 0 and the friction force the static one, λ = −kx, at every step. (The
  // trapezoidal rule alone cannot damp the jump of ẍ at the onset of stick: ẍ and λ alternated
  // step by step about these values, ẍ_{n+1} = −ẍ_n while u is held, before the integrator held
  // the stuck coordinates' acceleration at zero.) Tolerances: ẍ against the size of the forces
  // over the mass, k|x|/m, to 1e-9; λ to 1e-9 F.
  const CoulombOscillator sys;
  const double x0 = 0.1013;
  const int N = 200;
  const double h = 2 * pi / sys.omega() / N;
  fem::Newmark integrator(sys.system, sys.C, &sys.friction, h);
  Eigen::VectorXd u(1), v(1), f = Eigen::VectorXd::Zero(1);
  u << x0;
  v << 0.0;
  integrator.set_state(u, v, f);
  for (int i = 0; i < 7 * N; ++i)
    ASSERT_TRUE(integrator.step(f).ok());
  const double x_stop = integrator.u()(0);
  const double rounding = 64 * eps * (2.0 / h) * std::abs(x_stop);
  const double acceleration_scale = sys.k * std::abs(x_stop) / sys.m;
  for (int i = 0; i < N; ++i) {
    ASSERT_TRUE(integrator.step(f).ok());
    EXPECT_LE(std::abs(integrator.v()(0)), rounding) << i;
    EXPECT_NEAR(integrator.u()(0), x_stop, 4 * eps * std::abs(x_stop) + rounding * (i + 1) * h)
        << i;
    EXPECT_LE(std::abs(integrator.a()(0)), 1e-9 * acceleration_scale) << i;
    const double force = integrator.local_force()(0);
    EXPECT_LE(std::abs(force), sys.F) << i;
    EXPECT_NEAR(force, -sys.k * x_stop, 1e-9 * sys.F) << i;
  }
}

TEST(Newmark, StuckJointOfABeamHasZeroAccelerationWhileItSticks) {
  // A cantilever (6 beam elements, light Rayleigh damping) with a Coulomb joint (fc = 6 N)
  // and a spring at the tip, driven at 1 Hz with 10 N: the tip sticks for part of each period.
  // While it sticks (this step and the last), the tip's acceleration is 0 (to 1e-9 of the
  // largest tip acceleration of the period) — it alternated ±a* before — and the velocity 0 to
  // rounding.
  fem::Model model = test::cantilever(6, {});
  model.damping.kind = fem::Damping::Kind::rayleigh;
  model.damping.alpha = 0.5; // ≈ 1 % at the first two modes: the start's transient dies out
  model.damping.beta = 1e-4;
  const fem::Assembled system = fem::assemble(model);
  const fem::SparseMatrix C = fem::damping_matrix(system, model.damping);
  const std::vector<joints::Joint> js{
      joint("tip", 7, 0, Dof::uy, {joints::Term::k, joints::Term::fc}, {4800.0, 6.0})};
  const joints::JointForces forces(js, system.dofs);
  const int tip = system.dofs.equation({7, Dof::uy});
  const double f = 1.0, w = 2 * pi * f; // below the first resonance (3 Hz, 4.2 Hz with k)
  const int N = 512;
  const double h = 1.0 / (f * N);
  fem::Newmark integrator(system, C, &forces, h);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(system.dofs.num_equations());
  integrator.set_state(zero, zero, zero);
  Eigen::VectorXd load = zero;
  int held = 0;
  double largest = 0.0;
  std::vector<double> stuck_accelerations;
  double previous_v = 1.0;
  for (int i = 1; i <= 16 * N; ++i) {
    load(tip) = 10.0 * std::sin(w * i * h);
    ASSERT_TRUE(integrator.step(load).ok());
    if (i <= 14 * N) continue; // the last two periods
    largest = std::max(largest, std::abs(integrator.a()(tip)));
    const double v = integrator.v()(tip);
    const double vscale = 1e-9 * w * std::abs(integrator.u()(tip)) + 1e-300;
    if (std::abs(v) <= vscale && std::abs(previous_v) <= vscale) {
      ++held;
      stuck_accelerations.push_back(integrator.a()(tip));
    }
    previous_v = v;
  }
  ASSERT_GT(held, N / 10); // it does stick, for a good part of the period
  ASSERT_GT(largest, 0.0);
  for (double a : stuck_accelerations)
    EXPECT_LE(std::abs(a), 1e-9 * largest);
}

TEST(Newmark, ForceBelowTheFrictionLimitNeverSlips) {
  // F0 sin ωt with F0 < F from rest: the joint sticks throughout, x ≡ 0 and the friction force
  // carries the whole load, λ = f(t), to rounding.
  const CoulombOscillator sys;
  const double F0 = 0.8 * sys.F, w = 0.7 * sys.omega(), h = 2 * pi / w / 100;
  fem::Newmark integrator(sys.system, sys.C, &sys.friction, h);
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), f(1);
  integrator.set_state(zero, zero, zero);
  for (int i = 1; i <= 300; ++i) {
    f(0) = F0 * std::sin(w * i * h);
    ASSERT_TRUE(integrator.step(f).ok());
    EXPECT_LE(std::abs(integrator.u()(0)), 1e-15 * F0 / sys.k) << i;
    EXPECT_NEAR(integrator.local_force()(0), f(0), 1e-12 * sys.F) << i;
  }
}

TEST(Newmark, JointForcesEqualTheSameSpringsInTheModel) {
  // A linear joint is just a spring and a dashpot: integrating K + k_j, C + c_j with no local
  // forces must give the same history as the condensed local solve. The two routes differ by
  // the Newton tolerance (1e-13) and rounding amplified by cond(K_eff) (≈1e3) per step, carried
  // undamped by the trapezoidal rule over 2000 steps: ≲ 2000 · 3e-13 ≈ 6e-10; 5e-9 asserted.
  // Joint to ground at the tip and between nodes 2 and 4 (sign of B).
  const double k_tip = 5e3, c_tip = 20.0, k_mid = 2e4;
  fem::Model with_springs = test::cantilever(4, {});
  with_springs.springs.push_back({5, 0, Dof::uy, k_tip});
  with_springs.springs.push_back({2, 4, Dof::uy, k_mid});
  const fem::Model bare = test::cantilever(4, {});
  const fem::Assembled sa = fem::assemble(with_springs), sb = fem::assemble(bare);
  ASSERT_EQ(sa.dofs.num_equations(), sb.dofs.num_equations());
  const int tip = sb.dofs.equation({5, Dof::uy});
  fem::SparseMatrix Ca(sa.dofs.num_equations(), sa.dofs.num_equations());
  Ca.insert(tip, tip) = c_tip;
  const fem::SparseMatrix Cb(sb.dofs.num_equations(), sb.dofs.num_equations());
  const joints::JointForces forces(
      {joint("tip", 5, 0, Dof::uy, {joints::Term::k, joints::Term::c}, {k_tip, c_tip}),
       joint("mid", 2, 4, Dof::uy, {joints::Term::k}, {k_mid})},
      sb.dofs);
  const double h = 1e-4;
  fem::Newmark a(sa, Ca, nullptr, h), b(sb, Cb, &forces, h);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(sa.dofs.num_equations());
  a.set_state(zero, zero, zero);
  b.set_state(zero, zero, zero);
  Eigen::VectorXd f = zero;
  for (int i = 1; i <= 2000; ++i) {
    f(tip) = 100.0 * std::sin(2 * pi * 7.0 * i * h);
    ASSERT_TRUE(a.step(f).ok());
    ASSERT_TRUE(b.step(f).ok());
  }
  EXPECT_LE((a.u() - b.u()).norm(), 5e-9 * a.u().norm());
  EXPECT_LE((a.v() - b.v()).norm(), 5e-9 * a.v().norm());
  // The local force reported is the joints' force g = k y + c ẏ.
  const double y_tip = b.u()(tip), v_tip = b.v()(tip);
  EXPECT_NEAR(b.local_force()(0), k_tip * y_tip + c_tip * v_tip, 1e-9 * std::abs(k_tip * y_tip));
  const double y_mid =
      b.u()(sb.dofs.equation({2, Dof::uy})) - b.u()(sb.dofs.equation({4, Dof::uy}));
  EXPECT_NEAR(b.local_force()(1), k_mid * y_mid, 1e-9 * std::abs(k_mid * y_mid));
}

TEST(Newmark, BadTimeStepThrows) {
  const fem::Assembled s = fem::assemble(test::oscillator(1.0, 1.0));
  const fem::SparseMatrix C(1, 1);
  EXPECT_THROW(fem::Newmark(s, C, nullptr, 0.0), std::invalid_argument);
  EXPECT_TRUE(fem::Newmark(s, C, nullptr, 0.01).status().ok());
}

TEST(Newmark, ASingularEffectiveStiffnessIsAStatusPassedUp) {
  // A DOF with neither mass nor stiffness: K + a1 C + a0 M is zero there. A numerical outcome:
  // the integrator's status, and the status of the simulations built on it.
  const fem::Assembled nothing = fem::assemble(test::oscillator(0.0, 0.0));
  ASSERT_EQ(nothing.dofs.num_equations(), 1);
  const fem::SparseMatrix C(1, 1);
  const std::string reason = "Newmark: the effective stiffness K + a1 C + a0 M is singular (a DOF "
                             "with neither stiffness nor mass?)";
  const fem::Newmark integrator(nothing, C, nullptr, 0.01);
  EXPECT_EQ(integrator.status().code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(integrator.status().reason, reason);
  const std::vector<int> out{0};
  const fem::SteadyState steady = fem::steady_state(nothing, C, nullptr, {0, 1.0, 1.0}, out);
  EXPECT_EQ(steady.status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(steady.status.reason, reason);
  EXPECT_EQ(steady.u.size(), 0);
}

TEST(Newmark, AJointIterationThatFailsIsAStatusSayingWhen) {
  // One Newton iteration cannot solve a step with a joint (the first only measures the
  // residual): the first step, t = h = T/32 = 0.03125 s, fails — a status, not an exception.
  const fem::Assembled s = fem::assemble(test::oscillator(1.0, 100.0));
  const joints::JointForces cubic{{joint("cubic", 1, 0, Dof::ux, {joints::Term::k3}, {1e6})},
                                  s.dofs};
  const fem::SparseMatrix C(1, 1);
  fem::SteadyStateOptions o;
  o.steps_per_period = 32;
  o.newmark.max_newton = 1;
  const std::vector<int> out{0};
  fem::Newmark integrator(s, C, &cubic, 1.0 / 32.0, o.newmark);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), unit = Eigen::VectorXd::Ones(1);
  integrator.set_state(zero, zero, zero);
  const fem::Status step = integrator.step(unit);
  EXPECT_EQ(step.code, fem::Status::Code::not_converging);
  EXPECT_EQ(step.reason, "the joints' Newton iteration did not converge in 1 iterations");
  const fem::SteadyState ss = fem::steady_state(s, C, &cubic, {0, 1.0, 1.0}, out, o);
  EXPECT_EQ(ss.status.code, fem::Status::Code::not_converging);
  EXPECT_EQ(ss.status.reason, "the joints' Newton iteration failed in period 1 (t = 0.03125 s; "
                              "no convergence in 1 iterations)");
  EXPECT_EQ(ss.periods_run, 1);
  // With the default iterations the same steps converge.
  o.newmark.max_newton = fem::NewmarkOptions{}.max_newton;
  o.max_periods = 3;
  o.output_periods = 1;
  const fem::SteadyState more = fem::steady_state(s, C, &cubic, {0, 1.0, 1.0}, out, o);
  EXPECT_NE(more.status.code, fem::Status::Code::not_converging) << more.status.reason;
}

TEST(Newmark, JenkinsSlidesExactlyAtItsSlipForce) {
  // A nearly massless oscillator (spring k0 to ground) with a Jenkins joint (kt in series with a
  // slider of slip force fs) under a force ramped by 0.13 N a step: quasi-static, k0 y + g = f.
  // While it sticks, g = kt y exactly (the slider has not moved); it must start to slide at the
  // first step where kt·f/(k0 + kt) exceeds fs (f* = fs (k0 + kt)/kt = 5.5 N, between steps 42
  // and 43), and from then on g = fs exactly — no regularisation rounds the corner. Ramped back
  // down it sticks at once (g falls with slope kt from fs) and slides the other way at −fs.
  // Tolerances: the trapezoidal rule's inertia m ÿ against the stiffness is at most
  // m (2/h)² / k0 = 4e-6 relative; g = kt y and g = ±fs hold to rounding.
  const double m = 1e-9, k0 = 1000.0, kt = 1.0e4, fs = 5.0, h = 1e-3, rate = 0.13;
  const fem::Assembled s = fem::assemble(test::oscillator(m, k0));
  joints::Joint j{"jenkins", 1, 0, Dof::ux, {joints::Term::jenkins}, {1.0}, {true}, {}};
  j.set_parameters(0, {kt, fs});
  const joints::JointForces forces({j}, s.dofs);
  ASSERT_EQ(forces.state_size(), 1);
  const fem::SparseMatrix C(1, 1);
  fem::Newmark integrator(s, C, &forces, h);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(1);
  integrator.set_state(f, f, f);
  int first_slide = -1;
  double y_top = 0.0;
  for (int n = 1; n <= 80; ++n) { // up to 10.4 N
    f(0) = rate * n;
    ASSERT_TRUE(integrator.step(f).ok()) << n;
    const double y = integrator.y()(0), g = integrator.local_force()(0);
    EXPECT_NEAR(k0 * y + g, f(0), 1e-5 * f(0)) << n; // quasi-static balance
    if (std::abs(g - fs) <= 1e-12 * fs) {
      if (first_slide < 0) first_slide = n;
      EXPECT_NEAR(integrator.history()[0], y - fs / kt, 1e-15) << n; // the slider moved along
    } else {
      EXPECT_LT(g, fs) << n;
      EXPECT_EQ(first_slide, -1) << "stuck again while loading, step " << n;
      EXPECT_NEAR(g, kt * y, 1e-12 * fs) << n;
      EXPECT_EQ(integrator.history()[0], 0.0) << n;
    }
    y_top = y;
  }
  EXPECT_EQ(first_slide, 43);
  EXPECT_LT(kt * (rate * 42) / (k0 + kt), fs); // (the quasi-static transition: step 43)
  EXPECT_GT(kt * (rate * 43) / (k0 + kt), fs);
  // Unloading: sticks at once, g = fs − kt (y_top − y), until g reaches −fs.
  bool slid_back = false;
  for (int n = 79; n >= -80 && !slid_back; --n) {
    f(0) = rate * n;
    ASSERT_TRUE(integrator.step(f).ok()) << n;
    const double y = integrator.y()(0), g = integrator.local_force()(0);
    if (std::abs(g + fs) <= 1e-12 * fs) {
      slid_back = true;
      // it slides back where fs − kt (y_top − y) reaches −fs: f = k0 y − fs with y = y_top − 2fs/kt
      EXPECT_GE(f(0), k0 * (y_top - 2.0 * fs / kt) - fs - rate * (1.0 + 1e-9)) << n;
    } else {
      EXPECT_NEAR(g, fs - kt * (y_top - y), 1e-12 * fs * 10.0) << n;
    }
  }
  EXPECT_TRUE(slid_back);
}

TEST(Newmark, ClearanceOscillatorKeepsItsAnalyticPeriod) {
  // A mass m on a spring k0 with a clearance (gap δ, contact stiffness kg) released from rest at
  // A > δ: in contact it swings about x_e = kg δ/(k0 + kg) at ω2 = √((k0 + kg)/m), reaching δ
  // after t1 = arccos((δ − x_e)/(A − x_e))/ω2 at speed v1 = ω2 √((A − x_e)² − (δ − x_e)²); free,
  // it swings about 0 at ω1 = √(k0/m) and reaches 0 after t2 = atan(ω1 δ / v1)/ω1: the period is
  // 4 (t1 + t2), and the energy ½mv² + ½k0x² + ½kg(|x| − δ)₊² is conserved. The contact is taken
  // exactly at each step's end (no penalty smoothing, no event location): the force has a kink
  // in time there, the trapezoidal rule errs by O(h² kg |ẏ|) at that step, so the method stays
  // second order — halving h divides the period's error by ≈ 4 (asserted: 3 to 5) — and the
  // energy is kept to O(h²) with no drift.
  const double m = 1.0, k0 = 1000.0, kg = 9000.0, delta = 1e-3, A = 3e-3;
  const double w1 = std::sqrt(k0 / m), w2 = std::sqrt((k0 + kg) / m), xe = kg * delta / (k0 + kg);
  const double t1 = std::acos((delta - xe) / (A - xe)) / w2;
  const double v1 = w2 * std::sqrt(std::pow(A - xe, 2) - std::pow(delta - xe, 2));
  const double t2 = std::atan(w1 * delta / v1) / w1, period = 4.0 * (t1 + t2);
  const fem::Assembled s = fem::assemble(test::oscillator(m, k0));
  joints::Joint j{"gap", 1, 0, Dof::ux, {joints::Term::gap}, {1.0}, {true}, {}};
  j.set_parameters(0, {delta, kg});
  const joints::JointForces forces({j}, s.dofs);
  EXPECT_EQ(forces.state_size(), 0);
  const fem::SparseMatrix C(1, 1);
  auto energy = [&](double x, double v) {
    const double pen = std::max(std::abs(x) - delta, 0.0);
    return 0.5 * m * v * v + 0.5 * k0 * x * x + 0.5 * kg * pen * pen;
  };
  const double E0 = energy(A, 0.0);
  auto run = [&](int steps) { // the mean period over 4 periods from downward zero crossings
    const double h = period / steps;
    fem::Newmark integrator(s, C, &forces, h);
    Eigen::VectorXd u(1), zero = Eigen::VectorXd::Zero(1);
    u << A;
    integrator.set_state(u, zero, zero);
    std::vector<double> crossings;
    double x_before = A, worst = 0.0;
    for (int n = 1; n <= 5 * steps; ++n) {
      EXPECT_TRUE(integrator.step(zero).ok());
      const double x = integrator.u()(0);
      worst = std::max(worst, std::abs(energy(x, integrator.v()(0)) - E0) / E0);
      if (x_before > 0.0 && x <= 0.0) crossings.push_back(h * (n - 1 + x_before / (x_before - x)));
      x_before = x;
    }
    EXPECT_LT(worst, 2.0 * std::pow(w2 * h, 2)) << steps; // O(h²), no drift over 5 periods
    return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  };
  const double coarse = run(200), fine = run(400);
  const double e_coarse = std::abs(coarse - period), e_fine = std::abs(fine - period);
  EXPECT_LT(e_fine, 1e-3 * period);
  EXPECT_GT(e_coarse / e_fine, 3.0);
  EXPECT_LT(e_coarse / e_fine, 5.0);
}
