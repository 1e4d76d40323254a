// frf_figure(): part of jointid_io_output, with the other figures (the palette lives there).
#include "report/frf_figure.hpp"
#include "io/frf_output.hpp"

#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <numbers>

namespace jointid::report {

Figure frf_figure(const frf::FrfSweep& sweep, const fem::DofMap& dofs) {
  const fem::NodeDof drive = dofs.node_dof(sweep.drive);
  Chart magnitude, phase;
  magnitude.title =
      fmt::format("{}: magnitude, drive {}", frf::frf_kind_name(sweep.kind), fem::to_string(drive));
  magnitude.x_label = phase.x_label = "frequency (Hz)";
  magnitude.log_y = true;
  phase.title = "phase";
  phase.y_label = "phase (deg)";
  std::string units;
  for (std::size_t c = 0; c < sweep.responses.size(); ++c) {
    const fem::NodeDof at = dofs.node_dof(sweep.responses[c]);
    const std::string unit =
        io::frf_unit(sweep.kind, fem::is_rotation(at.dof), fem::is_rotation(drive.dof));
    if (units.find(unit) == std::string::npos) units += (units.empty() ? "" : ", ") + unit;
    Series mag, ph;
    mag.label = ph.label = fem::to_string(at);
    mag.color = ph.color = palette_color(c);
    ph.style = Series::Style::points;
    ph.width = 2.0;
    for (std::size_t i = 0; i < sweep.freq_hz.size(); ++i) {
      const std::complex<double> h =
          sweep.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c));
      // A log axis takes positive values only: an exact zero (the static point of a mobility)
      // is left out of the magnitude.
      if (std::abs(h) > 0.0 && std::isfinite(std::abs(h))) {
        mag.x.push_back(sweep.freq_hz[i]);
        mag.y.push_back(std::abs(h));
      }
      if (std::isfinite(std::arg(h))) {
        ph.x.push_back(sweep.freq_hz[i]);
        ph.y.push_back(std::arg(h) * 180.0 / std::numbers::pi);
      }
    }
    magnitude.series.push_back(std::move(mag));
    phase.series.push_back(std::move(ph));
  }
  magnitude.y_label = "|H| (" + units + ")";
  phase.legend = false;
  Figure figure;
  figure.width = 1200;
  figure.height = 900;
  figure.columns = 1;
  figure.charts = {std::move(magnitude), std::move(phase)};
  return figure;
}

} // namespace jointid::report
