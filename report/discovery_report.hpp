#pragma once
/// The discovery report: DIR/report.md with its PNG plots (VTK's charts, in jointid_io_vtk).
#include "discover/discover.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace jointid::report {

struct ReportContext {
  std::string model;               ///< the model file, as given
  std::vector<std::string> inputs; ///< the measurement files, as given
  bool plots = true;               ///< false: the report without pictures
};

/// Writes `dir/report.md` and its plots: `gap.png` (the gap after each step, and the noise
/// level), `response_<i>.png` per step i (measured and simulated receptance |X₁/F₁| over
/// frequency — or over force level when the tests have more levels than frequencies — at every
/// force level, before and after the step, one row per channel) and `candidates_<i>.png` (the
/// share of the gap each candidate explains). Every file is written atomically. Without an X
/// display the plots are skipped, the report says so and a warning is added. Returns the files
/// written.
std::vector<std::filesystem::path> write_discovery_report(const std::filesystem::path& dir,
                                                          const discover::Result& result,
                                                          const ReportContext& context,
                                                          std::vector<std::string>& warnings);

} // namespace jointid::report
