#include "joints/basis.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace jointid::joints {

namespace {
struct Info {
  std::string_view name, effect, unit;
};
constexpr std::array<Info, 7> info{{
    {"k", "linear stiffness", "N/m"},
    {"c", "viscous damping", "N s/m"},
    {"k2", "quadratic stiffness", "N/m^2"},
    {"k3", "cubic stiffness", "N/m^3"},
    {"c2", "velocity-squared damping", "N s^2/m^2"},
    {"c3", "cubic damping", "N s^3/m^3"},
    {"fc", "Coulomb friction", "N"},
}};
} // namespace

std::string_view term_name(Term t) {
  return info[static_cast<int>(t)].name;
}
std::string_view term_effect(Term t) {
  return info[static_cast<int>(t)].effect;
}
std::string_view term_unit(Term t) {
  return info[static_cast<int>(t)].unit;
}

Term parse_term(std::string_view name) {
  for (Term t : all_terms)
    if (term_name(t) == name) return t;
  throw std::invalid_argument("unknown joint term '" + std::string(name) +
                              "': expected one of k, c, k2, k3, c2, c3, fc");
}

double basis(Term t, double y, double v) {
  switch (t) {
  case Term::k:
    return y;
  case Term::c:
    return v;
  case Term::k2:
    return y * y;
  case Term::k3:
    return y * y * y;
  case Term::c2:
    return v * std::abs(v);
  case Term::c3:
    return v * v * v;
  case Term::fc:
    return v > 0.0 ? 1.0 : v < 0.0 ? -1.0 : 0.0;
  }
  return 0.0;
}

double basis_dy(Term t, double y, double) {
  switch (t) {
  case Term::k:
    return 1.0;
  case Term::k2:
    return 2.0 * y;
  case Term::k3:
    return 3.0 * y * y;
  default:
    return 0.0;
  }
}

double basis_dydot(Term t, double, double v) {
  switch (t) {
  case Term::c:
    return 1.0;
  case Term::c2:
    return 2.0 * std::abs(v);
  case Term::c3:
    return 3.0 * v * v;
  default:
    return 0.0;
  }
}

} // namespace jointid::joints
