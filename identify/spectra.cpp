#include "identify/spectra.hpp"

#include "fem/fft.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::identify {

Eigen::VectorXd WelchSpectra::psd(int i) const {
  if (i < 0 || i >= static_cast<int>(G.size()))
    throw std::invalid_argument(fmt::format("spectra: no column {}", i));
  return G[static_cast<std::size_t>(i)].col(i).real();
}

WelchSpectra welch(const Eigen::MatrixXd& signals, double fs, const WelchOptions& o) {
  if (!(std::isfinite(fs) && fs > 0.0))
    throw std::invalid_argument(fmt::format("Welch: expected a sample rate > 0 Hz, got {}", fs));
  if (o.segment < 8)
    throw std::invalid_argument(
        fmt::format("Welch: expected a segment of at least 8 samples, got {}", o.segment));
  if (!(o.overlap >= 0.0 && o.overlap < 1.0))
    throw std::invalid_argument(
        fmt::format("Welch: expected an overlap from 0 to below 1, got {}", o.overlap));
  const int N = o.segment;
  if (signals.rows() < N)
    throw std::invalid_argument(fmt::format(
        "Welch: the record has {} samples, fewer than one segment of {}", signals.rows(), N));
  for (Eigen::Index c = 0; c < signals.cols(); ++c)
    for (Eigen::Index i = 0; i < signals.rows(); ++i)
      if (!std::isfinite(signals(i, c)))
        throw std::invalid_argument(
            fmt::format("Welch: sample {} of channel {} is {}, not a finite number", i + 1, c + 1,
                        signals(i, c)));
  const int step = std::max(1, static_cast<int>(std::lround(N * (1.0 - o.overlap))));
  const auto channels = signals.cols();
  Eigen::VectorXd window(N);
  for (int n = 0; n < N; ++n)
    window(n) = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * n / N);
  const double scale = 1.0 / (fs * window.squaredNorm());
  const int bins = N / 2 + 1;

  WelchSpectra s;
  s.frequency_hz = Eigen::VectorXd::LinSpaced(bins, 0.0, (bins - 1) * fs / N);
  s.resolution_hz = fs / N;
  s.noise_bandwidth_hz = 1.5 * fs / N;
  s.G.assign(static_cast<std::size_t>(channels), Eigen::MatrixXcd::Zero(bins, channels));
  fem::RealFft fft(N);
  Eigen::MatrixXcd X(bins, channels);
  for (Eigen::Index start = 0; start + N <= signals.rows(); start += step) {
    for (Eigen::Index c = 0; c < channels; ++c) {
      const auto segment = signals.col(c).segment(start, N);
      X.col(c) = fft.forward((segment.array() - segment.mean()).matrix().cwiseProduct(window));
    }
    for (Eigen::Index i = 0; i < channels; ++i)
      for (Eigen::Index j = 0; j < channels; ++j)
        s.G[static_cast<std::size_t>(i)].col(j) += X.col(i).conjugate().cwiseProduct(X.col(j));
    ++s.averages;
  }
  Eigen::VectorXd weight = Eigen::VectorXd::Constant(bins, 2.0 * scale / s.averages);
  weight(0) = scale / s.averages;
  if (N % 2 == 0) weight(bins - 1) = scale / s.averages;
  for (auto& g : s.G)
    g = weight.asDiagonal() * g;
  return s;
}

PowerSpectrum power_spectrum(const Eigen::VectorXd& x, double fs, const WelchOptions& o) {
  const WelchSpectra s = welch(x, fs, o);
  return {s.frequency_hz, s.psd(0), s.averages};
}

FrfEstimate h1_estimate(const Eigen::VectorXd& force, const Eigen::VectorXd& response, double fs,
                        const WelchOptions& o) {
  if (force.size() != response.size())
    throw std::invalid_argument(fmt::format("H1: the force has {} samples, the response {}",
                                            force.size(), response.size()));
  Eigen::MatrixXd both(force.size(), 2);
  both << force, response;
  const WelchSpectra s = welch(both, fs, o);
  FrfEstimate e;
  e.frequency_hz = s.frequency_hz;
  e.averages = s.averages;
  const Eigen::VectorXd Gff = s.psd(0), Gxx = s.psd(1);
  const Eigen::VectorXcd Gfx = s.G[0].col(1);
  e.H.resize(Gff.size());
  e.coherence.resize(Gff.size());
  for (Eigen::Index k = 0; k < Gff.size(); ++k) {
    e.H(k) = Gff(k) > 0.0 ? Gfx(k) / Gff(k) : std::complex<double>(0.0, 0.0);
    e.coherence(k) = Gff(k) > 0.0 && Gxx(k) > 0.0 ? std::norm(Gfx(k)) / (Gff(k) * Gxx(k)) : 0.0;
  }
  return e;
}

} // namespace jointid::identify
