#include "identify/harmonics.hpp"

#include "fem/minimise.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::identify {

Eigen::MatrixXcd fit_harmonics(const Eigen::VectorXd& t, const Eigen::MatrixXd& x, double omega,
                               int K) {
  const int n = static_cast<int>(t.size());
  if (K < 0) throw std::invalid_argument("fit_harmonics: K must be >= 0");
  if (n < 2 * K + 1)
    throw std::invalid_argument("fit_harmonics: " + std::to_string(n) +
                                " samples cannot determine " + std::to_string(K) + " harmonics");
  Eigen::MatrixXd D(n, 2 * K + 1);
  const double t0 = t(0); // fit on t − t0 for conditioning, then shift the phase back
  for (int i = 0; i < n; ++i) {
    D(i, 0) = 1.0;
    for (int k = 1; k <= K; ++k) {
      const double a = k * omega * (t(i) - t0);
      D(i, 2 * k - 1) = std::cos(a);
      D(i, 2 * k) = std::sin(a);
    }
  }
  const Eigen::MatrixXd c = D.colPivHouseholderQr().solve(x);
  Eigen::MatrixXcd X(K + 1, x.cols());
  for (int j = 0; j < x.cols(); ++j) {
    X(0, j) = c(0, j);
    for (int k = 1; k <= K; ++k)
      X(k, j) =
          std::complex<double>(c(2 * k - 1, j), -c(2 * k, j)) * std::polar(1.0, -k * omega * t0);
  }
  return X;
}

Eigen::VectorXcd fit_harmonics(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double omega,
                               int K) {
  return fit_harmonics(t, Eigen::MatrixXd(x), omega, K).col(0);
}

double estimate_frequency(const Eigen::VectorXd& t, const Eigen::VectorXd& x) {
  const int n = static_cast<int>(t.size());
  if (n < 4) throw std::invalid_argument("estimate_frequency: need at least 4 samples");
  const double span = t(n - 1) - t(0), dt = span / (n - 1);
  if (!(span > 0.0)) throw std::invalid_argument("estimate_frequency: time does not increase");
  const double mean = x.mean();
  auto power = [&](double f) {
    const double w = 2.0 * std::numbers::pi * f;
    double c = 0.0, s = 0.0;
    for (int i = 0; i < n; ++i) {
      c += (x(i) - mean) * std::cos(w * t(i));
      s += (x(i) - mean) * std::sin(w * t(i));
    }
    return c * c + s * s;
  };
  // Coarse grid at a quarter of the DFT resolution, up to Nyquist.
  const double df = 1.0 / (4.0 * span), f_max = 0.5 / dt;
  double best_f = df, best_p = -1.0;
  for (double f = df; f < f_max; f += df) {
    const double p = power(f);
    if (p > best_p) best_p = p, best_f = f;
  }
  // Golden-section refinement around the peak: minimise the residual of a mean + sine fit
  // (zero at the true frequency of a pure sinusoid; the fitted amplitude is not a safe
  // criterion, it can exceed the true one off-frequency on a non-whole number of periods).
  auto misfit = [&](double f) {
    const double w = 2.0 * std::numbers::pi * f;
    const Eigen::VectorXcd X = fit_harmonics(t, x, w, 1);
    double ss = 0.0;
    for (int i = 0; i < n; ++i)
      ss += std::pow(x(i) - X(0).real() - (X(1) * std::polar(1.0, w * t(i))).real(), 2);
    return ss;
  };
  return fem::golden_section_minimum(misfit, std::max(best_f - df, 1e-12), best_f + df, 80,
                                     1e-12 * best_f);
}

int whole_period_samples(const Eigen::VectorXd& t, double frequency_hz) {
  const int n = static_cast<int>(t.size());
  if (n < 2) return 0;
  const double dt = (t(n - 1) - t(0)) / (n - 1), T = 1.0 / frequency_hz;
  // The samples cover n·dt seconds (each sample stands for one interval).
  // In double until the count is known to fit an int: a frequency far above the sampling's (or
  // NaN) must not overflow the conversion.
  const double periods = std::floor(n * dt / T + 1e-9);
  if (!(periods >= 1.0)) return 0;
  const double samples = std::round(periods * T / dt);
  if (!(samples >= 0.0)) return 0;
  return samples >= n ? n : static_cast<int>(samples);
}

} // namespace jointid::identify
