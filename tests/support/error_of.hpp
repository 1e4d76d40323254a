#pragma once
// The message of the exception `f` throws (any std::exception), or "(no error)": for tests that
// assert a message exactly.
#include <exception>
#include <functional>
#include <string>

namespace jointid::test {

inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

} // namespace jointid::test
