#pragma once
// The paper's cantilever (support/cantilever.hpp) as a substructure, built once for every test
// of a program that uses it.
#include "frf/substructure.hpp"
#include "support/cantilever.hpp"

namespace jointid::test {

inline const frf::Substructure& cantilever() {
  static const frf::Substructure s(paper_cantilever());
  return s;
}

} // namespace jointid::test
