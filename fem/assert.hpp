#pragma once
/// JOINTID_ASSERT(condition, message): a debug check of an internal invariant, something the
/// code itself guarantees (matrix sizes that agree, an index in range, a basis orthonormal to
/// rounding) — never a check of the caller's input, which throws (DESIGN.md). Without NDEBUG a
/// false condition writes "file:line: internal invariant violated: condition: message" to
/// stderr and aborts (a bug, not an outcome to handle). With NDEBUG (Release) it compiles to
/// nothing: neither the condition nor the message is evaluated. `message` is anything a
/// std::string_view can be made from, evaluated only when the condition is false.
#include <cstdio>
#include <cstdlib>
#include <string_view>

namespace jointid::fem::detail {

[[noreturn]] inline void assertion_failed(const char* file, int line, const char* condition,
                                          std::string_view message) {
  std::fprintf(stderr, "%s:%d: internal invariant violated: %s: %.*s\n", file, line, condition,
               static_cast<int>(message.size()), message.data());
  std::abort();
}

} // namespace jointid::fem::detail

#ifdef NDEBUG
// sizeof: the condition and the message are named (no unused-variable warnings) but never
// evaluated.
#define JOINTID_ASSERT(condition, message) static_cast<void>(sizeof(!(condition)) + sizeof(message))
#else
#define JOINTID_ASSERT(condition, message)                                                         \
  ((condition)                                                                                     \
       ? static_cast<void>(0)                                                                      \
       : ::jointid::fem::detail::assertion_failed(__FILE__, __LINE__, #condition, (message)))
#endif
