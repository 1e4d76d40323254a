#pragma once
/// The outcome of a numerical computation, the one vocabulary of every folder (DESIGN.md: bad
/// input throws an exception; a numerical outcome is a status with its reason, passed up; an
/// internal invariant is a debug assert). A result that can fail numerically carries a Status;
/// a function that computes a value that can fail returns an Outcome. A caller that must refuse
/// (the command line) throws with `reason`; a library function passes the status up.
#include "fem/assert.hpp"

#include <string>
#include <string_view>
#include <utility>

namespace jointid::fem {

struct Status {
  enum class Code {
    ok,
    not_converging,  ///< an iteration stopped at its limit short of its tolerance
    not_periodic,    ///< a time simulation reached its limit of periods without a steady state
    numerical_issue, ///< a factorisation or solve failed: a matrix singular or not definite
    not_separable,   ///< the equations do not determine the unknowns (rank deficient)
  };
  Code code = Code::ok;
  std::string reason; ///< why, when not ok (empty when ok)

  bool ok() const { return code == Code::ok; }
  /// A failure (code not ok) and why, in words that name the cause.
  static Status failure(Code code, std::string reason) {
    JOINTID_ASSERT(code != Code::ok, "a failure needs a code other than ok");
    return {code, std::move(reason)};
  }
  /// The same status with `context` before its reason ("substructure 2: " + reason); ok stays
  /// ok.
  Status within(std::string_view context) const {
    if (ok()) return *this;
    return {code, std::string(context) + reason};
  }
};

/// "ok", "not_converging", "not_periodic", "numerical_issue", "not_separable": the code as the
/// JSON results write it.
constexpr std::string_view code_name(Status::Code code) {
  switch (code) {
  case Status::Code::ok:
    return "ok";
  case Status::Code::not_converging:
    return "not_converging";
  case Status::Code::not_periodic:
    return "not_periodic";
  case Status::Code::numerical_issue:
    return "numerical_issue";
  case Status::Code::not_separable:
    return "not_separable";
  }
  return "unknown";
}

/// A computed value and the status of computing it: `value` is meaningful when status.ok().
template <class T> struct Outcome {
  Status status;
  T value{};
};

} // namespace jointid::fem
