// Welch spectra against independent truths: a sine's power, Parseval on white noise, and the
// H1 estimate of a linear structure under band-limited random force against the exact
// receptance by modal synthesis (frf::).
#include "identify/spectra.hpp"

#include "fem/excitation.hpp"
#include "identify/random_tests.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

using namespace jointid;
using namespace jointid::identify;

namespace {
using jointid::test::two_pi;

Eigen::VectorXd sine(double amplitude, double f, double fs, int n, double phase = 0.3) {
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i)
    x(i) = amplitude * std::sin(two_pi * f * i / fs + phase);
  return x;
}

// ∫ G df over the bins within `half` bins of f.
double peak_power(const PowerSpectrum& p, double f, int half) {
  const double df = p.frequency_hz(1);
  const auto centre = static_cast<Eigen::Index>(std::lround(f / df));
  double sum = 0.0;
  for (Eigen::Index k = centre - half; k <= centre + half; ++k)
    sum += p.psd(k) * df;
  return sum;
}
} // namespace

TEST(Welch, SineOfKnownAmplitudeHasPowerAOver2) {
  // A = 3: power A²/2 = 4.5. On a bin (f = 50 fs/N) the Hann window spreads it over exactly
  // three bins, so the sum is exact to rounding; off the bin (f = 50.37 fs/N) its leakage
  // beyond ±6 bins is below 1e-4 of the power.
  const double fs = 1000.0, A = 3.0;
  const int N = 1000;
  const WelchOptions o{N, 0.5};
  const PowerSpectrum on = power_spectrum(sine(A, 50.0, fs, 20 * N), fs, o);
  EXPECT_NEAR(peak_power(on, 50.0, 1), A * A / 2.0, 1e-10);
  EXPECT_EQ(on.averages, 39);
  // Peak bin: |X| = A Σw/2 = AN/4 and Σw² = 3N/8, so G = 2|X|²/(fs Σw²) = A²N/(3 fs) — two
  // thirds of the power, the neighbours a sixth each.
  EXPECT_NEAR(on.psd(50), A * A * N / (3.0 * fs), 1e-10);
  const PowerSpectrum off = power_spectrum(sine(A, 50.37, fs, 20 * N), fs, o);
  EXPECT_NEAR(peak_power(off, 50.37, 6), A * A / 2.0, 1e-4 * A * A / 2.0);
}

TEST(Welch, ParsevalOnWhiteNoise) {
  // White Gaussian noise, σ = 2: the PSD is flat at 2σ²/fs and integrates to the variance.
  // The integral equals the segments' windowed mean square, whose relative scatter about σ² is
  // about sqrt(2/n_samples) ≈ 0.4 %; 2 % allowed. The level of the flat spectrum is checked
  // over its 2048 bins likewise.
  const double fs = 2048.0, sigma = 2.0;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::VectorXd x(1 << 17);
  for (auto& v : x)
    v = normal(rng);
  const PowerSpectrum p = power_spectrum(x, fs, {4096, 0.5});
  const double df = p.frequency_hz(1);
  const double integral = p.psd.sum() * df;
  const double variance = (x.array() - x.mean()).square().mean();
  EXPECT_NEAR(integral, variance, 0.02 * variance);
  EXPECT_NEAR(p.psd.segment(10, 2000).mean(), 2.0 * sigma * sigma / fs,
              0.02 * 2 * sigma * sigma / fs);
}

TEST(Welch, H1OfALinearStructureIsTheExactReceptance) {
  // The cantilever without joints, 5 % modal damping, driven at the tip by band-limited random
  // force (5–60 Hz, modes 2 and 3 inside), simulated in modal coordinates (every mode), 1 %
  // white noise added to the response. H1 is unbiased by response noise; its random error
  // (Bendat & Piersol) is sqrt((1 − γ²)/(2 n γ²)) for n independent averages. With 50 %
  // overlap the Hann segments are not independent: n is taken as the averages / 1.5 (a
  // conservative bound), and 4 standard errors allowed. Deterministic errors add a floor of
  // 1.5 %: the Hann window's resolution bias at a peak, (B_e/B_r)²/3 with B_e = 1.5 · 0.25 Hz
  // and the half-power bandwidth B_r = 2ζf = 1.9 Hz at 18.8 Hz: 1.3 %; the Newmark period
  // error (ωh)²/12 ≈ 1e-4 (h = 1/4096 s); the linear interpolation of the force between
  // samples, ≈ (πf/fs)²/3 ≤ 1e-3 below 60 Hz at 1024 Hz.
  fem::Model model = test::paper_cantilever();
  model.damping.modal_ratio = 0.05;
  const frf::Substructure sub(model);
  const fem::NodeDof tip{7, fem::Dof::uy};
  const double fs = 1024.0;
  ForceInput in;
  in.at = {tip};
  in.sample_rate_hz = fs;
  in.samples = fem::band_limited_random({5.0, 60.0, 10.0, 3}, {64.0, fs});
  ForcedOptions o;
  o.route = TransientRoute::modal;
  o.modal_cutoff_hz = 1e6; // every mode
  o.substeps = 4;
  o.quantities = {Quantity::displacement};
  ForcedTest test = simulate_forced(sub, {}, in, o);
  add_noise(test.record, 0.01, 5, false);
  const Eigen::VectorXd& f = test.record.find(Quantity::force, tip)->samples;
  const Eigen::VectorXd& x = test.record.find(Quantity::displacement, tip)->samples;
  const FrfEstimate h1 = h1_estimate(f, x, fs, {4096, 0.5});
  EXPECT_EQ(h1.averages, 31);
  const int eq = sub.dofs().equation(tip);
  const frf::ModalSynthesis exact = sub.synthesis({eq}, 200.0);
  const std::vector<int> at{eq};
  const double n_independent = h1.averages / 1.5;
  double worst = 0.0, worst_allowed = 0.0;
  int checked = 0;
  for (Eigen::Index k = 0; k < h1.H.size(); ++k) {
    const double fk = h1.frequency_hz(k);
    if (fk < 8.0 || fk > 57.0) continue;
    const std::complex<double> H = exact.receptance(two_pi * fk, at, at)(0, 0);
    const double g2 = h1.coherence(k);
    const double allowed = 4.0 * std::sqrt((1.0 - g2) / (2.0 * n_independent * g2)) + 1.5e-2;
    const double error = std::abs(h1.H(k) - H) / std::abs(H);
    EXPECT_LT(error, allowed) << fk << " Hz, coherence " << g2;
    if (error > worst) {
      worst = error;
      worst_allowed = allowed;
    }
    ++checked;
    if (std::abs(fk - 18.75) < 1e-9)
      std::printf("H1 at 18.75 Hz (mode 2): relative error %.3g, coherence %.4f\n", error, g2);
  }
  std::printf("H1 vs exact receptance, 8-57 Hz (%d lines): worst relative error %.3g (allowed "
              "there %.3g)\n",
              checked, worst, worst_allowed);
  EXPECT_GT(checked, 190);
}

// Coherence against its definition for a known noise (issue 31): the response is the force
// (gain 1.5) plus independent white noise, both white, so at every line γ² = S / (S + N) with
// S = 1.5² σ_f² and N = σ_n². With n ≈ 255 overlapped averages (Hann, 50 %: about 190
// independent ones) the estimate's bias is (1 − γ²)²/n < 2e-3 and its scatter per line
// √2 γ (1 − γ²)/√n ≤ 0.04; the mean over 400 lines is within 1e-2 of γ² (its scatter 2e-3),
// and every line within 0.2. Halving the coherence, or squaring it once more, fails.
TEST(Welch, CoherenceIsSignalOverSignalPlusNoise) {
  const double fs = 1024.0, gain = 1.5, sigma_f = 1.0;
  std::mt19937_64 rng(23);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd f(1 << 17), noise(1 << 17);
  for (auto& v : f)
    v = sigma_f * normal(rng);
  for (auto& v : noise)
    v = normal(rng);
  for (const double sigma_n : {1.5, 0.75, 3.0}) {
    const double S = gain * gain * sigma_f * sigma_f, N = sigma_n * sigma_n;
    const double expected = S / (S + N); // 0.5, 0.8, 0.2
    const Eigen::VectorXd x = gain * f + sigma_n * noise;
    const FrfEstimate h = h1_estimate(f, x, fs, {1024, 0.5});
    const Eigen::VectorXd lines = h.coherence.segment(50, 400);
    EXPECT_NEAR(lines.mean(), expected, 1e-2) << "sigma_n = " << sigma_n;
    EXPECT_LT((lines.array() - expected).abs().maxCoeff(), 0.2) << "sigma_n = " << sigma_n;
    // H1 is unbiased by the response's noise: the gain, within its random error.
    EXPECT_NEAR(h.H.segment(50, 400).real().mean(), gain, 0.02 * gain) << "sigma_n = " << sigma_n;
  }
}

TEST(Welch, BadInputsAreRefused) {
  const Eigen::VectorXd x = Eigen::VectorXd::Ones(100);
  EXPECT_THROW(power_spectrum(x, 0.0), std::invalid_argument);
  EXPECT_THROW(power_spectrum(x, 10.0, {200, 0.5}), std::invalid_argument);
  EXPECT_THROW(power_spectrum(x, 10.0, {16, 1.0}), std::invalid_argument);
  EXPECT_THROW(h1_estimate(x, Eigen::VectorXd::Ones(99), 10.0, {16, 0.5}), std::invalid_argument);
  // A NaN is named by its sample and channel (the response of an H1 estimate is channel 2).
  Eigen::VectorXd y = x;
  y(41) = std::numeric_limits<double>::quiet_NaN();
  try {
    h1_estimate(x, y, 10.0, {16, 0.5});
    FAIL() << "a NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "Welch: sample 42 of channel 2 is nan, not a finite number");
  }
}
