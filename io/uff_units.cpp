#include "io/uff_units.hpp"

#include "io/uff_format.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace jointid::io {

namespace {

constexpr double g_n = 9.80665;                     // standard gravity, m/s²
constexpr double pound_force = 4.4482216152605;     // N
constexpr double inch = 0.0254;                     // m
constexpr double degree = std::numbers::pi / 180.0; // rad

} // namespace

std::string_view uff_unit_noun(UffUnitKind kind) {
  switch (kind) {
  case UffUnitKind::length:
    return "a displacement";
  case UffUnitKind::velocity:
    return "a velocity";
  case UffUnitKind::acceleration:
    return "an acceleration";
  case UffUnitKind::force:
    return "a force";
  case UffUnitKind::angle:
    return "a rotation";
  case UffUnitKind::angular_velocity:
    return "an angular velocity";
  case UffUnitKind::angular_acceleration:
    return "an angular acceleration";
  case UffUnitKind::moment:
    return "a moment";
  case UffUnitKind::time:
    return "a time";
  case UffUnitKind::frequency:
    return "a frequency";
  }
  return "";
}

std::span<const UffUnitLabel> uff_unit_labels(UffUnitKind kind) {
  static constexpr UffUnitLabel length[] = {
      {"m", 1.0}, {"mm", 1e-3}, {"cm", 1e-2}, {"um", 1e-6}, {"in", inch}};
  static constexpr UffUnitLabel velocity[] = {
      {"m/s", 1.0}, {"mm/s", 1e-3}, {"cm/s", 1e-2}, {"um/s", 1e-6}, {"in/s", inch}};
  static constexpr UffUnitLabel acceleration[] = {{"m/s2", 1.0},   {"mm/s2", 1e-3}, {"cm/s2", 1e-2},
                                                  {"in/s2", inch}, {"g", g_n},      {"G", g_n}};
  static constexpr UffUnitLabel force[] = {
      {"N", 1.0}, {"kN", 1e3}, {"mN", 1e-3}, {"lbf", pound_force}};
  static constexpr UffUnitLabel angle[] = {{"rad", 1.0}, {"mrad", 1e-3}, {"deg", degree}};
  static constexpr UffUnitLabel angular_velocity[] = {
      {"rad/s", 1.0}, {"mrad/s", 1e-3}, {"deg/s", degree}};
  static constexpr UffUnitLabel angular_acceleration[] = {
      {"rad/s2", 1.0}, {"mrad/s2", 1e-3}, {"deg/s2", degree}};
  static constexpr UffUnitLabel moment[] = {
      {"Nm", 1.0}, {"kNm", 1e3}, {"Nmm", 1e-3}, {"mNm", 1e-3}};
  // "Time" and "Frequency" name the quantity, not a unit (some writers put them there).
  static constexpr UffUnitLabel time[] = {{"s", 1.0}, {"Time", 1.0}, {"time", 1.0}, {"ms", 1e-3}};
  static constexpr UffUnitLabel frequency[] = {
      {"Hz", 1.0}, {"hz", 1.0}, {"Frequency", 1.0}, {"frequency", 1.0}};
  switch (kind) {
  case UffUnitKind::length:
    return length;
  case UffUnitKind::velocity:
    return velocity;
  case UffUnitKind::acceleration:
    return acceleration;
  case UffUnitKind::force:
    return force;
  case UffUnitKind::angle:
    return angle;
  case UffUnitKind::angular_velocity:
    return angular_velocity;
  case UffUnitKind::angular_acceleration:
    return angular_acceleration;
  case UffUnitKind::moment:
    return moment;
  case UffUnitKind::time:
    return time;
  case UffUnitKind::frequency:
    return frequency;
  }
  return {};
}

std::string uff_normalised_unit(std::string_view label) {
  std::string out;
  for (std::size_t i = 0; i < label.size(); ++i) {
    const std::string_view rest = label.substr(i);
    if (rest.starts_with("\xC2\xB2")) { // ²
      out += '2';
      ++i;
    } else if (rest.starts_with("\xC2\xB5") || rest.starts_with("\xCE\xBC")) { // µ, μ
      out += 'u';
      ++i;
    } else if (rest.starts_with("\xC2\xB7")) { // ·
      ++i;
    } else if (rest.starts_with("sec")) {
      out += 's';
      i += 2;
    } else if (label[i] != ' ' && label[i] != '*' && label[i] != '.' && label[i] != '^') {
      out += label[i];
    }
  }
  return out;
}

bool uff_no_units_label(std::string_view label) {
  const std::string_view t = detail::trim(label);
  return t.empty() || t == "NONE" || t == "none";
}

std::optional<double> uff_unit_to_si(UffUnitKind kind, std::string_view label) {
  const std::string normalised = uff_normalised_unit(detail::trim(label));
  const auto units = uff_unit_labels(kind);
  const auto it = std::find_if(units.begin(), units.end(),
                               [&](const UffUnitLabel& u) { return u.label == normalised; });
  if (it == units.end()) return std::nullopt;
  return it->to_si;
}

std::string uff_unit_list(UffUnitKind kind) {
  std::string list;
  for (const UffUnitLabel& u : uff_unit_labels(kind))
    list += (list.empty() ? "" : ", ") + std::string(u.label);
  return list;
}

std::optional<UffAxisQuantity> uff_axis_quantity(int data_type, bool rotation) {
  using identify::Quantity;
  switch (data_type) {
  case uff_data_type::excitation_force:
    return rotation ? UffAxisQuantity{Quantity::force, UffUnitKind::moment, 1, 1}
                    : UffAxisQuantity{Quantity::force, UffUnitKind::force, 0, 1};
  case uff_data_type::displacement:
    return rotation ? UffAxisQuantity{Quantity::displacement, UffUnitKind::angle, 0, 0}
                    : UffAxisQuantity{Quantity::displacement, UffUnitKind::length, 1, 0};
  case uff_data_type::velocity:
    return rotation ? UffAxisQuantity{Quantity::velocity, UffUnitKind::angular_velocity, 0, 0}
                    : UffAxisQuantity{Quantity::velocity, UffUnitKind::velocity, 1, 0};
  case uff_data_type::acceleration:
    return rotation
               ? UffAxisQuantity{Quantity::acceleration, UffUnitKind::angular_acceleration, 0, 0}
               : UffAxisQuantity{Quantity::acceleration, UffUnitKind::acceleration, 1, 0};
  default:
    return std::nullopt;
  }
}

std::optional<UffAxisQuantity> uff_label_quantity(std::string_view label, bool rotation) {
  struct KindType {
    UffUnitKind kind;
    int data_type;
  };
  static constexpr KindType translational[] = {
      {UffUnitKind::length, uff_data_type::displacement},
      {UffUnitKind::velocity, uff_data_type::velocity},
      {UffUnitKind::acceleration, uff_data_type::acceleration},
      {UffUnitKind::force, uff_data_type::excitation_force}};
  static constexpr KindType rotational[] = {
      {UffUnitKind::angle, uff_data_type::displacement},
      {UffUnitKind::angular_velocity, uff_data_type::velocity},
      {UffUnitKind::angular_acceleration, uff_data_type::acceleration},
      {UffUnitKind::moment, uff_data_type::excitation_force}};
  for (const KindType& k :
       rotation ? std::span<const KindType>(rotational) : std::span<const KindType>(translational))
    if (uff_unit_to_si(k.kind, label)) return uff_axis_quantity(k.data_type, rotation);
  return std::nullopt;
}

double uff164_to_si(const UffUnits& units, int length_exponent, int force_exponent) {
  return 1.0 / (std::pow(units.length, length_exponent) * std::pow(units.force, force_exponent));
}

} // namespace jointid::io
