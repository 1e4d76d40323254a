#pragma once
/// The units of universal files (io/uff58.hpp) and their factors to SI (m, N, rad, s, Hz): the
/// axis units labels (records 8–11 field 6) that jointid reads, the quantity and Addendum A
/// exponents of a specific data type, and the unit systems of dataset 164. A value in the file
/// times its factor is SI. uff58_tests and uff58_frfs convert through these functions; the tests
/// check every label against hand-computed factors.
#include "identify/measurement.hpp"
#include "io/uff58.hpp"

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace jointid::io {

/// What an axis holds, which decides the units its label may name.
enum class UffUnitKind {
  length,
  velocity,
  acceleration,
  force,
  angle,
  angular_velocity,
  angular_acceleration,
  moment,
  time,     ///< the abscissa of a time response
  frequency ///< the abscissa of an FRF
};

/// "a displacement", "an angular velocity", "a moment", ... (for messages).
std::string_view uff_unit_noun(UffUnitKind kind);

/// A units label as jointid reads it, normalised (see uff_normalised_unit), and its factor to SI.
struct UffUnitLabel {
  std::string_view label;
  double to_si;
};

/// Every label read for `kind`, normalised:
///  - length m, mm, cm, um, in; velocity the same per s; acceleration the same per s2, and g, G
///    (standard gravity 9.80665 m/s²); force N, kN, mN, lbf (4.4482216152605 N);
///  - angle rad, mrad, deg (π/180); angular velocity and acceleration the same per s and s2;
///    moment Nm, kNm, Nmm, mNm;
///  - time s, ms, and "Time"/"time" (s: some writers put the quantity there); frequency Hz, hz,
///    and "Frequency"/"frequency".
std::span<const UffUnitLabel> uff_unit_labels(UffUnitKind kind);

/// A label as uff_unit_labels spells it: "m/s^2", "m/s**2", "m/s²" → "m/s2"; "N m", "N*m",
/// "N.m", "N·m" → "Nm"; "µm", "μm" → "um"; "m/sec" → "m/s".
std::string uff_normalised_unit(std::string_view label);

/// True when an axis gives no units label: blank, "NONE" or "none".
bool uff_no_units_label(std::string_view label);

/// The factor to SI of a value of `kind` labelled `label` (as written: blanks around it and the
/// spellings of uff_normalised_unit allowed); nullopt when jointid does not read that label.
std::optional<double> uff_unit_to_si(UffUnitKind kind, std::string_view label);

/// The labels of `kind` as a list for messages: "m, mm, cm, um, in".
std::string uff_unit_list(UffUnitKind kind);

/// What a specific data type (records 9 and 10 field 1) measures at a translational or
/// rotational DOF, and the length and force exponents the standard's Addendum A gives it.
struct UffAxisQuantity {
  identify::Quantity quantity = identify::Quantity::force;
  UffUnitKind kind = UffUnitKind::force;
  int length_exponent = 0;
  int force_exponent = 0;
};

/// 13 excitation force → force (moment at a rotation: exponents 1 1, else 0 1), 8 displacement,
/// 11 velocity, 12 acceleration → the motion (exponents 1 0; rotations 0 0). Other data types:
/// nullopt.
std::optional<UffAxisQuantity> uff_axis_quantity(int data_type, bool rotation);

/// The quantity an axis units label names, for an axis whose specific data type does not say it
/// (0 unknown, 1 general, as many data acquisition systems write): a length → displacement, a
/// velocity, an acceleration (g and G included), a force → excitation force; at a rotational DOF
/// a rotation, an angular velocity, an angular acceleration, a moment. The exponents are those
/// of the quantity's data type (uff_axis_quantity). nullopt when the label is none of these
/// units (time and frequency labels included).
std::optional<UffAxisQuantity> uff_label_quantity(std::string_view label, bool rotation);

/// Dataset 164: the factor to SI of a value in the file's unit system with these exponents,
/// 1 / (length^length_exponent · force^force_exponent) (UffUnits: a value in the file's units
/// divided by the factor is SI).
double uff164_to_si(const UffUnits& units, int length_exponent, int force_exponent);

} // namespace jointid::io
