#pragma once
/// Measured FRFs read from files, for a substructure given by them (a model file's [frf]
/// section): universal files (dataset 58, function type 4; io/uff58.hpp) and CSV tables in the
/// form `jointid frf` writes.
///
/// CSV: `#` comment lines, then a header `freq_hz,<node>:<dof>.re,<node>:<dof>.im,…` (one pair
/// per response), then one row per line: frequency (Hz, increasing) and the complex values
/// (SI). One drive per file, given by a comment line in either form
///   `# receptance from a force at 7:uy: ...`   (the first line `jointid frf` writes)
///   `# drive = 7:uy` and `# kind = receptance` (mobility, accelerance; default receptance)
/// Mobility Y = iωH and accelerance A = −ω²H are converted to the receptance H (their 0 Hz line
/// is dropped). A UTF-8 byte-order mark is skipped.
#include "frf/measured_frf.hpp"

#include <filesystem>
#include <vector>

namespace jointid::io {

/// The functions of one CSV table. Throws io::Error naming the file, the line and what was
/// expected: no drive given (or given twice), an unknown kind, a header that is not freq_hz
/// and .re/.im pairs of NODE:DOF, a row of the wrong length or with a value that is not a
/// finite number, frequencies that are negative or do not increase, fewer than 2 rows.
std::vector<frf::MeasuredFunction> read_frf_csv(const std::filesystem::path& path);

/// The functions of every file (a universal file when its first non-blank line is `    -1`,
/// else a CSV table), the DOFs being every response and drive in order of first appearance.
/// Throws io::Error naming the file: no function, or the same response and drive in two files.
frf::MeasuredFrf read_measured_frf(const std::vector<std::filesystem::path>& files);

} // namespace jointid::io
