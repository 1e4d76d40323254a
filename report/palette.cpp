// The default colours of chart series (see chart.hpp); without VTK too, since the discovery
// report picks its colours before it knows whether it can draw.
#include "report/chart.hpp"

namespace jointid::report {

namespace {

/// Matplotlib's "tab10" (Tableau 10): distinct, readable on white, known to every reader.
constexpr std::array<std::array<int, 3>, 10> palette{{{31, 119, 180},
                                                      {255, 127, 14},
                                                      {44, 160, 44},
                                                      {214, 39, 40},
                                                      {148, 103, 189},
                                                      {140, 86, 75},
                                                      {227, 119, 194},
                                                      {127, 127, 127},
                                                      {188, 189, 34},
                                                      {23, 190, 207}}};

} // namespace

std::array<int, 3> palette_color(std::size_t i) {
  return palette[i % palette.size()];
}

} // namespace jointid::report
