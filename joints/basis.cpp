#include "joints/basis.hpp"

#include "fem/constants.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace jointid::joints {

namespace {

double zero(double, double) {
  return 0.0;
}
double one(double, double) {
  return 1.0;
}

// The parametric terms' parameters (docs/method.md, "Terms with named parameters").
constexpr std::array<ParameterInfo, 2> jenkins_parameters{{
    {"kt", "stiffness of the spring in series with the slider", "N/m", "N m/rad", 0.0, true, inf,
     true},
    {"fs", "slip force", "N", "N m", 0.0, true, inf, true},
}};
constexpr std::array<ParameterInfo, 4> iwan_parameters{{
    {"fs", "macroslip force", "N", "N m", 0.0, true, inf, true},
    {"kt", "stiffness before any slip", "N/m", "N m/rad", 0.0, true, inf, true},
    {"chi", "microslip exponent", "1", "1", -1.0, true, 0.0, false},
    {"beta", "strength of the density's Dirac at the macroslip end", "1", "1", 0.0, false, inf,
     true},
}};
constexpr std::array<ParameterInfo, 2> gap_parameters{{
    {"delta", "clearance on either side", "m", "rad", 0.0, false, inf, true},
    {"kg", "contact stiffness beyond the clearance", "N/m", "N m/rad", 0.0, false, inf, true},
}};

constexpr std::array<TermInfo, 10> table{{
    {Term::k, "k", "linear stiffness", "N/m", "N m/rad", [](double y, double) { return y; }, one,
     zero, Nature::conservative, 1, false, false},
    {Term::c, "c", "viscous damping", "N s/m", "N m s/rad", [](double, double v) { return v; },
     zero, one, Nature::dissipative, 1, false, false},
    {Term::k2, "k2", "quadratic stiffness", "N/m^2", "N m/rad^2",
     [](double y, double) { return y * y; }, [](double y, double) { return 2.0 * y; }, zero,
     Nature::conservative, 2, true, false},
    {Term::k3, "k3", "cubic stiffness", "N/m^3", "N m/rad^3",
     [](double y, double) { return y * y * y; }, [](double y, double) { return 3.0 * y * y; }, zero,
     Nature::conservative, 3, false, false},
    {Term::c2, "c2", "velocity-squared damping", "N s^2/m^2", "N m s^2/rad^2",
     [](double, double v) { return v * std::abs(v); }, zero,
     [](double, double v) { return 2.0 * std::abs(v); }, Nature::dissipative, 2, false, false},
    {Term::c3, "c3", "cubic damping", "N s^3/m^3", "N m s^3/rad^3",
     [](double, double v) { return v * v * v; }, zero, [](double, double v) { return 3.0 * v * v; },
     Nature::dissipative, 3, false, false},
    {Term::fc, "fc", "Coulomb friction", "N", "N m",
     [](double, double v) { return v > 0.0   ? 1.0
                                   : v < 0.0 ? -1.0
                                             : 0.0; }, zero, zero,
     Nature::dissipative, 0, false, true},
    {Term::jenkins, "jenkins", "elastic dry friction (Jenkins element)", "1", "1", nullptr, nullptr,
     nullptr, Nature::hysteretic, -1, false, false, jenkins_parameters, true},
    {Term::iwan, "iwan", "microslip (four-parameter Iwan model)", "1", "1", nullptr, nullptr,
     nullptr, Nature::hysteretic, -1, false, false, iwan_parameters, true},
    {Term::gap, "gap", "clearance (contact beyond a gap)", "1", "1", nullptr, nullptr, nullptr,
     Nature::conservative, -1, false, false, gap_parameters, false},
}};

[[noreturn]] void refuse_parametric(Term t, const char* what) {
  throw std::invalid_argument(std::string(what) + ": term '" + std::string(term_name(t)) +
                              "' has named parameters (" + parameter_names(t) +
                              ") and no basis function g(y, ydot)");
}

} // namespace

bool in_range(const ParameterInfo& p, double v) {
  if (!std::isfinite(v)) return false;
  const bool above = p.low_open ? v > p.low : v >= p.low;
  const bool below = p.high_open ? v < p.high : v <= p.high;
  return above && below;
}

std::string range_text(const ParameterInfo& p) {
  std::ostringstream s;
  if (std::isinf(p.high)) {
    s << (p.low_open ? "> " : ">= ") << p.low;
  } else if (std::isinf(p.low)) {
    s << (p.high_open ? "< " : "<= ") << p.high;
  } else {
    s << "in " << (p.low_open ? "(" : "[") << p.low << ", " << p.high << (p.high_open ? ")" : "]");
  }
  return s.str();
}

const std::array<TermInfo, 10>& term_table() {
  return table;
}

const TermInfo& term_info(Term t) {
  return table[static_cast<std::size_t>(t)];
}

std::string_view term_name(Term t) {
  return term_info(t).name;
}
std::string_view term_effect(Term t) {
  return term_info(t).effect;
}
std::string_view term_unit(Term t) {
  return term_info(t).unit;
}

std::string term_names() {
  std::string names;
  for (const TermInfo& info : table)
    names += (names.empty() ? "" : ", ") + std::string(info.name);
  return names;
}

Term parse_term(std::string_view name) {
  for (const TermInfo& info : table)
    if (info.name == name) return info.term;
  throw std::invalid_argument("unknown joint term '" + std::string(name) + "': expected one of " +
                              term_names());
}

int parameter_index(Term t, std::string_view name) {
  const auto& list = term_info(t).parameters;
  for (std::size_t i = 0; i < list.size(); ++i)
    if (list[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string parameter_names(Term t) {
  std::string names;
  for (const ParameterInfo& p : term_info(t).parameters)
    names += (names.empty() ? "" : ", ") + std::string(p.name);
  return names;
}

double basis(Term t, double y, double v) {
  if (has_parameters(t)) refuse_parametric(t, "basis");
  return term_info(t).g(y, v);
}

double basis_dy(Term t, double y, double v) {
  if (has_parameters(t)) refuse_parametric(t, "basis_dy");
  return term_info(t).dg_dy(y, v);
}

double basis_dydot(Term t, double y, double v) {
  if (has_parameters(t)) refuse_parametric(t, "basis_dydot");
  return term_info(t).dg_dydot(y, v);
}

// The table's functions, one loop per term so that the compiler vectorises them; the test
// (tests/joints/basis_test.cpp) holds them equal to the table's for every term.
void add_samples(Term t, double b, std::span<const double> y, std::span<const double> v,
                 std::span<double> g, std::span<double> gy, std::span<double> gv) {
  const std::size_t n = y.size();
  if (v.size() != n || g.size() != n || gy.size() != n || gv.size() != n)
    throw std::invalid_argument("add_samples: the sample arrays differ in length");
  switch (t) {
  case Term::k:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * y[i], gy[i] += b;
    return;
  case Term::c:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * v[i], gv[i] += b;
    return;
  case Term::k2:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * y[i] * y[i], gy[i] += 2.0 * b * y[i];
    return;
  case Term::k3:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * y[i] * y[i] * y[i], gy[i] += 3.0 * b * y[i] * y[i];
    return;
  case Term::c2:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * v[i] * std::abs(v[i]), gv[i] += 2.0 * b * std::abs(v[i]);
    return;
  case Term::c3:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * v[i] * v[i] * v[i], gv[i] += 3.0 * b * v[i] * v[i];
    return;
  case Term::fc:
    for (std::size_t i = 0; i < n; ++i)
      g[i] += b * (v[i] > 0.0 ? 1.0 : v[i] < 0.0 ? -1.0 : 0.0);
    return;
  case Term::jenkins:
  case Term::iwan:
  case Term::gap:
    refuse_parametric(t, "add_samples");
  }
  throw std::invalid_argument("add_samples: unknown term");
}

} // namespace jointid::joints
