// libFuzzer target: the MatrixMarket reader (io::read_matrix_market) and the DOF table reader
// (io::read_dof_table), both on the same input. Contract: a result or io::Error; anything else
// escaping is a finding.
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/matrix_market.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;
  const auto path = jointid::fuzz::input_file("input.mtx", data, size);
  try {
    (void)jointid::io::read_matrix_market(path);
  } catch (const jointid::io::Error&) {
  }
  try {
    (void)jointid::io::read_dof_table(path);
  } catch (const jointid::io::Error&) {
  }
  return 0;
}
