#pragma once
/// Joint force basis functions g(y, ẏ) of METHOD.md. y is the joint's deformation (m or rad),
/// ẏ its rate. A joint's force is g = Σ_j b_j g_j(y, ẏ) with real b_j; b is physical (a spring
/// has k > 0) and the force the joint applies to the structure is −g (it resists deformation).
///
/// Every term is described once, in term_table(): its name, the effect it models, the unit of
/// its coefficient, g and its derivatives, and the properties the rest of jointid reads from
/// it (error lists, the harmonic balance's linear start, discovery's diagnosis).
#include <array>
#include <span>
#include <string>
#include <string_view>

namespace jointid::joints {

enum class Term { k, c, k2, k3, c2, c3, fc };

/// What a term's force does over a cycle: a conservative force depends on y only (it shifts
/// resonances: stiffness), a dissipative one on ẏ only (it takes energy: damping).
enum class Nature { conservative, dissipative };

struct TermInfo {
  Term term;
  std::string_view name;   ///< "k3"
  std::string_view effect; ///< "cubic stiffness"
  /// SI unit of b for a translational joint ("N/m^3") and for a rotational one ("N m/rad^3").
  std::string_view unit, rotational_unit;
  double (*g)(double y, double ydot);
  double (*dg_dy)(double y, double ydot);
  double (*dg_dydot)(double y, double ydot);
  Nature nature;
  /// Power of the force in the amplitude: g(s·y, s·ẏ) = s^degree g(y, ẏ) for s > 0 (k, c: 1;
  /// k2, c2: 2; k3, c3: 3; fc: 0). Degree 1 is linear: the response scales with the force.
  int degree;
  /// g(−y, −ẏ) = g(y, ẏ): the force is even, so it makes a mean and even harmonics (k2).
  bool even;
  /// The force is set-valued at ẏ = 0 (dry friction: anywhere in [−b, b] while stuck); g
  /// returns the identification basis value 0 there and ∂g/∂ẏ is taken as 0.
  bool set_valued;
};

/// The library of terms, in the order of enum Term.
const std::array<TermInfo, 7>& term_table();
const TermInfo& term_info(Term term);
inline constexpr std::array<Term, 7> all_terms{Term::k,  Term::c,  Term::k2, Term::k3,
                                               Term::c2, Term::c3, Term::fc};

std::string_view term_name(Term term);   ///< "k", "c", ...
std::string_view term_effect(Term term); ///< "linear stiffness", ...
/// SI unit of the coefficient b for a translational joint ("N/m", "N s/m", ...).
std::string_view term_unit(Term term);
/// "k, c, k2, k3, c2, c3, fc": the accepted names, for error messages.
std::string term_names();
/// Parses a term name; throws std::invalid_argument listing the accepted names.
Term parse_term(std::string_view name);
/// k and c: the force is linear in (y, ẏ).
inline bool is_linear(Term term) {
  return term_info(term).degree == 1;
}

/// g(y, ẏ). Coulomb friction: sign(ẏ) with g = 0 at ẏ = 0 (the identification basis).
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
