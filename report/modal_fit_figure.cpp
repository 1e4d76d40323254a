// stabilisation_figure(), modal_fit_figure(): part of jointid_report, with the other figures.
#include "report/modal_fit_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

namespace jointid::report {

namespace {

constexpr std::array<int, 3> grey{170, 170, 170}, blue{31, 119, 180}, green{44, 160, 44},
    red{214, 39, 40}, black{0, 0, 0}, orange{255, 127, 14};

// The unit of a receptance from the driving point to a response.
std::string unit(const fem::NodeDof& response, const fem::NodeDof& drive) {
  const bool turn = fem::is_rotation(response.dof), moment = fem::is_rotation(drive.dof);
  return std::string(turn ? "rad" : "m") + "/" + (moment ? "(N m)" : "N");
}

double degrees(std::complex<double> h) {
  return std::arg(h) * 180.0 / std::numbers::pi;
}

/// A phase drawn as a line, split where it wraps (a jump of more than 180°), so that no line
/// crosses the chart there; the pieces after the first have no legend entry.
std::vector<Series> split_at_wraps(const Series& phase) {
  std::vector<Series> pieces;
  Series piece = phase;
  piece.x.clear();
  piece.y.clear();
  for (std::size_t i = 0; i < phase.x.size(); ++i) {
    if (!piece.x.empty() && std::abs(phase.y[i] - piece.y.back()) > 180.0) {
      pieces.push_back(piece);
      piece.label.clear();
      piece.x.clear();
      piece.y.clear();
    }
    piece.x.push_back(phase.x[i]);
    piece.y.push_back(phase.y[i]);
  }
  if (!piece.x.empty()) pieces.push_back(std::move(piece));
  return pieces;
}

} // namespace

Figure stabilisation_figure(const identify::ModalFit& fit, const identify::MeasuredFrfs& data) {
  Chart chart;
  chart.title = fmt::format("stabilisation diagram (LSCF), {} mode{} chosen", fit.modes.size(),
                            fit.modes.size() == 1 ? "" : "s");
  chart.x_label = "frequency (Hz)";
  chart.y_label = "model order";
  const double top = std::max(2, fit.max_order) + 2.0;

  // The mean |H| over the responses, its logarithm mapped onto orders 0 … top.
  const Eigen::Index L = data.num_lines();
  if (L > 1) {
    Eigen::VectorXd level(L);
    for (Eigen::Index j = 0; j < L; ++j)
      level(j) = std::log10(std::max(data.H.row(j).cwiseAbs().mean(), 1e-300));
    const double lo = level.minCoeff(), hi = level.maxCoeff();
    Series mean;
    mean.label = "mean |H| (log scale)";
    mean.color = grey;
    mean.width = 1.5;
    for (Eigen::Index j = 0; j < L; ++j) {
      mean.x.push_back(data.frequency_hz(j));
      mean.y.push_back(hi > lo ? top * (level(j) - lo) / (hi - lo) : 0.5 * top);
    }
    chart.series.push_back(std::move(mean));
  }
  Series fresh, frequency, stable;
  fresh.label = "new pole";
  fresh.color = {120, 120, 120};
  fresh.style = frequency.style = stable.style = Series::Style::points;
  fresh.width = 1.0;
  frequency.label = "stable frequency";
  frequency.color = blue;
  frequency.width = 1.3;
  stable.label = "stable frequency and damping";
  stable.color = green;
  stable.width = 1.8;
  for (const identify::DiagramPole& p : fit.diagram) {
    Series& s = p.stability == identify::PoleStability::stable      ? stable
                : p.stability == identify::PoleStability::frequency ? frequency
                                                                    : fresh;
    s.x.push_back(p.frequency_hz);
    s.y.push_back(p.order);
  }
  for (Series* s : {&fresh, &frequency, &stable})
    if (!s->x.empty()) chart.series.push_back(std::move(*s));
  for (std::size_t r = 0; r < fit.modes.size(); ++r) {
    Series line;
    line.label = r == 0 ? "mode chosen" : "";
    line.color = red;
    line.style = Series::Style::dashed;
    line.width = 1.5;
    line.x = {fit.modes[r].frequency_hz, fit.modes[r].frequency_hz};
    line.y = {0.0, top};
    chart.series.push_back(std::move(line));
  }
  Figure figure;
  figure.width = 1400;
  figure.height = 800;
  figure.charts = {std::move(chart)};
  return figure;
}

Figure modal_fit_figure(const identify::ModalFit& fit, const identify::MeasuredFrfs& data) {
  const int O = data.num_responses();
  const Eigen::Index L = data.num_lines();
  const bool has_fit = fit.fitted.rows() == L && fit.fitted.cols() == O;
  const bool has_model = fit.model_frf.rows() == L && fit.model_frf.cols() == O;
  std::vector<Chart> magnitudes, phases;
  for (int c = 0; c < O; ++c) {
    const auto k = static_cast<std::size_t>(c);
    Chart mag, ph;
    // Receptance whatever was measured: the title says which channel it was converted from.
    const std::string to = fem::to_string(data.responses[k]);
    mag.title = data.response_names[k] == to
                    ? fmt::format("receptance {} / {}", to, fem::to_string(data.drive))
                    : fmt::format("receptance {} / {} (from {})", to, fem::to_string(data.drive),
                                  data.response_names[k]);
    mag.x_label = ph.x_label = "frequency (Hz)";
    mag.y_label = "|H| (" + unit(data.responses[k], data.drive) + ")";
    mag.log_y = true;
    ph.title = fmt::format("phase, {}", fem::to_string(data.responses[k]));
    ph.y_label = "phase (deg)";
    // The model as written differs from the fit by the lower residual and any mode left out:
    // drawn where that shows (more than 1 % of the measured FRF's size).
    const bool model_differs =
        has_fit && has_model &&
        (fit.model_frf.col(c) - fit.fitted.col(c)).norm() > 0.01 * data.H.col(c).norm();
    Series measured, fitted, model, mp, fp, modelp;
    measured.label = "measured";
    fitted.label = "fitted";
    model.label = "model written";
    measured.style = mp.style = Series::Style::points;
    measured.color = mp.color = black;
    measured.width = mp.width = 0.8;
    fitted.color = fp.color = red;
    model.color = modelp.color = orange;
    model.style = modelp.style = Series::Style::dashed;
    auto add = [](Series& m, Series& p, double f, std::complex<double> h) {
      if (!(std::abs(h) > 0.0 && std::isfinite(std::abs(h)))) return; // a log axis: > 0 only
      m.x.push_back(f);
      m.y.push_back(std::abs(h));
      p.x.push_back(f);
      p.y.push_back(degrees(h));
    };
    for (Eigen::Index j = 0; j < L; ++j) {
      const double f = data.frequency_hz(j);
      add(measured, mp, f, data.H(j, c));
      if (has_fit) add(fitted, fp, f, fit.fitted(j, c));
      if (model_differs) add(model, modelp, f, fit.model_frf(j, c));
    }
    mag.legend = c == 0;
    ph.legend = false;
    for (auto* s : {&measured, &fitted, &model})
      if (!s->x.empty()) mag.series.push_back(std::move(*s));
    if (!mp.x.empty()) ph.series.push_back(std::move(mp));
    for (const Series* line : {&fp, &modelp})
      for (Series& piece : split_at_wraps(*line))
        ph.series.push_back(std::move(piece));
    magnitudes.push_back(std::move(mag));
    phases.push_back(std::move(ph));
  }
  Figure figure;
  if (O <= 4) { // a row of magnitudes above a row of phases
    figure.columns = std::max(O, 1);
    for (auto* row : {&magnitudes, &phases})
      for (Chart& chart : *row)
        figure.charts.push_back(std::move(chart));
    figure.width = std::max(1000, 450 * figure.columns);
    figure.height = 900;
    return figure;
  }
  // More responses: two a row, each its magnitude and phase side by side.
  figure.columns = 4;
  for (int c = 0; c < O; ++c) {
    figure.charts.push_back(std::move(magnitudes[static_cast<std::size_t>(c)]));
    figure.charts.push_back(std::move(phases[static_cast<std::size_t>(c)]));
  }
  const int rows = (O + 1) / 2;
  figure.width = 1800;
  figure.height = std::min(16000, 340 * rows);
  return figure;
}

} // namespace jointid::report
