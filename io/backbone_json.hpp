#pragma once
/// `jointid backbone`'s DIR/backbone.json: the model's backbone (frf/backbone.hpp) and the
/// measured one (identify/one_mode_fit.hpp).
#include "frf/backbone.hpp"
#include "identify/one_mode_fit.hpp"

#include <string>
#include <vector>

namespace jointid::io {

/// {"mode": N, "harmonics": K, "amplitude": {"dof": "7:uy", "unit": "m", "quantity": …},
/// "reference_joint": name, "linear": {"frequency_hz", "damping_ratio"}, "status", "reason",
/// "notes": [...], "points": [{"amplitude", "joint_amplitude", "frequency_hz", "damping_ratio"}],
/// "measured": [{"table", "status", "reason", "force_amplitude", "amplitude", "frequency_hz",
/// "frequency_std_hz", "damping_ratio", "damping_ratio_std", "relative_residual"}]}. Amplitudes
/// are the fundamental's peak |X_1| (m, or rad at a rotation); non-finite numbers are null.
std::string backbone_json(const frf::Backbone& backbone, const std::vector<joints::Joint>& joints,
                          const std::vector<identify::MeasuredBackbonePoint>& measured);

} // namespace jointid::io
