#pragma once
/// Joint force basis functions g(y, ẏ) of METHOD.md. y is the joint's deformation (m or rad),
/// ẏ its rate. A joint's force is g = Σ_j b_j g_j(y, ẏ) with real b_j; b is physical (a spring
/// has k > 0) and the force the joint applies to the structure is −g (it resists deformation).
#include <array>
#include <string_view>

namespace jointid::joints {

enum class Term { k, c, k2, k3, c2, c3, fc };
inline constexpr std::array<Term, 7> all_terms{Term::k,  Term::c,  Term::k2, Term::k3,
                                               Term::c2, Term::c3, Term::fc};

std::string_view term_name(Term term);   ///< "k", "c", ...
std::string_view term_effect(Term term); ///< "linear stiffness", ...
/// SI unit of the coefficient b for a translational joint ("N/m", "N s/m", ...).
std::string_view term_unit(Term term);
/// Parses a term name; throws std::invalid_argument listing the accepted names.
Term parse_term(std::string_view name);

/// g(y, ẏ). Coulomb friction: sign(ẏ) with g = 0 at ẏ = 0 (the identification basis).
double basis(Term term, double y, double ydot);
/// ∂g/∂y and ∂g/∂ẏ (the sign function's derivative is taken as 0; the time integrator treats
/// dry friction as set-valued instead).
double basis_dy(Term term, double y, double ydot);
double basis_dydot(Term term, double y, double ydot);
/// True for the set-valued dry-friction term.
inline bool is_dry_friction(Term term) {
  return term == Term::fc;
}

} // namespace jointid::joints
