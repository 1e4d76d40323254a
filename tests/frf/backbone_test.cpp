#include "frf/backbone.hpp"

#include "../support/cantilever.hpp"
#include "support/numbers.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace jointid;
using fem::Dof;
using joints::Term;

namespace {

using jointid::test::two_pi;

joints::Joint make(int node, std::vector<Term> terms, std::vector<double> values) {
  joints::Joint j{"joint", node, 0, Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

// A single-DOF oscillator as a substructure of one mode: f_r = 5 Hz, ζ = 2 %, the
// mass-normalised shape φ = 0.5 at 1:uy, so the modal mass is m = 1/φ² = 4 kg, and the
// physical equation of y = x(1:uy) is m ÿ + m 2ζω_r ẏ + m ω_r² y + g(y, ẏ) = 0.
struct Oscillator {
  double f_r = 5.0, zeta = 0.02, phi = 0.5;
  double m() const { return 1.0 / (phi * phi); }
  double omega_r() const { return two_pi * f_r; }
  frf::Substructure sub = [this] {
    frf::ModalModel modal;
    modal.dofs = {{1, Dof::uy}};
    modal.frequencies_hz = Eigen::VectorXd::Constant(1, f_r);
    modal.damping = Eigen::VectorXd::Constant(1, zeta);
    modal.shapes = Eigen::MatrixXd::Constant(1, 1, phi);
    return frf::Substructure(modal);
  }();
};

// Every point of b on the single-DOF Duffing backbone of the oscillator with g = k y + k3 y³
// (ω0² = w0sq), in the fundamental's amplitude a, r = ε a² / ω0² with ε = k3/m, by
// Lindstedt–Poincaré: ω² = ω0² (1 + 3r/4 + 3r²/128 − 0.013916 r³ + O(r⁴)), within r⁴ ω0² (the
// next term's coefficient is below 1) plus the Newton tolerance's 1e-9 ω0²; and the linear
// damping put back whole, ξ = 2ζω_r, at every amplitude.
void expect_duffing(const frf::Backbone& b, const Oscillator& o, double k3, double w0sq) {
  for (const frf::BackbonePoint& p : b.points) {
    const double a = p.joint_amplitude, w = two_pi * p.frequency_hz;
    const double r = k3 / o.m() * a * a / w0sq;
    const double series = 0.75 * r + 3.0 / 128.0 * r * r - 0.013916 * r * r * r;
    EXPECT_NEAR(w * w / w0sq - 1.0, series, std::pow(r, 4) + 1e-9) << "r = " << r;
    EXPECT_NEAR(p.self_excitation, 2.0 * o.zeta * o.omega_r(), 1e-8 * o.omega_r());
  }
}

} // namespace

TEST(Backbone, ZeroAmplitudeEndIsTheLinearModeOfAnOscillator) {
  // With g = k y + c ẏ + k3 y³: ω0² = ω_r² + k/m and ξ = 2ζω_r + c/m exactly (one mode, no
  // residual flexibility), D0 = ξ / (2ω0). The linear mode is solved to the Newton tolerance
  // (1e-10 relative); the backbone's first point at a = 1e-6 m differs from it by the cubic
  // spring's shift (3/4) k3 a² / m in ω², 1e-9 of ω0² here.
  const Oscillator o;
  const double k = 400.0, c = 2.0, k3 = 1e7;
  const std::vector<joints::Joint> js{make(1, {Term::k, Term::c, Term::k3}, {k, c, k3})};
  const frf::Backbone b = frf::backbone(o.sub, js, 1, {1, Dof::uy}, 1e-6, 1e-5, {.points = 3});
  ASSERT_TRUE(b.status.ok()) << b.status.reason;
  const double w0 = std::sqrt(o.omega_r() * o.omega_r() + k / o.m());
  const double xi = 2.0 * o.zeta * o.omega_r() + c / o.m();
  EXPECT_NEAR(b.linear.frequency_hz, w0 / two_pi, 1e-9 * w0 / two_pi);
  EXPECT_NEAR(b.linear.damping_ratio, xi / (2.0 * w0), 1e-9 * xi / (2.0 * w0));
  EXPECT_NEAR(b.linear.amplitude_ratio, 1.0, 1e-12); // the amplitude DOF is the joint's
  ASSERT_EQ(b.points.size(), 3u);
  EXPECT_NEAR(b.points[0].amplitude, 1e-6, 1e-15);
  EXPECT_NEAR(b.points[0].frequency_hz, w0 / two_pi, 1e-8 * w0 / two_pi);
  EXPECT_NEAR(b.points[0].damping_ratio, xi / (2.0 * w0), 1e-8 * xi / (2.0 * w0));
}

TEST(Backbone, LinearModesOfACantileverWithMassProportionalDamping) {
  // The paper's cantilever with C = αM and a spring k at the tip: the modes of (K + k e eᵀ, M)
  // (a dense generalised eigenproblem, the second method) with ξ = α exactly (−ξM cancels C),
  // so D = α / (2ω). Both from the finite element model: to 1e-8.
  fem::Model model = test::paper_cantilever();
  model.damping.kind = fem::Damping::Kind::rayleigh;
  model.damping.alpha = 0.3;
  const frf::Substructure sub(model);
  const double k = 4800.0;
  const std::vector<joints::Joint> js{make(7, {Term::k, Term::k3}, {k, 1.6e8})};
  const fem::Assembled system = fem::assemble(model);
  Eigen::MatrixXd K = Eigen::MatrixXd(system.K), M = Eigen::MatrixXd(system.M);
  const int tip = system.dofs.equation({7, Dof::uy});
  K(tip, tip) += k;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  for (const int mode : {1, 2}) {
    SCOPED_TRACE(mode);
    const frf::Backbone b = frf::backbone(sub, js, mode, {7, Dof::uy}, 1e-7, 1e-6, {.points = 2});
    ASSERT_TRUE(b.status.ok()) << b.status.reason;
    const double w = std::sqrt(eig.eigenvalues()(mode - 1));
    EXPECT_NEAR(b.linear.frequency_hz, w / two_pi, 1e-8 * w / two_pi);
    EXPECT_NEAR(b.linear.damping_ratio, 0.3 / (2.0 * w), 1e-8 * 0.3 / (2.0 * w));
  }
}

TEST(Backbone, CubicSpringFollowsTheDuffingBackbone) {
  // g = k y + k3 y³ on the oscillator: the single-DOF Duffing backbone in the fundamental's
  // amplitude a, r = ε a² / ω0² with ε = k3/m, by Lindstedt–Poincaré:
  //     ω = ω0 (1 + 3r/8 − 15r²/256 + 123r³/8192 + O(r⁴)), so
  //     ω² = ω0² (1 + 3r/4 + 3r²/128 − 0.013916 r³ + O(r⁴)),
  // asserted within r⁴ ω0² (the next term's coefficient is below 1) plus the Newton tolerance's
  // 1e-9 ω0², for r up to 0.05. The describing function (one harmonic) lacks the r² term,
  // 3/128 r² ω0², more than the tolerance wherever r > 1e-3. The linear damping is put back
  // whole: ξ = 2ζω_r at every amplitude.
  const Oscillator o;
  const double k = 400.0, k3 = 4e6;
  const std::vector<joints::Joint> js{make(1, {Term::k, Term::k3}, {k, k3})};
  const double w0sq = o.omega_r() * o.omega_r() + k / o.m();
  const double a_max = std::sqrt(0.05 * w0sq * o.m() / k3);
  const frf::Backbone b =
      frf::backbone(o.sub, js, 1, {1, Dof::uy}, a_max / 100.0, a_max, {.points = 12});
  ASSERT_TRUE(b.status.ok()) << b.status.reason;
  ASSERT_EQ(b.points.size(), 12u);
  expect_duffing(b, o, k3, w0sq);
  EXPECT_GT(b.points.back().frequency_hz, b.points.front().frequency_hz); // hardening
}

TEST(Backbone, JenkinsDampingEqualsTheEnergyDissipatedPerCycle) {
  // g = k y + jenkins(kt, fs) on the oscillator, with the fundamental alone (K = 1: y = a cos ωt
  // exactly). The self-excitation returns per cycle what the damping and the slider take:
  //     ξ m ω² a² π/ω = 2ζω_r m ω² a² π/ω + 4 fs (a − fs/kt)      (a > fs/kt),
  // the loop's area of a Jenkins element. The harmonic balance transforms the loop's force
  // from Nt = 512 samples h = 2π/Nt apart (the reversals, at θ = 0 and π, are samples): the
  // rule is exact for the fundamental but at the two slip onsets a cycle, where ∂g/∂θ jumps by
  // kt a |sin θ| ≤ kt a, each leaving at most h² kt a / 8 in the integral of g cos θ; so the
  // energy π a Im G_1 is within kt a² h² / 4: the tolerance.
  const Oscillator o;
  const double k = 400.0, kt = 2000.0, fs = 1.0;
  joints::Joint j = make(1, {Term::k, Term::jenkins}, {k, 1.0});
  j.set_parameters(1, {kt, fs});
  const std::vector<joints::Joint> js{j};
  frf::BackboneOptions opt{.points = 10};
  opt.hb.harmonics = 1, opt.hb.time_samples = 512;
  const frf::Backbone b =
      frf::backbone(o.sub, js, 1, {1, Dof::uy}, 0.1 * fs / kt, 20.0 * fs / kt, opt);
  ASSERT_TRUE(b.status.ok()) << b.status.reason;
  int checked = 0;
  for (const frf::BackbonePoint& p : b.points) {
    const double a = p.joint_amplitude, w = two_pi * p.frequency_hz;
    const double per_cycle = std::numbers::pi * o.m() * w * a * a; // energy per unit ξ
    const double slider = a > fs / kt ? 4.0 * fs * (a - fs / kt) : 0.0;
    const double expected = 2.0 * o.zeta * o.omega_r() + slider / per_cycle;
    const double h = 2.0 * std::numbers::pi / 512;
    EXPECT_NEAR(p.self_excitation, expected, kt * a * a * h * h / 4.0 / per_cycle) << "a = " << a;
    checked += slider > 0.0;
  }
  EXPECT_GE(checked, 5);
  // The damping ratio rises from the linear one, 2ζω_r/(2ω0).
  EXPECT_GT(b.points.back().damping_ratio, 2.0 * b.linear.damping_ratio);
}

TEST(Backbone, RefusesBadInput) {
  const Oscillator o;
  const std::vector<joints::Joint> js{make(1, {Term::k, Term::k3}, {400.0, 1e6})};
  EXPECT_THROW(frf::backbone(o.sub, js, 2, {1, Dof::uy}, 1e-4, 1e-3), std::invalid_argument);
  EXPECT_THROW(frf::backbone(o.sub, js, 0, {1, Dof::uy}, 1e-4, 1e-3), std::invalid_argument);
  EXPECT_THROW(frf::backbone(o.sub, {}, 1, {1, Dof::uy}, 1e-4, 1e-3), std::invalid_argument);
  EXPECT_THROW(frf::backbone(o.sub, js, 1, {1, Dof::uy}, 1e-3, 1e-4), std::invalid_argument);
  // Two modes; the joint's DOF 2:uy is at a node of mode 2 (φ = 0 there): mode 2 is refused,
  // naming the reason, mode 1 is not.
  frf::ModalModel modal;
  modal.dofs = {{1, Dof::uy}, {2, Dof::uy}};
  modal.frequencies_hz = Eigen::Vector2d(5.0, 12.0);
  modal.damping = Eigen::Vector2d(0.01, 0.01);
  modal.shapes.resize(2, 2);
  modal.shapes << 0.5, 0.5, 0.5, 0.0;
  const frf::Substructure two(modal);
  const std::vector<joints::Joint> at_node{make(2, {Term::k, Term::k3}, {400.0, 1e6})};
  try {
    frf::backbone(two, at_node, 2, {1, Dof::uy}, 1e-4, 1e-3);
    ADD_FAILURE() << "a joint at a node of the mode was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("node of the mode"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(frf::backbone(two, at_node, 1, {1, Dof::uy}, 1e-4, 1e-3, {.points = 2}).status.ok());
}

TEST(Backbone, ACubicSpringAloneStartsFromTheSubstructuresOwnMode) {
  // g = k3 y³ alone on the oscillator: no linear term, so the linear mode is the oscillator's
  // own, f_r and ζ exactly (a pole of the receptance, where the EPMC's equations cannot be
  // evaluated: found in modal coordinates), and the backbone is the Duffing one of
  // CubicSpringFollowsTheDuffingBackbone with ω0 = ω_r, within r⁴ ω0² and the tolerance.
  const Oscillator o;
  const double k3 = 4e6;
  const std::vector<joints::Joint> js{make(1, {Term::k3}, {k3})};
  const double w0sq = o.omega_r() * o.omega_r();
  const double a_max = std::sqrt(0.05 * w0sq * o.m() / k3);
  const frf::Backbone b =
      frf::backbone(o.sub, js, 1, {1, Dof::uy}, a_max / 100.0, a_max, {.points = 12});
  ASSERT_TRUE(b.status.ok()) << b.status.reason;
  EXPECT_DOUBLE_EQ(b.linear.frequency_hz, o.f_r);
  EXPECT_NEAR(b.linear.damping_ratio, o.zeta, 1e-15);
  EXPECT_NEAR(b.linear.amplitude_ratio, 1.0, 1e-12);
  ASSERT_EQ(b.points.size(), 12u);
  expect_duffing(b, o, k3, w0sq);
}

TEST(Backbone, AGapIsTheLinearModeUntilContactThenItsDescribingFunction) {
  // A clearance δ with contact stiffness kg alone on the oscillator, the fundamental alone
  // (K = 1): below δ the joint exerts no force and the point is the linear mode exactly; beyond
  // it, ω² = ω_r² + N(a)/m with the dead-zone spring's describing function
  //     N(a) = kg (1 − (2/π)(asin(δ/a) + (δ/a) √(1 − δ²/a²))).
  // The force is transformed from Nt = 512 samples h = 2π/Nt apart; at each of the four contact
  // instants a cycle ∂g/∂θ jumps by at most kg a, each leaving at most kg a h²/8 in ∫ g cos θ,
  // so |ΔN| ≤ kg h² / (2π): the tolerance on m ω², with the Newton tolerance.
  const Oscillator o;
  const double delta = 1e-3, kg = 1e4;
  joints::Joint j = make(1, {Term::gap}, {1.0});
  j.set_parameters(0, {delta, kg});
  const std::vector<joints::Joint> js{j};
  frf::BackboneOptions opt{.points = 12};
  opt.hb.harmonics = 1, opt.hb.time_samples = 512;
  const frf::Backbone b = frf::backbone(o.sub, js, 1, {1, Dof::uy}, 0.2 * delta, 10.0 * delta, opt);
  ASSERT_TRUE(b.status.ok()) << b.status.reason;
  ASSERT_EQ(b.points.size(), 12u);
  const double h = 2.0 * std::numbers::pi / 512;
  int below = 0, beyond = 0;
  for (const frf::BackbonePoint& p : b.points) {
    const double a = p.joint_amplitude, w = two_pi * p.frequency_hz;
    double N = 0.0;
    if (a > delta) {
      const double d = delta / a;
      N = kg * (1.0 - 2.0 / std::numbers::pi * (std::asin(d) + d * std::sqrt(1.0 - d * d)));
      ++beyond;
    } else {
      EXPECT_EQ(p.frequency_hz, o.f_r) << "a = " << a;
      ++below;
    }
    EXPECT_NEAR(o.m() * (w * w - o.omega_r() * o.omega_r()), N,
                kg * h * h / (2.0 * std::numbers::pi) + 1e-9 * o.m() * w * w)
        << "a = " << a;
  }
  EXPECT_GE(below, 3);
  EXPECT_GE(beyond, 6);
}

TEST(Backbone, RefusesExactDryFriction) {
  // A joint with exact dry friction sticks at small amplitudes: it does not deform, so its
  // deformation cannot parametrise the backbone from 0. Refused, saying what to use instead.
  const Oscillator o;
  const std::vector<joints::Joint> js{make(1, {Term::k, Term::fc}, {400.0, 1.0})};
  try {
    frf::backbone(o.sub, js, 1, {1, Dof::uy}, 1e-4, 1e-3);
    ADD_FAILURE() << "exact dry friction was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sticks"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("jenkins"), std::string::npos) << e.what();
  }
}
