// A backbone (frf/backbone.hpp, the extended periodic motion concept) against the free decay it
// stands for, by the second method: time integration (identify::simulate_forced, exact slider
// states) of the structure set ringing by a short pulse and left alone. From the decay's
// extrema, each half cycle gives the amplitude, the frequency (π over the time between
// extrema) and the damping ratio (the logarithmic decrement per half cycle, π D / √(1 − D²));
// the backbone at the same amplitude must give both.
#include "frf/backbone.hpp"

#include "identify/random_tests.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace jointid;
using fem::Dof;
using joints::Term;

namespace {

using jointid::test::pi;

// One mode, f_r = 5 Hz, ζ = 0.5 %, φ = 0.5 at 1:uy (modal mass 4 kg), with a spring k and a
// Jenkins element (kt, fs) to ground at 1:uy: the joint's slider dominates the damping once it
// slips (fs/kt = 5e-4 m).
frf::Substructure oscillator() {
  frf::ModalModel modal;
  modal.dofs = {{1, Dof::uy}};
  modal.frequencies_hz = Eigen::VectorXd::Constant(1, 5.0);
  modal.damping = Eigen::VectorXd::Constant(1, 0.005);
  modal.shapes = Eigen::MatrixXd::Constant(1, 1, 0.5);
  return frf::Substructure(modal);
}

struct HalfCycle {
  double amplitude = 0.0;    // m, half the swing between two extrema
  double frequency_hz = 0.0; // from the time between them
  double damping = 0.0;      // from the decrement to the next swing
};

// The extrema of x (a parabola through each sample maximum of |x − trend| and its neighbours),
// then every half cycle's swing, frequency and decrement.
std::vector<HalfCycle> half_cycles(const Eigen::VectorXd& t, const Eigen::VectorXd& x,
                                   Eigen::Index from) {
  std::vector<double> te, xe;
  for (Eigen::Index n = std::max<Eigen::Index>(from, 1); n + 1 < x.size(); ++n) {
    const double a = x(n - 1), b = x(n), c = x(n + 1);
    if (!((b > a && b >= c) || (b < a && b <= c))) continue;
    const double curvature = a - 2.0 * b + c;
    const double shift = curvature != 0.0 ? 0.5 * (a - c) / curvature : 0.0; // samples
    const double h = t(1) - t(0);
    te.push_back(t(n) + shift * h);
    xe.push_back(b - 0.25 * (a - c) * shift);
  }
  std::vector<HalfCycle> out;
  for (std::size_t i = 0; i + 2 < xe.size(); ++i) {
    const double swing = 0.5 * std::abs(xe[i + 1] - xe[i]);
    const double next = 0.5 * std::abs(xe[i + 2] - xe[i + 1]);
    const double delta = std::log(swing / next); // per half cycle
    const double D = delta / std::sqrt(pi * pi + delta * delta);
    out.push_back({std::sqrt(swing * next), 0.5 / (0.5 * (te[i + 2] - te[i])), D});
  }
  return out;
}

// The backbone's frequency and damping ratio at the joint amplitude a (linear in log a
// between its points).
std::pair<double, double> backbone_at(const frf::Backbone& b, double a) {
  const auto& p = b.points;
  for (std::size_t i = 0; i + 1 < p.size(); ++i)
    if (p[i].joint_amplitude <= a && a <= p[i + 1].joint_amplitude) {
      const double s = std::log(a / p[i].joint_amplitude) /
                       std::log(p[i + 1].joint_amplitude / p[i].joint_amplitude);
      return {p[i].frequency_hz + s * (p[i + 1].frequency_hz - p[i].frequency_hz),
              p[i].damping_ratio + s * (p[i + 1].damping_ratio - p[i].damping_ratio)};
    }
  return {std::nan(""), std::nan("")};
}

} // namespace

TEST(BackboneDecay, AJenkinsJointsBackboneIsItsFreeDecay) {
  const frf::Substructure sub = oscillator();
  const double k = 400.0, kt = 2000.0, fs = 1.0;
  joints::Joint j{"joint", 1, 0, Dof::uy, {Term::k, Term::jenkins}, {k, 1.0}, {}, {}};
  j.fixed.assign(j.terms.size(), true);
  j.set_parameters(1, {kt, fs});
  const std::vector<joints::Joint> js{j};

  // The backbone from below slip to 12 fs/kt, 7 harmonics (the slider's loop is not a sine).
  frf::BackboneOptions options{.points = 30};
  options.hb.harmonics = 7;
  const frf::Backbone b =
      frf::backbone(sub, js, 1, {1, Dof::uy}, 0.5 * fs / kt, 12.0 * fs / kt, options);
  ASSERT_TRUE(b.status.ok()) << b.status.reason;

  // The decay: a half-sine pulse of 60 N over 20 ms (shorter than a tenth of the period) sets
  // the oscillator ringing at about 10 fs/kt; then 3 s free, 4 000 samples a second.
  const double rate = 4000.0;
  identify::ForceInput pulse;
  pulse.at = {{1, Dof::uy}};
  pulse.sample_rate_hz = rate;
  pulse.samples = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(3.0 * rate), 1);
  for (Eigen::Index n = 0; n < static_cast<Eigen::Index>(0.02 * rate); ++n)
    pulse.samples(n, 0) = 60.0 * std::sin(pi * static_cast<double>(n) / (0.02 * rate));
  identify::ForcedOptions to;
  to.substeps = 4;
  to.quantities = {identify::Quantity::displacement};
  const identify::ForcedTest decay = identify::simulate_forced(sub, js, pulse, to);
  ASSERT_TRUE(decay.status.ok()) << decay.status.reason;
  const identify::Channel* x =
      decay.record.find(identify::Quantity::displacement, fem::NodeDof{1, Dof::uy});
  ASSERT_NE(x, nullptr);

  const std::vector<HalfCycle> cycles =
      half_cycles(decay.record.t, x->samples, static_cast<Eigen::Index>(0.05 * rate));
  int compared = 0;
  for (const HalfCycle& c : cycles) {
    if (c.amplitude < 3.0 * fs / kt) break; // in macroslip: the slider slides most of a cycle
    const auto [f, D] = backbone_at(b, c.amplitude);
    if (std::isnan(f)) continue;
    SCOPED_TRACE(testing::Message() << "amplitude " << c.amplitude << " m");
    // The backbone is the decay's slow flow to first order in D (averaging); the half cycle
    // also spans its own decrement, about π D in log amplitude, over which D changes. So π D²
    // is allowed for the damping ratio and D² (relative) for the frequency, plus the extrema's
    // interpolation error (h² ω² / 8 of the swing, 3e-4 here). Measured: 0.6-1.5 D² and
    // 0.25-0.35 D².
    EXPECT_NEAR(c.damping, D, pi * D * D + 3e-4 * D);
    EXPECT_NEAR(c.frequency_hz, f, (D * D + 3e-4) * f);
    ++compared;
  }
  EXPECT_GE(compared, 6);
  // The damping the slider adds: well above the linear ζ, and falling with the amplitude
  // towards it (below slip, the joint is a spring).
  EXPECT_GT(b.points.back().damping_ratio, 3.0 * b.linear.damping_ratio);
}
