#include "fem/excitation.hpp"

#include "fem/constants.hpp"
#include "fem/fft.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

namespace jointid::fem {

namespace {

std::string str(double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.10g", x);
  return buffer;
}

int sample_count(const Sampling& s, const char* what) {
  if (!(std::isfinite(s.sample_rate_hz) && s.sample_rate_hz > 0.0))
    throw std::invalid_argument(std::string(what) + ": expected a sample rate > 0 Hz, got " +
                                str(s.sample_rate_hz));
  if (!(std::isfinite(s.duration_s) && s.duration_s > 0.0))
    throw std::invalid_argument(std::string(what) + ": expected a duration > 0 s, got " +
                                str(s.duration_s));
  const double n = std::round(s.duration_s * s.sample_rate_hz);
  if (n < 4 || n > 2e9)
    throw std::invalid_argument(std::string(what) + ": duration × sample rate gives " + str(n) +
                                " samples; expected 4 to 2e9");
  return static_cast<int>(n);
}

void check_band(double f0, double f1, const Sampling& s, const char* what, bool zero_ok) {
  const double nyquist = 0.5 * s.sample_rate_hz;
  if (!(std::isfinite(f0) && std::isfinite(f1) && (zero_ok ? f0 >= 0.0 : f0 > 0.0) && f1 > f0 &&
        f1 < nyquist))
    throw std::invalid_argument(std::string(what) + ": expected a band " +
                                (zero_ok ? "0 <= F0" : "0 < F0") +
                                " < F1 below half the sample rate (" + str(nyquist) + " Hz), got " +
                                str(f0) + ":" + str(f1) + " Hz");
}

void scale_to_rms(Eigen::VectorXd& x, double rms) {
  const double now = std::sqrt(x.squaredNorm() / static_cast<double>(x.size()));
  if (now > 0.0) x *= rms / now;
}

void check_rms(double rms, const char* what) {
  if (!(std::isfinite(rms) && rms > 0.0))
    throw std::invalid_argument(std::string(what) + ": expected an RMS > 0, got " + str(rms));
}

} // namespace

Eigen::VectorXd band_limited_random(const BandLimitedRandom& spec, const Sampling& sampling) {
  const int n = sample_count(sampling, "band-limited random");
  check_band(spec.f0_hz, spec.f1_hz, sampling, "band-limited random", true);
  check_rms(spec.rms, "band-limited random");
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd white(n);
  for (int i = 0; i < n; ++i)
    white(i) = normal(rng);
  RealFft fft(n);
  Eigen::VectorXcd X = fft.forward(white);
  const double df = sampling.sample_rate_hz / n;
  int kept = 0;
  for (Eigen::Index k = 0; k < X.size(); ++k) {
    const double f = static_cast<double>(k) * df;
    // The DC bin is left out: the force has a zero mean.
    if (k == 0 || f < spec.f0_hz || f > spec.f1_hz)
      X(k) = 0.0;
    else
      ++kept;
  }
  if (kept == 0)
    throw std::invalid_argument("band-limited random: no frequency line k/T (spacing " + str(df) +
                                " Hz) lies in the band " + str(spec.f0_hz) + ":" + str(spec.f1_hz) +
                                " Hz; lengthen the duration");
  Eigen::VectorXd x = fft.inverse(X);
  scale_to_rms(x, spec.rms);
  return x;
}

Eigen::VectorXd sine_sweep(const SineSweep& spec, const Sampling& sampling) {
  const int n = sample_count(sampling, "sine sweep");
  if (!(std::isfinite(spec.f0_hz) && std::isfinite(spec.f1_hz) && spec.f0_hz > 0.0 &&
        spec.f1_hz > 0.0 && spec.f0_hz < 0.5 * sampling.sample_rate_hz &&
        spec.f1_hz < 0.5 * sampling.sample_rate_hz))
    throw std::invalid_argument("sine sweep: expected frequencies > 0 below half the sample rate, "
                                "got " +
                                str(spec.f0_hz) + " and " + str(spec.f1_hz) + " Hz");
  if (!(std::isfinite(spec.amplitude) && spec.amplitude > 0.0))
    throw std::invalid_argument("sine sweep: expected an amplitude > 0, got " +
                                str(spec.amplitude));
  const double T = n / sampling.sample_rate_hz;
  Eigen::VectorXd x(n);
  const bool geometric = spec.logarithmic && spec.f1_hz != spec.f0_hz;
  const double r = geometric ? std::log(spec.f1_hz / spec.f0_hz) / T : 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = i / sampling.sample_rate_hz;
    const double phase =
        geometric ? two_pi * spec.f0_hz * std::expm1(r * t) / r
                  : two_pi * (spec.f0_hz * t + 0.5 * (spec.f1_hz - spec.f0_hz) * t * t / T);
    x(i) = spec.amplitude * std::sin(phase);
  }
  return x;
}

Eigen::VectorXd multisine(const Multisine& spec, const Sampling& sampling) {
  const int total = sample_count(sampling, "multisine");
  check_band(spec.f0_hz, spec.f1_hz, sampling, "multisine", false);
  check_rms(spec.rms, "multisine");
  int n = total; // samples of a period
  if (spec.period_s != 0.0) {
    const double per = spec.period_s * sampling.sample_rate_hz;
    if (!(std::isfinite(per) && per >= 4.0 && std::abs(per - std::round(per)) <= 1e-6 * per))
      throw std::invalid_argument("multisine: a period of " + str(spec.period_s) + " s holds " +
                                  str(per) + " samples at " + str(sampling.sample_rate_hz) +
                                  " Hz; expected a whole number of samples, at least 4");
    n = static_cast<int>(std::lround(per));
    if (total % n != 0)
      throw std::invalid_argument("multisine: the duration (" + str(total) +
                                  " samples) is not a whole number of periods of " + str(n) +
                                  " samples");
  }
  const double T = n / sampling.sample_rate_hz;
  const auto first = static_cast<long>(std::ceil(spec.f0_hz * T - 1e-9));
  const auto last = static_cast<long>(std::floor(spec.f1_hz * T + 1e-9));
  if (last < first || last < 1)
    throw std::invalid_argument("multisine: no line k/T (spacing " + str(1.0 / T) +
                                " Hz) in the band " + str(spec.f0_hz) + ":" + str(spec.f1_hz) +
                                " Hz; lengthen the duration");
  const long K = last - std::max(first, 1L) + 1;
  Eigen::VectorXcd X = Eigen::VectorXcd::Zero(n / 2 + 1);
  for (long k = std::max(first, 1L), j = 0; k <= last; ++k, ++j)
    X(k) = std::polar(1.0, -std::numbers::pi * static_cast<double>(j * (j + 1)) /
                               static_cast<double>(K));
  RealFft fft(n);
  Eigen::VectorXd period = fft.inverse(X);
  scale_to_rms(period, spec.rms);
  return period.replicate(total / n, 1);
}

} // namespace jointid::fem
