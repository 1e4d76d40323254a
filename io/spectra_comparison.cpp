// compare_json(): part of jointid_io.
#include "io/spectra_comparison.hpp"

#include "io/json_text.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace jointid::io {

using json::Json;
using json::number;

namespace {

Json numbers(const Eigen::VectorXd& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i)
    a.push_back(std::isfinite(v(i)) ? Json(v(i)) : Json(nullptr));
  return a;
}

} // namespace

std::string psd_unit(const std::string& channel) {
  const identify::Channel c = identify::parse_channel_name(channel);
  const bool turn = fem::is_rotation(c.at.dof);
  switch (c.quantity) {
  case identify::Quantity::displacement:
    return turn ? "rad^2/Hz" : "m^2/Hz";
  case identify::Quantity::velocity:
    return turn ? "(rad/s)^2/Hz" : "(m/s)^2/Hz";
  case identify::Quantity::acceleration:
    return turn ? "(rad/s^2)^2/Hz" : "(m/s^2)^2/Hz";
  case identify::Quantity::force:
    return turn ? "(N m)^2/Hz" : "N^2/Hz";
  }
  return "";
}

std::string compare_json(const identify::Comparison& c) {
  Json j;
  j["record"] = c.source;
  j["band_hz"] = Json::array({number(c.f0_hz), number(c.f1_hz)});
  j["sample_rate_hz"] = number(c.sample_rate_hz);
  j["segment"] = c.segment;
  j["averages"] = c.averages;
  j["resolution_hz"] = number(c.resolution_hz);
  j["skip_s"] = number(c.skip_s);
  j["statistical_db"] = number(c.statistical_db);
  j["psd_convention"] = "one-sided PSD per Hz (Welch: Hann window, 50 % overlap, segment mean "
                        "removed); difference_db = 10 log10(predicted / measured)";
  j["notes"] = c.notes;
  Json channels = Json::array();
  for (const auto& ch : c.channels) {
    Json o;
    o["channel"] = ch.channel;
    o["unit"] = psd_unit(ch.channel);
    o["rms_difference_db"] = number(ch.rms_db);
    o["max_difference_db"] = number(ch.max_db);
    o["frequency_hz"] = numbers(ch.frequency_hz);
    o["measured"] = numbers(ch.measured);
    o["predicted"] = numbers(ch.predicted);
    o["difference_db"] = numbers(ch.difference_db);
    channels.push_back(std::move(o));
  }
  j["channels"] = std::move(channels);
  return j.dump(1) + "\n";
}

} // namespace jointid::io
