// libFuzzer target: the tests as identify, discover and design read them, io::read_tests (a CSV
// time record or stepped-sine table, told apart by the header; a universal file by its name),
// then each test reduced to its harmonics, identify::measure. The same input is read as
// input.csv and as input.uff. Contract: io::Error from the readers, std::invalid_argument from
// measure (a test it cannot reduce, named); anything else escaping is a finding, and so is a
// record that breaks the record contract (record_contract.hpp) or a measurement whose
// excitation frequency is not finite and > 0.
#include "fuzz_input.hpp"
#include "identify/measurement.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "record_contract.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <variant>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;
  for (const char* name : {"input.csv", "input.uff"}) {
    const auto path = jointid::fuzz::input_file(name, data, size);
    try {
      const auto tests = jointid::io::read_tests({path});
      for (const auto& test : tests) {
        if (const auto* record = std::get_if<jointid::identify::Record>(&test))
          jointid::fuzz::check_record(*record);
        try {
          const auto m = jointid::identify::measure(test, {.harmonics = 2});
          if (!(std::isfinite(m.frequency_hz) && m.frequency_hz > 0.0)) std::abort();
        } catch (const std::invalid_argument&) {
        }
      }
    } catch (const jointid::io::Error&) {
    }
  }
  return 0;
}
