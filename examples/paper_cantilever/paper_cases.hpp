#pragma once
// The paper's test cases I–IV (METHOD.md): ten sine tests each, frequencies in Hz and force
// amplitudes in N at the cantilever's tip. Shared by the paper study and the design study.
#include "identify/sine_tests.hpp"

#include <string>
#include <vector>

namespace jointid::examples {

struct PaperCase {
  std::string name;        ///< "I" … "IV"
  std::string description; ///< "1–4.6 Hz, 80 N"
  std::vector<identify::SineTestPlan> tests;
};

inline std::vector<PaperCase> paper_cases() {
  PaperCase c1{"I", "1–4.6 Hz, 80 N", {}}, c2{"II", "17–20.6 Hz, 80 N", {}},
      c3{"III", "3 Hz, 10–100 N", {}}, c4{"IV", "19 Hz, 10–100 N", {}};
  for (int i = 0; i < 10; ++i) {
    c1.tests.push_back({1.0 + 0.4 * i, 80.0});
    c2.tests.push_back({17.0 + 0.4 * i, 80.0});
    c3.tests.push_back({3.0, 10.0 * (i + 1)});
    c4.tests.push_back({19.0, 10.0 * (i + 1)});
  }
  return {c1, c2, c3, c4};
}

} // namespace jointid::examples
