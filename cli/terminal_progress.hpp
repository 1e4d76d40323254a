#pragma once
/// Progress of a long run (simulations, continuation, predictions, Monte Carlo) on stderr, as
/// "\r<label>:  42 %", only when stderr is a terminal: a run whose output goes to a file or a
/// pipe (CI, scripts) stays quiet. clear() wipes the line before the next output.
#include <functional>
#include <string>

namespace jointid::cli {

class TerminalProgress {
public:
  /// `enabled` false: never shows (e.g. an MPI rank other than 0).
  explicit TerminalProgress(std::string label, bool enabled = true);
  /// Shows `fraction` (0 … 1) of the run done, if on.
  void show(double fraction) const;
  /// A callback that shows the fraction it is called with; empty when off.
  std::function<void(double)> callback() const;
  /// Wipes the line, if on.
  void clear() const;
  bool on() const { return on_; }

private:
  std::string label_;
  bool on_ = false;
};

} // namespace jointid::cli
