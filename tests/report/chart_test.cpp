// Charts written as PNG pictures, read back with VTK's PNG reader and checked pixel by pixel:
// the picture's size, where the series' colours land, and the errors for bad figures.
#include "report/chart.hpp"

#include "io/test_files.hpp"
#include "support/display.hpp"

#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace jointid::report {
namespace {

namespace fs = std::filesystem;
using Style = Series::Style;

using jointid::test::have_display;
using jointid::test::no_display;

/// A picture read back: width, height and RGB of each pixel, row 0 at the bottom (as VTK).
struct Picture {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> rgb;
  const std::array<int, 3>& at(int x, int y) const {
    return rgb[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
               static_cast<std::size_t>(x)];
  }
};

Picture read_png(const fs::path& png) {
  vtkNew<vtkPNGReader> reader;
  EXPECT_TRUE(reader->CanReadFile(png.c_str())) << png;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  Picture p{dims[0], dims[1], {}};
  EXPECT_GE(image->GetNumberOfScalarComponents(), 3);
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const auto* c = static_cast<unsigned char*>(image->GetScalarPointer(x, y, 0));
      p.rgb.push_back({c[0], c[1], c[2]});
    }
  return p;
}

/// Pixels of one pure colour: each channel within `tolerance` of it.
std::function<bool(const std::array<int, 3>&)> near(std::array<int, 3> colour, int tolerance = 40) {
  return [=](const std::array<int, 3>& c) {
    for (int i = 0; i < 3; ++i)
      if (std::abs(c[i] - colour[i]) > tolerance) return false;
    return true;
  };
}

struct Pixels {
  std::vector<double> x, y;
  std::size_t size() const { return x.size(); }
};

Pixels find(const Picture& p, const std::function<bool(const std::array<int, 3>&)>& match) {
  Pixels found;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x)
      if (match(p.at(x, y))) {
        found.x.push_back(x);
        found.y.push_back(y);
      }
  return found;
}

/// Least-squares line y = a + b x through the pixels: slope b and the correlation coefficient.
struct Fit {
  double slope, correlation;
};

Fit fit_line(const Pixels& px) {
  const double n = static_cast<double>(px.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < px.size(); ++i)
    mx += px.x[i] / n, my += px.y[i] / n;
  double sxx = 0, syy = 0, sxy = 0;
  for (std::size_t i = 0; i < px.size(); ++i) {
    sxx += (px.x[i] - mx) * (px.x[i] - mx);
    syy += (px.y[i] - my) * (px.y[i] - my);
    sxy += (px.x[i] - mx) * (px.y[i] - my);
  }
  return {sxy / sxx, sxy / std::sqrt(sxx * syy)};
}

double min_of(const std::vector<double>& v) {
  return *std::min_element(v.begin(), v.end());
}
double max_of(const std::vector<double>& v) {
  return *std::max_element(v.begin(), v.end());
}

constexpr std::array<int, 3> red{255, 0, 0}, blue{0, 0, 255};

Series ramp(int n, std::array<int, 3> colour, Style style = Style::line) {
  Series s;
  for (int i = 0; i <= n; ++i) {
    s.x.push_back(i);
    s.y.push_back(i);
  }
  s.color = colour;
  s.style = style;
  return s;
}

Chart chart(std::string title, std::vector<Series> series) {
  Chart c;
  c.title = std::move(title);
  c.series = std::move(series);
  return c;
}

/// Throws std::invalid_argument whose message contains every one of `parts`.
void expect_invalid(const Figure& figure, const std::vector<std::string>& parts) {
  test::TempDir dir;
  try {
    write_chart_png(dir / "x.png", figure);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "'" << part << "' not in: " << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

// ----- pictures -------------------------------------------------------------------------------

TEST(VtkPng, ChartLineLiesOnTheDiagonalOfItsPlot) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  const fs::path png = dir / "line.png";
  Figure figure{.width = 640, .height = 480, .columns = 1, .charts = {}};
  figure.charts.push_back(chart("y = x", {ramp(10, red)}));
  figure.charts[0].x_label = "x";
  figure.charts[0].y_label = "y";
  write_chart_png(png, figure);

  const Picture p = read_png(png);
  EXPECT_EQ(p.width, 640);
  EXPECT_EQ(p.height, 480);
  // Mostly white, and the red pixels form one rising straight line across most of the picture.
  const Pixels white = find(p, near({255, 255, 255}, 10));
  EXPECT_GT(white.size(), 640u * 480u / 2);
  const Pixels line = find(p, near(red, 60));
  ASSERT_GT(line.size(), 300u);
  const Fit fit = fit_line(line);
  EXPECT_GT(fit.correlation, 0.995);
  EXPECT_GT(fit.slope, 0.3);
  EXPECT_LT(fit.slope, 1.5);
  EXPECT_GT(max_of(line.x) - min_of(line.x), 0.6 * 640);
  EXPECT_GT(max_of(line.y) - min_of(line.y), 0.5 * 480);
  // Axis lines and text are black.
  EXPECT_GT(find(p, near({0, 0, 0}, 60)).size(), 500u);

  // No temporary files are left next to the picture.
  int files = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 1);
}

TEST(VtkPng, ChartTwoChartsFillTheirOwnHalves) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  const fs::path png = dir / "two.png";
  Figure figure{.width = 800, .height = 300, .columns = 2, .charts = {}};
  figure.charts.push_back(chart("left", {ramp(5, red)}));
  figure.charts.push_back(chart("right", {ramp(5, blue)}));
  write_chart_png(png, figure);

  const Picture p = read_png(png);
  EXPECT_EQ(p.width, 800);
  EXPECT_EQ(p.height, 300);
  const Pixels left = find(p, near(red, 60)), right = find(p, near(blue, 60));
  ASSERT_GT(left.size(), 100u);
  ASSERT_GT(right.size(), 100u);
  EXPECT_LT(max_of(left.x), 400);
  EXPECT_GT(min_of(right.x), 400);
  EXPECT_GT(max_of(left.x) - min_of(left.x), 0.5 * 400);
  EXPECT_GT(max_of(right.x) - min_of(right.x), 0.5 * 400);
}

TEST(VtkPng, ChartGridFillsRowsFromTheTop) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  const fs::path png = dir / "grid.png";
  // Three charts in two columns: red top left, blue top right, green bottom left, bottom right
  // empty.
  constexpr std::array<int, 3> green{0, 200, 0};
  Figure figure{.width = 800, .height = 600, .columns = 2, .charts = {}};
  figure.charts.push_back(chart("a", {ramp(5, red)}));
  figure.charts.push_back(chart("b", {ramp(5, blue)}));
  figure.charts.push_back(chart("c", {ramp(5, green)}));
  write_chart_png(png, figure);

  const Picture p = read_png(png);
  const Pixels a = find(p, near(red, 60)), b = find(p, near(blue, 60)),
               c = find(p, near(green, 60));
  ASSERT_GT(a.size(), 100u);
  ASSERT_GT(b.size(), 100u);
  ASSERT_GT(c.size(), 100u);
  // Row 0 of the image is its bottom.
  EXPECT_LT(max_of(a.x), 400);
  EXPECT_GT(min_of(a.y), 300);
  EXPECT_GT(min_of(b.x), 400);
  EXPECT_GT(min_of(b.y), 300);
  EXPECT_LT(max_of(c.x), 400);
  EXPECT_LT(max_of(c.y), 300);
  // The empty cell is white.
  for (int y = 10; y < 290; y += 7)
    for (int x = 410; x < 790; x += 7)
      ASSERT_TRUE(near({255, 255, 255}, 10)(p.at(x, y))) << x << ", " << y;
}

/// The bars of one colour, left to right: each one's height and bottom row, in pixels.
struct Bar {
  int height, bottom;
};

std::vector<Bar> bars_of(const Picture& p, std::array<int, 3> colour) {
  const Pixels coloured = find(p, near(colour, 60));
  std::vector<int> column_height(static_cast<std::size_t>(p.width), 0);
  std::vector<int> column_bottom(static_cast<std::size_t>(p.width), p.height);
  for (std::size_t i = 0; i < coloured.size(); ++i) {
    const auto x = static_cast<std::size_t>(coloured.x[i]);
    ++column_height[x];
    column_bottom[x] = std::min(column_bottom[x], static_cast<int>(coloured.y[i]));
  }
  std::vector<Bar> bars;
  bool was = false;
  for (std::size_t x = 0; x < column_height.size(); ++x) {
    const bool in = column_height[x] > 3;
    if (in && !was) bars.push_back({0, column_bottom[x]});
    if (in) bars.back().height = std::max(bars.back().height, column_height[x]);
    was = in;
  }
  return bars;
}

TEST(VtkPng, ChartBarsStandOnZeroWithHeightsInProportion) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  const fs::path png = dir / "bars.png";
  Series bars{.label = "", .x = {}, .y = {1.0, 3.0, 2.0}, .style = Style::bars, .color = blue};
  Figure figure{.width = 600, .height = 400, .columns = 1, .charts = {}};
  figure.charts.push_back(chart("Ranking", {bars}));
  figure.charts[0].y_label = "score";
  figure.charts[0].x_categories = {"k", "k3", "c2"};
  write_chart_png(png, figure);

  // Three bars, left to right, heights 1 : 3 : 2 from one baseline (y = 0).
  const std::vector<Bar> b = bars_of(read_png(png), blue);
  ASSERT_EQ(b.size(), 3u);
  ASSERT_GT(b[0].height, 30);
  EXPECT_NEAR(static_cast<double>(b[1].height) / b[0].height, 3.0, 0.15);
  EXPECT_NEAR(static_cast<double>(b[2].height) / b[0].height, 2.0, 0.1);
  EXPECT_NEAR(b[0].bottom, b[1].bottom, 2);
  EXPECT_NEAR(b[0].bottom, b[2].bottom, 2);
}

TEST(VtkPng, ChartBarsOnALogAxisRiseFromItsBottom) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  const fs::path png = dir / "log_bars.png";
  // Values two decades apart: on a log axis the bars' tops are equally spaced, and every bar
  // rises from the axis (VTK on its own would hang the ones below 1 down from y = 1).
  Series bars{.label = "", .x = {}, .y = {1e-3, 1e-1, 10.0}, .style = Style::bars, .color = blue};
  Figure figure{.width = 600, .height = 400, .columns = 1, .charts = {}};
  figure.charts.push_back(chart("Contributions", {bars}));
  figure.charts[0].log_y = true;
  figure.charts[0].x_categories = {"k", "k3", "c2"};
  write_chart_png(png, figure);

  const std::vector<Bar> b = bars_of(read_png(png), blue);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_GT(b[0].height, 3);
  EXPECT_NEAR(b[1].height - b[0].height, b[2].height - b[1].height, 3);
  EXPECT_GT(b[1].height - b[0].height, 60);
  EXPECT_NEAR(b[0].bottom, b[1].bottom, 2);
  EXPECT_NEAR(b[0].bottom, b[2].bottom, 2);
}

TEST(VtkPng, ChartLogAxisStraightensAPowerLaw) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  // y = 10^x over five decades: straight on a logarithmic y axis, bent on a linear one.
  Series decades;
  for (int i = 0; i <= 50; ++i) {
    decades.x.push_back(0.1 * i);
    decades.y.push_back(std::pow(10.0, 0.1 * i - 6.0));
  }
  decades.color = red;
  auto correlation = [&](bool log_y) {
    Figure figure{.width = 600, .height = 400, .columns = 1, .charts = {}};
    figure.charts.push_back(chart("gap", {decades}));
    figure.charts[0].log_y = log_y;
    const fs::path png = dir / (log_y ? "log.png" : "linear.png");
    write_chart_png(png, figure);
    const Pixels line = find(read_png(png), near(red, 60));
    EXPECT_GT(line.size(), 200u);
    return fit_line(line).correlation;
  };
  EXPECT_GT(correlation(true), 0.995);
  EXPECT_LT(correlation(false), 0.8);
}

TEST(VtkPng, ChartDashedLineHasGaps) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  auto red_pixels = [&](Style style) {
    Figure figure{.width = 600, .height = 400, .columns = 1, .charts = {}};
    figure.charts.push_back(chart("dashes", {ramp(10, red, style)}));
    const fs::path png = dir / "dash.png";
    write_chart_png(png, figure);
    return find(read_png(png), near(red, 60)).size();
  };
  const std::size_t solid = red_pixels(Style::line), dashed = red_pixels(Style::dashed);
  EXPECT_GT(solid, 300u);
  EXPECT_LT(dashed, 0.85 * solid);
  EXPECT_GT(dashed, 0.2 * solid);
}

TEST(VtkPng, ChartMarkersAddPixelsToALine) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  auto red_pixels = [&](Style style) {
    Figure figure{.width = 600, .height = 400, .columns = 1, .charts = {}};
    figure.charts.push_back(chart("markers", {ramp(10, red, style)}));
    const fs::path png = dir / "markers.png";
    write_chart_png(png, figure);
    return find(read_png(png), near(red, 60)).size();
  };
  const std::size_t line = red_pixels(Style::line), points = red_pixels(Style::points),
                    both = red_pixels(Style::line_points);
  EXPECT_GT(points, 11u * 9u); // 11 markers of 6 px
  EXPECT_LT(points, line);     // markers alone cover less than the line
  EXPECT_GT(both, line + points / 3);
}

TEST(VtkPng, ChartLegendSitsBesideThePlot) {
  if (!have_display()) GTEST_SKIP() << no_display;
  test::TempDir dir;
  // A line ending in the top right corner, where a legend inside the plot would cover it.
  Series rising = ramp(10, red);
  rising.label = "measured";
  Figure figure{.width = 800, .height = 400, .columns = 1, .charts = {}};
  figure.charts.push_back(chart("legend", {rising}));
  const fs::path with = dir / "with.png", without = dir / "without.png";
  write_chart_png(with, figure);
  figure.charts[0].legend = false;
  write_chart_png(without, figure);
  const Pixels a = find(read_png(with), near(red, 60)), b = find(read_png(without), near(red, 60));
  ASSERT_GT(a.size(), 100u);
  ASSERT_GT(b.size(), 100u);

  // The legend's red sample is the rightmost red: a short horizontal run in the upper half.
  const double right = max_of(a.x);
  double sample_y = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a.x[i] == right) sample_y = a.y[i];
  EXPECT_GT(sample_y, 0.5 * 400);
  double sample_left = right, line_right = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::abs(a.y[i] - sample_y) <= 3 && a.x[i] > right - 80)
      sample_left = std::min(sample_left, a.x[i]);
    else
      line_right = std::max(line_right, a.x[i]);
  }
  EXPECT_GT(right - sample_left, 15.0); // a line sample, not a stray pixel
  // The line ends left of the legend, and the plot gave up room for it: without the legend the
  // same line reaches further right.
  EXPECT_LT(line_right, sample_left - 5);
  EXPECT_LT(line_right, max_of(b.x) - 30);
}

// ----- validation: no picture is drawn, so no display is needed -------------------------------

TEST(ChartValidation, EmptyFigureIsRefused) {
  expect_invalid(Figure{}, {"no charts"});
}

TEST(ChartValidation, LengthMismatchNamesChartAndSeries) {
  Series s{.label = "measured", .x = {1, 2, 3, 4, 5}, .y = {1, 2, 3, 4}};
  Figure figure;
  figure.charts.push_back(chart("Gap per step", {s}));
  expect_invalid(figure, {"chart 'Gap per step', series 'measured': x has 5 values and y 4"});
}

TEST(ChartValidation, UnlabelledSeriesAndUntitledChartAreNumbered) {
  Series good{.label = "a", .x = {1}, .y = {1}};
  Series bad{.label = "", .x = {1, 2}, .y = {1}};
  Figure figure;
  figure.charts.push_back(chart("first", {good}));
  figure.charts.push_back(chart("", {good, bad}));
  expect_invalid(figure, {"chart 2, series 2: x has 2 values and y 1"});
}

TEST(ChartValidation, NonFiniteValuesAreRefused) {
  Series s{.label = "simulated", .x = {1, 2, 3}, .y = {1, NAN, 3}};
  Figure figure;
  figure.charts.push_back(chart("FRF", {s}));
  expect_invalid(figure, {"chart 'FRF', series 'simulated'", "y[1]", "not finite"});
  figure.charts[0].series[0].y[1] = 2.0;
  figure.charts[0].series[0].x[2] = INFINITY;
  expect_invalid(figure, {"chart 'FRF', series 'simulated'", "x[2]", "not finite"});
}

TEST(ChartValidation, LogAxisWithZeroOrNegativeThrows) {
  Series s{.label = "gap", .x = {1, 2, 3}, .y = {1e-3, 0.0, 1e-5}};
  Figure figure;
  figure.charts.push_back(chart("Gap per step", {s}));
  figure.charts[0].log_y = true;
  expect_invalid(figure, {"chart 'Gap per step', series 'gap'", "y[1] = 0", "logarithmic y"});
  figure.charts[0].log_y = false;
  figure.charts[0].log_x = true;
  figure.charts[0].series[0].x[0] = -1.0;
  expect_invalid(figure, {"x[0] = -1", "logarithmic x"});
}

TEST(ChartValidation, BadSizeColumnsColourAndWidthAreRefused) {
  Figure figure;
  figure.charts.push_back(chart("t", {ramp(3, red)}));
  Figure small = figure;
  small.width = 0;
  expect_invalid(small, {"size 0"});
  Figure no_columns = figure;
  no_columns.columns = 0;
  expect_invalid(no_columns, {"columns = 0"});
  Figure bad_colour = figure;
  bad_colour.charts[0].series[0].color = {300, 0, 0};
  expect_invalid(bad_colour, {"chart 't', series 1", "colour {300, 0, 0}"});
  Figure bad_width = figure;
  bad_width.charts[0].series[0].width = 0.0;
  expect_invalid(bad_width, {"width = 0"});
  Figure no_series = figure;
  no_series.charts[0].series.clear();
  expect_invalid(no_series, {"chart 't' has no series"});
}

TEST(ChartValidation, MissingDirectoryIsNamed) {
  Figure figure;
  figure.charts.push_back(chart("t", {ramp(3, red)}));
  test::TempDir dir;
  const fs::path png = dir / "missing" / "x.png";
  try {
    write_chart_png(png, figure);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(png.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "missing"));
}

TEST(ChartValidation, WithoutDisplayTheErrorSaysToUseXvfbRun) {
  Figure figure;
  figure.charts.push_back(chart("t", {ramp(3, red)}));
  test::TempDir dir;
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display != nullptr ? display : "";
  const bool had_display = display != nullptr;
  ::unsetenv("DISPLAY");
  std::string why;
  EXPECT_FALSE(can_render_charts(&why));
  EXPECT_NE(why.find("DISPLAY"), std::string::npos) << why;
  try {
    write_chart_png(dir / "x.png", figure);
    ADD_FAILURE() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("xvfb-run"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find((dir / "x.png").string()), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
  if (had_display) {
    ::setenv("DISPLAY", saved.c_str(), 1);
    EXPECT_TRUE(can_render_charts(&why)) << why;
    EXPECT_TRUE(why.empty()) << why;
  }
}

} // namespace
} // namespace jointid::report
