#include "identify/harmonics.hpp"

#include "fem/fft.hpp"
#include "fem/minimise.hpp"

#include <Eigen/Dense>
#include <algorithm>
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
  // The peak of the Hann-windowed spectrum (bins of 1/(n dt) Hz), then the parabola through the
  // logarithms of its magnitude and its neighbours' (a window whose main lobe is nearly
  // Gaussian: good to a few hundredths of a bin).
  const double mean = x.mean();
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i)
    w(i) = (x(i) - mean) * 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * i / n));
  fem::RealFft fft(n);
  const Eigen::VectorXd magnitude = fft.forward(w).cwiseAbs();
  Eigen::Index peak = 1;
  magnitude.tail(magnitude.size() - 1).maxCoeff(&peak);
  peak += 1;
  double offset = 0.0;
  if (peak + 1 < magnitude.size()) {
    const double a = std::log(std::max(magnitude(peak - 1), 1e-300)),
                 b = std::log(std::max(magnitude(peak), 1e-300)),
                 c = std::log(std::max(magnitude(peak + 1), 1e-300));
    const double curvature = a - 2.0 * b + c;
    if (curvature < 0.0) offset = std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
  }
  const double bin = 1.0 / (n * dt), estimate = (static_cast<double>(peak) + offset) * bin;
  // Refinement: minimise the residual of a mean + sine fit (zero at the true frequency of a pure
  // sinusoid; the fitted amplitude is not a safe criterion, it can exceed the true one
  // off-frequency on a non-whole number of periods). O(n) per evaluation.
  auto misfit = [&](double f) {
    const double omega = 2.0 * std::numbers::pi * f;
    const Eigen::VectorXcd X = fit_harmonics(t, x, omega, 1);
    double ss = 0.0;
    for (int i = 0; i < n; ++i)
      ss += std::pow(x(i) - X(0).real() - (X(1) * std::polar(1.0, omega * t(i))).real(), 2);
    return ss;
  };
  return fem::golden_section_minimum(misfit, std::max(estimate - bin, 0.25 * bin),
                                     std::min(estimate + bin, 0.5 / dt), 80, 1e-12 * estimate);
}

Eigen::MatrixXcd period_harmonics(const Eigen::MatrixXd& x, double t0, double omega, int K) {
  const auto N = static_cast<int>(x.rows());
  if (K < 0 || 2 * K >= N)
    throw std::invalid_argument("period_harmonics: harmonic " + std::to_string(K) +
                                " is not below half the " + std::to_string(N) +
                                " samples of the period");
  fem::RealFft fft(N);
  Eigen::MatrixXcd X(K + 1, x.cols());
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    const Eigen::VectorXcd S = fft.forward(x.col(j));
    X(0, j) = S(0).real() / N;
    for (int k = 1; k <= K; ++k) // x(t) = Re(X_k e^{ikω(t − t0)}) · …: shift to absolute time
      X(k, j) = (2.0 / N) * S(k) * std::polar(1.0, -k * omega * t0);
  }
  return X;
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

Eigen::VectorXd synthesise(const Eigen::VectorXd& t, const Eigen::VectorXcd& X, double omega) {
  Eigen::VectorXd x = Eigen::VectorXd::Constant(t.size(), X(0).real());
  for (Eigen::Index i = 0; i < t.size(); ++i)
    for (Eigen::Index k = 1; k < X.size(); ++k)
      x(i) += (X(k) * std::polar(1.0, static_cast<double>(k) * omega * t(i))).real();
  return x;
}

Eigen::VectorXcd differentiate(const Eigen::VectorXcd& X, double omega, int power) {
  Eigen::VectorXcd Y(X.size());
  Y(0) = 0.0;
  for (Eigen::Index k = 1; k < X.size(); ++k)
    Y(k) = X(k) * std::pow(std::complex<double>(0.0, static_cast<double>(k) * omega), power);
  return Y;
}

} // namespace jointid::identify
