#include "io/response_curves.hpp"

#include "io/json_text.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace jointid::io {

using json::Json;
using json::number;

std::string response_json(const frf::ResponseCurves& c) {
  Json j;
  j["harmonics"] = c.harmonics;
  Json names = Json::array();
  for (const fem::NodeDof& d : c.dofs)
    names.push_back(fem::to_string(d));
  j["dofs"] = names;
  j["notes"] = c.notes;
  Json curves = Json::array();
  for (std::size_t i = 0; i < c.curves.size(); ++i) {
    const frf::ResponseBranch& b = c.curves[i];
    Json curve;
    curve["amplitude"] = number(c.amplitudes.at(i));
    curve["complete"] = b.complete;
    curve["folds"] = b.folds;
    curve["notes"] = b.notes;
    Json points = Json::array();
    for (const frf::ResponsePoint& p : b.points) {
      Json point;
      point["freq_hz"] = number(p.hb.frequency_hz);
      point["stable"] = p.stable ? Json(*p.stable) : Json(nullptr);
      point["max_multiplier"] = number(p.max_multiplier);
      point["stability_checked"] = p.stability_checked;
      Json x = Json::object();
      for (std::size_t d = 0; d < c.dofs.size(); ++d) {
        Json harmonics = Json::array();
        for (Eigen::Index k = 0; k < p.hb.X.rows(); ++k)
          harmonics.push_back(
              Json::array({number(p.hb.X(k, static_cast<Eigen::Index>(d)).real()),
                           number(p.hb.X(k, static_cast<Eigen::Index>(d)).imag())}));
        x[names[d].get<std::string>()] = harmonics;
      }
      point["x"] = x;
      points.push_back(point);
    }
    curve["points"] = points;
    curves.push_back(curve);
  }
  j["curves"] = curves;
  return j.dump(1) + "\n";
}

} // namespace jointid::io
