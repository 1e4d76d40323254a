// harmonic_fit_figure(): part of jointid_io_output, with the other figures (the palette lives
// there).
#include "io/harmonic_fit_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <numbers>
#include <stdexcept>

namespace jointid::io {

Figure harmonic_fit_figure(const std::vector<identify::Measurement>& tests,
                           const std::vector<fem::NodeDof>& shown) {
  Figure figure;
  for (const identify::Measurement& m : tests) {
    Chart chart;
    chart.x_label = "t / T";
    chart.y_label = "displacement (m or rad)";
    double residual2 = 0.0, peak = 0.0;
    Eigen::Index samples = 0;
    for (std::size_t s = 0; s < shown.size(); ++s) {
      const int r = m.response_index(shown[s]);
      if (r < 0 || m.measured_as[static_cast<std::size_t>(r)] != identify::Quantity::displacement)
        continue;
      const double T = 1.0 / m.frequency_hz, w = 2.0 * std::numbers::pi * m.frequency_hz;
      const bool mean = m.has_mean[static_cast<std::size_t>(r)];
      const double offset = mean ? 0.0 : m.x.col(r).mean();
      Series points, fit;
      points.label = fem::to_string(shown[s]) + " record";
      fit.label = fem::to_string(shown[s]) + " harmonics 0-" + std::to_string(m.harmonics);
      points.style = Series::Style::points;
      points.width = 1.5;
      points.color = palette_color(s);
      fit.color = {0, 0, 0}; // black over the coloured samples
      fit.width = 1.5;
      auto fitted = [&](double t) {
        double value = 0.0;
        for (int k = mean ? 0 : 1; k <= m.harmonics; ++k)
          value += (m.X(k, r) * std::exp(std::complex<double>(0.0, k * w * t))).real();
        return value;
      };
      for (Eigen::Index i = 0; i < m.t.size(); ++i) {
        const double phase = std::fmod((m.t(i) - m.t(0)) / T, 1.0);
        points.x.push_back(phase);
        points.y.push_back(m.x(i, r) - offset);
        residual2 += std::pow(m.x(i, r) - offset - fitted(m.t(i)), 2);
        peak = std::max(peak, std::abs(m.x(i, r) - offset));
        ++samples;
      }
      for (int i = 0; i <= 200; ++i) {
        const double phase = i / 200.0;
        fit.x.push_back(phase);
        fit.y.push_back(fitted(m.t(0) + phase * T));
      }
      chart.series.push_back(std::move(points));
      chart.series.push_back(std::move(fit));
    }
    if (chart.series.empty()) continue;
    chart.title = fmt::format("{} ({:g} Hz): residual {:.2g} % of peak",
                              std::filesystem::path(m.source).filename().string(), m.frequency_hz,
                              100.0 * std::sqrt(residual2 / std::max<Eigen::Index>(samples, 1)) /
                                  std::max(peak, 1e-300));
    figure.charts.push_back(std::move(chart));
  }
  if (figure.charts.empty())
    throw std::invalid_argument(
        "harmonic fits: no test has a displacement channel at the DOFs shown");
  const auto n = static_cast<int>(figure.charts.size());
  figure.columns = std::min(n, 3);
  const int rows = (n + figure.columns - 1) / figure.columns;
  figure.width = 500 * figure.columns;
  figure.height = 380 * rows;
  return figure;
}

} // namespace jointid::io
