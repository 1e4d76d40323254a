#include "identify/harmonics.hpp"

#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

using namespace jointid::identify;
using cd = std::complex<double>;

namespace {
using jointid::test::pi;

// x(t) = 0.3 + Re(X1 e^{iωt}) + Re(X3 e^{3iωt}) with known complex amplitudes.
const cd X1 = std::polar(2.0, 0.4), X3 = std::polar(0.5, -1.0);
double signal(double t, double omega) {
  return 0.3 + (X1 * std::polar(1.0, omega * t)).real() +
         (X3 * std::polar(1.0, 3 * omega * t)).real();
}
Eigen::VectorXd times(int n, double dt, double t0) {
  Eigen::VectorXd t(n);
  for (int i = 0; i < n; ++i)
    t(i) = t0 + i * dt;
  return t;
}
} // namespace

TEST(FitHarmonics, RecoversKnownAmplitudesOnWholePeriods) {
  const double f = 3.0, omega = 2 * pi * f;
  const Eigen::VectorXd t = times(400, 1.0 / (f * 100), 0.0); // 4 periods, 100 samples each
  Eigen::VectorXd x(t.size());
  for (int i = 0; i < t.size(); ++i)
    x(i) = signal(t(i), omega);
  const Eigen::VectorXcd X = fit_harmonics(t, x, omega, 3);
  // Exact model: only rounding remains.
  EXPECT_NEAR(X(0).real(), 0.3, 1e-12);
  EXPECT_NEAR(std::abs(X(1) - X1), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(X(2)), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(X(3) - X3), 0.0, 1e-12);
}

TEST(FitHarmonics, RecoversKnownAmplitudesWithoutWholePeriodsAndShiftedTime) {
  const double f = 7.3, omega = 2 * pi * f;
  const Eigen::VectorXd t = times(537, 1.0 / 211.0, 12.345); // 2.53 periods, not aligned
  Eigen::VectorXd x(t.size());
  for (int i = 0; i < t.size(); ++i)
    x(i) = signal(t(i), omega);
  const Eigen::VectorXcd X = fit_harmonics(t, x, omega, 3);
  EXPECT_NEAR(std::abs(X(1) - X1), 0.0, 1e-10);
  EXPECT_NEAR(std::abs(X(3) - X3), 0.0, 1e-10);
}

TEST(FitHarmonics, EqualsPaperEquation17OnWholePeriods) {
  // Paper eq. 17: A = 2/N Σ x cos(nωΔt), B = 2/N Σ x sin(nωΔt), amplitude A − jB.
  const double f = 2.0, omega = 2 * pi * f;
  const int N = 250;
  const Eigen::VectorXd t = times(N, 1.0 / (f * 125), 0.0);
  Eigen::VectorXd x(N);
  double A = 0, B = 0;
  for (int i = 0; i < N; ++i) {
    x(i) = std::tanh(3 * std::sin(omega * t(i) + 0.2)); // rich in odd harmonics
    A += 2.0 / N * x(i) * std::cos(omega * t(i));
    B += 2.0 / N * x(i) * std::sin(omega * t(i));
  }
  // The fit includes harmonics up to 9; on whole periods the columns are orthogonal, so its
  // fundamental equals eq. 17 to rounding whatever the other harmonics.
  const Eigen::VectorXcd X = fit_harmonics(t, x, omega, 9);
  EXPECT_NEAR(X(1).real(), A, 1e-12);
  EXPECT_NEAR(X(1).imag(), -B, 1e-12);
}

TEST(FitHarmonics, TooFewSamplesIsAnError) {
  const Eigen::VectorXd t = times(4, 0.1, 0.0), x = Eigen::VectorXd::Ones(4);
  EXPECT_THROW(fit_harmonics(t, x, 1.0, 3), std::invalid_argument);
}

TEST(EstimateFrequency, FindsANonBinFrequency) {
  const double f = 13.37;
  const Eigen::VectorXd t = times(3000, 1e-3, 0.5);
  Eigen::VectorXd x(t.size());
  for (int i = 0; i < t.size(); ++i)
    x(i) = 5.0 * std::sin(2 * pi * f * t(i) + 1.0) + 0.2;
  // The DFT resolution is 1/3 s⁻¹; the refined fit must reach far below it.
  EXPECT_NEAR(estimate_frequency(t, x), f, 1e-6 * f);
}

TEST(WholePeriodSamples, CountsWholePeriods) {
  const Eigen::VectorXd t = times(1050, 1e-3, 0.0); // 1.05 s
  EXPECT_EQ(whole_period_samples(t, 2.0), 1000);    // 2 whole periods of 0.5 s
  EXPECT_EQ(whole_period_samples(t, 0.5), 0);       // shorter than one period
  // Frequencies far above the sampling's, infinite or NaN no longer overflow the conversion to
  // int (UBSan; seen while fixing what fuzzing found in identify::stepped_sine_table).
  EXPECT_EQ(whole_period_samples(t, 1e300), 1050);
  EXPECT_EQ(whole_period_samples(t, std::numeric_limits<double>::infinity()), 0);
  EXPECT_EQ(whole_period_samples(t, std::numeric_limits<double>::quiet_NaN()), 0);
}
