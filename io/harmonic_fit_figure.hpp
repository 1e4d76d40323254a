#pragma once
/// Time records with their harmonic fits, as `jointid identify --fit-png` draws them: what the
/// identification sees of each test.
#include "fem/dof.hpp"
#include "identify/measurement.hpp"
#include "io/chart.hpp"

#include <vector>

namespace jointid::io {

/// One chart per test (in order; grid of up to 3 columns): at each of `shown` measured as a
/// displacement channel, the samples of the record's averaged period (points) and the harmonic
/// fit Re Σ_{k=0…K} X_k e^{ikωt} that the identification uses (line; without the mean when it is
/// unknown), over t/T from 0 to 1; the title gives the test, its frequency and the fit's RMS
/// residual relative to the signal's peak. DOFs not measured as displacements (derived from v
/// or a: their samples are the fit itself) are left out. Throws std::invalid_argument when no
/// test has a displacement channel at any of `shown`.
Figure harmonic_fit_figure(const std::vector<identify::Measurement>& tests,
                           const std::vector<fem::NodeDof>& shown);

} // namespace jointid::io
