// Sine sweeps reduced to stepped-sine rows, against the stepped-sine response of the same
// system (its receptance H(ω), exact) — and the sweep rate's bias the rows state, against the
// error they actually have.
#include "identify/sweep.hpp"

#include "support/cantilever.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <string>
#include <vector>

using namespace jointid;
using namespace jointid::identify;

namespace {

using jointid::test::two_pi;
using Complex = std::complex<double>;
using jointid::test::tip;

// One degree of freedom: m = 1 kg, 5 Hz, damping ratio ζ.
struct Oscillator {
  double zeta = 0.05;
  double wn = two_pi * 5.0;
  Complex H(double w) const { return 1.0 / (wn * wn - w * w + Complex(0.0, 2.0 * zeta * wn * w)); }
};

// A linear sweep f0 → f1 Hz over T s, sampled at `rate`, driving the oscillator from rest; its
// response by the classical Runge–Kutta method with 8 steps a sample (an error of (ωh)⁴/120
// ≈ 1e-9 at 7 Hz: nothing next to the sweep's bias). White noise of `noise` × RMS added.
Record sweep(const Oscillator& s, double f0, double f1, double T, double rate, double noise,
             bool declared = true) {
  const double alpha = (f1 - f0) / T;
  auto force = [&](double t) { return std::sin(two_pi * (f0 * t + 0.5 * alpha * t * t)); };
  const int n = static_cast<int>(std::lround(T * rate)), sub = 8;
  const double h = 1.0 / (rate * sub);
  Record r;
  r.source = "sweep.csv";
  r.sweep = declared;
  r.t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / rate);
  Eigen::VectorXd f(n), x(n), v(n);
  double y = 0.0, u = 0.0, t = 0.0;
  auto acc = [&](double tt, double yy, double uu) {
    return force(tt) - 2.0 * s.zeta * s.wn * uu - s.wn * s.wn * yy;
  };
  for (int i = 0; i < n; ++i) {
    f(i) = force(r.t(i));
    x(i) = y;
    v(i) = u;
    for (int j = 0; j < sub; ++j) {
      const double k1y = u, k1u = acc(t, y, u);
      const double k2y = u + 0.5 * h * k1u, k2u = acc(t + 0.5 * h, y + 0.5 * h * k1y, k2y);
      const double k3y = u + 0.5 * h * k2u, k3u = acc(t + 0.5 * h, y + 0.5 * h * k2y, k3y);
      const double k4y = u + h * k3u, k4u = acc(t + h, y + h * k3y, k4y);
      y += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
      u += h / 6.0 * (k1u + 2.0 * k2u + 2.0 * k3u + k4u);
      t += h;
    }
  }
  std::mt19937_64 gen(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Eigen::VectorXd* c : {&f, &x, &v}) {
    const double rms = std::sqrt(c->squaredNorm() / n);
    for (int i = 0; i < n; ++i)
      (*c)(i) += noise * rms * normal(gen);
  }
  r.channels = {
      {Quantity::force, tip, f}, {Quantity::displacement, tip, x}, {Quantity::velocity, tip, v}};
  return r;
}

RecordClass declared_sweep() {
  RecordClass c;
  c.kind = RecordKind::sweep;
  c.declared = true;
  c.evidence = "declared: excitation = sweep";
  return c;
}

struct Errors {
  double largest_error = 0.0, largest_bias = 0.0; // over rows in the middle of the sweep
  double error_at_peak = 0.0, bias_at_peak = 0.0; // the row nearest the resonance
  int rows = 0;
};

// Every row's FRF X_1/F_1 against H(ω) at the row's frequency (4–6 Hz: away from the start,
// where the free vibration of the start dies away, and from the ends).
Errors against_stepped_sine(const Oscillator& s, const std::vector<Measurement>& rows) {
  Errors e;
  double nearest = 1e9;
  for (const Measurement& m : rows) {
    if (m.frequency_hz < 4.0 || m.frequency_hz > 6.0) continue;
    ++e.rows;
    const Complex H = s.H(two_pi * m.frequency_hz);
    const double error = std::abs(m.X(1, 0) / m.F(1, 0) - H) / std::abs(H);
    e.largest_error = std::max(e.largest_error, error);
    e.largest_bias = std::max(e.largest_bias, m.sweep_bias);
    if (std::abs(m.frequency_hz - 5.0) < nearest) {
      nearest = std::abs(m.frequency_hz - 5.0);
      e.error_at_peak = error;
      e.bias_at_peak = m.sweep_bias;
    }
  }
  return e;
}

} // namespace

TEST(ReduceSweep, RowsAreTheSteppedSineResponseUpToTheStatedBias) {
  // 3 → 7 Hz at 0.05 Hz/s through a 5 Hz mode of 5 % damping. The first-order bias at the
  // peak: ½ ω̇ |H''/H| with ω̇ = 2π·0.05 and |H''/H| ≈ 2/(ζω_n)² = 0.81: about 13 %.
  const Oscillator s;
  MeasureOptions o;
  o.harmonics = 3;
  const std::vector<Measurement> rows =
      reduce_sweep(sweep(s, 3.0, 7.0, 80.0, 200.0, 0.0), declared_sweep(), o);
  const Errors e = against_stepped_sine(s, rows);
  ASSERT_GE(e.rows, 8);
  for (const Measurement& m : rows) {
    EXPECT_EQ(m.kind, RecordKind::sweep);
    // The rate from the phase's curvature (the analytic signal's phase bends at the record's
    // ends: the first and last windows are left out of this check).
    if (m.frequency_hz > 3.5 && m.frequency_hz < 6.5) {
      EXPECT_NEAR(m.sweep_rate_hz_per_s, 0.05, 0.005) << m.source;
    }
  }
  // The stated bias is the error's size, not merely a bound: at the peak within a factor of
  // two (the first-order expansion and the curvature read from rows 0.1–0.2 Hz apart).
  RecordProperty("bias_at_peak", std::to_string(e.bias_at_peak));
  RecordProperty("error_at_peak", std::to_string(e.error_at_peak));
  EXPECT_GT(e.bias_at_peak, 0.05);
  EXPECT_LT(e.error_at_peak, 2.0 * e.bias_at_peak);
  EXPECT_GT(e.error_at_peak, 0.5 * e.bias_at_peak);
  // And it bounds the error everywhere in the middle of the sweep (with the same factor).
  EXPECT_LT(e.largest_error, 2.0 * e.largest_bias);
  // The warning says so, naming the record.
  bool said = false;
  for (const auto& w : rows.front().warnings)
    said = said || (w.find("sweep.csv") != std::string::npos &&
                    w.find("sweep rate biases") != std::string::npos);
  EXPECT_TRUE(said);
}

TEST(ReduceSweep, ASlowerSweepHasASmallerBiasAndMatchesSteppedSine) {
  // Ten times slower (0.005 Hz/s would take 800 s: 4.5 → 5.5 Hz over 200 s instead), with 1 %
  // noise: the bias ten times smaller, about 1.3 % at the peak; the rows agree with H(ω) to it
  // and their noise.
  const Oscillator s;
  MeasureOptions o;
  o.harmonics = 3;
  const std::vector<Measurement> fast =
      reduce_sweep(sweep(s, 3.0, 7.0, 80.0, 200.0, 0.0), declared_sweep(), o);
  const std::vector<Measurement> slow =
      reduce_sweep(sweep(s, 4.5, 5.5, 200.0, 100.0, 0.01), declared_sweep(), o);
  const Errors ef = against_stepped_sine(s, fast), es = against_stepped_sine(s, slow);
  ASSERT_GE(es.rows, 8);
  RecordProperty("slow_bias_at_peak", std::to_string(es.bias_at_peak));
  RecordProperty("slow_error_at_peak", std::to_string(es.error_at_peak));
  EXPECT_LT(es.bias_at_peak, 0.25 * ef.bias_at_peak);
  EXPECT_LT(es.error_at_peak, 0.25 * ef.error_at_peak);
  EXPECT_LT(es.error_at_peak, 0.03);
}

TEST(ReduceSweep, ATooShortRecordIsRefusedNamingIt) {
  const Oscillator s;
  MeasureOptions o;
  o.harmonics = 3;
  const Record r = sweep(s, 3.0, 3.1, 0.3, 200.0, 0.0); // under two periods of 3 Hz
  try {
    reduce_sweep(r, declared_sweep(), o);
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sweep.csv"), std::string::npos) << e.what();
  }
}
