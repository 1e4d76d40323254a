#pragma once
/// The picture of `jointid frf`: the substructure's FRFs (frf::frf_sweep).
#include "fem/dof_map.hpp"
#include "frf/sweep.hpp"
#include "report/chart.hpp"

namespace jointid::report {

/// Magnitude (log scale) and phase (degrees, -180 … 180) over frequency, one colour per
/// response DOF: two charts, one above the other.
Figure frf_figure(const frf::FrfSweep& sweep, const fem::DofMap& dofs);

} // namespace jointid::report
