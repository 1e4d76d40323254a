#include "io/backbone_json.hpp"

#include "io/json_text.hpp"

namespace jointid::io {

using json::Json;
using json::number;

std::string backbone_json(const frf::Backbone& b, const std::vector<joints::Joint>& joints,
                          const std::vector<identify::MeasuredBackbonePoint>& measured) {
  Json j;
  j["mode"] = b.mode;
  j["harmonics"] = b.harmonics;
  j["amplitude"] = {{"dof", fem::to_string(b.amplitude_dof)},
                    {"unit", fem::is_rotation(b.amplitude_dof.dof) ? "rad" : "m"},
                    {"quantity", "peak amplitude of the fundamental, |X_1|"}};
  const auto ref = static_cast<std::size_t>(b.reference_joint);
  j["reference_joint"] = ref < joints.size() ? Json(joints[ref].name) : Json(nullptr);
  j["linear"] = {{"frequency_hz", number(b.linear.frequency_hz)},
                 {"damping_ratio", number(b.linear.damping_ratio)}};
  j["status"] = std::string(fem::code_name(b.status.code));
  j["reason"] = b.status.reason;
  j["notes"] = b.notes;
  Json points = Json::array();
  for (const frf::BackbonePoint& p : b.points)
    points.push_back({{"amplitude", number(p.amplitude)},
                      {"joint_amplitude", number(p.joint_amplitude)},
                      {"frequency_hz", number(p.frequency_hz)},
                      {"damping_ratio", number(p.damping_ratio)}});
  j["points"] = points;
  Json levels = Json::array();
  for (const identify::MeasuredBackbonePoint& m : measured) {
    const identify::OneModeFit& f = m.fit;
    levels.push_back({{"table", m.table},
                      {"status", std::string(fem::code_name(f.status.code))},
                      {"reason", f.status.reason},
                      {"force_amplitude", number(f.force_amplitude)},
                      {"amplitude", number(f.amplitude)},
                      {"frequency_hz", number(f.frequency_hz)},
                      {"frequency_std_hz", number(f.frequency_std_hz)},
                      {"damping_ratio", number(f.damping_ratio)},
                      {"damping_ratio_std", number(f.damping_ratio_std)},
                      {"relative_residual", number(f.relative_residual)}});
  }
  j["measured"] = levels;
  return json::text(j);
}

} // namespace jointid::io
