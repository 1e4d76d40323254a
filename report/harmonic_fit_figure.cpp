// harmonic_fit_figure(): part of jointid_io_output, with the other figures (the palette lives
// there).
#include "report/harmonic_fit_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <numbers>
#include <stdexcept>

namespace jointid::report {

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

std::vector<fem::NodeDof> harmonic_fit_dofs(const std::vector<joints::Joint>& joints) {
  std::vector<fem::NodeDof> shown;
  for (const joints::Joint& j : joints)
    for (const int node : {j.node, j.node_b})
      if (node != 0 &&
          std::find(shown.begin(), shown.end(), fem::NodeDof{node, j.dof}) == shown.end())
        shown.push_back({node, j.dof});
  return shown;
}

Figure parameter_figure(const identify::FitResult& result,
                        const std::vector<joints::Joint>& model_joints) {
  Chart chart;
  chart.title = "identified / model value, with the 95 % intervals";
  chart.y_label = "identified / model";
  chart.legend = false;
  Series values;
  values.style = Series::Style::points;
  values.width = 6.0;
  values.color = palette_color(0);
  std::vector<Series> intervals;
  for (const identify::JointEstimate& je : result.joints) {
    const auto given = std::find_if(model_joints.begin(), model_joints.end(),
                                    [&](const joints::Joint& j) { return j.name == je.name; });
    if (given == model_joints.end()) continue;
    for (const identify::TermEstimate& t : je.terms) {
      const int at = given->term_index(t.term);
      if (t.fixed || at < 0 || !given->has_value(static_cast<std::size_t>(at))) continue;
      const double reference = given->values[static_cast<std::size_t>(at)];
      if (reference == 0.0 || !std::isfinite(t.value)) continue;
      const double x = static_cast<double>(chart.x_categories.size() + 1);
      chart.x_categories.push_back(fmt::format("{} {}", je.name, joints::term_name(t.term)));
      values.x.push_back(x);
      values.y.push_back(t.value / reference);
      Series interval;
      interval.color = palette_color(0);
      interval.x = {x, x};
      interval.y = {t.ci_low / reference, t.ci_high / reference};
      if (std::isfinite(interval.y[0]) && std::isfinite(interval.y[1]))
        intervals.push_back(std::move(interval));
    }
  }
  if (values.x.empty())
    throw std::invalid_argument(
        "parameters: no identified term has a non-zero value in the model to compare with");
  Series one;
  one.style = Series::Style::dashed;
  one.color = {0, 0, 0};
  one.width = 1.0;
  one.x = {0.5, values.x.back() + 0.5};
  one.y = {1.0, 1.0};
  chart.series.push_back(std::move(one));
  for (Series& s : intervals)
    chart.series.push_back(std::move(s));
  chart.series.push_back(std::move(values));
  Figure figure;
  figure.width = std::max(600, 110 * static_cast<int>(chart.x_categories.size()) + 200);
  figure.height = 600;
  figure.charts.push_back(std::move(chart));
  return figure;
}

} // namespace jointid::report
