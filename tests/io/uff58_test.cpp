// Universal File Format dataset 58 (ASCII and 58b): a hand-written file read field by field,
// round trips, files mixing datasets, units and direction signs, sine tests identified through
// UFF files exactly as through CSV, and malformed files.
#include "io/uff58.hpp"

#include "identify/fit.hpp"
#include "identify/sine_tests.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "io/test_files.hpp"
#include "support/cantilever.hpp"
#include "support/numbers.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace jointid::io {
namespace {

using jointid::test::same_bits;

using identify::Quantity;

// A time response written by hand after the standard: real single precision (ordinate type 2),
// 8 values evenly spaced at 12.5 ms, displacement in mm at node 7, +Y; the response entity name
// holds a blank (read by columns).
const std::string hand_written = "    -1\n"
                                 "    58\n"
                                 "Tip displacement, sine test at 3 Hz\n"
                                 "excitation_hz = 3\n"
                                 "12-Mar-24 10:15:00\n"
                                 "Run 7\n"
                                 "NONE\n"
                                 "    1         2    3         0 tip gauge          7   2 NONE  "
                                 "             7   2\n"
                                 "         2         8         1  0.00000E+00  1.25000E-02  "
                                 "0.00000E+00\n"
                                 "        17    0    0    0 Time                 s             "
                                 "      \n"
                                 "         8    1    0    0 Displacement         mm            "
                                 "      \n"
                                 "         0    0    0    0 NONE                 NONE          "
                                 "      \n"
                                 "         0    0    0    0 NONE                 NONE          "
                                 "      \n"
                                 "  1.00000E+00  2.50000E+00 -3.25000E+00  4.00000E-01  "
                                 "0.00000E+00 -1.50000E+00\n"
                                 "  7.75000E+00  8.12500E+00\n"
                                 "    -1\n";

const double hand_values[] = {1.0, 2.5, -3.25, 0.4, 0.0, -1.5, 7.75, 8.125};

class Uff58Test : public ::testing::Test {
protected:
  std::filesystem::path write(const std::string& text, const std::string& name = "test.uff") {
    const auto path = dir / name;
    test::write_text(path, text);
    return path;
  }
  // The message of the io::Error that f throws ("" if none).
  template <class F> static std::string error_of(F&& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  // Expects read_uff58 to fail naming the file, `where` ("bad.uff:12:" or "bad.uff: byte 345:")
  // and every one of `parts`.
  void expect_error(const std::string& text, const std::string& where,
                    std::initializer_list<std::string> parts) {
    const auto path = write(text, "bad.uff");
    const std::string message = error_of([&] { read_uff58(path); });
    ASSERT_FALSE(message.empty()) << "accepted:\n" << text.substr(0, 400);
    EXPECT_NE(message.find(where), std::string::npos) << "'" << where << "' not in: " << message;
    for (const auto& p : parts)
      EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' not in: " << message;
  }
  // Expects read_uff58 to accept the file and uff58_tests to refuse it, naming the file, the
  // dataset and every one of `parts`.
  void expect_test_error(const std::string& text, std::initializer_list<std::string> parts) {
    const auto path = write(text, "bad.uff");
    std::vector<Uff58Function> functions;
    ASSERT_NO_THROW(functions = read_uff58(path));
    const std::string message = error_of([&] { uff58_tests(functions, path); });
    ASSERT_FALSE(message.empty()) << "accepted:\n" << text.substr(0, 400);
    EXPECT_NE(message.find(path.string() + ": dataset 1 (line 1)"), std::string::npos) << message;
    for (const auto& p : parts)
      EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' not in: " << message;
  }
  test::TempDir dir;
};

TEST_F(Uff58Test, ReadsAHandWrittenFileFieldByField) {
  const auto path = write(hand_written, "hand.uff");
  const std::vector<Uff58Function> functions = read_uff58(path);
  ASSERT_EQ(functions.size(), 1u);
  const Uff58Function& f = functions[0];
  EXPECT_EQ(f.id_lines[0], "Tip displacement, sine test at 3 Hz");
  EXPECT_EQ(f.id_lines[1], "excitation_hz = 3");
  EXPECT_EQ(f.id_lines[2], "12-Mar-24 10:15:00");
  EXPECT_EQ(f.id_lines[3], "Run 7");
  EXPECT_EQ(f.id_lines[4], "NONE");
  EXPECT_EQ(f.function_type, uff_function_type::time_response);
  EXPECT_EQ(f.function_id, 2);
  EXPECT_EQ(f.version, 3);
  EXPECT_EQ(f.load_case, 0);
  EXPECT_EQ(f.response_entity, "tip gauge");
  EXPECT_EQ(f.response_node, 7);
  EXPECT_EQ(f.response_direction, 2);
  EXPECT_EQ(f.reference_entity, "NONE");
  EXPECT_EQ(f.reference_node, 7);
  EXPECT_EQ(f.reference_direction, 2);
  EXPECT_EQ(f.ordinate_type, 2);
  EXPECT_FALSE(f.is_complex());
  EXPECT_TRUE(f.even);
  EXPECT_EQ(f.num_points(), 8);
  EXPECT_EQ(f.abscissa_min, 0.0);
  EXPECT_EQ(f.abscissa_increment, 0.0125);
  EXPECT_EQ(f.z_value, 0.0);
  EXPECT_EQ(f.abscissa, (Uff58Axis{17, 0, 0, 0, "Time", "s"}));
  EXPECT_EQ(f.ordinate, (Uff58Axis{8, 1, 0, 0, "Displacement", "mm"}));
  EXPECT_EQ(f.denominator, (Uff58Axis{0, 0, 0, 0, "NONE", "NONE"}));
  EXPECT_EQ(f.z_axis, (Uff58Axis{0, 0, 0, 0, "NONE", "NONE"}));
  ASSERT_EQ(f.data.size(), 8);
  EXPECT_EQ(f.complex_data.size(), 0);
  EXPECT_EQ(f.abscissa_values.size(), 0);
  for (int i = 0; i < 8; ++i) // single precision: 0.4 is its nearest float
    EXPECT_TRUE(same_bits(f.data(i), static_cast<float>(hand_values[i]))) << i;
  EXPECT_FALSE(f.units.has_value());
  EXPECT_EQ(f.dataset, 1);
  EXPECT_EQ(f.line, 1);
  EXPECT_FALSE(f.binary);

  // As a sine test: x@7:uy in m, t = i · 12.5 ms, the excitation frequency from ID line 2.
  const auto tests = uff58_tests(functions, path);
  ASSERT_EQ(tests.size(), 1u);
  const auto* r = std::get_if<identify::Record>(&tests[0]);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->source, path.string() + "#1");
  ASSERT_TRUE(r->excitation_hz.has_value());
  EXPECT_EQ(*r->excitation_hz, 3.0);
  ASSERT_EQ(r->t.size(), 8);
  for (int i = 0; i < 8; ++i)
    EXPECT_EQ(r->t(i), i * 0.0125);
  ASSERT_EQ(r->channels.size(), 1u);
  EXPECT_EQ(r->channels[0].name(), "x@7:uy");
  for (int i = 0; i < 8; ++i)
    EXPECT_EQ(r->channels[0].samples(i), 1e-3 * static_cast<float>(hand_values[i]));

  // The same file with Windows line ends, and with a byte-order mark, reads the same.
  std::string crlf;
  for (const char c : hand_written)
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  for (const auto& text : {crlf, "\xEF\xBB\xBF" + hand_written}) {
    const auto again = read_uff58(write(text, "again.uff"));
    ASSERT_EQ(again.size(), 1u);
    EXPECT_EQ(again[0].id_lines, f.id_lines);
    EXPECT_EQ(again[0].response_entity, "tip gauge");
    EXPECT_EQ(again[0].ordinate, f.ordinate);
    EXPECT_EQ(again[0].data, f.data);
  }
}

// A record with force, displacement and velocity whose values need all 17 digits, or none, or
// sit at the edges of double precision.
identify::Record uff_sample_record() {
  identify::Record r;
  r.source = "sample.csv";
  const int n = 40;
  const double h = 1.0 / (3.4 * 16);
  r.t.resize(n);
  for (int i = 0; i < n; ++i)
    r.t(i) = i * h;
  r.excitation_hz = 3.4;
  Eigen::VectorXd force(n), x(n), v(n);
  for (int i = 0; i < n; ++i) {
    force(i) = 80.0 * std::sin(2.0 * std::numbers::pi * 3.4 * r.t(i));
    x(i) = 1e-3 * std::cos(0.7 * i) / 3.0;
    v(i) = std::exp(0.9 * i - 18.0);
  }
  x(0) = 0.1 + 0.2;
  x(1) = -0.0;
  x(2) = std::numeric_limits<double>::denorm_min();
  x(3) = std::numeric_limits<double>::max();
  x(4) = -std::numeric_limits<double>::min();
  x(5) = 1.0 / 3.0;
  x(6) = -std::numeric_limits<double>::max();
  r.channels.push_back({Quantity::force, {7, fem::Dof::uy}, force});
  r.channels.push_back({Quantity::displacement, {7, fem::Dof::uy}, x});
  r.channels.push_back({Quantity::velocity, {12, fem::Dof::rz}, v});
  return r;
}

void expect_same_function(const Uff58Function& a, const Uff58Function& b) {
  EXPECT_EQ(a.id_lines, b.id_lines);
  EXPECT_EQ(a.function_type, b.function_type);
  EXPECT_EQ(a.function_id, b.function_id);
  EXPECT_EQ(a.version, b.version);
  EXPECT_EQ(a.load_case, b.load_case);
  EXPECT_EQ(a.response_entity, b.response_entity);
  EXPECT_EQ(a.response_node, b.response_node);
  EXPECT_EQ(a.response_direction, b.response_direction);
  EXPECT_EQ(a.reference_entity, b.reference_entity);
  EXPECT_EQ(a.reference_node, b.reference_node);
  EXPECT_EQ(a.reference_direction, b.reference_direction);
  EXPECT_EQ(a.ordinate_type, b.ordinate_type);
  EXPECT_EQ(a.even, b.even);
  EXPECT_TRUE(same_bits(a.abscissa_min, b.abscissa_min));
  EXPECT_TRUE(same_bits(a.abscissa_increment, b.abscissa_increment));
  EXPECT_TRUE(same_bits(a.z_value, b.z_value));
  EXPECT_EQ(a.abscissa, b.abscissa);
  EXPECT_EQ(a.ordinate, b.ordinate);
  EXPECT_EQ(a.denominator, b.denominator);
  EXPECT_EQ(a.z_axis, b.z_axis);
  EXPECT_EQ(a.units, b.units);
  ASSERT_EQ(a.data.size(), b.data.size());
  for (Eigen::Index i = 0; i < a.data.size(); ++i)
    EXPECT_TRUE(same_bits(a.data(i), b.data(i)) || (std::isnan(a.data(i)) && std::isnan(b.data(i))))
        << i << ": " << a.data(i) << " vs " << b.data(i);
  ASSERT_EQ(a.complex_data.size(), b.complex_data.size());
  for (Eigen::Index i = 0; i < a.complex_data.size(); ++i) {
    EXPECT_TRUE(same_bits(a.complex_data(i).real(), b.complex_data(i).real())) << i;
    EXPECT_TRUE(same_bits(a.complex_data(i).imag(), b.complex_data(i).imag())) << i;
  }
  ASSERT_EQ(a.abscissa_values.size(), b.abscissa_values.size());
  for (Eigen::Index i = 0; i < a.abscissa_values.size(); ++i)
    EXPECT_TRUE(same_bits(a.abscissa_values(i), b.abscissa_values(i))) << i;
}

TEST_F(Uff58Test, RecordRoundTripIsBitExactInAsciiAndBinary) {
  const identify::Record r = uff_sample_record();
  const std::vector<Uff58Function> functions = uff58_from_record(r);
  ASSERT_EQ(functions.size(), 3u);
  EXPECT_EQ(functions[0].id_lines[0], "f@7:uy");
  EXPECT_EQ(functions[0].id_lines[1], "excitation_hz = 3.4");
  EXPECT_EQ(functions[0].ordinate, (Uff58Axis{13, 0, 1, 0, "Force", "N"}));
  EXPECT_EQ(functions[1].ordinate, (Uff58Axis{8, 1, 0, 0, "Displacement", "m"}));
  EXPECT_EQ(functions[2].ordinate, (Uff58Axis{11, 0, 0, 0, "Angular velocity", "rad/s"}));
  EXPECT_EQ(functions[2].response_node, 12);
  EXPECT_EQ(functions[2].response_direction, 6);
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "58b" : "58");
    const auto path = dir / (binary ? "binary.uff" : "ascii.uff");
    write_uff58(path, functions, binary);
    const std::string text = test::read_text(path);
    EXPECT_EQ(text.rfind(binary ? "    -1\n    58b     1     2          11         320"
                                : "    -1\n    58\n",
                         0),
              0u)
        << text.substr(0, 100);
    const std::vector<Uff58Function> back = read_uff58(path);
    ASSERT_EQ(back.size(), functions.size());
    for (std::size_t i = 0; i < back.size(); ++i) {
      expect_same_function(back[i], functions[i]);
      EXPECT_EQ(back[i].binary, binary);
      EXPECT_EQ(back[i].dataset, static_cast<int>(i + 1));
    }
    // Through the tests reader: one record, the same channels bit for bit, t to rounding.
    const auto tests = read_tests({path});
    ASSERT_EQ(tests.size(), 1u);
    const auto& rec = std::get<identify::Record>(tests[0]);
    EXPECT_EQ(rec.source, path.string() + "#1");
    ASSERT_TRUE(rec.excitation_hz.has_value());
    EXPECT_TRUE(same_bits(*rec.excitation_hz, *r.excitation_hz));
    ASSERT_EQ(rec.t.size(), r.t.size());
    for (Eigen::Index i = 0; i < r.t.size(); ++i)
      EXPECT_NEAR(rec.t(i), r.t(i), 1e-15) << i;
    ASSERT_EQ(rec.channels.size(), r.channels.size());
    for (std::size_t c = 0; c < r.channels.size(); ++c) {
      EXPECT_EQ(rec.channels[c].name(), r.channels[c].name());
      for (Eigen::Index i = 0; i < r.t.size(); ++i)
        EXPECT_TRUE(same_bits(rec.channels[c].samples(i), r.channels[c].samples(i)))
            << rec.channels[c].name() << " " << i;
    }
  }

  // What the writer refuses.
  identify::Record bad = r;
  bad.t(5) += 0.3 * r.dt();
  EXPECT_NE(error_of([&] { uff58_from_record(bad); }).find("uniform"), std::string::npos);
  bad = r;
  bad.channels[1].samples(2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of([&] { uff58_from_record(bad); }).find("x@7:uy"), std::string::npos);
  bad = r;
  bad.channels[0].samples.conservativeResize(10);
  EXPECT_NE(error_of([&] { uff58_from_record(bad); }).find("f@7:uy"), std::string::npos);
}

TEST_F(Uff58Test, EveryOrdinateTypeAndSpacingRoundTrips) {
  // Complex double uneven, real single even, complex single uneven, real double uneven (with a
  // NaN, as FRFs at 0 Hz have), each with its units; ASCII and binary give them back exactly.
  std::vector<Uff58Function> functions(4);
  Uff58Function& a = functions[0];
  a.function_type = uff_function_type::frequency_response;
  a.ordinate_type = 6;
  a.even = false;
  a.abscissa = {uff_data_type::frequency, 0, 0, 0, "Frequency", "Hz"};
  a.ordinate = {uff_data_type::acceleration, 1, 0, 0, "Acceleration", "m/s^2"};
  a.denominator = {uff_data_type::excitation_force, 0, 1, 0, "Force", "N"};
  a.complex_data.resize(3);
  a.complex_data << std::complex<double>(1.0 / 3.0, -2e-300), std::complex<double>(-0.0, 7.0),
      std::complex<double>(1e300, 0.1);
  a.abscissa_values.resize(3);
  a.abscissa_values << 0.5, 1.0 / 7.0, 400.25;
  a.response_entity = "Mic 01";
  a.reference_node = 3;
  a.reference_direction = -3;
  a.z_value = 0.1;
  Uff58Function& b = functions[1];
  b.ordinate_type = 2;
  b.abscissa_min = -0.5;
  b.abscissa_increment = 1.0 / 3.0;
  b.ordinate = {uff_data_type::velocity, 1, 0, 0, "Velocity", "mm/s"};
  b.data.resize(7);
  b.data << 1.0, static_cast<float>(0.1), -static_cast<float>(1.0 / 3.0),
      std::numeric_limits<float>::max(), -std::numeric_limits<float>::denorm_min(), 0.0, 2.5;
  b.units = UffUnits{5, "mm (milli newton)", 2, 1000.0, 1000.0, 1.0, 273.15};
  Uff58Function& c = functions[2];
  c.ordinate_type = 5;
  c.even = false;
  c.complex_data.resize(2);
  c.complex_data << std::complex<double>(static_cast<float>(0.3), -1.5),
      std::complex<double>(2.0, static_cast<float>(1e-20));
  c.abscissa_values.resize(2);
  c.abscissa_values << static_cast<float>(0.1), 17.0;
  c.units = b.units;
  Uff58Function& d = functions[3];
  d.ordinate_type = 4;
  d.even = false;
  d.data.resize(3);
  d.data << std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity(), 4.0;
  d.abscissa_values.resize(3);
  d.abscissa_values << 0.0, 0.1, 0.2;
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "58b" : "58");
    const auto path = dir / "all.uff";
    write_uff58(path, functions, binary);
    const auto back = read_uff58(path);
    ASSERT_EQ(back.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
      SCOPED_TRACE(i);
      // The file returns the units in force: b's dataset 164 is written before b and c, and an
      // SI one before d, which had none.
      Uff58Function expected = functions[i];
      if (i == 3) expected.units = UffUnits{};
      expect_same_function(back[i], expected);
    }
    EXPECT_EQ(back[1].dataset, 3); // a, then the 164, then b
    EXPECT_EQ(back[2].dataset, 4);
    EXPECT_EQ(back[3].dataset, 6);
  }
  // A function the writer refuses names itself and the field.
  std::vector<Uff58Function> bad = functions;
  bad[1].id_lines[2] = std::string(81, 'a');
  EXPECT_NE(error_of([&] { uff58_text(bad); }).find("function 2: ID line 3"), std::string::npos);
  bad = functions;
  bad[0].response_entity = "a long entity";
  EXPECT_NE(error_of([&] { uff58_text(bad); }).find("response entity name"), std::string::npos);
  bad = functions;
  bad[1].data(0) = 1e39;
  EXPECT_NE(error_of([&] { uff58_text(bad); }).find("single precision"), std::string::npos);
  bad = functions;
  bad[3].abscissa_values.resize(2);
  EXPECT_NE(error_of([&] { uff58_text(bad); }).find("function 4"), std::string::npos);
  bad = functions;
  bad[1].ordinate_type = 6;
  EXPECT_NE(error_of([&] { uff58_text(bad); }).find("ordinate data type 6"), std::string::npos);
  bad = functions;
  bad[2].response_direction = 7;
  EXPECT_NE(error_of([&] { uff58_text(bad); }).find("direction 7"), std::string::npos);
  bad = functions;
  bad[1].abscissa_increment = 0.0;
  EXPECT_NE(error_of([&] { write_uff58(dir / "x.uff", bad); }).find("x.uff: function 2"),
            std::string::npos);
}

// Other datasets a test system writes around its functions.
const std::string header_151 = "    -1\n"
                               "   151\n"
                               "cantilever\n"
                               "NONE\n"
                               "Test system 4.2\n"
                               "12-Mar-24 10:15:00\n"
                               "    -1\n";
const std::string units_mm = "    -1\n"
                             "   164\n"
                             "         5mm (milli newton)            2\n"
                             "  1.00000000000000000D+03  1.00000000000000000D+03  "
                             "1.00000000000000000D+00\n"
                             "  2.73150000000000000D+02\n"
                             "    -1\n";
const std::string nodes_2411 = "    -1\n"
                               "  2411\n"
                               "         7         1         1        11\n"
                               "   2.0000000000000000E+00   0.0000000000000000E+00   "
                               "0.0000000000000000E+00\n"
                               "    -1\n";

// A dataset 58 time response in the standard's double-precision layout (4E20.12).
std::string time_response(int node, int direction, int data_type, int exponents_length,
                          int exponents_force, const std::string& units,
                          double increment = 0.0125) {
  std::string out = "    -1\n    58\nNONE\nNONE\nNONE\nNONE\nNONE\n";
  out += fmt::format("{:5}{:10}{:5}{:10} {:<10}{:10}{:4} {:<10}{:10}{:4}\n", 1, 0, 0, 0, "NONE",
                     node, direction, "NONE", 0, 0);
  out += fmt::format("{:10}{:10}{:10}{:13.5E}{:13.5E}{:13.5E}\n", 4, 8, 1, 0.0, increment, 0.0);
  out += fmt::format("{:10}{:5}{:5}{:5} {:<20} {:<20}\n", 17, 0, 0, 0, "Time", "s");
  out += fmt::format("{:10}{:5}{:5}{:5} {:<20} {:<20}\n", data_type, exponents_length,
                     exponents_force, 0, "Response", units);
  out += fmt::format("{:10}{:5}{:5}{:5} {:<20} {:<20}\n", 0, 0, 0, 0, "NONE", "NONE");
  out += fmt::format("{:10}{:5}{:5}{:5} {:<20} {:<20}\n", 0, 0, 0, 0, "NONE", "NONE");
  for (int i = 0; i < 8; ++i)
    out += fmt::format("{:20.12E}{}", hand_values[i], i % 4 == 3 ? "\n" : "");
  return out + "    -1\n";
}

// Fuzzing regressions (docs/fuzzing.md): records whose values were read finite but came out of
// uff58_tests broken. An increment lost against a large abscissa minimum gave sample times that
// are not uniform; a dataset 164 length factor of 1e-300 turned finite values into
// infinite ones in SI.
TEST_F(Uff58Test, SampleTimesAndSiValuesMustStayFiniteAndUniform) {
  expect_test_error(
      test::replaced(hand_written, "  0.00000E+00  1.25000E-02", "  1.00000E+10  1.25000E-02"),
      {"record 7 fields 4–5 (abscissa minimum, increment) are 10000000000 and 0.0125 "
       "s: the 8 sample times are not finite, increasing and uniform"});
  const std::string tiny_metre = "    -1\n"
                                 "   164\n"
                                 "         1tiny                          2\n"
                                 "  1.0E-300  1.0E+00  1.0E+00\n"
                                 "  0.0E+00\n"
                                 "    -1\n";
  std::string text =
      test::replaced(hand_written, "Displacement         mm  ", "Displacement         NONE");
  text = test::replaced(text, "  2.50000E+00 -3.25000E+00", "  2.50000E+10 -3.25000E+00");
  const auto path = write(tiny_metre + text, "tiny.uff");
  const std::string e = error_of([&] { uff58_tests(read_uff58(path), path); });
  EXPECT_NE(
      e.find("tiny.uff: dataset 2 (line 7), ID line 1 \"Tip displacement, sine test at 3 "
             "Hz\": record 12 (data values) value 2 is 24999999488, which is inf in SI units"),
      std::string::npos)
      << e;
}

TEST_F(Uff58Test, SeveralDatasetsWithOthersBetweenAndUnits) {
  Uff58Function velocity; // a 58b among the ASCII ones
  velocity.response_node = 7;
  velocity.response_direction = 2;
  velocity.abscissa_increment = 0.0125;
  velocity.ordinate = {uff_data_type::velocity, 1, 0, 0, "Velocity", "m/s"};
  velocity.data = Eigen::Map<const Eigen::VectorXd>(hand_values, 8);
  const std::string text = header_151 + units_mm + time_response(7, 2, 8, 1, 0, "NONE") +
                           nodes_2411 + time_response(7, 2, 13, 0, 1, "N") +
                           time_response(4, -2, 12, 1, 0, "g") + uff58_text({velocity}, true) +
                           time_response(9, 1, 8, 0, 0, "m", 0.025);
  const auto path = write(text, "mixed.unv");
  const auto functions = read_uff58(path);
  ASSERT_EQ(functions.size(), 5u);
  const int datasets[] = {3, 5, 6, 7, 8};
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(functions[i].dataset, datasets[i]) << i;
    ASSERT_TRUE(functions[i].units.has_value()) << i;
    EXPECT_EQ(functions[i].units->code, 5);
    EXPECT_EQ(functions[i].units->description, "mm (milli newton)");
    EXPECT_EQ(functions[i].units->temperature_mode, 2);
    EXPECT_EQ(functions[i].units->length, 1000.0);
    EXPECT_EQ(functions[i].units->force, 1000.0);
    EXPECT_EQ(functions[i].units->temperature_offset, 273.15);
  }
  EXPECT_TRUE(functions[3].binary);
  EXPECT_EQ(functions[0].line, 14); // after 7 lines of 151 and 6 of 164

  // Two records: the four functions at 12.5 ms, and node 9 at 25 ms. Units: no label → the
  // dataset 164's millimetres; a label wins over the 164 (N, g, m/s, m).
  const auto tests = read_tests({path});
  ASSERT_EQ(tests.size(), 2u);
  const auto& a = std::get<identify::Record>(tests[0]);
  const auto& b = std::get<identify::Record>(tests[1]);
  EXPECT_EQ(a.source, path.string() + "#3");
  EXPECT_EQ(b.source, path.string() + "#8");
  EXPECT_FALSE(a.excitation_hz.has_value());
  ASSERT_EQ(a.channels.size(), 4u);
  EXPECT_EQ(a.channels[0].name(), "x@7:uy");
  EXPECT_EQ(a.channels[1].name(), "f@7:uy");
  EXPECT_EQ(a.channels[2].name(), "a@4:uy");
  EXPECT_EQ(a.channels[3].name(), "v@7:uy");
  const double factor[] = {1e-3, 1.0, -9.80665, 1.0};
  for (std::size_t c = 0; c < 4; ++c)
    for (int i = 0; i < 8; ++i)
      EXPECT_DOUBLE_EQ(a.channels[c].samples(i), factor[c] * hand_values[i]) << c << " " << i;
  ASSERT_EQ(b.channels.size(), 1u);
  EXPECT_EQ(b.channels[0].name(), "x@9:ux");
  EXPECT_EQ(b.t(7), 7 * 0.025);
}

TEST_F(Uff58Test, DirectionSignAndUnits) {
  // −Y: the samples change sign; −RZ in degrees: sign and π/180; mm/s, kN, in/s^2, µm, ms.
  struct Case {
    int direction, data_type, length_exponent, force_exponent;
    std::string units, channel;
    double factor;
  };
  const Case cases[] = {
      {-2, 8, 1, 0, "m", "x@7:uy", -1.0},
      {2, 8, 0, 0, "NONE", "x@7:uy", 1.0},
      {-6, 8, 0, 0, "deg", "x@7:rz", -std::numbers::pi / 180.0},
      {3, 11, 1, 0, "mm/s", "v@7:uz", 1e-3},
      {-1, 13, 0, 1, "kN", "f@7:ux", -1e3},
      {6, 13, 1, 1, "N m", "f@7:rz", 1.0},
      {2, 12, 1, 0, "in/s**2", "a@7:uy", 0.0254},
      {2, 12, 0, 0, "m/s²", "a@7:uy", 1.0},
      {2, 8, 1, 0, "\xC2\xB5m", "x@7:uy", 1e-6},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.units);
    const auto path = write(
        time_response(7, c.direction, c.data_type, c.length_exponent, c.force_exponent, c.units),
        "sign.uff");
    const auto tests = uff58_tests(read_uff58(path), path);
    const auto& r = std::get<identify::Record>(tests[0]);
    EXPECT_EQ(r.channels[0].name(), c.channel);
    for (int i = 0; i < 8; ++i)
      EXPECT_DOUBLE_EQ(r.channels[0].samples(i), c.factor * hand_values[i]) << i;
  }
  // Time in ms.
  std::string ms = time_response(7, 2, 8, 1, 0, "m");
  ms = test::replaced(ms, "Time                 s  ", "Time                 ms ");
  const auto path = write(ms, "ms.uff");
  const auto tests = uff58_tests(read_uff58(path), path); // kept: r refers into it
  const auto& r = std::get<identify::Record>(tests[0]);
  EXPECT_DOUBLE_EQ(r.t(4), 4 * 0.0125e-3);
}

TEST_F(Uff58Test, SineTestsIdentifyAsFromCsv) {
  // Records of force, displacement and velocity at the tip, simulated with a cubic joint, go
  // through CSV and through UFF (ASCII and binary): the identification is the same to 1e-12.
  joints::Joint joint{"tip",
                      7,
                      0,
                      fem::Dof::uy,
                      {joints::Term::k, joints::Term::c, joints::Term::k3},
                      {4800.0, 20.0, 1.6e8},
                      {},
                      {}};
  joint.fixed.assign(3, false);
  const std::vector<joints::Joint> js{joint};
  const frf::Substructure substructure(test::paper_cantilever());
  identify::SimulationOptions o;
  o.method = identify::SimulationMethod::harmonic_balance;
  o.steps_per_period = 256;
  o.periods = 2;
  const auto simulated = identify::simulate_sine_tests(
      substructure, js, {7, fem::Dof::uy}, {{2.0, 40.0}, {3.0, 60.0}, {4.0, 80.0}, {5.0, 80.0}}, o);
  std::vector<std::filesystem::path> csv, uff;
  for (std::size_t i = 0; i < simulated.size(); ++i) {
    const identify::Record& r = simulated[i].record;
    ASSERT_NE(r.find(Quantity::force, {7, fem::Dof::uy}), nullptr);
    ASSERT_NE(r.find(Quantity::velocity, {7, fem::Dof::uy}), nullptr);
    csv.push_back(dir / fmt::format("test{}.csv", i));
    write_record(csv.back(), r);
    uff.push_back(dir / fmt::format("test{}.{}", i, i % 2 ? "UFF" : "unv"));
    write_uff58(uff.back(), uff58_from_record(r), i % 2 == 1);
  }
  const auto from_csv = read_tests(csv);
  const auto from_uff = read_tests(uff);
  ASSERT_EQ(from_uff.size(), from_csv.size());
  EXPECT_EQ(identify::source_of(from_uff[1]), uff[1].string() + "#1");
  identify::FitOptions options;
  options.harmonics = {1, 3};
  const auto fit_csv = identify::fit(
      substructure, js, identify::measure(from_csv, identify::measure_options(options)), options);
  const auto fit_uff = identify::fit(
      substructure, js, identify::measure(from_uff, identify::measure_options(options)), options);
  ASSERT_EQ(fit_uff.joints.size(), 1u);
  for (std::size_t t = 0; t < 3; ++t) {
    const double a = fit_csv.joints[0].terms[t].value, b = fit_uff.joints[0].terms[t].value;
    EXPECT_LE(std::abs(a - b), 1e-12 * std::abs(a)) << t << ": " << a << " vs " << b;
    EXPECT_NEAR(b, joint.values[t], 1e-3 * joint.values[t]) << t; // and it is the truth
  }
  // A UFF file given twice is refused like a CSV.
  const std::string twice = error_of([&] { read_tests({uff[0], csv[1], uff[0]}); });
  EXPECT_NE(twice.find("given twice"), std::string::npos) << twice;
}

// A force channel on a node the model lacks is the record's fault: the message starts with the
// universal file's record and the channel, and says what the model has (issue 31; the CSV
// record and the stepped-sine table are in record_csv_test.cpp).
TEST_F(Uff58Test, ForceChannelOnANodeTheModelLacksIsTheRecordsFault) {
  identify::Record r;
  r.excitation_hz = 3.0;
  const int n = 64; // two periods of 32 samples
  r.t.resize(n);
  Eigen::VectorXd force(n), x(n);
  for (int i = 0; i < n; ++i) {
    r.t(i) = i / (32.0 * 3.0);
    force(i) = 10.0 * std::sin(2.0 * std::numbers::pi * 3.0 * r.t(i));
    x(i) = 1e-3 * std::cos(2.0 * std::numbers::pi * 3.0 * r.t(i));
  }
  r.channels.push_back({Quantity::force, {99, fem::Dof::uy}, force});
  r.channels.push_back({Quantity::displacement, {7, fem::Dof::uy}, x});
  const auto path = dir / "foreign_force.uff";
  write_uff58(path, uff58_from_record(r));
  const auto tests = read_tests({path});
  ASSERT_EQ(tests.size(), 1u);
  joints::Joint tip{"tip", 7, 0, fem::Dof::uy, {joints::Term::k}, {4800.0}, {false}, {}};
  const fem::DofMap dofs(test::paper_cantilever());
  std::vector<std::string> warnings;
  try {
    identify::spectrum(identify::measure(tests[0], {.harmonics = 1}), dofs, {tip}, warnings);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + "#1: force channel f@99:uy: the model has no node 99 (its nodes: "
                              "1–7); a force must act on a free DOF of the model");
  }
}

TEST_F(Uff58Test, MalformedFilesNameFileLineRecordAndField) {
  const std::string& g = hand_written;
  expect_error("junk\n" + g, "bad.uff:1:", {"expected '    -1'"});
  expect_error(test::replaced(g, "         8         1", "         x         1"),
               "bad.uff:9:", {"dataset 1 (58)", "record 7", "field 2 (number of points)", "\"x\""});
  expect_error(test::replaced(g, "         2         8", "         3         8"),
               "bad.uff:9:", {"record 7", "field 1 (ordinate data type)", "got 3"});
  expect_error(test::replaced(g, "         8         1  0.0", "         8         2  0.0"),
               "bad.uff:9:", {"record 7", "field 3 (abscissa spacing)", "got 2"});
  expect_error(test::replaced(g, "1.25000E-02", "0.00000E+00"),
               "bad.uff:9:", {"record 7", "field 5 (abscissa increment)", "> 0"});
  expect_error(test::replaced(g, "         7   2 NONE", "         7   9 NONE"),
               "bad.uff:8:", {"record 6", "field 7 (response direction)", "got 9"});
  expect_error(test::replaced(g, "         7   2 NONE", "       abc   2 NONE"),
               "bad.uff:8:", {"record 6", "field 6 (response node)", "columns 42–51", "\"abc\""});
  expect_error(test::replaced(g, "         8    1    0", "         x    1    0"),
               "bad.uff:11:", {"record 9", "field 1 (specific data type)", "\"x\""});
  expect_error(test::replaced(g, "  8.12500E+00", ""),
               "bad.uff:16:", {"record 12", "7 values", "expected 8"});
  expect_error(test::replaced(g, "-3.25000E+00", "-3.25000X+00"),
               "bad.uff:14:", {"record 12", "value 3", "expected a number", "\"-3.25000X+00\""});
  expect_error(test::replaced(g, "  8.12500E+00\n", "  8.12500E+00  9.0\n"),
               "bad.uff:15:", {"record 12", "more than the 8 values"});
  const std::string unclosed = g.substr(0, g.size() - 7);
  expect_error(unclosed, "bad.uff:15:", {"no closing '    -1'", "opened at line 1"});
  expect_error(unclosed + g,
               "bad.uff:17:", {"expected '    -1' opening a dataset", "closing '    -1' missing"});
  expect_error("    -1\n    58\nid\nid\n    -1\n",
               "bad.uff:5:", {"record 3 (ID line 3)", "ends early"});
  expect_error("    -1\n    58\nid\nid\n", "bad.uff:4:", {"the file ends before record 3"});
  expect_error("    -1\n  abc\n    -1\n", "bad.uff:2:", {"dataset 1", "dataset number"});
  expect_error(test::replaced(units_mm, "  1.00000000000000000D+03  1.000",
                              "  1.00000000000000000Q+03  1.000") +
                   g,
               "bad.uff:4:", {"dataset 1 (164)", "record 2 field 1 (length factor)"});
  expect_error(header_151.substr(0, header_151.size() - 7),
               "bad.uff:6:", {"dataset 1 (151)", "closing '    -1'"});

  // 58b: unsupported flags, a byte count that does not fit, truncated data, no closing -1.
  Uff58Function f;
  f.response_node = 7;
  f.response_direction = 2;
  f.abscissa_increment = 0.0125;
  f.ordinate = {uff_data_type::displacement, 1, 0, 0, "Displacement", "m"};
  f.data = Eigen::Map<const Eigen::VectorXd>(hand_values, 8);
  const std::string b = uff58_text({f}, true);
  const std::size_t data_start = b.size() - 64 - 7;
  expect_error(test::replaced(b, "    58b     1     2", "    58b     2     2"), "bad.uff:2:",
               {"dataset 1 (58b)", "field 3 (byte ordering)", "big-endian", "only 1"});
  expect_error(test::replaced(b, "    58b     1     2", "    58b     1     3"),
               "bad.uff:2:", {"field 4 (floating-point format)", "IBM", "only 2 (IEEE 754)"});
  expect_error(test::replaced(b, "          11          64", "          11          60"),
               "bad.uff:2:", {"field 6 (number of bytes)", "60", "expected 64 bytes"});
  expect_error(test::replaced(b, "          11          64", "          12          64"),
               "bad.uff:2:", {"field 5 (number of ASCII lines)", "expected 11"});
  expect_error(b.substr(0, data_start + 10), fmt::format("bad.uff: byte {}:", data_start),
               {"dataset 1 (58b)", "record 12", "expected 64 bytes", "ends after 10"});
  expect_error(b.substr(0, data_start + 64) + "    58\n",
               fmt::format("bad.uff: byte {}:", data_start + 64),
               {"closing '    -1'", "64 bytes of binary data"});
  expect_error(b.substr(0, data_start + 64), fmt::format("bad.uff: byte {}:", data_start + 64),
               {"the file ends after the 64 bytes"});
  // A line break after the binary data before the closing -1 is tolerated.
  EXPECT_EQ(read_uff58(write(b.substr(0, data_start + 64) + "\n    -1\n")).size(), 1u);

  // What read_uff58 accepts but is not a sine test.
  expect_test_error(test::replaced(g, "    1         2    3", "    4         2    3"),
                    {"function type) is 4 (frequency response function), not a test record",
                     "[frf] section", "jointid modal-fit", "function type 1, or 0 with a time"});
  expect_test_error(
      test::replaced(test::replaced(g, "         8    1    0", "         0    1    0"),
                     "Displacement         mm ", "Displacement         NONE"),
      {"cannot tell the quantity", "record 9 field 1", "0 (unknown)", "13 (excitation force)"});
  expect_test_error(test::replaced(g, "Displacement         mm ", "Displacement         V  "),
                    {"record 9 field 6 (axis units label) 'V'", "displacement", "mm"});
  expect_test_error(test::replaced(g, "         8    1    0", "         8    2    0"),
                    {"record 9 fields 2–4", "2 0 0", "expected 1 0 0"});
  expect_test_error(test::replaced(g, "         7   2 NONE", "         7   0 NONE"),
                    {"record 6 field 7 (response direction)", "0 (scalar)"});
  expect_test_error(test::replaced(g, "excitation_hz = 3", "excitation_hz = -3"),
                    {"record 2 (ID line 2)", "excitation_hz", "\"-3\""});
  expect_test_error(test::replaced(g, "Time                 s  ", "Time                 min"),
                    {"record 8 field 6", "'min'"});
  {
    const auto path = write(g + g, "twice.uff");
    const std::string e = error_of([&] { uff58_tests(read_uff58(path), path); });
    EXPECT_NE(e.find("channel x@7:uy is given twice"), std::string::npos) << e;
    EXPECT_NE(e.find("datasets 1 at line 1 and 2 at line 17"), std::string::npos) << e;
  }
  {
    Uff58Function uneven = read_uff58(write(g))[0];
    uneven.even = false;
    uneven.abscissa_values = uneven.data;
    uneven.dataset = 4;
    uneven.line = 30;
    const std::string e = error_of([&] { uff58_tests({uneven}, "x.uff"); });
    EXPECT_NE(e.find("x.uff: dataset 4 (line 30), ID line 1 \"Tip displacement, sine test at 3 "
                     "Hz\": record 7 field 3"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("uneven"), std::string::npos) << e;
    Uff58Function complex = read_uff58(write(g))[0];
    complex.ordinate_type = 6;
    complex.complex_data = complex.data.cast<std::complex<double>>();
    complex.data.resize(0);
    EXPECT_NE(error_of([&] { uff58_tests({complex}, "x.uff"); }).find("must be real"),
              std::string::npos);
    EXPECT_NE(error_of([&] { uff58_tests({}, "x.uff"); }).find("x.uff: no dataset 58"),
              std::string::npos);
  }
  // read_tests: a universal file without datasets 58.
  const auto empty = write(header_151, "header.uff");
  EXPECT_NE(error_of([&] { read_tests({empty}); }).find("no dataset 58"), std::string::npos);
}

// Function type 0 ("general or unknown") and data types 0 and 1 ("unknown", "general"), as data
// acquisition systems write time data: a time abscissa makes a time response, the units label
// names the quantity. Four channels of one record, 4 samples at 5 ms, read as the command line
// reads them; the SI values by hand.
TEST_F(Uff58Test, TypeZeroAndGeneralDataReadTheirQuantityFromTheUnitsLabel) {
  const auto function = [](const std::string& id, int type, const std::string& dof,
                           const std::string& abscissa, const std::string& ordinate,
                           const std::string& values) {
    return "    -1\n    58\n" + id + "\nNONE\nNONE\nNONE\nNONE\n" + fmt::format("{:5}", type) +
           "         1    0         0 NONE      " + dof + " NONE               0   0\n" +
           "         4         4         1  0.00000E+00  5.00000E-03  0.00000E+00\n" + abscissa +
           "\n" + ordinate + "\n" + "         0    0    0    0 NONE                 NONE\n" +
           "         0    0    0    0 NONE                 NONE\n" + values + "\n    -1\n";
  };
  const std::string text =
      // Type 0, abscissa time (17), ordinate unknown (0) in m/s² at node 4, +Z.
      function("Tip acceleration", 0, "         4   3",
               "        17    0    0    0 Time                 s",
               "         0    0    0    0 Response             m/s\xC2\xB2",
               "  2.500000000000E+00 -1.000000000000E+00  5.000000000000E-01  "
               "0.000000000000E+00") +
      // Type 1, ordinate general (1) in mm/s^2 at node 6, +Y.
      function("Mid acceleration", 1, "         6   2",
               "        17    0    0    0 Time                 s",
               "         1    0    0    0 Response             mm/s^2",
               "  1.250000000000E+03 -2.500000000000E+02  4.000000000000E+00  "
               "0.000000000000E+00") +
      // Type 0, abscissa general (1) in s, ordinate general in kN at node 4, +Z: the force.
      function("Drive force", 0, "         4   3",
               "         1    0    0    0 Abscissa             s",
               "         1    0    0    0 Force                kN",
               "  1.000000000000E-02 -2.000000000000E-02  0.000000000000E+00  "
               "5.000000000000E-03") +
      // Type 0, abscissa unknown (0) in ms, ordinate acceleration (12) in g at node 8, -Y.
      function("Root acceleration", 0, "         8  -2",
               "         0    0    0    0 NONE                 ms",
               "        12    1    0    0 Acceleration         g",
               "  1.000000000000E+00 -5.000000000000E-01  0.000000000000E+00  "
               "2.000000000000E+00");
  const auto path = write(text, "daq.uff");
  const auto tests = read_tests({path});
  // The fourth's abscissa is 5 ms in ms: 0.005 ms steps, another record.
  ASSERT_EQ(tests.size(), 2u);
  const auto& r = std::get<identify::Record>(tests[0]);
  ASSERT_EQ(r.channels.size(), 3u);
  EXPECT_EQ(r.channels[0].name(), "a@4:uz");
  EXPECT_EQ(r.channels[1].name(), "a@6:uy");
  EXPECT_EQ(r.channels[2].name(), "f@4:uz");
  const double a4[] = {2.5, -1.0, 0.5, 0.0};     // m/s²
  const double a6[] = {1.25, -0.25, 0.004, 0.0}; // m/s², from mm/s²
  const double f4[] = {10.0, -20.0, 0.0, 5.0};   // N, from kN
  for (Eigen::Index i = 0; i < 4; ++i) {
    EXPECT_NEAR(r.channels[0].samples(i), a4[i], 1e-15) << i;
    EXPECT_NEAR(r.channels[1].samples(i), a6[i], 1e-15) << i;
    EXPECT_NEAR(r.channels[2].samples(i), f4[i], 1e-14) << i;
  }
  EXPECT_DOUBLE_EQ(r.t(3), 0.015);
  const auto& root = std::get<identify::Record>(tests[1]);
  ASSERT_EQ(root.channels.size(), 1u);
  EXPECT_EQ(root.channels[0].name(), "a@8:uy");
  const double a8[] = {-9.80665, 4.903325, 0.0, -19.6133}; // m/s², from g along -Y
  for (Eigen::Index i = 0; i < 4; ++i)
    EXPECT_NEAR(root.channels[0].samples(i), a8[i], 1e-14) << i;
  EXPECT_DOUBLE_EQ(root.t(3), 15e-6); // 3 × 0.005 ms
}

// What is not a time response, or does not say its quantity, is refused naming the dataset, its
// line and ID line 1, the record and field to fix, and what jointid can use instead.
TEST_F(Uff58Test, FunctionsThatAreNotTimeResponsesSayWhatTheyAreAndWhatToFix) {
  const std::string& g = hand_written;
  const std::string id = "ID line 1 \"Tip displacement, sine test at 3 Hz\"";
  const std::string type0 = test::replaced(g, "    1         2    3", "    0         2    3");
  // Type 0 with a time abscissa (data type 17, or a unit of time) is read; the same without a
  // time abscissa is refused.
  EXPECT_NO_THROW(uff58_tests(read_uff58(write(type0)), "t.uff"));
  EXPECT_NO_THROW(uff58_tests(read_uff58(write(test::replaced(type0, "Time                 s  ",
                                                              "Time                 NONE"))),
                              "t.uff"));
  EXPECT_NO_THROW(uff58_tests(
      read_uff58(write(test::replaced(type0, "        17    0    0    0 Time                 s  ",
                                      "         1    0    0    0 Time                 ms "))),
      "t.uff"));
  expect_test_error(test::replaced(type0, "        17    0    0    0 Time                 s  ",
                                   "         0    0    0    0 NONE                 NONE"),
                    {id, "record 6 field 1 (function type) is 0 (general or unknown)",
                     "record 8 (abscissa) does not say time",
                     "set record 8 field 1 to 17 (time) or field 6 to s"});
  expect_test_error(test::replaced(type0, "        17    0    0    0 Time                 s  ",
                                   "        18    0    0    0 Frequency            Hz "),
                    {id, "is 18 (frequency)", "frequency response functions (function type 4)"});
  // The quantity: neither the data type nor the units label says it.
  const std::string unknown = test::replaced(type0, "         8    1    0", "         0    0    0");
  expect_test_error(
      test::replaced(unknown, "Displacement         mm ", "Displacement         NONE"),
      {id, "cannot tell the quantity",
       "record 9 field 1 (ordinate specific data "
       "type) is 0 (unknown)",
       "field 6 (axis units label) gives no unit",
       "set field 1 to 13 (excitation force), 8 (displacement)", "m/s^2"});
  expect_test_error(
      test::replaced(unknown, "Displacement         mm ", "Displacement         V  "),
      {id, "cannot tell the quantity", "'V' is not a unit jointid reads", "m/s2, mm/s2"});
  expect_test_error(test::replaced(unknown, "Displacement         mm ", "Displacement         rad"),
                    {id, "record 9 field 6 (axis units label) 'rad' is a unit of a rotation",
                     "record 6 field 7 (response direction) is 2 (+Y), a translation"});
  // Unit exponents are checked against the quantity the label names.
  expect_test_error(test::replaced(unknown, "         0    0    0    0 Displacement",
                                   "         0    0    1    0 Displacement"),
                    {"record 9 fields 2–4", "0 1 0", "expected 1 0 0"});
  // Other function types: spectra, FRFs, the rest.
  expect_test_error(test::replaced(g, "    1         2    3", "    9         2    3"),
                    {id, "is 9 (power spectral density): a spectrum has lost the time history",
                     "export the time responses", "jointid reads time responses"});
  expect_test_error(test::replaced(g, "    1         2    3", "    6         2    3"),
                    {"is 6 (coherence), which jointid does not use", "jointid reads time"});
  expect_test_error(test::replaced(g, "    1         2    3", "    4         2    3"),
                    {"not a test record", "[frf] section", "jointid modal-fit"});
  // No refusal of a time record says "[frf]" as if it were an FRF, nor speaks of CSV columns.
  for (const std::string& text :
       {test::replaced(unknown, "Displacement         mm ", "Displacement         NONE"),
        test::replaced(type0, "excitation_hz = 3", "excitation_hz = -3")}) {
    const auto path = write(text, "bad.uff");
    std::string message;
    try {
      uff58_tests(read_uff58(path), path);
    } catch (const Error& e) {
      message = e.what();
    }
    ASSERT_FALSE(message.empty());
    EXPECT_EQ(message.find("[frf]"), std::string::npos) << message;
    EXPECT_EQ(message.find("column"), std::string::npos) << message;
  }
}

TEST_F(Uff58Test, TimeRecordsMustBeFiniteAndHoldFourSamples) {
  // read_uff58 reads NaN and infinities (FRFs hold them); a time record must not.
  expect_test_error(test::replaced(hand_written, "-3.25000E+00", "         NAN"),
                    {"record 12 (data values) value 3 is nan: a time record must be finite"});
  expect_test_error(test::replaced(hand_written, "  7.75000E+00", "         INF"),
                    {"record 12 (data values) value 7 is inf: a time record must be finite"});
  std::string three = test::replaced(hand_written, "         2         8", "         2         3");
  three = test::replaced(
      three, "  4.00000E-01  0.00000E+00 -1.50000E+00\n  7.75000E+00  8.12500E+00\n", "\n");
  expect_test_error(three,
                    {"record 7 field 2 (number of points) is 3: a time record needs at least "
                     "4 samples"});
}

} // namespace
} // namespace jointid::io
