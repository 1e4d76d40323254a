#pragma once
/// File helpers shared by the readers and writers, and the error type of all of `io`.
#include <filesystem>
#include <stdexcept>
#include <string>

namespace jointid::io {

/// Any input or output problem: a file that cannot be read or written, or content that breaks
/// its contract. The message names the file, the line when known, the key or field, and what
/// was expected, e.g. `cantilever.toml:14: [[joints]] 'tip': key 'dof': expected one of ux, uy,
/// uz, rx, ry, rz, got "uw"`.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The whole file as a string; throws Error naming the path when it cannot be read.
std::string read_file(const std::filesystem::path& path);

/// Writes `content` to a temporary file in the same directory and renames it over `path`, so
/// that an existing file is either replaced whole or left untouched. Throws Error naming the
/// path (the temporary file is removed).
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

} // namespace jointid::io
