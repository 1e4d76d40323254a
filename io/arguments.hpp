#pragma once
/// The checks of a run's arguments that the command line and the Python module share. Each
/// takes the argument's name as its caller spells it ("--harmonics" on the command line,
/// "harmonics" in Python) and throws io::Error starting with that name and saying what was
/// expected, so that both front ends refuse the same input with the same words.
#include "identify/record.hpp"
#include "identify/sine_tests.hpp"

#include <string>
#include <vector>

namespace jointid::io {

/// Harmonics to fit or balance: at least one, each >= `lowest` and listed once, not 0 alone.
/// No upper cap: the sampling sets the highest harmonic a record has (identify::measure says
/// so, naming the record).
void check_harmonics(const std::string& name, const std::vector<int>& harmonics, int lowest);
/// A harmonic balance's number of harmonics, from `lowest` to 200; `why` says where the
/// lowest comes from (e.g. "the highest fitted harmonic").
void check_balance_harmonics(const std::string& name, int harmonics, int lowest,
                             const std::string& why = "");
/// Force amplitudes (N or N m): at least one, each finite and > 0.
void check_amplitudes(const std::string& name, const std::vector<double>& amplitudes);
/// Measurement noise as a fraction of each channel's RMS, from 0 to below 1.
void check_noise(const std::string& name, double noise);
/// Measured quantities "x", "v", "a" (displacement, velocity, acceleration), each once.
std::vector<identify::Quantity> parse_channels(const std::string& name,
                                               const std::vector<std::string>& channels);

/// How a front end spells the options of its sine tests (check_sine_tests).
struct SineTestNames {
  std::string freq, periods, steps_per_period, samples_per_period, balance_harmonics;
};
/// Sine tests' frequencies (at least one, each > 0 Hz) and sampling: at least one period, 8
/// steps a period, the samples kept a divisor of the steps (0: every step), at least one
/// balance harmonic.
void check_sine_tests(const SineTestNames& names, const std::vector<double>& frequencies,
                      const identify::SimulationOptions& options);

} // namespace jointid::io
