// libFuzzer target: the universal file reader (datasets 58, 58b and 164), io::read_uff58, then
// the time responses as sine tests, io::uff58_tests, and the FRFs as a substructure's measured
// functions, io::uff58_frfs. Contract: a result or io::Error; anything else escaping is a
// finding, and so is a sine test's record that breaks what the reader promises
// (record_contract.hpp) or FRFs that frf::MeasuredFrf::validate refuses.
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/uff58.hpp"
#include "record_contract.hpp"

#include <algorithm>
#include <stdexcept>

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
    try {
      jointid::frf::MeasuredFrf frf;
      frf.functions = jointid::io::uff58_frfs(functions, path);
      for (const auto& f : frf.functions)
        for (const auto& at : {f.response, f.drive})
          if (std::find(frf.dofs.begin(), frf.dofs.end(), at) == frf.dofs.end())
            frf.dofs.push_back(at);
      try {
        frf.validate();
      } catch (const std::invalid_argument&) {
        std::abort(); // the reader returned functions it should have refused
      }
    } catch (const jointid::io::Error&) {
    }
  } catch (const jointid::io::Error&) {
  }
  return 0;
}
