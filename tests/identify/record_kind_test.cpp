// What kind of test a record is: a sine test, a periodic broadband test or a sweep, told from
// its force channel (or its comments); anything else refused, saying so.
#include "identify/record_kind.hpp"

#include "support/cantilever.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

using namespace jointid;
using namespace jointid::identify;

namespace {

using jointid::test::tip;
using jointid::test::two_pi;

// A record of n samples at `rate` Hz whose force is f(t) (plus white noise of `noise` × its
// RMS) and whose response is the force scaled (the kind is told from the force alone).
template <class Force>
Record record(int n, double rate, Force f, double noise = 0.0, std::uint64_t seed = 3) {
  Record r;
  r.source = "test.csv";
  r.t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / rate);
  Eigen::VectorXd force(n);
  for (int i = 0; i < n; ++i)
    force(i) = f(r.t(i));
  const double rms = std::sqrt(force.squaredNorm() / n);
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < n; ++i)
    force(i) += noise * rms * normal(gen);
  r.channels = {{Quantity::force, tip, force}, {Quantity::displacement, tip, 1e-4 * force}};
  return r;
}

// The ground-vibration test of issue 30: a multisine of 2–15 Hz (lines every 400/8192 Hz,
// Schroeder phases, or random ones) sampled at 400 Hz, 8192 samples a period, `periods` periods.
Record multisine(int periods, double noise = 0.0, bool schroeder = true) {
  constexpr int N = 8192;
  constexpr double rate = 400.0, df = rate / N;
  const int from = static_cast<int>(std::ceil(2.0 / df)), to = static_cast<int>(15.0 / df);
  const int lines = to - from + 1;
  Record r;
  r.source = "gvt.csv";
  const int n = N * periods;
  r.t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / rate);
  // By the period's inverse FFT would be faster; the sum is independent of the code under test.
  Eigen::VectorXd one = Eigen::VectorXd::Zero(N);
  std::mt19937_64 phases(23);
  std::uniform_real_distribution<double> uniform(0.0, two_pi);
  for (int k = from; k <= to; ++k) {
    const int j = k - from;
    const double phase = schroeder ? -std::numbers::pi * j * (j + 1) / lines : uniform(phases);
    for (int i = 0; i < N; ++i)
      one(i) += std::cos(two_pi * k * i / N + phase);
  }
  Eigen::VectorXd force(n);
  for (int p = 0; p < periods; ++p)
    force.segment(p * N, N) = one;
  std::mt19937_64 gen(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double rms = std::sqrt(one.squaredNorm() / N);
  for (int i = 0; i < n; ++i)
    force(i) += noise * rms * normal(gen);
  r.channels = {{Quantity::force, tip, force}, {Quantity::acceleration, tip, 1e-2 * force}};
  return r;
}

std::string refusal(const Record& r) {
  try {
    classify(r);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(ClassifyRecord, ASineOffTheBinsIsASineAtItsFrequency) {
  // 7.3456 Hz is no whole number of cycles in 4096 samples at 400 Hz; 5 % noise. The
  // least-squares frequency of a sine in white noise has a standard deviation of
  // √(6/N³)·σ/(π A Δt)-ish ≈ 1e-6 Hz here: 1e-4 Hz is well beyond chance.
  const double f0 = 7.3456;
  const Record r = record(
      4096, 400.0, [&](double t) { return 3.0 * std::sin(two_pi * f0 * t + 0.4); }, 0.05);
  const RecordClass c = classify(r);
  EXPECT_EQ(c.kind, RecordKind::sine);
  EXPECT_FALSE(c.declared);
  EXPECT_NEAR(c.frequency_hz, f0, 1e-4);
}

TEST(ClassifyRecord, AMultisineIsPeriodicWithItsPeriodNotOneOfItsLines) {
  // Issue 30: this record was taken as a sine at one of its lines.
  const RecordClass c = classify(multisine(9, 0.02));
  EXPECT_EQ(c.kind, RecordKind::periodic);
  EXPECT_EQ(c.period_samples, 8192);
  EXPECT_NEAR(c.period_s, 8192 / 400.0, 1e-12);
}

TEST(ClassifyRecord, ADeclaredPeriodIsTakenAndCheckedAgainstTheSampling) {
  Record r = multisine(2);
  r.period_s = 20.48;
  const RecordClass c = classify(r);
  EXPECT_EQ(c.kind, RecordKind::periodic);
  EXPECT_TRUE(c.declared);
  EXPECT_EQ(c.period_samples, 8192);
  r.period_s = 20.0011; // 8000.44 samples
  const std::string why = refusal(r);
  EXPECT_NE(why.find("gvt.csv"), std::string::npos) << why;
  EXPECT_NE(why.find("period_s"), std::string::npos) << why;
  EXPECT_NE(why.find("whole number of samples"), std::string::npos) << why;
  r.period_s = 100.0; // longer than the record (40.96 s)
  EXPECT_NE(refusal(r).find("longer than the record"), std::string::npos) << refusal(r);
}

TEST(ClassifyRecord, ALinearSweepIsASweepOverItsRange) {
  // 2 → 20 Hz in 60 s at 200 Hz: φ = 2π (f0 t + ½ α t²), α = 0.3 Hz/s.
  const double f0 = 2.0, f1 = 20.0, T = 60.0, alpha = (f1 - f0) / T;
  const Record r = record(
      12000, 200.0, [&](double t) { return std::sin(two_pi * (f0 * t + 0.5 * alpha * t * t)); });
  const RecordClass c = classify(r);
  ASSERT_EQ(c.kind, RecordKind::sweep);
  // The spectrogram's 16 windows of 3.75 s: their centres are at 1.9 s and 58.1 s, where the
  // frequency is 2.56 and 19.4 Hz; the peak is read to a fraction of a bin (0.27 Hz).
  EXPECT_NEAR(c.sweep_from_hz, f0 + alpha * 1.875, 0.3);
  EXPECT_NEAR(c.sweep_to_hz, f0 + alpha * (T - 1.875), 0.3);
}

TEST(ClassifyRecord, RandomExcitationIsRefusedSayingWhatItIsNot) {
  // White noise: no line, no period, no sweep.
  std::mt19937_64 gen(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Record r = record(16384, 400.0, [&](double) { return normal(gen); });
  const std::string why = refusal(r);
  EXPECT_NE(why.find("test.csv"), std::string::npos) << why;
  EXPECT_NE(why.find("neither a sine test, a periodic test nor a sweep"), std::string::npos) << why;
  EXPECT_NE(why.find("f@7:uy"), std::string::npos) << why;
  for (const char* comment : {"excitation_hz", "period_s", "excitation = sweep"})
    EXPECT_NE(why.find(comment), std::string::npos) << comment << ": " << why;
}

TEST(ClassifyRecord, OnePeriodOfAMultisineIsRefused) {
  // A periodic test needs its period seen at least twice. (Random phases: one period of a
  // Schroeder multisine is a chirp — its frequency rises through the period — and is rightly
  // taken as a sweep.)
  const std::string why = refusal(multisine(1, 0.0, false));
  EXPECT_NE(why.find("neither a sine test, a periodic test nor a sweep"), std::string::npos) << why;
}

TEST(ClassifyRecord, AZeroForceIsRefused) {
  const Record r = record(1024, 100.0, [](double) { return 0.0; });
  EXPECT_NE(refusal(r).find("zero in every sample"), std::string::npos) << refusal(r);
}
