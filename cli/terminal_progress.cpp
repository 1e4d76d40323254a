#include "cli/terminal_progress.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include <unistd.h>

namespace jointid::cli {

TerminalProgress::TerminalProgress(std::string label, bool enabled)
    : label_(std::move(label)), on_(enabled && isatty(STDERR_FILENO) == 1) {}

TerminalProgress::~TerminalProgress() {
  clear();
}

void TerminalProgress::print(const std::string& line) const {
  fmt::print(stderr, "\r{}", line);
  std::fflush(stderr);
  shown_ = std::max(shown_, line.size());
}

void TerminalProgress::show(double fraction) const {
  if (on_) print(fmt::format("{}: {:3.0f} %", label_, 100.0 * fraction));
}

void TerminalProgress::show(std::string_view step, double fraction) const {
  if (on_) print(fmt::format("{}: {}: {:3.0f} %", label_, step, 100.0 * fraction));
}

std::function<void(double)> TerminalProgress::callback() const {
  if (!on_) return {};
  return [this](double fraction) { show(fraction); };
}

void TerminalProgress::clear() const {
  if (!on_ || shown_ == 0) return;
  fmt::print(stderr, "\r{}\r", std::string(shown_, ' '));
  std::fflush(stderr);
  shown_ = 0;
}

} // namespace jointid::cli
