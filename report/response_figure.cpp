// response_figure(): part of jointid_io_vtk, with the other figures (the palette lives there).
#include "report/response_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace jointid::report {

Figure response_figure(const frf::ResponseCurves& c, const fem::NodeDof& shown) {
  const auto at = std::find(c.dofs.begin(), c.dofs.end(), shown);
  if (at == c.dofs.end())
    throw std::invalid_argument("response figure: " + fem::to_string(shown) +
                                " is not among the curves' DOFs");
  const auto d = static_cast<Eigen::Index>(at - c.dofs.begin());
  Chart chart;
  chart.title = fmt::format("Response at {} (fundamental): solid stable, dashed unstable, "
                            "dots folds",
                            fem::to_string(shown));
  chart.x_label = "frequency (Hz)";
  chart.y_label = fmt::format("|X1| at {} (m or rad, peak)", fem::to_string(shown));
  Series folds;
  folds.label = "folds";
  folds.style = Series::Style::points;
  folds.color = {0, 0, 0};
  folds.width = 7.0;
  for (std::size_t i = 0; i < c.curves.size(); ++i) {
    const frf::ResponseBranch& b = c.curves[i];
    const std::array<int, 3> color = palette_color(i);
    // Runs of equal stability, each drawn in its style; neighbouring runs share a point.
    std::size_t start = 0;
    bool labelled = false;
    while (start < b.points.size()) {
      const std::optional<bool> state = b.points[start].stable;
      std::size_t end = start + 1;
      while (end < b.points.size() && b.points[end].stable == state)
        ++end;
      Series s;
      s.color = color;
      s.style = !state   ? Series::Style::line_points
                : *state ? Series::Style::line
                         : Series::Style::dashed;
      s.width = !state ? 2.0 : 2.5;
      for (std::size_t p = start; p < std::min(end + 1, b.points.size()); ++p) {
        s.x.push_back(b.points[p].hb.frequency_hz);
        s.y.push_back(std::abs(b.points[p].hb.X(1, d)));
      }
      if (!labelled) {
        s.label =
            fmt::format("{:g} N{}", c.amplitudes.at(i), state ? "" : " (stability not determined)");
        labelled = true;
      } else if (state && !*state) {
        s.label = "";
      }
      chart.series.push_back(std::move(s));
      start = end;
    }
    for (int f : b.folds) {
      folds.x.push_back(b.points.at(f).hb.frequency_hz);
      folds.y.push_back(std::abs(b.points.at(f).hb.X(1, d)));
    }
  }
  if (!folds.x.empty()) chart.series.push_back(std::move(folds));
  Figure figure;
  figure.width = 1200;
  figure.height = 750;
  figure.charts.push_back(std::move(chart));
  return figure;
}

bool response_figure_can_show(const std::vector<joints::Joint>& joints,
                              const fem::NodeDof& force_at, const fem::NodeDof& dof) {
  if (dof == force_at) return true;
  return std::any_of(joints.begin(), joints.end(), [&](const joints::Joint& j) {
    return dof == fem::NodeDof{j.node, j.dof} ||
           (j.node_b != 0 && dof == fem::NodeDof{j.node_b, j.dof});
  });
}

} // namespace jointid::report
