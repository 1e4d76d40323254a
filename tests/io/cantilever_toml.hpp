#pragma once
// The planar cantilever of DESIGN.md as a model file: 6 beam elements along x (L = 2 m, steel,
// b = 0.25 m, t = 0.0144 m), fixed at node 1, modal damping 0.01, a joint "tip" to ground at
// node 7 uy with k = 4800 N/m, c = 20 N s/m, k3 = 1.6e8 N/m^3.
#include <sstream>
#include <string>

namespace jointid::test {

inline constexpr double length = 2.0, width = 0.25, thickness = 0.0144;
inline constexpr double E = 210e9, rho = 7850.0;
inline constexpr double area = width * thickness;
inline constexpr double Iz = width * thickness * thickness * thickness / 12.0;

inline std::string cantilever_toml() {
  std::ostringstream s;
  s.precision(17);
  s << "# cantilever for the io and cli tests\n"
       "[model]\n"
       "dimension = 2\n"
       "\n"
       "[[materials]]\n"
       "name = \"steel\"\n"
       "E = 210e9\n"
       "rho = 7850.0\n"
       "nu = 0.3\n"
       "\n"
       "[[sections]]\n"
       "name = \"bar\"\n"
    << "A = " << area << "\n"
    << "Iz = " << Iz << "\n"
    << "\n[mesh]\nnodes = [";
  for (int i = 0; i < 7; ++i)
    s << (i ? ", " : "") << "[" << i + 1 << ", " << length * i / 6.0 << ", 0.0]";
  s << "]\n"
       "elements = [[1, 1, 2], [2, 2, 3], [3, 3, 4], [4, 4, 5], [5, 5, 6], [6, 6, 7]]\n"
       "\n"
       "[[element_sets]]\n"
       "elements = \"all\"\n"
       "type = \"beam\"\n"
       "material = \"steel\"\n"
       "section = \"bar\"\n"
       "\n"
       "[[supports]]\n"
       "node = 1\n"
       "fix = [\"ux\", \"uy\", \"rz\"]\n"
       "\n"
       "[damping]\n"
       "modal = 0.01\n"
       "\n"
       "[[joints]]\n"
       "name = \"tip\"\n"
       "node = 7\n"
       "dof = \"uy\"\n"
       "terms = [\"k\", \"c\", \"k3\"]\n"
       "values = { k = 4800.0, c = 20.0, k3 = 1.6e8 }\n";
  return s.str();
}

} // namespace jointid::test
