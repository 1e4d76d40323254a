#pragma once
/// `jointid compare`'s outputs: the JSON of identify::Comparison and its figure (measured vs
/// predicted response PSD, log y, one chart per channel).
#include "identify/compare.hpp"

#include <string>

namespace jointid::io {

/// {"record": "...", "band_hz": [F0, F1], "sample_rate_hz": fs, "segment": N, "averages": n,
///  "resolution_hz": df, "skip_s": s, "statistical_db": e, "psd_convention": "...",
///  "notes": [...], "channels": [{"channel": "x@7:uy", "unit": "m^2/Hz",
///  "rms_difference_db": r, "max_difference_db": m, "frequency_hz": [...], "measured": [...],
///  "predicted": [...], "difference_db": [...]}]}. Non-finite numbers are written as null.
std::string compare_json(const identify::Comparison& comparison);

/// The unit of the one-sided PSD of a channel ("x@7:uy"): "m^2/Hz", "(rad/s)^2/Hz" for v@7:rz, …
std::string psd_unit(const std::string& channel);

} // namespace jointid::io
