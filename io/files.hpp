#pragma once
/// File helpers shared by the readers and writers, and the error type of all of `io`.
///
/// Outputs are atomic: every file is written under a temporary name in its own directory and
/// renamed over the target at the end, so an existing file is either replaced whole or left
/// untouched. Temporary files and directories in progress are registered, so that an
/// interrupt (install_interrupt_cleanup) removes them before the process exits.
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace jointid::io {

/// Any input or output problem: a file that cannot be read or written, or content that breaks
/// its contract. The message names the file, the line when known, the key or field, and what
/// was expected, e.g. `cantilever.toml:14: [[joints]] 'tip': key 'dof': expected one of ux, uy,
/// uz, rx, ry, rz, got "uw"`.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The whole file as a string; throws Error naming the path when it cannot be read. After
/// protect_inputs(), the file is remembered as an input of this run.
std::string read_file(const std::filesystem::path& path);

/// Writes `content` to a temporary file in the same directory and renames it over `path`, so
/// that an existing file is either replaced whole or left untouched. Throws Error naming the
/// path (the temporary file is removed).
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

/// A temporary file or directory this process is writing, removed if the process is
/// interrupted while it is registered (see install_interrupt_cleanup). Register the name
/// before creating it; the destructor only unregisters (removing it is the owner's job).
/// At most 256 are tracked at a time; beyond that a name is simply not tracked.
class InFlight {
public:
  enum class Kind { file, directory };
  InFlight(const std::filesystem::path& path, Kind kind);
  InFlight(const InFlight&) = delete;
  InFlight& operator=(const InFlight&) = delete;
  ~InFlight();

private:
  int slot_ = -1;
};

/// Several output files replaced together: add() writes each under a temporary name in its
/// target's directory, commit() renames them all into place (an interrupt arriving meanwhile
/// waits until the last is renamed). Temporary files not committed are removed on
/// destruction, so a failure before commit() leaves every target as it was.
class OutputFiles {
public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles();

  /// Writes `content` to a temporary file beside `path`; throws Error naming the path.
  void add(const std::filesystem::path& path, const std::string& content);
  /// Renames every added file over its target; throws Error naming the first that failed.
  void commit();

private:
  struct Staged {
    std::filesystem::path target, temporary;
    std::unique_ptr<InFlight> registration;
  };
  std::vector<Staged> staged_;
};

/// While one exists, an interrupt is held back: the process exits when the last one ends.
/// Wraps the renames that put outputs in place, so that a set of outputs (or an old
/// directory moved aside for its replacement) is never left half-replaced.
class CommitSection {
public:
  CommitSection();
  CommitSection(const CommitSection&) = delete;
  CommitSection& operator=(const CommitSection&) = delete;
  ~CommitSection();
};

/// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove every registered temporary
/// file and directory (InFlight) and exit with status 128 + the signal (130 for SIGINT).
/// For programs (the `jointid` command), not for libraries.
void install_interrupt_cleanup();

/// From now on, every file read through read_file() is an input of this run, and outputs are
/// never written over one: write_file_atomically, OutputFiles and the VTK and PNG writers
/// throw Error instead (see check_not_an_input).
void protect_inputs();

/// Throws Error if `path` is (the same file as) an input read since protect_inputs().
void check_not_an_input(const std::filesystem::path& path);

} // namespace jointid::io
