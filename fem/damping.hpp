#pragma once
/// Viscous damping matrix of the substructure for direct solves and time integration.
#include "fem/assembly.hpp"
#include "fem/modal.hpp"

namespace jointid::fem {

/// Rayleigh: C = αM + βK. Modal: C = M Φ diag(2 ζ ω_r) Φᵀ M, which needs `all_modes` to hold
/// every mode of the model (so that C is diagonalised by Φ exactly); throws otherwise.
/// None: an empty matrix of the right size. Units N·s/m.
SparseMatrix damping_matrix(const Assembled& system, const Damping& damping,
                            const Modes* all_modes = nullptr);

} // namespace jointid::fem
