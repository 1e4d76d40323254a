#pragma once
/// What a record returned by a reader promises (io/record_csv.hpp, io/uff58.hpp): at least 4
/// samples, finite values, time strictly increasing and uniform to 1e-6 of its step. The record
/// targets check it on every record they get, and abort (a finding) when it does not hold.
#include "identify/record.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace jointid::fuzz {

[[noreturn]] inline void broken(const identify::Record& record, const std::string& what) {
  std::fprintf(stderr, "record contract broken (%s): %s\n", record.source.c_str(), what.c_str());
  std::abort();
}

inline void check_record(const identify::Record& record) {
  const Eigen::Index n = record.t.size();
  if (n < 4) broken(record, "fewer than 4 samples");
  if (!record.t.allFinite()) broken(record, "t is not finite");
  const double dt = record.dt();
  if (!(std::isfinite(dt) && dt > 0.0)) broken(record, "the mean step is not finite and > 0");
  for (Eigen::Index i = 1; i < n; ++i) {
    const double step = record.t(i) - record.t(i - 1);
    if (!(step > 0.0)) broken(record, "t does not increase at sample " + std::to_string(i));
    if (!(std::abs(step - dt) <= 1e-6 * dt * (1.0 + 1e-9)))
      broken(record, "the step at sample " + std::to_string(i) + " is not uniform");
  }
  for (const auto& channel : record.channels) {
    if (channel.samples.size() != n) broken(record, channel.name() + ": not as long as t");
    if (!channel.samples.allFinite()) broken(record, channel.name() + ": not finite");
  }
  if (record.excitation_hz && !(std::isfinite(*record.excitation_hz) && *record.excitation_hz > 0))
    broken(record, "excitation_hz is not a frequency > 0");
}

} // namespace jointid::fuzz
