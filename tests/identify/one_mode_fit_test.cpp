#include "identify/one_mode_fit.hpp"

#include "frf/backbone.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

using namespace jointid;
using Complex = std::complex<double>;

namespace {

using jointid::test::two_pi;

} // namespace

TEST(OneModeFit, RecoversASingleModeExactly) {
  // X = F A / (ω_n² − ω² + iωd) with a complex residue and forces that differ row to row: the
  // fit is exact to rounding (1e-9) and its deviations vanish with its residual.
  const double fn = 7.0, zeta = 0.015, wn = two_pi * fn, d = 2.0 * zeta * wn;
  const Complex A(0.3, -0.02);
  std::vector<double> f;
  Eigen::VectorXcd X(9), F(9);
  for (int i = 0; i < 9; ++i) {
    f.push_back(fn * (1.0 + 0.01 * (i - 4)));
    const double w = two_pi * f.back();
    F(i) = std::polar(2.0 + 0.1 * i, 0.3 * i);
    X(i) = F(i) * A / Complex(wn * wn - w * w, w * d);
  }
  const identify::OneModeFit fit = identify::fit_one_mode(f, X, F);
  ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
  EXPECT_NEAR(fit.frequency_hz, fn, 1e-9 * fn);
  EXPECT_NEAR(fit.damping_ratio, zeta, 1e-9 * zeta);
  EXPECT_LT(fit.frequency_std_hz, 1e-9 * fn);
  EXPECT_LT(fit.damping_ratio_std, 1e-9 * zeta);
  // The level's amplitude: |X| of the row of largest |X/F|.
  Eigen::Index best = 0;
  (X.array() / F.array()).abs().maxCoeff(&best);
  EXPECT_EQ(fit.amplitude, std::abs(X(best)));
}

TEST(OneModeFit, RefusesTooFewRowsAndNoResonance) {
  const std::vector<double> f{1.0, 2.0};
  EXPECT_FALSE(
      identify::fit_one_mode(f, Eigen::VectorXcd::Ones(2), Eigen::VectorXcd::Ones(2)).status.ok());
  EXPECT_THROW(identify::fit_one_mode(f, Eigen::VectorXcd::Ones(3), Eigen::VectorXcd::Ones(2)),
               std::invalid_argument);
  const std::vector<double> g{1.0, 2.0, 3.0, 4.0};
  // A mass line X/F = −1/(m ω²): no resonance (ω_n² = 0, d = 0).
  Eigen::VectorXcd X(4);
  for (int i = 0; i < 4; ++i)
    X(i) = -1.0 / std::pow(two_pi * g[static_cast<std::size_t>(i)], 2);
  EXPECT_FALSE(identify::fit_one_mode(g, X, Eigen::VectorXcd::Ones(4)).status.ok());
}

namespace {

// The backbone's frequency and damping ratio at amplitude a, linear in log a between points.
std::pair<double, double> on_backbone(const frf::Backbone& b, double a) {
  const auto& p = b.points;
  if (!(a >= p.front().amplitude && a <= p.back().amplitude))
    throw std::out_of_range("beyond the backbone's amplitudes");
  std::size_t i = 1;
  while (i + 1 < p.size() && p[i].amplitude < a)
    ++i;
  const double x = std::log(a / p[i - 1].amplitude) / std::log(p[i].amplitude / p[i - 1].amplitude);
  return {p[i - 1].frequency_hz + x * (p[i].frequency_hz - p[i - 1].frequency_hz),
          p[i - 1].damping_ratio + x * (p[i].damping_ratio - p[i - 1].damping_ratio)};
}

} // namespace

TEST(OneModeFit, MeasuredBackboneOfAJenkinsJointMatchesTheModels) {
  // Stepped-sine tests made by harmonic balance of a known model (one mode, 5 Hz, ζ = 1 %, modal
  // mass 4 kg, a joint k + jenkins at its DOF), one force level per table, rows within about the
  // half-power band around the resonance; each level's one-mode fit against the model's
  // backbone (EPMC) at the fitted amplitude. The fit assumes a linear mode where the frequency
  // and damping change with the amplitude across the rows: that misfit is in its residual and
  // so in its deviations, and the backbone must lie within 3 of them (or 1e-4 relative, the
  // backbone's own interpolation between its points).
  frf::ModalModel modal;
  modal.dofs = {{1, fem::Dof::uy}};
  modal.frequencies_hz = Eigen::VectorXd::Constant(1, 5.0);
  modal.damping = Eigen::VectorXd::Constant(1, 0.01);
  modal.shapes = Eigen::MatrixXd::Constant(1, 1, 0.5);
  const frf::Substructure sub(modal);
  joints::Joint j{
      "joint",      1, 0, fem::Dof::uy, {joints::Term::k, joints::Term::jenkins}, {400.0, 1.0},
      {true, true}, {}};
  j.set_parameters(1, {400.0, 0.5});
  const std::vector<joints::Joint> js{j};
  const frf::Backbone b = frf::backbone(sub, js, 1, {1, fem::Dof::uy}, 1e-4, 1e-1, {.points = 80});
  ASSERT_TRUE(b.status.ok()) << b.status.reason;
  const frf::ModalSynthesis H = sub.synthesis({0}, 100.0);
  const double m = 4.0;
  std::optional<Complex> residue;
  for (const double F0 : {0.05, 0.1, 0.2, 0.5, 1.0}) {
    SCOPED_TRACE(F0);
    // The resonance's amplitude, where the force balances the damping: F0 = m ξ ω a with
    // ξ = 2Dω, by bisection in log a over the backbone.
    auto balance = [&](double a) {
      const auto [fb, Db] = on_backbone(b, a);
      return m * 2.0 * Db * std::pow(two_pi * fb, 2) * a - F0;
    };
    double lo = b.points.front().amplitude, hi = b.points.back().amplitude;
    ASSERT_LT(balance(lo), 0.0);
    ASSERT_GT(balance(hi), 0.0);
    for (int it = 0; it < 60; ++it) {
      const double mid = std::sqrt(lo * hi);
      (balance(mid) < 0.0 ? lo : hi) = mid;
    }
    const auto [fb, Db] = on_backbone(b, lo);
    std::vector<double> f;
    Eigen::VectorXcd X(9), F(9);
    for (int i = 0; i < 9; ++i) {
      f.push_back(fb * (1.0 + Db * 0.25 * (i - 4))); // the half-power band
      const frf::HarmonicBalanceResult r =
          frf::harmonic_balance(H, js, sub.dofs(), 0, F0, f.back(), std::vector<int>{0});
      ASSERT_TRUE(r.status.ok()) << r.status.reason;
      X(i) = r.X(1, 0);
      F(i) = frf::sine_force(F0)(1, 0);
    }
    // The lowest level (stuck: linear) gives the residue the others share (share_residue()).
    identify::OneModeFit fit = identify::fit_one_mode(f, X, F, residue ? &*residue : nullptr);
    ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
    if (!residue) residue = fit.residue;
    const auto [f_model, D_model] = on_backbone(b, fit.amplitude);
    EXPECT_NEAR(fit.frequency_hz, f_model, 3.0 * fit.frequency_std_hz + 1e-4 * f_model);
    EXPECT_NEAR(fit.damping_ratio, D_model, 3.0 * fit.damping_ratio_std + 1e-4 * D_model);
  }
}
