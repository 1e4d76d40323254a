// libFuzzer target: the measurement CSV readers on the same input, a time record
// (io::read_record, then its fundamentals, identify::stepped_sine_table, at its excitation_hz or at
// the frequency estimated from it) and a stepped-sine table
// (io::read_stepped_sine, then its tests). Contract: a result or io::Error; anything else
// escaping is a finding, and so is a record or table that breaks what the reader promises
// (record_contract.hpp; a table's frequencies > 0 and values finite).
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "record_contract.hpp"

#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;
  const auto path = jointid::fuzz::input_file("input.csv", data, size);
  try {
    const auto record = jointid::io::read_record(path);
    jointid::fuzz::check_record(record);
    try { // its fundamentals at excitation_hz, or at the estimated frequency
      (void)jointid::identify::stepped_sine_table({record});
    } catch (const std::invalid_argument&) { // a record whose fundamental cannot be fitted
    }
  } catch (const jointid::io::Error&) {
  }
  try {
    const auto table = jointid::io::read_stepped_sine(path);
    for (const double f : table.freq_hz)
      if (!(std::isfinite(f) && f > 0.0)) std::abort();
    if (!table.values.allFinite()) std::abort();
    (void)jointid::io::stepped_sine_tests(table, path);
  } catch (const jointid::io::Error&) {
  }
  return 0;
}
