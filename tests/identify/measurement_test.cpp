// Reduction of sine tests to harmonics: synthetic records whose harmonics are known exactly,
// white Gaussian noise of known σ (checked against the analytic variance of a harmonic estimate
// and against Monte Carlo), stepped-sine rows, errors and warnings.
#include "identify/measurement.hpp"

#include "support/cantilever.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <string>

using namespace jointid;
using namespace jointid::identify;
using cd = std::complex<double>;

namespace {

using jointid::test::two_pi;
constexpr double f_hz = 2.5, omega = two_pi * f_hz;
using jointid::test::mid;
using jointid::test::tip;
const fem::NodeDof root{2, fem::Dof::rz};

// The displacement x(t) = X0 + Re Σ_{k=1..3} X_k e^{ikωt} (m) and the force F0 sin ωt plus a
// small third harmonic (N): harmonics known exactly.
const std::array<cd, 4> X_true{cd(1.5e-4), std::polar(3e-3, 0.7), std::polar(4e-4, -1.2),
                               std::polar(2e-4, 2.1)};
const std::array<cd, 4> F_true{cd(0.0), cd(0.0, -80.0), cd(0.0), std::polar(2.0, 0.3)};

// d^p/dt^p of Re Σ X_k e^{ikωt} at t: harmonic k multiplied by (ikω)^p (the mean drops out for
// p > 0).
double signal(const std::array<cd, 4>& X, double t, int p = 0) {
  double s = p == 0 ? X[0].real() : 0.0;
  for (int k = 1; k < 4; ++k)
    s += (std::pow(cd(0.0, k * omega), p) * X[k] * std::polar(1.0, k * omega * t)).real();
  return s;
}

// `periods` periods of `per_period` samples (need not be an integer), starting at t0, with the
// force and, at the tip, the response quantities asked.
Record make_record(double per_period, int periods, const std::vector<Quantity>& quantities,
                   double t0 = 0.0) {
  Record r;
  r.source = "synthetic.csv";
  r.excitation_hz = f_hz;
  const int n = static_cast<int>(std::lround(per_period * periods));
  const double dt = 1.0 / (f_hz * per_period);
  r.t.resize(n);
  for (int i = 0; i < n; ++i)
    r.t(i) = t0 + i * dt;
  Eigen::VectorXd force(n);
  for (int i = 0; i < n; ++i)
    force(i) = signal(F_true, r.t(i));
  r.channels.push_back({Quantity::force, tip, force});
  for (Quantity q : quantities) {
    const int p = q == Quantity::displacement ? 0 : q == Quantity::velocity ? 1 : 2;
    Eigen::VectorXd s(n);
    for (int i = 0; i < n; ++i)
      s(i) = signal(X_true, r.t(i), p);
    r.channels.push_back({q, tip, s});
  }
  return r;
}

bool has_warning(const Measurement& m, const std::string& what) {
  for (const auto& w : m.warnings)
    if (w.find(what) != std::string::npos) return true;
  return false;
}

std::string error_of(const SineTest& test, const MeasureOptions& o = {}) {
  try {
    measure(test, o);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// The signals are exactly band-limited and sampled without aliasing, so the least-squares fit
// on whole periods (orthogonal columns) recovers them to rounding: ≈ eps·√n·max|x| ≈ 1e-14 of
// the largest harmonic, and dividing by (kω)^p changes the ratio to |X_k| by at most ≈ 10 here.
// 1e-9 relative per harmonic leaves a wide margin while any wrong factor, sign or phase fails.
constexpr double exact = 1e-9;

void expect_recovered(const Measurement& m, bool with_mean) {
  ASSERT_EQ(m.X.rows(), 4);
  ASSERT_EQ(m.X.cols(), 1);
  for (int k = 1; k <= 3; ++k)
    EXPECT_LE(std::abs(m.X(k, 0) - X_true[k]), exact * std::abs(X_true[k])) << "harmonic " << k;
  if (with_mean)
    EXPECT_NEAR(m.X(0, 0).real(), X_true[0].real(), exact * X_true[0].real());
  else
    EXPECT_EQ(m.X(0, 0), cd(0.0)); // unknown, taken as 0
  for (int k = 1; k <= 3; ++k)
    EXPECT_LE(std::abs(m.F(k, 0) - F_true[k]), exact * std::abs(F_true[1])) << "force " << k;
  EXPECT_LE(std::abs(m.F(0, 0)), exact * std::abs(F_true[1]));
}

} // namespace

TEST(Measure, DisplacementVelocityOrAccelerationGiveTheSameDisplacementHarmonics) {
  for (const double t0 : {0.0, 0.37}) { // phases refer to absolute time
    const std::vector<std::pair<Quantity, std::string>> cases{
        {Quantity::displacement, ""},
        {Quantity::velocity, "derived from velocity"},
        {Quantity::acceleration, "derived from acceleration"}};
    for (const auto& [q, warning] : cases) {
      SCOPED_TRACE("quantity " + std::string(1, quantity_letter(q)) + ", t0 " + std::to_string(t0));
      const Measurement m = measure(make_record(256, 4, {q}, t0), {.harmonics = 3});
      EXPECT_EQ(m.frequency_hz, f_hz);
      EXPECT_EQ(m.harmonics, 3);
      EXPECT_FALSE(m.fundamental_only);
      ASSERT_EQ(m.response_at.size(), 1u);
      EXPECT_EQ(m.response_at[0], tip);
      EXPECT_EQ(m.measured_as[0], q);
      ASSERT_EQ(m.has_mean.size(), 1u);
      EXPECT_EQ(m.has_mean[0], q == Quantity::displacement);
      expect_recovered(m, q == Quantity::displacement);
      if (!warning.empty()) {
        EXPECT_TRUE(has_warning(m, warning));
      }
      // The period handed to the basis functions: x (without the unknown mean when derived)
      // and ẋ, from the same analytic signal.
      ASSERT_EQ(m.periods_averaged, 4);
      ASSERT_EQ(m.t.size(), 256);
      const double mean = q == Quantity::displacement ? 0.0 : X_true[0].real();
      const double scale_x = std::abs(X_true[1]), scale_v = omega * scale_x;
      for (Eigen::Index i = 0; i < m.t.size(); ++i) {
        ASSERT_NEAR(m.x(i, 0), signal(X_true, m.t(i)) - mean, exact * scale_x) << i;
        ASSERT_NEAR(m.v(i, 0), signal(X_true, m.t(i), 1), exact * scale_v) << i;
      }
    }
  }
}

TEST(Measure, DisplacementIsPreferredToVelocityAndAcceleration) {
  Record r =
      make_record(256, 2, {Quantity::acceleration, Quantity::velocity, Quantity::displacement});
  // Spoil the velocity and acceleration: the displacement channel must be the one used for X.
  r.channels[1].samples *= 3.0;
  r.channels[2].samples *= 3.0;
  const Measurement m = measure(r);
  ASSERT_EQ(m.response_at.size(), 1u);
  EXPECT_EQ(m.measured_as[0], Quantity::displacement);
  EXPECT_TRUE(m.has_mean[0]);
  expect_recovered(m, true);
}

TEST(Measure, NoiseVarianceAndHarmonicVarianceAgreeWithMonteCarlo) {
  // 8 periods × 256 samples (n = 2048) with white Gaussian noise σ_x on x, σ_v on v, σ_f on
  // the force. Each harmonic estimate X_k = (2/n) Σ x e^{−ikωt} has E|δX_k|² = 4σ²/n for k ≥ 1
  // and σ²/n for the mean; the scatter of the 8 periods about their synchronous average
  // estimates σ² without bias with (8 − 1)·256 = 1792 degrees of freedom.
  const int per = 256, periods = 8, n = per * periods, M = 1000;
  const double sx = 1e-5, sv = 2e-4, sf = 0.2;
  const Record clean = make_record(per, periods, {Quantity::displacement, Quantity::velocity});
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> normal;
  std::vector<Eigen::VectorXcd> X(M), F(M);
  Eigen::VectorXd Xvar = Eigen::VectorXd::Zero(4), Fvar = Eigen::VectorXd::Zero(4);
  double noise_x = 0.0, noise_f = 0.0; // mean of the estimated variances
  for (int s = 0; s < M; ++s) {
    Record r = clean;
    for (int i = 0; i < n; ++i) {
      r.channels[0].samples(i) += sf * normal(rng);
      r.channels[1].samples(i) += sx * normal(rng);
      r.channels[2].samples(i) += sv * normal(rng);
    }
    const Measurement m = measure(r, {.harmonics = 3});
    ASSERT_EQ(m.periods_averaged, periods);
    X[s] = m.X.col(0);
    F[s] = m.F.col(0);
    Xvar += m.X_variance.col(0) / M;
    Fvar += m.F_variance.col(0) / M;
    noise_x += m.channel_noise[0] * m.channel_noise[0] / M;
    if (s == 0) {
      // One record: σ̂²/σ² ~ χ²_1792/1792, so σ̂/σ has a relative standard deviation of
      // 1/√(2·1792) = 1.7 %; 4.5 of them: 7.5 %.
      EXPECT_NEAR(m.channel_noise[0] / sx, 1.0, 0.075);
      // The variance reported is the analytic one with σ̂ in place of σ.
      const double v = m.channel_noise[0] * m.channel_noise[0];
      EXPECT_NEAR(m.X_variance(0, 0), v / n, 1e-12 * v / n);
      for (int k = 1; k <= 3; ++k)
        EXPECT_NEAR(m.X_variance(k, 0), 4.0 * v / n, 1e-12 * v / n);
      EXPECT_FALSE(has_warning(m, "steady"));
    }
    // The force's variance comes from the force channel's own scatter.
    noise_f += m.F_variance(1, 0) * n / 4.0 / M;
  }
  // Mean of M = 1000 unbiased σ̂²: relative standard deviation √(2/1792/1000) = 0.11 %, so
  // 0.6 % (5.6 of them); a divisor n instead of n − 256 would be 12.5 % low.
  EXPECT_NEAR(noise_x / (sx * sx), 1.0, 6e-3);
  EXPECT_NEAR(noise_f / (sf * sf), 1.0, 6e-3);

  // Monte Carlo variance of the harmonics over the M records, against the mean reported
  // variance. For k ≥ 1, Re and Im of δX_k are independent with equal variance, so the sample
  // variance Σ|X − X̄|²/(M − 1) is a χ² with 2(M − 1) degrees of freedom: relative standard
  // deviation 1/√(M − 1) = 3.2 %; for the real mean √(2/(M − 1)) = 4.5 %. 4.5 standard
  // deviations: 14 % and 20 % (a missing factor 2 or 4 fails). The mean reported variance
  // itself scatters by only 0.11 %.
  auto mc_variance = [&](const std::vector<Eigen::VectorXcd>& v, int k) {
    cd mean = 0.0;
    for (const auto& x : v)
      mean += x(k) / static_cast<double>(M);
    double s = 0.0;
    for (const auto& x : v)
      s += std::norm(x(k) - mean);
    return s / (M - 1);
  };
  for (int k = 0; k <= 3; ++k) {
    const double tol = 4.5 * (k == 0 ? std::sqrt(2.0 / (M - 1)) : 1.0 / std::sqrt(M - 1.0));
    EXPECT_NEAR(mc_variance(X, k) / Xvar(k), 1.0, tol) << "X harmonic " << k;
    EXPECT_NEAR(mc_variance(F, k) / Fvar(k), 1.0, tol) << "F harmonic " << k;
    // And the analytic value with the true σ.
    const double analytic = (k == 0 ? 1.0 : 4.0) / n;
    EXPECT_NEAR(Xvar(k) / (analytic * sx * sx), 1.0, 6e-3) << k;
    EXPECT_NEAR(Fvar(k) / (analytic * sf * sf), 1.0, 6e-3) << k;
  }
  // The noise averages out: the mean over M records is within 4.5 standard errors of the truth.
  for (int k = 1; k <= 3; ++k) {
    cd mean = 0.0;
    for (const auto& x : X)
      mean += x(k) / static_cast<double>(M);
    EXPECT_LE(std::abs(mean - X_true[k]), 4.5 * std::sqrt(4.0 * sx * sx / n / M)) << k;
  }
}

TEST(Measure, VarianceOfADisplacementDerivedFromVelocity) {
  // Velocity only, with white noise σ_v: X_k = V_k/(ikω), so E|δX_k|² = 4σ_v²/n/(kω)²; the mean
  // displacement is unknown (its variance NaN). Monte Carlo over M = 400 records: the sample
  // variance of X_k is a χ² with 2(M − 1) degrees of freedom, relative standard deviation
  // 1/√(M − 1) = 5 %: 4.5 of them, 23 % (a gain 1/(kω) instead of 1/(kω)² is off by ×ω² ≈ 250).
  const int per = 256, periods = 8, n = per * periods, M = 400;
  const double sv = 2e-4;
  const Record clean = make_record(per, periods, {Quantity::velocity});
  std::mt19937_64 rng(77);
  std::normal_distribution<double> normal(0.0, sv);
  std::vector<Eigen::VectorXcd> X(M);
  for (int s = 0; s < M; ++s) {
    Record r = clean;
    for (int i = 0; i < n; ++i)
      r.channels[1].samples(i) += normal(rng);
    const Measurement m = measure(r, {.harmonics = 3});
    X[s] = m.X.col(0);
    EXPECT_TRUE(std::isnan(m.X_variance(0, 0)));
    for (int k = 1; k <= 3; ++k)
      ASSERT_NEAR(m.X_variance(k, 0),
                  4.0 * m.channel_noise[0] * m.channel_noise[0] / n / std::pow(k * omega, 2),
                  1e-12 * m.X_variance(k, 0));
  }
  for (int k = 1; k <= 3; ++k) {
    cd mean = 0.0;
    for (const auto& x : X)
      mean += x(k) / static_cast<double>(M);
    double v = 0.0;
    for (const auto& x : X)
      v += std::norm(x(k) - mean) / (M - 1);
    const double analytic = 4.0 * sv * sv / n / std::pow(k * omega, 2);
    EXPECT_NEAR(v / analytic, 1.0, 4.5 / std::sqrt(M - 1.0)) << k;
  }
}

TEST(Measure, PeriodsAreAveragedOnlyForAWholeNumberOfSamplesPerPeriod) {
  const Measurement whole = measure(make_record(256, 8, {Quantity::displacement}));
  EXPECT_EQ(whole.periods_averaged, 8);
  EXPECT_EQ(whole.t.size(), 256);
  expect_recovered(whole, true);
  // 255.5 samples per period: 8 periods are 2044 samples but no two periods sample the same
  // phases, so nothing is averaged; the fit over the whole record is still exact.
  for (const auto& q : {std::vector<Quantity>{Quantity::displacement},
                        std::vector<Quantity>{Quantity::displacement, Quantity::velocity}}) {
    const Measurement m = measure(make_record(255.5, 8, q));
    EXPECT_EQ(m.periods_averaged, 1);
    EXPECT_EQ(m.t.size(), 2044);
    expect_recovered(m, true);
  }
}

TEST(Measure, ResidualNoiseEstimateWithoutAveraging) {
  // Without synchronous averaging the noise comes from the residual of a many-harmonic fit
  // (63 harmonics here: 2044 − 127 = 1917 degrees of freedom); σ̂/σ has a relative standard
  // deviation of 1/√(2·1917) = 1.6 %: 4.5 of them, 7.3 %.
  Record r = make_record(255.5, 8, {Quantity::displacement, Quantity::velocity});
  std::mt19937_64 rng(99);
  std::normal_distribution<double> normal(0.0, 1e-5);
  for (Eigen::Index i = 0; i < r.t.size(); ++i)
    r.channels[1].samples(i) += normal(rng);
  const Measurement m = measure(r);
  ASSERT_EQ(m.periods_averaged, 1);
  EXPECT_NEAR(m.channel_noise[0] / 1e-5, 1.0, 0.073);
}

TEST(Measure, SteppedSineRowsConvertVelocityAndAcceleration) {
  const double f = 3.2, w = two_pi * f;
  const cd F(0.0, -40.0), Xa = std::polar(2e-3, -0.4), Xb = std::polar(5e-4, 1.1),
                          Xc = std::polar(7e-3, 2.9);
  Phasors row;
  row.source = "table.csv:5";
  row.frequency_hz = f;
  row.channels = {{Quantity::force, tip, F},
                  {Quantity::velocity, tip, cd(0.0, w) * Xa},         // V = iω X
                  {Quantity::acceleration, mid, -w * w * Xb},         // A = (iω)² X
                  {Quantity::acceleration, root, -w * w * Xc * 10.0}, // overridden by x below
                  {Quantity::displacement, root, Xc}};
  const Measurement m = measure(row, {.harmonics = 3});
  EXPECT_TRUE(m.fundamental_only);
  EXPECT_EQ(m.source, "table.csv:5");
  EXPECT_EQ(m.harmonics, 3);
  for (int k : {0, 2, 3, -1, 4})
    EXPECT_FALSE(m.has_harmonic(k)) << k;
  EXPECT_TRUE(m.has_harmonic(1));
  ASSERT_EQ(m.response_at, (std::vector<fem::NodeDof>{tip, mid, root}));
  EXPECT_EQ(m.measured_as, (std::vector<Quantity>{Quantity::velocity, Quantity::acceleration,
                                                  Quantity::displacement}));
  // One complex division each: rounding only.
  const std::array<cd, 3> expected{Xa, Xb, Xc};
  for (int j = 0; j < 3; ++j) {
    EXPECT_LE(std::abs(m.X(1, j) - expected[j]), 1e-14 * std::abs(expected[j])) << j;
    for (int k : {0, 2, 3})
      EXPECT_EQ(m.X(k, j), cd(0.0));
    EXPECT_TRUE(std::isnan(m.X_variance(1, j)));
    EXPECT_FALSE(m.has_mean[j]);
  }
  EXPECT_EQ(m.F(1, 0), F);
  EXPECT_TRUE(std::isnan(m.F_variance(1, 0)));
  EXPECT_DOUBLE_EQ(force_level(m), 40.0);
  // The period for the basis functions is the fundamental's sinusoid.
  for (Eigen::Index i = 0; i < m.t.size(); i += 7) {
    const cd e = std::polar(1.0, w * m.t(i));
    EXPECT_NEAR(m.x(i, 0), (Xa * e).real(), 1e-12 * std::abs(Xa));
    EXPECT_NEAR(m.v(i, 1), (cd(0.0, w) * Xb * e).real(), 1e-12 * w * std::abs(Xb));
  }
  EXPECT_LT(m.t(m.t.size() - 1), 1.0 / f); // one period, end excluded
}

TEST(Measure, RecordsHaveEveryHarmonicUpToK) {
  const Measurement m = measure(make_record(256, 2, {Quantity::displacement}), {.harmonics = 5});
  for (int k = 0; k <= 5; ++k)
    EXPECT_TRUE(m.has_harmonic(k)) << k;
  EXPECT_FALSE(m.has_harmonic(6));
  EXPECT_FALSE(m.has_harmonic(-1));
  EXPECT_EQ(m.X.rows(), 6);
  // Harmonics 4 and 5 are absent from the signal.
  EXPECT_LE(std::abs(m.X(4, 0)) + std::abs(m.X(5, 0)), exact * std::abs(X_true[1]));
}

TEST(Measure, ForceLevelIsTheLargestFundamentalForce) {
  Record r = make_record(256, 2, {Quantity::displacement});
  Eigen::VectorXd second(r.t.size());
  for (Eigen::Index i = 0; i < r.t.size(); ++i)
    second(i) = 120.0 * std::cos(omega * r.t(i) + 0.3) + 500.0 * std::sin(3 * omega * r.t(i));
  r.channels.push_back({Quantity::force, mid, second});
  const Measurement m = measure(r);
  ASSERT_EQ(m.force_at, (std::vector<fem::NodeDof>{tip, mid}));
  EXPECT_EQ(m.force_index(mid), 1);
  EXPECT_EQ(m.force_index(root), -1);
  EXPECT_EQ(m.response_index(tip), 0);
  EXPECT_EQ(m.response_index(mid), -1);
  // 120 N beats 80 N; the 500 N third harmonic does not count.
  EXPECT_NEAR(force_level(m), 120.0, 1e-9 * 120.0);
}

TEST(Measure, ErrorsNameTheSource) {
  Record no_force = make_record(256, 2, {Quantity::displacement});
  no_force.channels.erase(no_force.channels.begin());
  std::string e = error_of(no_force);
  EXPECT_NE(e.find("synthetic.csv"), std::string::npos) << e;
  // Worded for every format a record comes from (no CSV "column" in a UFF58 record's message).
  EXPECT_NE(e.find("no force channel among its channels (x@7:uy)"), std::string::npos) << e;
  EXPECT_EQ(e.find("column"), std::string::npos) << e;

  e = error_of(make_record(256, 2, {}));
  EXPECT_NE(e.find("synthetic.csv"), std::string::npos) << e;
  EXPECT_NE(e.find("no response channel among its channels (f@7:uy)"), std::string::npos) << e;
  EXPECT_NE(e.find("e.g. x@7:uy"), std::string::npos) << e;
  EXPECT_EQ(e.find("column"), std::string::npos) << e;

  // 16 samples a period: Nyquist at 8 f; harmonic 9 lies above it.
  e = error_of(make_record(16, 4, {Quantity::displacement}), {.harmonics = 9});
  EXPECT_NE(e.find("synthetic.csv"), std::string::npos) << e;
  EXPECT_NE(e.find("Nyquist"), std::string::npos) << e;
  EXPECT_NE(e.find("harmonic 9"), std::string::npos) << e;
  EXPECT_EQ(error_of(make_record(64, 4, {Quantity::displacement}), {.harmonics = 7}), "");

  e = error_of(make_record(256, 2, {Quantity::displacement}), {.harmonics = 0});
  EXPECT_NE(e.find("harmonic"), std::string::npos) << e;

  Phasors row;
  row.source = "table.csv:9";
  row.frequency_hz = 3.0;
  row.channels = {{Quantity::displacement, tip, cd(1e-3)}};
  e = error_of(row);
  EXPECT_NE(e.find("table.csv:9"), std::string::npos) << e;
  EXPECT_NE(e.find("no force channel"), std::string::npos) << e;
  row.channels = {{Quantity::force, tip, cd(0.0, -10.0)}};
  e = error_of(row);
  EXPECT_NE(e.find("table.csv:9"), std::string::npos) << e;
  EXPECT_NE(e.find("no response channel"), std::string::npos) << e;
}

// A stepped-sine row with zero force measured no force, as a record whose force channel is zero
// in every sample: every force zero is refused naming the row and channel; one of two is said.
TEST(Measure, ZeroForceInASteppedSineRowIsRefusedLikeARecords) {
  Phasors row;
  row.source = "table.csv:4";
  row.frequency_hz = 3.0;
  row.channels = {{Quantity::force, tip, cd(0.0, 0.0)}, {Quantity::displacement, tip, cd(1e-3)}};
  const std::string e = error_of(row);
  EXPECT_EQ(e, "table.csv:4: every force channel is zero (f@7:uy): no force was measured; a sine "
               "test needs its force");
  row.channels.push_back({Quantity::force, mid, cd(0.0, -10.0)});
  const Measurement m = measure(row, {});
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0], "table.csv:4: channel f@7:uy: zero (no force was measured there)");
  EXPECT_DOUBLE_EQ(force_level(m), 10.0);
}

TEST(Measure, RecordsTooShortForThePeriodOrTheHarmonicsAreNamed) {
  // 200 samples of a period of 256: 0.3125 s of a 0.4 s period.
  Record part = make_record(256, 1, {Quantity::displacement});
  part.t.conservativeResize(200);
  for (auto& c : part.channels)
    c.samples.conservativeResize(200);
  EXPECT_EQ(error_of(part), "synthetic.csv: shorter than one period of the excitation (2.5 Hz): "
                            "0.3125 s recorded, a period lasts 0.4 s");
  // 6.2 samples a period, 2 periods: one whole period of 6 samples, below Nyquist for
  // harmonic 3 (7.75 Hz > 7.5 Hz) but fewer than the 7 unknowns of harmonics 0 to 3.
  EXPECT_EQ(error_of(make_record(6.2, 2, {Quantity::displacement}), {.harmonics = 3}),
            "synthetic.csv: its whole periods hold 6 samples, too few to fit harmonics 0 to 3 (at "
            "least 7 needed: record more periods, or ask fewer harmonics)");
  // One period is measured, with a warning: its steadiness cannot be checked.
  const Measurement one =
      measure(make_record(256, 1, {Quantity::displacement, Quantity::velocity}));
  ASSERT_EQ(one.warnings.size(), 1u) << ::testing::PrintToString(one.warnings);
  EXPECT_EQ(one.warnings[0],
            "synthetic.csv: only 1 period; steady state cannot be checked (record at least 2)");
  expect_recovered(one, true);
}

TEST(Measure, SteadyStateWarningIgnoresNoiseButNotGrowth) {
  // 2 % white noise (σ = 0.02 × the channel's RMS) on a steady record: the two halves'
  // fundamentals differ by a complex Gaussian with E|δ|² = 8σ²/n_half ≈ (1.2e-3 |X1|)²,
  // against a threshold of 1e-3 + 8σ/√n_half/|X1| ≈ 4.5e-3: a false alarm has probability
  // exp(−(4.5/1.2)²) ≈ 1e-6 per record. Checked on 30 seeds.
  const Record clean = make_record(256, 8, {Quantity::displacement, Quantity::velocity});
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    Record r = clean;
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    for (auto& c : r.channels) {
      const double rms = std::sqrt((c.samples.array() - c.samples.mean()).square().mean());
      for (Eigen::Index i = 0; i < c.samples.size(); ++i)
        c.samples(i) += 0.02 * rms * normal(rng);
    }
    const Measurement m = measure(r);
    EXPECT_FALSE(has_warning(m, "not a steady state")) << "seed " << seed;
  }
  // The same record without noise, its response growing linearly by 1 % over the record: the
  // halves' fundamentals differ by ≈ 0.5 %, five times the 1e-3 tolerance (the growth's own
  // period-to-period scatter adds only ≈ 5e-4 of allowance).
  Record growing = clean;
  const double span = clean.t(clean.t.size() - 1) - clean.t(0);
  for (std::size_t c = 1; c < growing.channels.size(); ++c)
    for (Eigen::Index i = 0; i < growing.t.size(); ++i)
      growing.channels[c].samples(i) *= 1.0 + 0.01 * (growing.t(i) - growing.t(0)) / span;
  // Its periods (whole numbers of samples) are checked first: every one differs from the next
  // beyond the (zero) noise, so the record does not repeat and is left out, named (issue 30).
  const Measurement left = measure(growing);
  EXPECT_FALSE(left.left_out.empty());
  EXPECT_EQ(left.left_out.rfind("synthetic.csv: periods 1 and 2, 2 and 3", 0), 0u) << left.left_out;
  EXPECT_NE(left.left_out.find("does not repeat"), std::string::npos) << left.left_out;
  // Without that check (periods not averaged), the halves' fundamentals warn.
  MeasureOptions halves;
  halves.average_periods = false;
  const Measurement m = measure(growing, halves);
  EXPECT_TRUE(m.left_out.empty());
  EXPECT_TRUE(has_warning(m, "not a steady state")) << ::testing::PrintToString(m.warnings);
  EXPECT_TRUE(has_warning(m, "synthetic.csv"));
  // It names the channel, the change and the limit (≈ 0.5 % against ≈ 0.15 %).
  std::string text;
  for (const auto& w : m.warnings)
    if (w.find("not a steady state") != std::string::npos) text = w;
  EXPECT_EQ(text.rfind("synthetic.csv: x@", 0), 0u) << text;
  EXPECT_NE(text.find("differ by 0.49"), std::string::npos) << text;
  EXPECT_NE(text.find("limit 0.15"), std::string::npos) << text;
  EXPECT_FALSE(has_warning(measure(clean), "not a steady state"));
}

TEST(Measure, ManyTests) {
  const std::vector<SineTest> tests{
      make_record(256, 2, {Quantity::displacement}),
      Phasors{"t.csv:2",
              3.0,
              {{Quantity::force, tip, cd(0.0, -1.0)}, {Quantity::displacement, tip, cd(1e-3)}}}};
  EXPECT_EQ(source_of(tests[0]), "synthetic.csv");
  EXPECT_EQ(source_of(tests[1]), "t.csv:2");
  const std::vector<Measurement> m = measure(tests, {.harmonics = 2});
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].harmonics, 2);
  EXPECT_FALSE(m[0].fundamental_only);
  EXPECT_TRUE(m[1].fundamental_only);
}
