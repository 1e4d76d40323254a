#include "cli/terminal_progress.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <utility>

#include <unistd.h>

namespace jointid::cli {

TerminalProgress::TerminalProgress(std::string label, bool enabled)
    : label_(std::move(label)), on_(enabled && isatty(STDERR_FILENO) == 1) {}

void TerminalProgress::show(double fraction) const {
  if (!on_) return;
  fmt::print(stderr, "\r{}: {:3.0f} %", label_, 100.0 * fraction);
  std::fflush(stderr);
}

std::function<void(double)> TerminalProgress::callback() const {
  if (!on_) return {};
  return [this](double fraction) { show(fraction); };
}

void TerminalProgress::clear() const {
  if (!on_) return;
  fmt::print(stderr, "\r{}\r", std::string(label_.size() + 8, ' '));
  std::fflush(stderr);
}

} // namespace jointid::cli
