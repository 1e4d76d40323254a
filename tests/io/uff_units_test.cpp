// The units of universal files against hand-computed SI factors: every axis units label the
// reader accepts, in every spelling it normalises, both alone (uff_unit_to_si) and as the
// factor that uff58_tests and uff58_frfs apply to the values; the dataset 164 factors for each
// quantity (length and force exponents of the standard's Addendum A); and two hand-written
// files read end to end: a time response in mm/s² and an FRF whose units come from dataset 164.
#include "io/uff_units.hpp"

#include "io/measured_frf_file.hpp"
#include "io/record_csv.hpp"
#include "io/test_files.hpp"
#include "io/uff58.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace jointid::io {
namespace {

using Kind = UffUnitKind;

// Hand-computed factors to SI.
constexpr double inch = 0.0254;                 // m (exact by definition)
constexpr double pound_force = 4.4482216152605; // N (exact by definition)
constexpr double g_n = 9.80665;                 // m/s² (exact by definition)
constexpr double degree = 0.017453292519943295; // π/180 rad, to 17 digits

struct Label {
  Kind kind;
  std::string written; ///< as a file may write it
  double si;           ///< the factor to SI, by hand
};

// Every label the reader accepts: first each one as uff_unit_labels spells it, then the other
// spellings it normalises (^2, **2, ², sec, blanks, *, ., ·, µ, μ).
const std::vector<Label> labels = {
    {Kind::length, "m", 1.0},
    {Kind::length, "mm", 1e-3},
    {Kind::length, "cm", 1e-2},
    {Kind::length, "um", 1e-6},
    {Kind::length, "in", inch},
    {Kind::velocity, "m/s", 1.0},
    {Kind::velocity, "mm/s", 1e-3},
    {Kind::velocity, "cm/s", 1e-2},
    {Kind::velocity, "um/s", 1e-6},
    {Kind::velocity, "in/s", inch},
    {Kind::acceleration, "m/s2", 1.0},
    {Kind::acceleration, "mm/s2", 1e-3},
    {Kind::acceleration, "cm/s2", 1e-2},
    {Kind::acceleration, "in/s2", inch},
    {Kind::acceleration, "g", g_n},
    {Kind::acceleration, "G", g_n},
    {Kind::force, "N", 1.0},
    {Kind::force, "kN", 1e3},
    {Kind::force, "mN", 1e-3},
    {Kind::force, "lbf", pound_force},
    {Kind::angle, "rad", 1.0},
    {Kind::angle, "mrad", 1e-3},
    {Kind::angle, "deg", degree},
    {Kind::angular_velocity, "rad/s", 1.0},
    {Kind::angular_velocity, "mrad/s", 1e-3},
    {Kind::angular_velocity, "deg/s", degree},
    {Kind::angular_acceleration, "rad/s2", 1.0},
    {Kind::angular_acceleration, "mrad/s2", 1e-3},
    {Kind::angular_acceleration, "deg/s2", degree},
    {Kind::moment, "Nm", 1.0},
    {Kind::moment, "kNm", 1e3},
    {Kind::moment, "Nmm", 1e-3},
    {Kind::moment, "mNm", 1e-3},
    {Kind::time, "s", 1.0},
    {Kind::time, "Time", 1.0},
    {Kind::time, "time", 1.0},
    {Kind::time, "ms", 1e-3},
    {Kind::frequency, "Hz", 1.0},
    {Kind::frequency, "hz", 1.0},
    {Kind::frequency, "Frequency", 1.0},
    {Kind::frequency, "frequency", 1.0},
    // Other spellings.
    {Kind::length, "\xC2\xB5m", 1e-6}, // µm (micro sign)
    {Kind::length, "\xCE\xBCm", 1e-6}, // μm (Greek mu)
    {Kind::length, "  mm  ", 1e-3},
    {Kind::velocity, "m/sec", 1.0},
    {Kind::velocity, "mm/sec", 1e-3},
    {Kind::velocity, "\xC2\xB5m/s", 1e-6},
    {Kind::acceleration, "m/s^2", 1.0},
    {Kind::acceleration, "m/s**2", 1.0},
    {Kind::acceleration, "m/s\xC2\xB2", 1.0}, // m/s²
    {Kind::acceleration, "m/sec^2", 1.0},
    {Kind::acceleration, "mm/s^2", 1e-3},
    {Kind::acceleration, "mm/s\xC2\xB2", 1e-3},
    {Kind::acceleration, "cm/s^2", 1e-2},
    {Kind::acceleration, "in/s^2", inch},
    {Kind::acceleration, "in/s\xC2\xB2", inch},
    {Kind::angular_acceleration, "rad/s^2", 1.0},
    {Kind::angular_acceleration, "mrad/s^2", 1e-3},
    {Kind::angular_acceleration, "deg/s\xC2\xB2", degree},
    {Kind::moment, "N m", 1.0},
    {Kind::moment, "N*m", 1.0},
    {Kind::moment, "N.m", 1.0},
    {Kind::moment, "N\xC2\xB7m", 1.0}, // N·m
    {Kind::moment, "kN m", 1e3},
    {Kind::moment, "N mm", 1e-3},
    {Kind::moment, "mN m", 1e-3},
    {Kind::time, "sec", 1.0},
    {Kind::time, "msec", 1e-3},
};

const Kind all_kinds[] = {
    Kind::length, Kind::velocity,         Kind::acceleration,         Kind::force,
    Kind::angle,  Kind::angular_velocity, Kind::angular_acceleration, Kind::moment,
    Kind::time,   Kind::frequency};

std::string trace(const Label& l) {
  return std::string(uff_unit_noun(l.kind)) + " in '" + l.written + "'";
}

void expect_relative(double actual, double expected, double tolerance, const std::string& what) {
  EXPECT_NEAR(actual, expected, tolerance * std::abs(expected)) << what;
}

TEST(UffUnits, EveryLabelHasItsHandComputedFactor) {
  for (const Label& l : labels) {
    const auto factor = uff_unit_to_si(l.kind, l.written);
    ASSERT_TRUE(factor.has_value()) << trace(l) << " is refused";
    expect_relative(*factor, l.si, 1e-15, trace(l));
  }
}

TEST(UffUnits, EveryLabelTheReaderAcceptsIsInTheTable) {
  // A label added to the reader without a hand-computed factor here fails.
  for (const Kind kind : all_kinds)
    for (const UffUnitLabel& u : uff_unit_labels(kind)) {
      const bool listed = std::any_of(labels.begin(), labels.end(), [&](const Label& l) {
        return l.kind == kind && l.written == u.label;
      });
      EXPECT_TRUE(listed) << uff_unit_noun(kind) << " in '" << u.label << "' has no row";
    }
}

TEST(UffUnits, OtherLabelsAndOtherQuantitiesAreRefused) {
  EXPECT_FALSE(uff_unit_to_si(Kind::length, "V"));
  EXPECT_FALSE(uff_unit_to_si(Kind::length, "mm/s")); // a velocity
  EXPECT_FALSE(uff_unit_to_si(Kind::velocity, "mm"));
  EXPECT_FALSE(uff_unit_to_si(Kind::acceleration, "m/s"));
  EXPECT_FALSE(uff_unit_to_si(Kind::force, "Nm")); // a moment
  EXPECT_FALSE(uff_unit_to_si(Kind::moment, "N"));
  EXPECT_FALSE(uff_unit_to_si(Kind::angle, "m"));
  EXPECT_FALSE(uff_unit_to_si(Kind::time, "min"));
  EXPECT_FALSE(uff_unit_to_si(Kind::frequency, "rad/s"));
  EXPECT_FALSE(uff_unit_to_si(Kind::force, "kgf"));
  for (const char* none : {"NONE", "none", "", "   "})
    EXPECT_TRUE(uff_no_units_label(none)) << "'" << none << "'";
  EXPECT_FALSE(uff_no_units_label("N"));
}

// The specific data type (records 9–10 field 1) of a quantity, and whether it is at a rotation.
int data_type_of(Kind kind) {
  switch (kind) {
  case Kind::length:
  case Kind::angle:
    return uff_data_type::displacement;
  case Kind::velocity:
  case Kind::angular_velocity:
    return uff_data_type::velocity;
  case Kind::acceleration:
  case Kind::angular_acceleration:
    return uff_data_type::acceleration;
  case Kind::force:
  case Kind::moment:
    return uff_data_type::excitation_force;
  default:
    return uff_data_type::unknown;
  }
}

bool at_rotation(Kind kind) {
  return kind == Kind::angle || kind == Kind::angular_velocity ||
         kind == Kind::angular_acceleration || kind == Kind::moment;
}

// A time response at node 3 (+Y, or +RZ for rotations), 4 samples at 10 ms.
Uff58Function time_response(int data_type, bool rotation, const std::string& units_label) {
  Uff58Function f;
  f.response_node = 3;
  f.response_direction = rotation ? 6 : 2;
  f.abscissa_increment = 0.01;
  f.ordinate = {data_type, 0, 0, 0, "Response", units_label};
  f.data = Eigen::Vector4d(1.0, -2.0, 0.5, 3.0);
  return f;
}

// An FRF from node 2 (+Y or +RZ) to node 5 (+Y or +RZ) at 10 and 11 Hz.
Uff58Function frf_function(const Uff58Axis& numerator, bool response_rotation,
                           const Uff58Axis& denominator, bool drive_rotation) {
  Uff58Function f;
  f.function_type = uff_function_type::frequency_response;
  f.ordinate_type = 6;
  f.response_node = 5;
  f.response_direction = response_rotation ? 6 : 2;
  f.reference_node = 2;
  f.reference_direction = drive_rotation ? 6 : 2;
  f.abscissa = {uff_data_type::frequency, 0, 0, 0, "Frequency", "Hz"};
  f.abscissa_min = 10.0;
  f.abscissa_increment = 1.0;
  f.ordinate = numerator;
  f.denominator = denominator;
  f.complex_data =
      Eigen::Vector2cd(std::complex<double>(1.0, 2.0), std::complex<double>(-3.0, 0.5));
  return f;
}

// The quantity a label names (for data types 0 and 1), by hand.
identify::Quantity quantity_of(Kind kind) {
  switch (kind) {
  case Kind::length:
  case Kind::angle:
    return identify::Quantity::displacement;
  case Kind::velocity:
  case Kind::angular_velocity:
    return identify::Quantity::velocity;
  case Kind::acceleration:
  case Kind::angular_acceleration:
    return identify::Quantity::acceleration;
  default:
    return identify::Quantity::force;
  }
}

TEST(UffUnits, EveryLabelNamesItsQuantityWhereTheDataTypeDoesNot) {
  for (const Label& l : labels) {
    SCOPED_TRACE(trace(l));
    const std::optional<UffAxisQuantity> q = uff_label_quantity(l.written, at_rotation(l.kind));
    if (l.kind == Kind::time || l.kind == Kind::frequency) {
      EXPECT_FALSE(q);
      continue;
    }
    ASSERT_TRUE(q);
    EXPECT_EQ(q->quantity, quantity_of(l.kind));
    EXPECT_EQ(q->kind, l.kind);
    // At the other kind of DOF (a translation's unit at a rotation, and back) it names nothing.
    EXPECT_FALSE(uff_label_quantity(l.written, !at_rotation(l.kind)));
  }
  EXPECT_FALSE(uff_label_quantity("V", false));
  EXPECT_FALSE(uff_label_quantity("NONE", false));
}

TEST(UffUnits, EveryLabelScalesTheTimeResponseItLabels) {
  // The quantity from the data type, or from the label where the data type is 0 (unknown) or 1
  // (general), as data acquisition systems write it.
  for (const Label& l : labels) {
    if (l.kind == Kind::time || l.kind == Kind::frequency) continue;
    for (const int data_type : {data_type_of(l.kind), 0, 1}) {
      SCOPED_TRACE(trace(l) + ", data type " + std::to_string(data_type));
      const Uff58Function f = time_response(data_type, at_rotation(l.kind), l.written);
      const auto tests = uff58_tests({f}, "labels.uff");
      const auto& r = std::get<identify::Record>(tests.at(0));
      ASSERT_EQ(r.channels.size(), 1u);
      EXPECT_EQ(r.channels[0].quantity, quantity_of(l.kind));
      for (Eigen::Index i = 0; i < 4; ++i)
        expect_relative(r.channels[0].samples(i), l.si * f.data(i), 1e-15, std::to_string(i));
    }
  }
  for (const Label& l : labels) {
    if (l.kind != Kind::time) continue;
    SCOPED_TRACE(trace(l));
    Uff58Function f = time_response(uff_data_type::displacement, false, "m");
    f.abscissa.units_label = l.written;
    const auto tests = uff58_tests({f}, "labels.uff");
    const auto& r = std::get<identify::Record>(tests.at(0));
    expect_relative(r.t(3), 3 * 0.01 * l.si, 1e-15, "t(3)");
  }
}

TEST(UffUnits, EveryLabelScalesTheFrfItLabels) {
  // Receptance = value × numerator factor / denominator factor; the numerator a displacement
  // or rotation (so that no 1/(iω) enters), the denominator a force or moment.
  const Uff58Axis metre{uff_data_type::displacement, 0, 0, 0, "Displacement", "m"};
  const Uff58Axis newton{uff_data_type::excitation_force, 0, 0, 0, "Force", "N"};
  // Data types 0 (unknown) and 1 (general) take their quantity from the label.
  for (const Label& l : labels)
    for (const int data_type : {data_type_of(l.kind), 0, 1}) {
      if (l.kind == Kind::time) continue;
      SCOPED_TRACE(trace(l) + ", data type " + std::to_string(data_type));
      const bool rotation = at_rotation(l.kind);
      const Uff58Axis axis{data_type, 0, 0, 0, "Axis", l.written};
      double num = 1.0, den = 1.0;
      Uff58Function f;
      if (l.kind == Kind::length || l.kind == Kind::angle) {
        f = frf_function(axis, rotation, newton, false);
        num = l.si;
      } else if (l.kind == Kind::force || l.kind == Kind::moment) {
        f = frf_function(metre, false, axis, rotation);
        den = l.si;
      } else if (l.kind == Kind::frequency) {
        f = frf_function(metre, false, newton, false);
        f.abscissa.units_label = l.written;
      } else {
        continue; // velocities and accelerations: their factors are checked with time responses
      }
      const auto frfs = uff58_frfs({f}, "labels.uff");
      ASSERT_EQ(frfs.size(), 1u);
      EXPECT_EQ(frfs[0].frequencies_hz, (std::vector<double>{10.0, 11.0}));
      for (std::size_t i = 0; i < 2; ++i) {
        const std::complex<double> expected =
            f.complex_data(static_cast<Eigen::Index>(i)) * num / den;
        EXPECT_NEAR(std::abs(frfs[0].receptance[i] - expected), 0.0, 1e-15 * std::abs(expected))
            << i;
      }
    }
}

// Dataset 164 unit systems: inch–pound-force, and millimetre–millinewton (I-DEAS "MM").
const UffUnits inch_pound{7, "IN (pound f)", 2, 1.0 / 0.0254, 1.0 / 4.4482216152605, 1.8, 459.67};
const UffUnits millimetre{5, "MM (milli newton)", 2, 1000.0, 1000.0, 1.0, 273.15};

struct SystemFactor {
  int data_type;
  bool rotation;
  Kind kind;
  int length_exponent, force_exponent; ///< Addendum A
  double inch_pound_si, millimetre_si; ///< by hand
};

// Addendum A: translational motion L¹, force F¹, moment L¹F¹, rotation dimensionless (so a
// unit system does not scale it).
const SystemFactor system_factors[] = {
    {uff_data_type::displacement, false, Kind::length, 1, 0, inch, 1e-3},
    {uff_data_type::velocity, false, Kind::velocity, 1, 0, inch, 1e-3},
    {uff_data_type::acceleration, false, Kind::acceleration, 1, 0, inch, 1e-3},
    {uff_data_type::excitation_force, false, Kind::force, 0, 1, pound_force, 1e-3},
    {uff_data_type::excitation_force, true, Kind::moment, 1, 1, inch* pound_force, 1e-6},
    {uff_data_type::displacement, true, Kind::angle, 0, 0, 1.0, 1.0},
    {uff_data_type::velocity, true, Kind::angular_velocity, 0, 0, 1.0, 1.0},
    {uff_data_type::acceleration, true, Kind::angular_acceleration, 0, 0, 1.0, 1.0},
};

TEST(UffUnits, Dataset164FactorOfEachQuantity) {
  for (const SystemFactor& s : system_factors) {
    SCOPED_TRACE(std::string(uff_unit_noun(s.kind)));
    const auto q = uff_axis_quantity(s.data_type, s.rotation);
    ASSERT_TRUE(q.has_value());
    EXPECT_EQ(q->kind, s.kind);
    EXPECT_EQ(q->length_exponent, s.length_exponent);
    EXPECT_EQ(q->force_exponent, s.force_exponent);
    expect_relative(uff164_to_si(inch_pound, s.length_exponent, s.force_exponent), s.inch_pound_si,
                    1e-15, "inch-pound");
    expect_relative(uff164_to_si(millimetre, s.length_exponent, s.force_exponent), s.millimetre_si,
                    1e-15, "millimetre");
  }
  for (const int other : {0, 1, 2, 9, 17, 18})
    EXPECT_FALSE(uff_axis_quantity(other, false).has_value()) << other;
}

TEST(UffUnits, Dataset164ScalesUnlabelledTimeResponses) {
  // No units label: the dataset 164 in force decides, with the exponents given (Addendum A) or
  // not (0 0 0); a label wins over it; time is not scaled.
  for (const SystemFactor& s : system_factors)
    for (const bool exponents : {false, true})
      for (const UffUnits* units : {&inch_pound, &millimetre}) {
        SCOPED_TRACE(std::string(uff_unit_noun(s.kind)) + " in " + units->description +
                     (exponents ? ", exponents given" : ""));
        Uff58Function f = time_response(s.data_type, s.rotation, "NONE");
        if (exponents) {
          f.ordinate.length_exponent = s.length_exponent;
          f.ordinate.force_exponent = s.force_exponent;
        }
        f.units = *units;
        const auto tests = uff58_tests({f}, "units.uff");
        const auto& r = std::get<identify::Record>(tests.at(0));
        const double si = units == &inch_pound ? s.inch_pound_si : s.millimetre_si;
        for (Eigen::Index i = 0; i < 4; ++i)
          expect_relative(r.channels[0].samples(i), si * f.data(i), 1e-14, std::to_string(i));
        EXPECT_EQ(r.t(3), 3 * 0.01);
      }
  Uff58Function labelled = time_response(uff_data_type::displacement, false, "mm");
  labelled.units = inch_pound;
  const auto tests = uff58_tests({labelled}, "units.uff");
  EXPECT_DOUBLE_EQ(std::get<identify::Record>(tests.at(0)).channels[0].samples(1), -2.0e-3);
}

TEST(UffUnits, Dataset164ScalesUnlabelledFrfs) {
  // Receptance in (file length)/(file force) → m/N: a displacement per force in inch–pound is
  // 0.0254/4.4482216152605 m/N; a rotation per moment 1/(0.0254 · 4.4482216152605) rad/(N m).
  // The denominator either says it is a force (13) without a label, or says nothing (0, NONE).
  const Uff58Axis none{uff_data_type::unknown, 0, 0, 0, "NONE", "NONE"};
  struct Case {
    bool rotation;
    bool denominator_given;
    double si;
  };
  const Case cases[] = {{false, true, inch / pound_force},
                        {false, false, inch / pound_force},
                        {true, true, 1.0 / (inch * pound_force)},
                        {true, false, 1.0 / (inch * pound_force)}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.rotation ? "rotation/moment" : "displacement/force") +
                 (c.denominator_given ? ", record 10 = 13" : ", record 10 empty"));
    const Uff58Axis num{uff_data_type::displacement, 0, 0, 0, "Response", "NONE"};
    const Uff58Axis den = c.denominator_given
                              ? Uff58Axis{uff_data_type::excitation_force, 0, 0, 0, "Force", "NONE"}
                              : none;
    Uff58Function f = frf_function(num, c.rotation, den, c.rotation);
    f.units = inch_pound;
    const auto frfs = uff58_frfs({f}, "units.uff");
    for (std::size_t i = 0; i < 2; ++i) {
      const std::complex<double> expected = f.complex_data(static_cast<Eigen::Index>(i)) * c.si;
      EXPECT_NEAR(std::abs(frfs.at(0).receptance[i] - expected), 0.0, 1e-14 * std::abs(expected))
          << i;
    }
  }
}

// End to end: hand-written files, read as the command line reads them.

TEST(UffUnits, TimeResponseInMillimetresPerSecondSquaredReadsInSi) {
  const test::TempDir dir;
  const auto path = dir / "accel.uff";
  test::write_text(path, "    -1\n"
                         "    58\n"
                         "Tip acceleration\n"
                         "NONE\nNONE\nNONE\nNONE\n"
                         "    1         1    0         0 NONE               4   3 NONE          "
                         "     0   0\n"
                         "         4         4         1  0.00000E+00  5.00000E-03  0.00000E+00\n"
                         "        17    0    0    0 Time                 s\n"
                         "        12    1    0    0 Acceleration         mm/s\xC2\xB2\n"
                         "         0    0    0    0 NONE                 NONE\n"
                         "         0    0    0    0 NONE                 NONE\n"
                         "  1.250000000000E+03 -2.500000000000E+02  4.000000000000E+00  "
                         "0.000000000000E+00\n"
                         "    -1\n");
  const auto tests = read_tests({path});
  ASSERT_EQ(tests.size(), 1u);
  const auto& r = std::get<identify::Record>(tests[0]);
  ASSERT_EQ(r.channels.size(), 1u);
  EXPECT_EQ(r.channels[0].name(), "a@4:uz");
  const double si[] = {1.25, -0.25, 0.004, 0.0}; // m/s², by hand from mm/s²
  for (Eigen::Index i = 0; i < 4; ++i)
    EXPECT_NEAR(r.channels[0].samples(i), si[i], 1e-15) << i;
  EXPECT_DOUBLE_EQ(r.t(3), 0.015);
}

TEST(UffUnits, FrfWithItsForceUnitFromDataset164ReadsInSi) {
  // Inch and pound-force (dataset 164, code 7): a receptance of 1 in/lbf is 0.0254/4.4482216152605
  // m/N. Record 9 is a displacement and record 10 a force, neither with a units label.
  const test::TempDir dir;
  const auto path = dir / "frf.uff";
  test::write_text(path, "    -1\n"
                         "   164\n"
                         "         7IN (pound f)                  2\n"
                         "  3.93700787401574803D+01  2.24808943099710480D-01  "
                         "1.80000000000000000D+00\n"
                         "  4.59670000000000000D+02\n"
                         "    -1\n"
                         "    -1\n"
                         "    58\n"
                         "Tip receptance\n"
                         "NONE\nNONE\nNONE\nNONE\n"
                         "    4         1    0         0 NONE               5   2 NONE          "
                         "     2   2\n"
                         "         6         3         1  1.00000E+01  5.00000E-01  0.00000E+00\n"
                         "        18    0    0    0 Frequency            Hz\n"
                         "         8    1    0    0 Displacement         NONE\n"
                         "        13    0    1    0 Force                NONE\n"
                         "         0    0    0    0 NONE                 NONE\n"
                         "  2.000000000000E+00 -1.000000000000E+00  4.000000000000E+00  "
                         "0.000000000000E+00\n"
                         "  0.000000000000E+00  5.000000000000E-01\n"
                         "    -1\n");
  const frf::MeasuredFrf m = read_measured_frf({path});
  ASSERT_EQ(m.functions.size(), 1u);
  const frf::MeasuredFunction& f = m.functions[0];
  EXPECT_EQ(f.response, (fem::NodeDof{5, fem::Dof::uy}));
  EXPECT_EQ(f.drive, (fem::NodeDof{2, fem::Dof::uy}));
  EXPECT_EQ(f.frequencies_hz, (std::vector<double>{10.0, 10.5, 11.0}));
  const double m_per_n = 0.0254 / 4.4482216152605; // 5.710147162e-3, by hand
  const std::complex<double> in_per_lbf[] = {{2.0, -1.0}, {4.0, 0.0}, {0.0, 0.5}};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::complex<double> expected = in_per_lbf[i] * m_per_n;
    EXPECT_NEAR(std::abs(f.receptance.at(i) - expected), 0.0, 1e-12 * std::abs(expected)) << i;
  }
}

} // namespace
} // namespace jointid::io
