#pragma once
/// Charts (lines, points, bars) written as PNG files through VTK's charts — jointid's one
/// plotting route. Target `jointid_io_vtk`; this header includes no VTK.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace jointid::report {

struct Series {
  enum class Style { line, dashed, points, line_points, bars };
  std::string label; ///< legend entry; empty: not in the legend
  std::vector<double> x, y;
  Style style = Style::line;
  /// RGB 0–255; {-1, -1, -1}: the next colour of a fixed palette (by series index).
  std::array<int, 3> color{-1, -1, -1};
  double width = 2.0; ///< line width or marker size, pixels
};

struct Chart {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
  /// Category names for bar charts: bar i is drawn at x = i + 1 and labelled with name i.
  std::vector<std::string> x_categories;
  std::vector<Series> series;
  bool legend = true;
};

/// A grid of charts in one picture, filled row by row.
struct Figure {
  int width = 1200, height = 800; ///< pixels, whole picture
  int columns = 1;
  std::vector<Chart> charts;
};

/// Renders the figure off screen into a PNG, written atomically (a temporary file renamed into
/// place). Debian's VTK renders through GLX and so needs an X server: without one this throws
/// std::runtime_error saying to run under `xvfb-run -a`. Throws std::invalid_argument for an
/// empty figure, a series whose x and y differ in length, non-finite values, or non-positive
/// values on a logarithmic axis (naming the chart and series).
void write_chart_png(const std::filesystem::path& png, const Figure& figure);

/// The i-th colour of the palette series get by default (Tableau 10, cycling), RGB 0–255.
std::array<int, 3> palette_color(std::size_t i);

/// True when a picture can be rendered here (an X display could be opened), else false and
/// `why` says what is missing.
bool can_render_charts(std::string* why = nullptr);

} // namespace jointid::report
