// libFuzzer target: the universal file reader (datasets 58, 58b and 164), io::read_uff58, then
// the time responses as sine tests, io::uff58_tests. Contract: a result or io::Error; anything
// else escaping is a finding, and so is a sine test's record that breaks what the reader
// promises (record_contract.hpp).
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/uff58.hpp"
#include "record_contract.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;
  const auto path = jointid::fuzz::input_file("input.uff", data, size);
  try {
    const auto functions = jointid::io::read_uff58(path);
    try {
      for (const auto& test : jointid::io::uff58_tests(functions, path))
        jointid::fuzz::check_record(std::get<jointid::identify::Record>(test));
    } catch (const jointid::io::Error&) {
    }
  } catch (const jointid::io::Error&) {
  }
  return 0;
}
