#pragma once
/// Output-error refinement (maximum likelihood under the noise model): every non-fixed term is
/// adjusted by Levenberg–Marquardt to minimise the weighted squared difference between the
/// re-simulated and the measured harmonics, starting from the equation-error estimate (which the
/// noise in the measured deformation makes less efficient). The 95 % intervals then come from
/// the output-error Jacobian J (finite differences): σ̂² (JᵀJ)⁻¹, with σ̂² the weighted residual
/// variance (at least 1 when the noise is known: a misfit beyond the noise widens the
/// intervals, never narrows them).
#include "discover/problem.hpp"

namespace jointid::discover::detail {

/// The state refined from `start` (its fit replaced by the output-error one); `start` itself
/// when nothing is identified, or its values are not physical and cannot be brought back.
State refine(const Problem& problem, const State& start, const Simulator& sim);

} // namespace jointid::discover::detail
