#pragma once
/// JSON results (DESIGN.md's contract): identification results and mode lists.
#include "fem/modal.hpp"
#include "identify/design.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace jointid::io {

/// The identification result as DESIGN.md's JSON:
/// {"joints": [{"name", "terms": [{"term", "effect", "value", "std", "ci95": [lo, hi],
/// "fixed", "determined"}]}], "equations", "unknowns", "condition_number", "residual_rms",
/// "residual_relative", "interval_method", "chi2_per_dof", "singular_values",
/// "identifiability": [...], "warnings": [...]}. `extra` warnings are appended to the result's.
/// NaN and infinite numbers are written as null.
/// With `measured` (the tests as fit() saw them), also "noise": [{"test", "frequency_hz",
/// "periods_averaged", "channels": {"x@7:uy": σ, "v@7:uy": σ, "f@7:uy": σ}}], each channel's
/// noise standard deviation per sample as estimated from the record (its unit; null where
/// unknown, e.g. stepped-sine tables). And always "status" ("ok" or "not_separable") with
/// "reason".
std::string identify_result_json(const identify::FitResult& result,
                                 const std::vector<std::string>& extra = {},
                                 const std::vector<identify::Measurement>* measured = nullptr);

/// {"modes": [{"mode": 1, "frequency_hz": ...}, ...]} for the first `count` modes (all when
/// count < 0 or larger than the number of modes).
std::string modes_json(const fem::Modes& modes, int count = -1,
                       const std::vector<std::string>& warnings = {});

/// An experiment design (README: "design.json"): {"noise", "periods", "harmonics",
/// "unknowns": [{"joint", "term", "prior", "std", "relative_std", "bias"}], "chosen":
/// [{"freq_hz", "amplitude", "record"}], "log_det", "exchanges", "candidates": [{"freq_hz",
/// "amplitude", "usable", "misfit", "reason", "joint_amplitude": [...], "chosen"}],
/// "warnings"}. `std` and `bias` are what fit() is predicted to show for the chosen tests
/// (null: undetermined). With `levels`: "parametric": [{"joint", "term", "regime",
/// "threshold", "levels": [{"freq_hz", "lowest_force" (null: no candidate reaches it),
/// "guess_force"}], "sentence"}].
std::string design_json(const identify::Design& design,
                        const std::vector<identify::CandidateTest>& candidates,
                        const std::vector<identify::DesignUnknown>& unknowns,
                        const identify::DesignOptions& options,
                        const std::vector<identify::ParametricLevel>& levels = {});

/// Writes JSON text atomically (see write_file_atomically).
void write_json(const std::filesystem::path& path, const std::string& json);

} // namespace jointid::io
