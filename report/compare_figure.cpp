// compare_figure(): the figure of `jointid compare` (report/compare_figure.hpp).
#include "report/compare_figure.hpp"

#include "io/spectra_comparison.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace jointid::report {

Figure compare_figure(const identify::Comparison& c) {
  Figure figure;
  const auto n = static_cast<int>(c.channels.size());
  figure.columns = n > 3 ? 2 : 1;
  const int rows = (n + figure.columns - 1) / figure.columns;
  figure.width = figure.columns == 1 ? 1200 : 1600;
  figure.height = std::max(500, 420 * rows);
  for (const auto& ch : c.channels) {
    Chart chart;
    chart.title = fmt::format("{}: predicted vs measured PSD, {:.2f} dB RMS ({:.2f} dB max) over "
                              "{:g}-{:g} Hz",
                              ch.channel, ch.rms_db, ch.max_db, c.f0_hz, c.f1_hz);
    chart.x_label = "frequency (Hz)";
    chart.y_label = fmt::format("PSD of {} ({})", ch.channel, io::psd_unit(ch.channel));
    chart.log_y = true;
    Series measured, predicted;
    measured.label = "measured";
    measured.color = palette_color(0);
    predicted.label = "predicted";
    predicted.color = palette_color(1);
    predicted.style = Series::Style::dashed;
    // A log axis takes positive values only: a zero bin (none in practice) is left out.
    for (Eigen::Index k = 0; k < ch.frequency_hz.size(); ++k)
      if (ch.measured(k) > 0.0 && ch.predicted(k) > 0.0 && std::isfinite(ch.measured(k)) &&
          std::isfinite(ch.predicted(k))) {
        measured.x.push_back(ch.frequency_hz(k));
        measured.y.push_back(ch.measured(k));
        predicted.x.push_back(ch.frequency_hz(k));
        predicted.y.push_back(ch.predicted(k));
      }
    chart.series = {std::move(measured), std::move(predicted)};
    figure.charts.push_back(std::move(chart));
  }
  return figure;
}

} // namespace jointid::report
