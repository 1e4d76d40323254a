#pragma once
/// The substructure's FRFs (frf::frf_sweep) as `jointid frf` writes them: a CSV table, a
/// universal file (dataset 58, function type 4) and a magnitude-and-phase figure.
#include "fem/dof_map.hpp"
#include "frf/sweep.hpp"
#include "io/uff58.hpp"

#include <string>
#include <vector>

namespace jointid::io {

/// SI unit of an FRF from a force at a translation (N) or a moment at a rotation (N m) to a
/// response at a translation or rotation, e.g. "m/N", "(m/s)/N", "rad/(N m)".
std::string frf_unit(frf::FrfKind kind, bool response_rotation, bool drive_rotation);

/// The table: `# ` comment lines (kind, drive, convention, each column's unit, the synthesis'
/// notes), then `freq_hz,<dof>.re,<dof>.im,…` (one pair per response DOF, e.g. `7:uy.re`) and
/// one row per frequency; every number in the shortest form that reads back exactly.
std::string frf_csv(const frf::FrfSweep& sweep, const fem::DofMap& dofs);

/// One dataset 58 per response: function type 4 (FRF), complex double, response node and
/// direction, reference = the drive's node and direction, abscissa frequency in Hz (even
/// spacing from the first frequency), ordinate data type 8/11/12 (displacement, velocity,
/// acceleration) over 13 (excitation force) with Addendum A exponents and SI units labels; ID
/// line 1 `<kind> <response>/<drive>`. Throws io::Error when the frequencies are not evenly
/// spaced (to 1e-9 of the step; dataset 58 would need uneven spacing) or fewer than 2.
std::vector<Uff58Function> frf_uff58(const frf::FrfSweep& sweep, const fem::DofMap& dofs);

} // namespace jointid::io
