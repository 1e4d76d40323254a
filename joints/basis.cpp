#include "joints/basis.hpp"

#include <cmath>
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

constexpr std::array<TermInfo, 7> table{{
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
}};

} // namespace

const std::array<TermInfo, 7>& term_table() {
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

double basis(Term t, double y, double v) {
  return term_info(t).g(y, v);
}

double basis_dy(Term t, double y, double v) {
  return term_info(t).dg_dy(y, v);
}

double basis_dydot(Term t, double y, double v) {
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
  }
  throw std::invalid_argument("add_samples: unknown term");
}

} // namespace jointid::joints
