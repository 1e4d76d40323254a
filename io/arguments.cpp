#include "io/arguments.hpp"

#include "io/files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace jointid::io {

void check_harmonics(const std::string& name, const std::vector<int>& harmonics, int lowest) {
  if (harmonics.empty())
    throw Error(fmt::format("{}: expected at least one harmonic, e.g. 1,2,3", name));
  if (harmonics.size() == 1 && harmonics[0] == 0)
    throw Error(fmt::format("{}: 0 alone is the mean (static) balance, which a sine test does "
                            "not excite: add harmonic 1 (e.g. 0,1,2,3)",
                            name));
  std::set<int> seen;
  for (int k : harmonics) {
    if (k < lowest)
      throw Error(fmt::format("{}: expected harmonics >= {}, got {}", name, lowest, k));
    if (!seen.insert(k).second)
      throw Error(fmt::format("{}: harmonic {} is listed twice", name, k));
  }
}

void check_balance_harmonics(const std::string& name, int harmonics, int lowest,
                             const std::string& why) {
  if (harmonics < lowest || harmonics > 200)
    throw Error(why.empty() ? fmt::format("{}: expected {} to 200, got {}", name, lowest, harmonics)
                            : fmt::format("{}: expected from {} ({}) to 200, got {}", name, lowest,
                                          why, harmonics));
}

void check_amplitudes(const std::string& name, const std::vector<double>& amplitudes) {
  if (amplitudes.empty()) throw Error(fmt::format("{}: expected at least one amplitude (N)", name));
  for (double a : amplitudes)
    if (!(std::isfinite(a) && a > 0.0))
      throw Error(fmt::format("{}: expected finite amplitudes > 0 (N or N m), got {}", name, a));
}

void check_noise(const std::string& name, double noise) {
  if (!(std::isfinite(noise) && noise >= 0.0 && noise < 1.0))
    throw Error(fmt::format(
        "{}: expected a fraction of each channel's RMS from 0 to below 1, got {}", name, noise));
}

std::vector<identify::Quantity> parse_channels(const std::string& name,
                                               const std::vector<std::string>& channels) {
  std::vector<identify::Quantity> out;
  for (const auto& c : channels) {
    const identify::Quantity q =
        c == "x"   ? identify::Quantity::displacement
        : c == "v" ? identify::Quantity::velocity
        : c == "a" ? identify::Quantity::acceleration
                   : throw Error(fmt::format("{}: expected x, v or a, got \"{}\"", name, c));
    if (std::find(out.begin(), out.end(), q) != out.end())
      throw Error(fmt::format("{}: {} is listed twice", name, c));
    out.push_back(q);
  }
  if (out.empty()) throw Error(fmt::format("{}: expected x, v and/or a", name));
  return out;
}

void check_sine_tests(const SineTestNames& names, const std::vector<double>& frequencies,
                      const identify::SimulationOptions& options) {
  if (frequencies.empty())
    throw Error(fmt::format("{}: expected at least one frequency (Hz)", names.freq));
  for (double f : frequencies)
    if (!(std::isfinite(f) && f > 0.0))
      throw Error(fmt::format("{}: expected frequencies > 0 Hz, got {}", names.freq, f));
  if (options.periods < 1)
    throw Error(fmt::format("{}: expected at least 1, got {}", names.periods, options.periods));
  if (options.steps_per_period < 8)
    throw Error(fmt::format("{}: expected at least 8, got {}", names.steps_per_period,
                            options.steps_per_period));
  if (options.samples_per_period != 0 &&
      (options.samples_per_period < 8 ||
       options.steps_per_period % options.samples_per_period != 0))
    throw Error(fmt::format("{}: expected at least 8 and a divisor of {} ({}), got {}",
                            names.samples_per_period, names.steps_per_period,
                            options.steps_per_period, options.samples_per_period));
  if (options.balance.harmonics < 1)
    throw Error(fmt::format("{}: expected at least 1, got {}", names.balance_harmonics,
                            options.balance.harmonics));
}

} // namespace jointid::io
