#pragma once
/// Joint force basis functions g(y, ẏ) of METHOD.md. y is the joint's deformation (m or rad),
/// ẏ its rate. A joint's force is g = Σ_j b_j g_j(y, ẏ) with real b_j; b is physical (a spring
/// has k > 0) and the force the joint applies to the structure is −g (it resists deformation).
///
/// Every term is described once, in term_table(): its name, the effect it models, the unit of
/// its coefficient, g and its derivatives, and the properties the rest of jointid reads from
/// it (error lists, the harmonic balance's linear start, discovery's diagnosis).
///
/// Two kinds of rows. The paper's terms k … fc are *coefficient terms*: g_j(y, ẏ) is a fixed
/// function and the joint's force is linear in its coefficient b_j (the equation-error route
/// Q b = p rests on it). The terms jenkins, iwan and gap are *parametric terms*: their force
/// depends non-linearly on named parameters (TermInfo::parameters, written "<term>.<name>" in
/// a joint's values), and jenkins and iwan are hysteretic — their force depends on the history
/// of y through the positions of their sliders (joints/hysteresis.hpp). A parametric term has
/// no basis function g(y, ẏ): its coefficient is 1, held, and the force is its own.
#include <array>
#include <limits>
#include <span>
#include <string>
#include <string_view>

namespace jointid::joints {

enum class Term { k, c, k2, k3, c2, c3, fc, jenkins, iwan, gap };

/// What a term's force does over a cycle: a conservative force depends on y only (it shifts
/// resonances: stiffness), a dissipative one on ẏ only (it takes energy: damping), a
/// hysteretic one on the history of y (it does both: a loop that softens and dissipates).
enum class Nature { conservative, dissipative, hysteretic };

/// A named parameter of a parametric term, and the values it may take: low < p (or <=) and
/// p <= high (or <); the bounds may be infinite.
struct ParameterInfo {
  std::string_view name;    ///< "fs"
  std::string_view meaning; ///< "slip force"
  /// SI unit for a translational joint ("N") and a rotational one ("N m"); "1": a number.
  std::string_view unit, rotational_unit;
  double low = -std::numeric_limits<double>::infinity();
  bool low_open = true; ///< true: p > low; false: p >= low
  double high = std::numeric_limits<double>::infinity();
  bool high_open = true; ///< true: p < high; false: p <= high
};
/// True when `value` is finite and in the parameter's range.
bool in_range(const ParameterInfo& info, double value);
/// The range in words for messages: "> 0", ">= 0", "in (-1, 0]".
std::string range_text(const ParameterInfo& info);

struct TermInfo {
  Term term;
  std::string_view name;   ///< "k3"
  std::string_view effect; ///< "cubic stiffness"
  /// SI unit of b for a translational joint ("N/m^3") and for a rotational one ("N m/rad^3").
  std::string_view unit, rotational_unit;
  /// The basis function and its derivatives; null for a parametric term (no g(y, ẏ)).
  double (*g)(double y, double ydot);
  double (*dg_dy)(double y, double ydot);
  double (*dg_dydot)(double y, double ydot);
  Nature nature;
  /// Power of the force in the amplitude: g(s·y, s·ẏ) = s^degree g(y, ẏ) for s > 0 (k, c: 1;
  /// k2, c2: 2; k3, c3: 3; fc: 0). Degree 1 is linear: the response scales with the force.
  /// −1: no such power (the parametric terms: a slip force or a clearance sets a scale).
  int degree;
  /// g(−y, −ẏ) = g(y, ẏ): the force is even, so it makes a mean and even harmonics (k2).
  bool even;
  /// The force is set-valued at ẏ = 0 (dry friction: anywhere in [−b, b] while stuck); g
  /// returns the identification basis value 0 there and ∂g/∂ẏ is taken as 0.
  bool set_valued;
  /// Named parameters (parametric terms; empty for the coefficient terms), in their order.
  std::span<const ParameterInfo> parameters{};
  /// The force depends on the history of y (sliders): jenkins, iwan.
  bool hysteretic = false;
};

/// The library of terms, in the order of enum Term.
const std::array<TermInfo, 10>& term_table();
const TermInfo& term_info(Term term);
/// Every term of the table.
inline constexpr std::array<Term, 10> all_terms{Term::k,    Term::c,  Term::k2, Term::k3,
                                                Term::c2,   Term::c3, Term::fc, Term::jenkins,
                                                Term::iwan, Term::gap};
/// The paper's terms, linear in their coefficient: g = b g(y, ẏ).
inline constexpr std::array<Term, 7> coefficient_terms{Term::k,  Term::c,  Term::k2, Term::k3,
                                                       Term::c2, Term::c3, Term::fc};
/// The terms with named parameters (non-linear in them).
inline constexpr std::array<Term, 3> parametric_terms{Term::jenkins, Term::iwan, Term::gap};

std::string_view term_name(Term term);   ///< "k", "c", ...
std::string_view term_effect(Term term); ///< "linear stiffness", ...
/// SI unit of the coefficient b for a translational joint ("N/m", "N s/m", ...).
std::string_view term_unit(Term term);
/// "k, c, k2, k3, c2, c3, fc, jenkins, iwan, gap": the accepted names, for error messages.
std::string term_names();
/// Parses a term name; throws std::invalid_argument listing the accepted names.
Term parse_term(std::string_view name);
/// The term has named parameters (jenkins, iwan, gap): no coefficient, no basis function.
inline bool has_parameters(Term term) {
  return !term_info(term).parameters.empty();
}
/// The term's force depends on the history of y (jenkins, iwan).
inline bool is_hysteretic(Term term) {
  return term_info(term).hysteretic;
}
/// Index of the parameter `name` among the term's, or -1.
int parameter_index(Term term, std::string_view name);
/// "fs, kt, chi, beta": the term's parameter names, for messages.
std::string parameter_names(Term term);
/// k and c: the force is linear in (y, ẏ).
inline bool is_linear(Term term) {
  return term_info(term).degree == 1;
}

/// g(y, ẏ). Coulomb friction: sign(ẏ) with g = 0 at ẏ = 0 (the identification basis).
/// basis(), basis_dy(), basis_dydot() and add_samples() are for the coefficient terms: they
/// throw std::invalid_argument for a parametric term (its force needs its parameters and, if
/// hysteretic, a history: joints/hysteresis.hpp).
double basis(Term term, double y, double ydot);
/// ∂g/∂y and ∂g/∂ẏ (the sign function's derivative is taken as 0; the time integrator treats
/// dry friction as set-valued instead).
double basis_dy(Term term, double y, double ydot);
double basis_dydot(Term term, double y, double ydot);
/// True for the set-valued dry-friction term.
inline bool is_dry_friction(Term term) {
  return term_info(term).set_valued;
}
/// Adds b g(y_n, ẏ_n), b ∂g/∂y and b ∂g/∂ẏ to g[n], gy[n], gv[n] at every sample n: the values
/// of basis(), basis_dy() and basis_dydot() without a call per sample (the harmonic balance
/// evaluates its joints at all time samples of a period at once). All spans have one length.
void add_samples(Term term, double b, std::span<const double> y, std::span<const double> ydot,
                 std::span<double> g, std::span<double> gy, std::span<double> gv);

} // namespace jointid::joints
