#pragma once
/// Measurement records and stepped-sine tables as CSV files (DESIGN.md's contracts).
/// Record: `#` comment lines (optionally `# excitation_hz = 3.0`), then `t,<channel>...`, then
/// uniformly sampled rows; channels are `<quantity>@<node>:<dof>` (SI units).
/// Stepped-sine table: `#` comments, then `freq_hz,<channel>.re,<channel>.im,...`, one test
/// per row, complex peak amplitudes with x(t) = Re(X e^{iωt}).
#include "fem/dof_map.hpp"
#include "identify/measurement.hpp"
#include "identify/record.hpp"
#include "identify/stepped_sine.hpp"
#include "joints/joint.hpp"

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace jointid::io {

/// Reads one record. Record::source is the path as given. Throws io::Error naming the file
/// and line: missing header, first column not `t`, unknown or repeated channel, a row with the
/// wrong number of fields, a field that is not a finite number, fewer than 4 rows, time not
/// strictly increasing or not uniform (a step deviating from the mean step by more than 1e-6,
/// relative).
identify::Record read_record(const std::filesystem::path& path);
std::vector<identify::Record> read_records(const std::vector<std::filesystem::path>& paths);

/// The CSV text of a record: each comment as `# ...` lines, `# excitation_hz = ...` when
/// set, the header and the rows, every number in its shortest form that reads back
/// bit-exactly. Throws io::Error if the channels' lengths differ from t's, a value is not
/// finite (the reader would refuse the file) or a comment line starts with `excitation_hz`
/// (that comment is written from Record::excitation_hz only).
std::string record_csv(const identify::Record& record,
                       const std::vector<std::string>& comments = {});
/// Writes record_csv(record, comments) atomically (see write_file_atomically).
void write_record(const std::filesystem::path& path, const identify::Record& record,
                  const std::vector<std::string>& comments = {});

using SteppedSineTable = identify::SteppedSineTable;

/// Reads a stepped-sine table; throws io::Error naming file, line and column as read_record.
/// A comment `# convention = ...` states the table's phase convention: x(t) = Re(X e^{iωt})
/// (jointid's, the default), x(t) = Re(X e^{-iωt}) (the values are conjugated as read) or
/// x(t) = Im(X e^{iωt}) (a sine reference: the values are multiplied by −i as read); blanks, the
/// case, "x(t) =", ω or w, i or j, e^{…} or exp(…) as one likes. Another convention, or two
/// that differ, are refused naming the line.
SteppedSineTable read_stepped_sine(const std::filesystem::path& path);

/// The CSV text of a stepped-sine table: each comment as `# ...` lines, the header and one row
/// per test, every number in its shortest form that reads back bit-exactly. Throws io::Error
/// if the sizes disagree or a value is not finite.
std::string stepped_sine_csv(const SteppedSineTable& table,
                             const std::vector<std::string>& comments = {});

/// The table's tests as sine tests; each one's source is "<path>:<line>".
std::vector<identify::SineTest> stepped_sine_tests(const SteppedSineTable& table,
                                                   const std::filesystem::path& path);

/// Reads measured sine tests from files of three kinds: universal files (name ending in .uff,
/// .unv or .uf58, any case: the time responses of their datasets 58, one test per abscissa, see
/// io/uff58.hpp's uff58_tests), and CSV files told apart by the header's first column: `t` (a
/// time record: one test) or `freq_hz` (a stepped-sine table: one test per row). Throws
/// io::Error naming the file for anything else, and when a file is given twice (its tests would
/// count twice and the intervals come out falsely narrow).
std::vector<identify::SineTest> read_tests(const std::vector<std::filesystem::path>& paths);

} // namespace jointid::io
