#pragma once
/// Response curves (frf::response_curves) as `jointid response` writes them: the JSON contract
/// and the figure.
#include "frf/continuation.hpp"

#include <string>

namespace jointid::io {

/// {"harmonics": K, "dofs": ["7:uy", …], "notes": [...], "curves": [{"amplitude": A,
/// "complete": true, "folds": [i, …], "notes": [...], "points": [{"freq_hz": f, "stable":
/// true|false|null, "max_multiplier": m|null, "x": {"7:uy": [[re, im], …]}}]}]}. `x` holds for
/// every DOF the harmonics k = 0 … K of its displacement (peak, SI, x(t) = Re Σ X_k e^{ikωt});
/// `points` follow the branch (the frequency may go back at folds); `folds` index `points`;
/// `stable` is null where not determined. Non-finite numbers are written as null.
std::string response_json(const frf::ResponseCurves& curves);

} // namespace jointid::io
