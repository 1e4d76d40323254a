#include "report/chart.hpp"

#include "fem/text.hpp"
#include "report/vtk_display.hpp"
#include "report/vtk_render.hpp"

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkCommand.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRect.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace jointid::report {

namespace fs = std::filesystem;

namespace {

using Rgb = std::array<int, 3>;

/// Markers are this many times a series' width: the default width of 2 px then gives 6 px
/// markers, readable at 1200 × 800.
constexpr double marker_per_width = 3.0;

// ---------------------------------------------------------------------------------------------
// Checks

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

std::string chart_name(const Chart& chart, std::size_t index) {
  return chart.title.empty() ? "chart " + std::to_string(index + 1)
                             : "chart " + quoted(chart.title);
}

std::string series_name(const Series& series, std::size_t index) {
  return series.label.empty() ? "series " + std::to_string(index + 1)
                              : "series " + quoted(series.label);
}

/// The x values a series is drawn at: its own, or 1 … n for bars on named categories.
std::vector<double> x_of(const Chart& chart, const Series& series) {
  if (series.x.empty() && series.style == Series::Style::bars && !chart.x_categories.empty()) {
    std::vector<double> x(series.y.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      x[i] = static_cast<double>(i + 1);
    return x;
  }
  return series.x;
}

void check_values(const std::string& where, const char* axis, const std::vector<double>& v,
                  bool log) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]))
      throw std::invalid_argument(where + ": " + axis + "[" + std::to_string(i) +
                                  "] = " + significant(v[i]) + " is not finite");
    if (log && !(v[i] > 0.0))
      throw std::invalid_argument(where + ": " + axis + "[" + std::to_string(i) +
                                  "] = " + significant(v[i]) + " on a logarithmic " + axis +
                                  " axis (need values > 0, or a linear axis)");
  }
}

void check_figure(const Figure& figure) {
  if (figure.charts.empty()) throw std::invalid_argument("chart picture: the figure has no charts");
  if (figure.width < 16 || figure.height < 16 || figure.width > 16384 || figure.height > 16384)
    throw std::invalid_argument("chart picture: size " + std::to_string(figure.width) + " × " +
                                std::to_string(figure.height) +
                                " pixels (need 16 … 16384 each way)");
  if (figure.columns < 1)
    throw std::invalid_argument("chart picture: columns = " + std::to_string(figure.columns) +
                                " (need at least 1)");
  for (std::size_t c = 0; c < figure.charts.size(); ++c) {
    const Chart& chart = figure.charts[c];
    const std::string name = chart_name(chart, c);
    if (chart.series.empty()) throw std::invalid_argument(name + " has no series to draw");
    if (!chart.x_categories.empty() && chart.log_x)
      throw std::invalid_argument(name + ": x_categories on a logarithmic x axis");
    for (std::size_t s = 0; s < chart.series.size(); ++s) {
      const Series& series = chart.series[s];
      const std::string where = name + ", " + series_name(series, s);
      const std::vector<double> x = x_of(chart, series);
      if (x.size() != series.y.size())
        throw std::invalid_argument(where + ": x has " + std::to_string(x.size()) +
                                    " values and y " + std::to_string(series.y.size()));
      if (x.empty()) throw std::invalid_argument(where + " has no values");
      check_values(where, "x", x, chart.log_x);
      check_values(where, "y", series.y, chart.log_y);
      const Rgb& rgb = series.color;
      const bool automatic = rgb == Rgb{-1, -1, -1};
      if (!automatic && std::any_of(rgb.begin(), rgb.end(), [](int v) { return v < 0 || v > 255; }))
        throw std::invalid_argument(where + ": colour {" + std::to_string(rgb[0]) + ", " +
                                    std::to_string(rgb[1]) + ", " + std::to_string(rgb[2]) +
                                    "} (need 0 … 255 each, or {-1, -1, -1} for the palette)");
      if (!(series.width > 0.0) || !(series.width <= 100.0))
        throw std::invalid_argument(where + ": width = " + significant(series.width) +
                                    " pixels (need 0 < width ≤ 100)");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Drawing

/// Font sizes (pixels) of one chart panel, from its size.
struct Fonts {
  int labels, axis_titles, title;
};

Fonts fonts_for(double panel_w, double panel_h) {
  const double base = std::clamp(std::min(panel_w, 1.5 * panel_h) / 70.0, 11.0, 18.0);
  return {static_cast<int>(std::lround(base)), static_cast<int>(std::lround(1.2 * base)),
          static_cast<int>(std::lround(1.4 * base))};
}

void style_text(vtkTextProperty* text, int size, bool bold = false) {
  text->SetColor(0.0, 0.0, 0.0);
  text->SetFontSize(size);
  text->SetBold(bold);
  text->SetItalic(false);
  text->SetShadow(false);
  text->SetFontFamilyToArial();
}

void style_axis(vtkAxis* axis, const std::string& title, bool log, const Fonts& fonts) {
  axis->SetTitle(title);
  style_text(axis->GetTitleProperties(), fonts.axis_titles);
  style_text(axis->GetLabelProperties(), fonts.labels);
  axis->GetPen()->SetColor(0, 0, 0);
  axis->GetPen()->SetWidth(1.0);
  axis->GetGridPen()->SetColor(215, 215, 215);
  axis->GetGridPen()->SetWidth(1.0);
  axis->SetLogScale(log);
  axis->SetNotation(vtkAxis::PRINTF_NOTATION); // 0.5, 1e-05, 2000: no padded zeros
  axis->SetLabelFormat("%g");
}

/// [min, max] of the values on one axis over all series (x uses x_of).
std::array<double, 2> range_of(const Chart& chart, bool x_axis) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Series& s : chart.series) {
    const std::vector<double> v = x_axis ? x_of(chart, s) : s.y;
    for (double value : v) {
      lo = std::min(lo, value);
      hi = std::max(hi, value);
    }
  }
  return {lo, hi};
}

/// The axis range drawn for data in `range`: data of one value get a visible range around it,
/// and `pad` (a fraction of the range, of its logarithm on a log axis) keeps lines off the frame.
std::array<double, 2> shown_range(std::array<double, 2> range, bool log, double pad) {
  auto [lo, hi] = range;
  if (log) {
    double a = std::log10(lo), b = std::log10(hi);
    if (b - a < 1e-9) a -= 0.3, b += 0.3; // a factor of 2 either way
    const double margin = pad * (b - a);
    return {std::pow(10.0, a - margin), std::pow(10.0, b + margin)};
  }
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
    const double half = lo == 0.0 ? 1.0 : 0.5 * std::abs(lo);
    lo -= half, hi += half;
  }
  const double margin = pad * (hi - lo);
  return {lo - margin, hi + margin};
}

/// A tick label: plain numbers (0.01, 1, 1000) unless the axis reaches below 1e-3 or above 1e4,
/// then powers of ten for all (1e-5, 2e-5, 1e6), so that one axis never mixes the two.
std::string log_label(double value, bool scientific) {
  char text[32];
  if (!scientific) {
    std::snprintf(text, sizeof text, "%g", value);
    return text;
  }
  const int exponent = static_cast<int>(std::floor(std::log10(value) + 1e-9));
  const double mantissa = value / std::pow(10.0, exponent);
  std::snprintf(text, sizeof text, "%ge%d", std::round(mantissa * 1e6) / 1e6, exponent);
  return text;
}

/// Ticks of a logarithmic axis over [lo, hi]: every decade (or every 2nd, 3rd … when there are
/// more than `max_ticks`); where that gives fewer than 3 ticks, 1-2-5, else 1 … 9. VTK's own
/// log ticks draw a grid line at every minor tick, which buries the data of a many-decade axis.
/// Tick positions are log10 of the value (VTK's scaled coordinate) less `shift`.
void set_log_ticks(vtkAxis* axis, double lo, double hi, int max_ticks, double shift = 0.0) {
  const double a = std::log10(lo), b = std::log10(hi);
  const int first = static_cast<int>(std::floor(a)), last = static_cast<int>(std::ceil(b));
  std::vector<double> ticks;
  auto inside = [&](double v) { return v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9); };
  const std::vector<std::vector<double>> mantissas = {
      {1.0}, {1.0, 2.0, 5.0}, {1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0}};
  for (const auto& m : mantissas) {
    ticks.clear();
    const int decades = last - first + 1;
    const int step = m.size() == 1 ? std::max(1, (decades + max_ticks - 1) / max_ticks) : 1;
    for (int e = first - first % step - step; e <= last; e += step)
      for (double factor : m) {
        const double v = factor * std::pow(10.0, e);
        if (inside(v)) ticks.push_back(v);
      }
    if (ticks.size() >= 3) break;
  }
  if (ticks.size() < 2) return; // less than a factor of two: VTK's linear-looking ticks do
  const bool scientific = ticks.front() < 1e-3 || ticks.back() > 1e4;
  vtkNew<vtkDoubleArray> positions;
  vtkNew<vtkStringArray> labels;
  for (double v : ticks) {
    positions->InsertNextValue(std::log10(v) - shift);
    labels->InsertNextValue(log_label(v, scientific));
  }
  axis->SetCustomTickPositions(positions, labels);
}

/// Fixes an axis to show `range` (VTK would fit it tightly to the data, or leave it empty for
/// data of one value), with our ticks on a logarithmic one.
void set_range(vtkAxis* axis, std::array<double, 2> range, bool log, int max_ticks) {
  axis->SetBehavior(vtkAxis::FIXED);
  axis->SetUnscaledRange(range[0], range[1]);
  if (log) set_log_ticks(axis, range[0], range[1], max_ticks);
}

/// The smallest distance between the x values of a chart's bars (1 for a single bar).
double bar_slot(const Chart& chart) {
  std::vector<double> x;
  for (const Series& s : chart.series)
    if (s.style == Series::Style::bars) {
      const std::vector<double> v = x_of(chart, s);
      x.insert(x.end(), v.begin(), v.end());
    }
  std::sort(x.begin(), x.end());
  double slot = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < x.size(); ++i)
    if (x[i] > x[i - 1]) slot = std::min(slot, x[i] - x[i - 1]);
  return std::isfinite(slot) ? slot : 1.0;
}

vtkSmartPointer<vtkTable> table_of(const std::vector<double>& x, const std::vector<double>& y) {
  vtkNew<vtkDoubleArray> xs, ys;
  xs->SetName("x");
  ys->SetName("y");
  xs->SetNumberOfTuples(static_cast<vtkIdType>(x.size()));
  ys->SetNumberOfTuples(static_cast<vtkIdType>(y.size()));
  for (std::size_t i = 0; i < x.size(); ++i) {
    xs->SetValue(static_cast<vtkIdType>(i), x[i]);
    ys->SetValue(static_cast<vtkIdType>(i), y[i]);
  }
  auto table = vtkSmartPointer<vtkTable>::New();
  table->AddColumn(xs);
  table->AddColumn(ys);
  return table;
}

/// How y values are drawn: as they are, or as log10(y) − log_base on a linear axis (bars on a
/// logarithmic axis: VTK would draw them from y = 1, the logarithm's zero, not from the axis).
struct YMap {
  bool log = false;
  double log_base = 0.0;
  std::vector<double> operator()(const std::vector<double>& y) const {
    if (!log) return y;
    std::vector<double> mapped(y.size());
    for (std::size_t i = 0; i < y.size(); ++i)
      mapped[i] = std::log10(y[i]) - log_base;
    return mapped;
  }
};

void add_series(vtkChartXY* chart, const Chart& spec, const Series& series, std::size_t index,
                const YMap& y_map) {
  using Style = Series::Style;
  const Rgb rgb = series.color == Rgb{-1, -1, -1} ? Rgb(palette_color(index)) : series.color;
  const auto r = static_cast<unsigned char>(rgb[0]), g = static_cast<unsigned char>(rgb[1]),
             b = static_cast<unsigned char>(rgb[2]);
  const int type = series.style == Style::bars     ? vtkChart::BAR
                   : series.style == Style::points ? vtkChart::POINTS
                                                   : vtkChart::LINE;
  vtkPlot* plot = chart->AddPlot(type);
  plot->SetInputData(table_of(x_of(spec, series), y_map(series.y)), 0, 1);
  plot->SetLabel(series.label);
  plot->SetLegendVisibility(!series.label.empty());
  const auto width = static_cast<float>(series.width);
  plot->GetPen()->SetColor(r, g, b, 255);
  plot->GetBrush()->SetColor(r, g, b, 255);
  if (series.style == Style::bars) {
    plot->GetPen()->SetColor(0, 0, 0, 255); // a thin outline keeps light bars visible
    plot->GetPen()->SetWidth(1.0f);
    return;
  }
  plot->SetWidth(width);
  if (series.style == Style::dashed) plot->GetPen()->SetLineType(vtkPen::DASH_LINE);
  auto* points = vtkPlotPoints::SafeDownCast(plot); // vtkPlotLine is one too
  if (points == nullptr) return;
  const bool markers = series.style == Style::points || series.style == Style::line_points;
  points->SetMarkerStyle(markers ? vtkPlotPoints::CIRCLE : vtkPlotPoints::NONE);
  points->SetMarkerSize(static_cast<float>(marker_per_width * series.width));
}

/// Category names under bars 1 … n; slanted when they would not fit side by side.
void set_categories(vtkAxis* axis, const std::vector<std::string>& names, double plot_width,
                    int font) {
  vtkNew<vtkDoubleArray> positions;
  vtkNew<vtkStringArray> labels;
  std::size_t longest = 0;
  for (std::size_t i = 0; i < names.size(); ++i) {
    positions->InsertNextValue(static_cast<double>(i + 1));
    labels->InsertNextValue(names[i]);
    longest = std::max(longest, names[i].size());
  }
  axis->SetCustomTickPositions(positions, labels);
  axis->SetBehavior(vtkAxis::FIXED);
  axis->SetRange(0.5, static_cast<double>(names.size()) + 0.5);
  const double label_width = 0.6 * font * static_cast<double>(longest) + font;
  if (label_width * static_cast<double>(names.size()) > plot_width) {
    // Slanted, their right ends at the ticks, so that they hang below the axis.
    vtkTextProperty* text = axis->GetLabelProperties();
    text->SetOrientation(35.0);
    text->SetJustificationToRight();
    text->SetVerticalJustificationToTop();
  }
}

void build_chart(vtkContextScene* scene, const Chart& spec, const vtkRectf& rect) {
  const Fonts fonts = fonts_for(rect.GetWidth(), rect.GetHeight());
  vtkNew<vtkChartXY> chart;
  chart->SetAutoSize(false);
  // A margin inside the panel keeps the title off the picture's edge and apart from neighbours.
  const float margin = 0.5f * static_cast<float>(fonts.title);
  chart->SetSize(vtkRectf(rect.GetX(), rect.GetY() + 0.5f * margin, rect.GetWidth() - margin,
                          rect.GetHeight() - 1.5f * margin));
  chart->SetRenderEmpty(true);
  chart->SetTitle(spec.title);
  style_text(chart->GetTitleProperties(), fonts.title, true);
  chart->SetBarWidthFraction(0.7f);

  vtkAxis* x_axis = chart->GetAxis(vtkAxis::BOTTOM);
  vtkAxis* y_axis = chart->GetAxis(vtkAxis::LEFT);
  style_axis(x_axis, spec.x_label, spec.log_x, fonts);
  style_axis(y_axis, spec.y_label, spec.log_y, fonts);

  bool any_bars = false, any_label = false;
  for (const Series& series : spec.series) {
    any_bars = any_bars || series.style == Series::Style::bars;
    any_label = any_label || !series.label.empty();
  }

  // Axis ranges: x fitted to the data (bars get half a slot either side), y with a margin; bars
  // stand on zero, so a linear y axis of bars includes it.
  const double plot_w = 0.75 * rect.GetWidth(), plot_h = 0.75 * rect.GetHeight();
  const int max_x_ticks = std::max(2, static_cast<int>(plot_w / (5 * fonts.labels)));
  const int max_y_ticks = std::max(2, static_cast<int>(plot_h / (2 * fonts.labels)));
  if (!spec.x_categories.empty()) {
    set_categories(x_axis, spec.x_categories, plot_w, fonts.labels);
  } else {
    const std::array<double, 2> x_data = range_of(spec, true);
    const double half_slot = any_bars && !spec.log_x ? 0.5 * bar_slot(spec) : 0.0;
    const std::array<double, 2> x_range =
        half_slot > 0.0 ? std::array<double, 2>{x_data[0] - half_slot, x_data[1] + half_slot}
                        : shown_range(x_data, spec.log_x, 0.0);
    set_range(x_axis, x_range, spec.log_x, max_x_ticks);
  }
  std::array<double, 2> y_data = range_of(spec, false);
  std::array<double, 2> y_range = shown_range(y_data, spec.log_y, 0.05);
  YMap y_map;
  if (any_bars && spec.log_y) { // bars stand on the axis: draw log10(y) on a linear axis
    y_map = {true, std::log10(y_range[0])};
    y_axis->SetLogScale(false);
    y_axis->SetBehavior(vtkAxis::FIXED);
    y_axis->SetUnscaledRange(0.0, std::log10(y_range[1]) - y_map.log_base);
    set_log_ticks(y_axis, y_range[0], y_range[1], max_y_ticks, y_map.log_base);
  } else {
    if (any_bars) {
      y_data = {std::min(y_data[0], 0.0), std::max(y_data[1], 0.0)};
      y_range = shown_range(y_data, false, 0.05);
      if (y_data[0] == 0.0 && y_data[1] > 0.0) y_range[0] = 0.0;
      if (y_data[1] == 0.0 && y_data[0] < 0.0) y_range[1] = 0.0;
    }
    set_range(y_axis, y_range, spec.log_y, max_y_ticks);
  }

  for (std::size_t s = 0; s < spec.series.size(); ++s)
    add_series(chart, spec, spec.series[s], s, y_map);

  // The legend goes to the right of the plot area, outside it, so that it never hides data.
  const bool legend = spec.legend && any_label;
  chart->SetShowLegend(legend);
  if (legend) {
    vtkChartLegend* box = chart->GetLegend();
    box->SetInline(false);
    box->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    box->SetVerticalAlignment(vtkChartLegend::TOP);
    box->SetLabelSize(fonts.labels);
    style_text(box->GetLabelProperties(), fonts.labels);
    box->SetSymbolWidth(3 * fonts.labels);
    box->GetPen()->SetColor(160, 160, 160);
    box->GetBrush()->SetColor(255, 255, 255, 255);
    box->SetDragEnabled(false);
  }
  chart->SetInteractive(false);
  scene->AddItem(chart);
}

void render_figure(const fs::path& png, const Figure& figure) {
  // Debian's VTK aborts the process if it cannot open the X display: open it first. Declared
  // before every VTK object, so that it is closed after all of them.
  const detail::RenderDisplay display;
  if (!display.problem().empty())
    throw std::runtime_error("cannot render " + png.string() + ": " + display.problem() +
                             "; run the program under `xvfb-run -a`");
  vtkNew<vtkRenderWindow> window;
  if (display.id() != nullptr) window->SetDisplayId(display.id());
  window->SetOffScreenRendering(1);
  window->SetSize(figure.width, figure.height);
  window->SetMultiSamples(0);

  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1.0, 1.0, 1.0);
  window->AddRenderer(renderer);
  vtkNew<vtkContextActor> actor;
  renderer->AddActor(actor);
  vtkContextScene* scene = actor->GetScene();
  scene->SetRenderer(renderer);

  // The grid, filled row by row from the top; scene coordinates start at the bottom left.
  const int count = static_cast<int>(figure.charts.size());
  const int columns = std::min(figure.columns, count);
  const int rows = (count + columns - 1) / columns;
  const double panel_w = static_cast<double>(figure.width) / columns;
  const double panel_h = static_cast<double>(figure.height) / rows;
  for (int i = 0; i < count; ++i) {
    const int column = i % columns, row = i / columns;
    const vtkRectf rect(static_cast<float>(column * panel_w),
                        static_cast<float>(figure.height - (row + 1) * panel_h),
                        static_cast<float>(panel_w), static_cast<float>(panel_h));
    build_chart(scene, figure.charts[static_cast<std::size_t>(i)], rect);
  }

  detail::render_to_png(window, png);
}

} // namespace

void write_chart_png(const fs::path& png, const Figure& figure) {
  check_figure(figure);
  const fs::path folder = png.parent_path().empty() ? fs::path(".") : png.parent_path();
  if (!fs::is_directory(folder))
    throw std::runtime_error("cannot write " + png.string() + ": the directory " + folder.string() +
                             " does not exist");
  render_figure(png, figure);
}

bool can_render_charts(std::string* why) {
  const detail::RenderDisplay display;
  if (why != nullptr) *why = display.problem();
  return display.problem().empty();
}

} // namespace jointid::report
