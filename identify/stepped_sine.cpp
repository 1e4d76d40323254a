#include "identify/stepped_sine.hpp"

#include "identify/harmonics.hpp"

#include <fmt/format.h>

#include <numbers>
#include <stdexcept>

namespace jointid::identify {

SteppedSineTable stepped_sine_table(const std::vector<Record>& records) {
  SteppedSineTable table;
  if (records.empty()) return table;
  for (const auto& c : records.front().channels)
    table.channels.push_back(c.name());
  table.values.resize(static_cast<Eigen::Index>(records.size()),
                      static_cast<Eigen::Index>(table.channels.size()));
  for (std::size_t i = 0; i < records.size(); ++i) {
    const Record& r = records[i];
    std::vector<std::string> names;
    for (const auto& c : r.channels)
      names.push_back(c.name());
    if (names != table.channels)
      throw std::invalid_argument(
          fmt::format("{}: its channels differ from those of {}; a stepped-sine table "
                      "needs the same channels in every test",
                      r.source, records.front().source));
    const double f = r.excitation_hz
                         ? *r.excitation_hz
                         : estimate_frequency(r.t, r.all(Quantity::force).empty()
                                                       ? r.channels.front().samples
                                                       : r.all(Quantity::force).front()->samples);
    const double nyquist = 0.5 / r.dt();
    if (!(f < nyquist))
      throw std::invalid_argument(
          fmt::format("{}: the excitation, {} Hz, is not below the Nyquist frequency of "
                      "its sampling, {} Hz (step {} s): its fundamental cannot be fitted",
                      r.source, f, nyquist, r.dt()));
    const int n = whole_period_samples(r.t, f);
    if (n == 0)
      throw std::invalid_argument(fmt::format("{}: shorter than one period of {} Hz", r.source, f));
    if (n < 3)
      throw std::invalid_argument(
          fmt::format("{}: its whole periods of {} Hz hold {} samples; fitting the "
                      "fundamental needs at least 3 (a longer record or faster sampling)",
                      r.source, f, n));
    table.freq_hz.push_back(f);
    for (std::size_t c = 0; c < r.channels.size(); ++c)
      table.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = fit_harmonics(
          Eigen::VectorXd(r.t.head(n)), Eigen::VectorXd(r.channels[c].samples.head(n)),
          2.0 * std::numbers::pi * f, 1)(1);
  }
  return table;
}

} // namespace jointid::identify
