// backbone_figure(): part of jointid_report, with the other figures.
#include "report/backbone_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace jointid::report {

Figure backbone_figure(const frf::Backbone& b,
                       const std::vector<identify::MeasuredBackbonePoint>& measured) {
  const std::string dof = fem::to_string(b.amplitude_dof);
  const char* unit = fem::is_rotation(b.amplitude_dof.dof) ? "rad" : "m";
  Series model_f, model_d, measured_f, measured_d, linear_f, linear_d;
  model_f.label = model_d.label = "model (EPMC)";
  model_f.color = model_d.color = palette_color(0);
  model_f.width = model_d.width = 2.5;
  for (const frf::BackbonePoint& p : b.points) {
    model_f.x.push_back(p.amplitude), model_f.y.push_back(p.frequency_hz);
    model_d.x.push_back(p.amplitude), model_d.y.push_back(100.0 * p.damping_ratio);
  }
  measured_f.label = measured_d.label = "measured (one-mode fit per level)";
  measured_f.style = measured_d.style = Series::Style::points;
  measured_f.color = measured_d.color = palette_color(1);
  measured_f.width = measured_d.width = 8.0;
  for (const identify::MeasuredBackbonePoint& m : measured) {
    if (!m.fit.status.ok() || !(m.fit.amplitude > 0.0)) continue;
    measured_f.x.push_back(m.fit.amplitude), measured_f.y.push_back(m.fit.frequency_hz);
    measured_d.x.push_back(m.fit.amplitude), measured_d.y.push_back(100.0 * m.fit.damping_ratio);
  }
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const auto* s : {&model_f, &measured_f})
    for (double x : s->x)
      lo = std::min(lo, x), hi = std::max(hi, x);
  if (!(hi > 0.0)) throw std::invalid_argument("backbone figure: no point to draw");
  if (b.linear.frequency_hz > 0.0) {
    linear_f.label = linear_d.label = "linear mode";
    linear_f.style = linear_d.style = Series::Style::dashed;
    linear_f.color = linear_d.color = {110, 110, 110};
    linear_f.x = linear_d.x = {lo, hi};
    linear_f.y = {b.linear.frequency_hz, b.linear.frequency_hz};
    linear_d.y = {100.0 * b.linear.damping_ratio, 100.0 * b.linear.damping_ratio};
  }
  const std::string x_label = fmt::format("amplitude |X1| at {} ({}, peak)", dof, unit);
  Chart frequency, damping;
  frequency.title = fmt::format("Mode {}: natural frequency", b.mode);
  frequency.x_label = damping.x_label = x_label;
  frequency.y_label = "natural frequency (Hz)";
  damping.title = fmt::format("Mode {}: damping ratio", b.mode);
  damping.y_label = "damping ratio (%)";
  frequency.log_x = damping.log_x = true;
  for (auto [chart, model, linear, test] :
       {std::tuple{&frequency, &model_f, &linear_f, &measured_f},
        std::tuple{&damping, &model_d, &linear_d, &measured_d}}) {
    if (!linear->x.empty()) chart->series.push_back(*linear);
    if (!model->x.empty()) chart->series.push_back(*model);
    if (!test->x.empty()) chart->series.push_back(*test);
  }
  Figure figure;
  figure.width = 1500;
  figure.height = 650;
  figure.columns = 2;
  figure.charts = {std::move(frequency), std::move(damping)};
  return figure;
}

} // namespace jointid::report
