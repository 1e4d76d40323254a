#pragma once
/// Progress of a long run (simulations, continuation, predictions, Monte Carlo) on stderr, as
/// "\r<label>:  42 %", only when stderr is a terminal: a run whose output goes to a file or a
/// pipe (CI, scripts) stays quiet. The line is wiped by clear(), and when the object ends
/// (however the run ends), so that the next output starts on a clean line.
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace jointid::cli {

class TerminalProgress {
public:
  /// `enabled` false: never shows (e.g. an MPI rank other than 0).
  explicit TerminalProgress(std::string label, bool enabled = true);
  ~TerminalProgress();
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  /// Shows `fraction` (0 … 1) of the run done, if on.
  void show(double fraction) const;
  /// Shows "<label>: <step>:  42 %", if on: a run of several steps (e.g. "10 N (1 of 2)").
  void show(std::string_view step, double fraction) const;
  /// A callback that shows the fraction it is called with; empty when off.
  std::function<void(double)> callback() const;
  /// Wipes the line, if anything is shown.
  void clear() const;
  bool on() const { return on_; }

private:
  void print(const std::string& line) const;

  std::string label_;
  bool on_ = false;
  mutable std::size_t shown_ = 0; ///< characters of the line shown (0: none)
};

} // namespace jointid::cli
