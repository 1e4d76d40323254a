#pragma once
/// discovery.json: the result of model discovery as DESIGN.md's JSON contract.
#include "discover/discover.hpp"

#include <string>

namespace jointid::report {

/// The discovery result as DESIGN.md's JSON, extended (README: "discovery.json"):
/// {"tests", "compared_values", "noise_gap", "at_noise_level", "start": {"notes", "gap",
/// "joints"}, "steps": [{"joint", "term", "effect", "value", "std", "ci95", "gap_before",
/// "gap_after", "explained", "cv_gap_before", "cv_gap_after", "finding", "ranking": [...]}],
/// "gap": [g0, g1, ...], "diagnosis": {...}, "final_model": {"joints": [...],
/// "substructure_damping_scale"}, "stop_reason", "last_ranking", "comparisons": {"start": [...],
/// "final": [...]}, "warnings"}. The substructure's damping scale appears as joint
/// "substructure", term "damping_scale". NaN and infinite numbers are written as null. Every
/// identified value's interval says whether it is "determined": when not (NaN, or zero width),
/// its "std" and "ci95" are null, never a number ± 0. "limits": the rules these tests did not
/// allow to be applied; "left_out" (start, final_model, a candidate with "gap_now"): the tests
/// whose re-simulation did not converge, left out of that model's gap.
std::string discovery_json(const discover::Result& result);

} // namespace jointid::report
