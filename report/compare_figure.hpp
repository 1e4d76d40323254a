#pragma once
/// The picture of `jointid compare`: measured vs predicted response PSD (identify::compare).
#include "identify/compare.hpp"
#include "report/chart.hpp"

namespace jointid::report {

/// One chart per channel: measured and predicted PSD over the band (log y), titled with the
/// channel and its RMS difference in dB. Part of jointid_io_output (the chart writer's library).
Figure compare_figure(const identify::Comparison& comparison);

} // namespace jointid::report
