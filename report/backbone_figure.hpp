#pragma once
/// The picture of `jointid backbone`: natural frequency and damping ratio against amplitude.
#include "frf/backbone.hpp"
#include "identify/one_mode_fit.hpp"
#include "report/chart.hpp"

#include <vector>

namespace jointid::report {

/// Two panels side by side, frequency (Hz) and damping ratio (%) against the amplitude |X_1| at
/// the backbone's amplitude DOF (log axis): the model's backbone (line), its linear mode
/// (dashed, over the amplitudes shown) and the measured backbone's levels that were fitted
/// (dots). Throws std::invalid_argument when there is nothing to draw (no point at all).
Figure backbone_figure(const frf::Backbone& backbone,
                       const std::vector<identify::MeasuredBackbonePoint>& measured);

} // namespace jointid::report
