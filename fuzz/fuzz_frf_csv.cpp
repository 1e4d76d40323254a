// libFuzzer target: the measured-FRF CSV reader, io::read_frf_csv, then the functions as a
// substructure's measured receptance (frf::MeasuredReceptance) evaluated at a line, between
// lines and outside the band. Contract: a result or io::Error (std::invalid_argument from the
// receptance outside the band); anything else escaping is a finding, and so are functions that
// break what the reader promises (at least 2 lines, frequencies increasing and >= 0, finite
// values: MeasuredFrf::validate).
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/measured_frf_file.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;
  const auto path = jointid::fuzz::input_file("input.csv", data, size);
  try {
    jointid::frf::MeasuredFrf frf = jointid::io::read_measured_frf({path});
    try {
      frf.validate();
    } catch (const std::invalid_argument&) {
      std::abort(); // the reader returned functions it should have refused
    }
    const jointid::frf::MeasuredReceptance H(frf);
    const auto& f = frf.functions.front();
    const int n = static_cast<int>(frf.dofs.size());
    std::vector<int> all(static_cast<std::size_t>(n));
    for (int e = 0; e < n; ++e)
      all[static_cast<std::size_t>(e)] = e;
    const double two_pi = 2.0 * std::numbers::pi;
    for (const double freq :
         {f.frequencies_hz.front(), 0.5 * (f.frequencies_hz[0] + f.frequencies_hz[1]),
          f.frequencies_hz.back() * 2.0 + 1.0, 0.0})
      try {
        const Eigen::MatrixXcd h = H.receptance(two_pi * freq, all, all);
        (void)h;
      } catch (const std::invalid_argument&) {
      }
    (void)H.interpolation_error(all);
  } catch (const jointid::io::Error&) {
  }
  return 0;
}
