#include "io/record_csv.hpp"

#include "identify/fit.hpp"
#include "support/numbers.hpp"

#include "io/files.hpp"
#include "io/test_files.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <tuple>

namespace jointid::io {
namespace {

using jointid::test::same_bits;

using identify::Quantity;

identify::Record sample_record() {
  identify::Record r;
  const int n = 64;
  const double f = 3.4, h = 1.0 / (f * 16);
  r.t.resize(n);
  for (int i = 0; i < n; ++i)
    r.t(i) = i * h;
  r.excitation_hz = f;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd force(n), x(n), v(n);
  for (int i = 0; i < n; ++i) {
    force(i) = 80.0 * std::sin(2.0 * std::numbers::pi * f * r.t(i));
    x(i) = 1e-3 * uniform(random) / 3.0;
    v(i) = std::exp(40.0 * uniform(random)); // spans many decades
  }
  // Values whose decimal forms need all 17 digits, or none, or are at the edges of double.
  x(0) = 0.1 + 0.2;
  x(1) = -0.0;
  x(2) = std::numeric_limits<double>::denorm_min();
  x(3) = std::numeric_limits<double>::max();
  x(4) = -std::numeric_limits<double>::min();
  x(5) = 1.0 / 3.0;
  r.channels.push_back({Quantity::force, {7, fem::Dof::uy}, force});
  r.channels.push_back({Quantity::displacement, {7, fem::Dof::uy}, x});
  r.channels.push_back({Quantity::velocity, {12, fem::Dof::rz}, v});
  return r;
}

class RecordCsvTest : public ::testing::Test {
protected:
  std::filesystem::path write(const std::string& text, const std::string& name = "f3.4.csv") {
    const auto path = dir / name;
    test::write_text(path, text);
    return path;
  }
  // Expects read_record to fail naming the file, `line` and every one of `parts`.
  void expect_error(const std::string& text, int line, std::initializer_list<std::string> parts) {
    const auto path = write(text);
    try {
      read_record(path);
      FAIL() << "expected io::Error";
    } catch (const Error& e) {
      const std::string message = e.what();
      const std::string where = line > 0 ? "f3.4.csv:" + std::to_string(line) + ":" : "f3.4.csv:";
      EXPECT_NE(message.find(where), std::string::npos) << message;
      for (const auto& p : parts)
        EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' not in: " << message;
    }
  }
  test::TempDir dir;
};

const std::string good_csv = "# bench test, 2024\n"
                             "# excitation_hz = 2.0\n"
                             "t,f@7:uy,x@7:uy\n"
                             "0.0,0.0,1e-3\n"
                             "0.125,1.0,2e-3\n"
                             "0.25,0.0,3e-3\n"
                             "0.375,-1.0,4e-3\n"
                             "0.5,0.0,5e-3\n";

TEST_F(RecordCsvTest, RoundTripIsBitExact) {
  const identify::Record r = sample_record();
  const auto path = dir / "round.csv";
  write_record(path, r, {"simulated", "second line\nthird line"});
  const identify::Record back = read_record(path);
  EXPECT_EQ(back.source, path.string());
  ASSERT_TRUE(back.excitation_hz.has_value());
  EXPECT_TRUE(same_bits(*back.excitation_hz, *r.excitation_hz));
  ASSERT_EQ(back.t.size(), r.t.size());
  for (Eigen::Index i = 0; i < r.t.size(); ++i)
    EXPECT_TRUE(same_bits(back.t(i), r.t(i))) << i;
  ASSERT_EQ(back.channels.size(), r.channels.size());
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    EXPECT_EQ(back.channels[c].name(), r.channels[c].name());
    EXPECT_EQ(back.channels[c].quantity, r.channels[c].quantity);
    EXPECT_EQ(back.channels[c].at, r.channels[c].at);
    for (Eigen::Index i = 0; i < r.t.size(); ++i)
      EXPECT_TRUE(same_bits(back.channels[c].samples(i), r.channels[c].samples(i)))
          << r.channels[c].name() << " row " << i << ": " << back.channels[c].samples(i) << " vs "
          << r.channels[c].samples(i);
  }
  // The file: comments first, one '#' line per comment line, then the header.
  const std::string text = test::read_text(path);
  EXPECT_EQ(text.rfind("# simulated\n# second line\n# third line\n# excitation_hz = "
                       "3.4\nt,f@7:uy,x@7:uy,v@12:rz\n",
                       0),
            0u)
      << text.substr(0, 200);
}

TEST_F(RecordCsvTest, ReadsCommentsHeaderAndRows) {
  const identify::Record r = read_record(write(good_csv));
  ASSERT_TRUE(r.excitation_hz.has_value());
  EXPECT_EQ(*r.excitation_hz, 2.0);
  ASSERT_EQ(r.channels.size(), 2u);
  EXPECT_EQ(r.channels[0].quantity, Quantity::force);
  EXPECT_EQ(r.channels[1].quantity, Quantity::displacement);
  EXPECT_EQ(r.channels[1].at, (fem::NodeDof{7, fem::Dof::uy}));
  EXPECT_EQ(r.t, (Eigen::VectorXd(5) << 0.0, 0.125, 0.25, 0.375, 0.5).finished());
  EXPECT_EQ(r.channels[1].samples, (Eigen::VectorXd(5) << 1e-3, 2e-3, 3e-3, 4e-3, 5e-3).finished());
  EXPECT_DOUBLE_EQ(r.dt(), 0.125);
}

TEST_F(RecordCsvTest, AcceptsWindowsLineEndsAndSpacesAndNoExcitationComment) {
  std::string text = "# other = 1\r\n t , f@7:uy , x@7:uy\r\n";
  for (int i = 0; i < 4; ++i)
    text += std::to_string(i) + ".0, +1.5 ,-2e-3\r\n";
  const identify::Record r = read_record(write(text));
  EXPECT_FALSE(r.excitation_hz.has_value());
  EXPECT_EQ(r.t.size(), 4);
  EXPECT_EQ(r.channels[0].samples(3), 1.5);
  EXPECT_EQ(r.channels[1].samples(0), -2e-3);
}

TEST_F(RecordCsvTest, MissingHeader) {
  const std::string text = "# no header\n0.0,1.0\n0.1,2.0\n0.2,3.0\n0.3,4.0\n";
  expect_error(text, 2, {"missing header"});
  expect_error("# only comments\n", 0, {"missing header"});
}

TEST_F(RecordCsvTest, FirstColumnMustBeTime) {
  expect_error(test::replaced(good_csv, "t,f@7", "time,f@7"), 3,
               {"first column must be 't'", "\"time\""});
}

TEST_F(RecordCsvTest, UnknownAndDuplicateChannels) {
  expect_error(test::replaced(good_csv, "x@7:uy", "y@7:uy"), 3, {"column 3", "y@7:uy"});
  expect_error(test::replaced(good_csv, "x@7:uy", "x@7:uw"), 3, {"column 3", "uw"});
  expect_error(test::replaced(good_csv, "f@7:uy", "x@7:uy"), 3,
               {"x@7:uy appears twice", "columns 2 and 3"});
}

TEST_F(RecordCsvTest, RaggedRow) {
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3", "0.25,0.0"), 6,
               {"row has 2 fields, expected 3", "t and 2 channels"});
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3", "0.25,0.0,3e-3,4"), 6,
               {"row has 4 fields, expected 3"});
}

TEST_F(RecordCsvTest, NonNumericNaNAndInfinity) {
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3", "0.25,zero,3e-3"), 6,
               {"column 2 (f@7:uy)", "expected a number", "\"zero\""});
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3", "0.25,0.0,nan"), 6,
               {"column 3 (x@7:uy)", "NaN"});
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3", "0.25,-inf,3e-3"), 6,
               {"column 2", "infinite"});
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3", "0.25,,3e-3"), 6,
               {"column 2", "empty field"});
}

TEST_F(RecordCsvTest, TooFewRows) {
  const std::string text = "t,f@7:uy,x@7:uy\n0,0,0\n1,0,0\n2,0,0\n";
  expect_error(text, 1, {"only 3 data rows, expected at least 4"});
}

TEST_F(RecordCsvTest, TimeMustIncreaseUniformly) {
  expect_error(test::replaced(good_csv, "0.375,", "0.25,"), 7, {"does not increase"});
  expect_error(test::replaced(good_csv, "0.375,", "0.376,"), 7, {"time step", "uniform"});
  // A deviation below 1e-6 of the step is accepted (printed time values are rounded).
  EXPECT_NO_THROW(read_record(write(test::replaced(good_csv, "0.375,", "0.37500001,"))));
}

// Fuzzing regression (docs/fuzzing.md): times near the limits of a double made the span
// overflow, the mean step infinite and every deviation NaN, so non-uniform sampling passed.
TEST_F(RecordCsvTest, TimeSpanBeyondTheRangeOfADoubleIsAnError) {
  expect_error("t,x@7:uy\n-1e308,0\n-5e307,0\n0,0\n1e308,0\n", 5,
               {"t runs from -1e+308 to 1e+308 s, a span beyond the range of a double"});
}

TEST_F(RecordCsvTest, CommentAfterHeader) {
  expect_error(test::replaced(good_csv, "0.25,0.0,3e-3\n", "0.25,0.0,3e-3\n# late\n"), 7,
               {"comment"});
}

TEST_F(RecordCsvTest, BadExcitationComment) {
  expect_error(test::replaced(good_csv, "excitation_hz = 2.0", "excitation_hz = fast"), 2,
               {"excitation_hz", "\"fast\""});
  expect_error(test::replaced(good_csv, "excitation_hz = 2.0", "excitation_hz = -2"), 2,
               {"excitation_hz"});
}

TEST_F(RecordCsvTest, ReadRecordsReadsEveryFile) {
  const auto a = write(good_csv, "a.csv");
  const auto b =
      write(test::replaced(good_csv, "excitation_hz = 2.0", "excitation_hz = 4.0"), "b.csv");
  const auto records = read_records({a, b});
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].source, a.string());
  EXPECT_EQ(*records[1].excitation_hz, 4.0);
  try {
    read_records({a, dir / "missing.csv"});
    FAIL() << "a missing file accepted";
  } catch (const Error& e) {
    EXPECT_NE(
        std::string(e.what()).find((dir / "missing.csv").string() + ": cannot open for reading: "),
        std::string::npos)
        << e.what();
  }
}

TEST_F(RecordCsvTest, HeaderWithoutChannels) {
  expect_error("# excitation_hz = 2.0\nt\n0\n0.125\n0.25\n0.375\n", 2,
               {"header: no channels after 't' (expected e.g. t,f@7:uy,x@7:uy)"});
}

TEST_F(RecordCsvTest, ExcitationGivenTwice) {
  const std::string twice = test::replaced(good_csv, "# excitation_hz = 2.0\n",
                                           "# excitation_hz = 2.0\n# excitation_hz = 2.5\n");
  expect_error(twice, 3, {"excitation_hz given twice (2 and 2.5 Hz)"});
  // The same value twice says nothing new: accepted.
  const std::string same = test::replaced(good_csv, "# excitation_hz = 2.0\n",
                                          "# excitation_hz = 2.0\n# excitation_hz = 2\n");
  EXPECT_EQ(*read_record(write(same)).excitation_hz, 2.0);
}

TEST_F(RecordCsvTest, PeriodOfAPeriodicTestIsReadAndWritten) {
  // `# period_s = T` (a periodic broadband test): read into Record::period_s, written back from
  // it, refused when not a period > 0 or given twice with two values.
  const std::string periodic =
      test::replaced(good_csv, "# excitation_hz = 2.0\n", "# period_s = 0.25\n");
  const identify::Record r = read_record(write(periodic));
  ASSERT_TRUE(r.period_s.has_value());
  EXPECT_EQ(*r.period_s, 0.25);
  EXPECT_FALSE(r.excitation_hz.has_value());
  EXPECT_FALSE(read_record(write(good_csv)).period_s.has_value());
  expect_error(test::replaced(good_csv, "# excitation_hz = 2.0\n", "# period_s = -1\n"), 2,
               {"period_s: expected a period > 0 s, got \"-1\""});
  expect_error(
      test::replaced(good_csv, "# excitation_hz = 2.0\n", "# period_s = 0.25\n# period_s = 0.5\n"),
      3, {"period_s given twice (0.25 and 0.5 s)"});

  identify::Record s = sample_record();
  s.excitation_hz.reset();
  s.period_s = 1.0 / 3.0;
  const auto path = dir / "periodic.csv";
  write_record(path, s);
  const identify::Record back = read_record(path);
  ASSERT_TRUE(back.period_s.has_value());
  EXPECT_TRUE(same_bits(*back.period_s, *s.period_s));
  EXPECT_THROW(write_record(path, s, {"period_s = 2"}), Error); // only from the record
}

TEST_F(RecordCsvTest, WriterRefusesWhatTheReaderWouldRefuse) {
  identify::Record r = sample_record();
  const auto path = dir / "keep.csv";
  test::write_text(path, "previous content\n");
  r.channels[1].samples(10) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_record(path, r), Error);
  r = sample_record();
  r.channels[2].samples.conservativeResize(10);
  EXPECT_THROW(write_record(path, r), Error);
  EXPECT_EQ(test::read_text(path), "previous content\n"); // untouched
}

// A model's DOF map for the channel checks: the planar cantilever's nodes 1–7, node 1 fixed.
fem::DofMap cantilever_dofs() {
  fem::Model m;
  for (int i = 0; i < 7; ++i)
    m.nodes.push_back({i + 1, Eigen::Vector3d(i / 3.0, 0.0, 0.0)});
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"bar", 0.0036, 6.2208e-8, 0.0, 0.0});
  for (int i = 0; i < 6; ++i) {
    fem::Element e;
    e.id = i + 1;
    e.node_a = i + 1;
    e.node_b = i + 2;
    m.elements.push_back(e);
  }
  m.supports.push_back({1, {fem::Dof::ux, fem::Dof::uy, fem::Dof::rz}});
  return fem::DofMap(m);
}

joints::Joint tip_joint() {
  joints::Joint j;
  j.name = "tip";
  j.node = 7;
  j.dof = fem::Dof::uy;
  j.terms = {joints::Term::k};
  j.values = {4800.0};
  j.fixed = {false};
  return j;
}

// The channel checks of identification (identify::spectrum) on records as read from files.
void check_channels(const identify::Record& r, const fem::DofMap& dofs) {
  std::vector<std::string> warnings;
  identify::spectrum(identify::measure(r, {.harmonics = 1}), dofs, {tip_joint()}, warnings);
}

TEST_F(RecordCsvTest, MissingJointChannelAtIdentify) {
  const fem::DofMap dofs = cantilever_dofs();
  const auto path = write(test::replaced(good_csv, "x@7:uy", "x@6:uy"));
  const identify::Record r = read_record(path);
  try {
    check_channels(r, dofs);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("f3.4.csv"), std::string::npos) << message;
    EXPECT_NE(message.find("x@7:uy"), std::string::npos) << message;
    EXPECT_NE(message.find("'tip'"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(check_channels(read_record(write(good_csv)), dofs));
}

TEST_F(RecordCsvTest, ForceChannelMustActOnAFreeDof) {
  const fem::DofMap dofs = cantilever_dofs();
  const identify::Record r = read_record(write(test::replaced(good_csv, "f@7:uy", "f@1:uy")));
  try {
    check_channels(r, dofs);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("f@1:uy"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fixed"), std::string::npos) << e.what();
  }
}

// A force channel on a node the model lacks is the record's fault: the message starts with the
// record (file, or file and line for a table's test) and its channel, and says what the model
// has (issue 31). The UFF58 case is in uff58_test.cpp.
TEST_F(RecordCsvTest, ForceChannelOnANodeTheModelLacksIsTheRecordsFault) {
  const fem::DofMap dofs = cantilever_dofs();
  const auto expect_blamed = [&](const identify::SineTest& test, const std::string& source) {
    std::vector<std::string> warnings;
    try {
      identify::spectrum(identify::measure(test, {.harmonics = 1}), dofs, {tip_joint()}, warnings);
      FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()),
                source + ": force channel f@99:uy: the model has no node 99 (its nodes: 1–7); a "
                         "force must act on a free DOF of the model");
    }
  };
  const auto record = write(test::replaced(good_csv, "f@7:uy", "f@99:uy"));
  expect_blamed(read_record(record), record.string());
  const auto table = write("# stepped sine\n"
                           "freq_hz,f@99:uy.re,f@99:uy.im,x@7:uy.re,x@7:uy.im\n"
                           "3.0,0.0,-10.0,1e-3,-2e-3\n",
                           "table.csv");
  expect_blamed(stepped_sine_tests(read_stepped_sine(table), table).at(0), table.string() + ":3");
}

const std::string table_csv = "# stepped sine, 2 tests\n"
                              "freq_hz,f@7:uy.re,f@7:uy.im,x@7:uy.re,x@7:uy.im\n"
                              "3.0,0.0,-10.0,1e-3,-2e-3\n"
                              "3.5,0.0,-10.0,-4e-3,-5e-4\n";

TEST_F(RecordCsvTest, ReadsASteppedSineTable) {
  const SteppedSineTable t = read_stepped_sine(write(table_csv, "table.csv"));
  EXPECT_EQ(t.freq_hz, (std::vector<double>{3.0, 3.5}));
  EXPECT_EQ(t.channels, (std::vector<std::string>{"f@7:uy", "x@7:uy"}));
  ASSERT_EQ(t.values.rows(), 2);
  ASSERT_EQ(t.values.cols(), 2);
  EXPECT_EQ(t.values(0, 0), std::complex<double>(0.0, -10.0));
  EXPECT_EQ(t.values(1, 1), std::complex<double>(-4e-3, -5e-4));
}

TEST_F(RecordCsvTest, SteppedSineTableErrors) {
  auto expect_table_error = [&](const std::string& text, int line, const std::string& part) {
    try {
      read_stepped_sine(write(text, "table.csv"));
      FAIL() << "expected io::Error for " << part;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("table.csv:" + std::to_string(line) + ":"), std::string::npos)
          << message;
      EXPECT_NE(message.find(part), std::string::npos) << message;
    }
  };
  expect_table_error(test::replaced(table_csv, "x@7:uy.im", "x@7:uy.imag"), 2,
                     "expected \"x@7:uy.im\"");
  expect_table_error(test::replaced(table_csv, "freq_hz,", "f,"), 2, "'freq_hz'");
  expect_table_error(test::replaced(table_csv, "3.5,0.0,", "3.5,"), 4,
                     "row has 4 fields, expected 5");
  expect_table_error(test::replaced(table_csv, "3.5,", "-3.5,"), 4, "> 0 Hz");
  expect_table_error(test::replaced(table_csv, "-4e-3", "inf"), 4, "infinite");
  expect_table_error(test::replaced(table_csv, ",x@7:uy.im", ""), 2,
                     "header: expected freq_hz then two columns per channel (<channel>.re, "
                     "<channel>.im), got 3 columns after freq_hz");
  expect_table_error(test::replaced(table_csv, "x@7:uy.re,x@7:uy.im", "f@7:uy.re,f@7:uy.im"), 2,
                     "header: column 4: channel f@7:uy appears twice (columns 2 and 4)");
  expect_table_error("# no tests yet\nfreq_hz,f@7:uy.re,f@7:uy.im,x@7:uy.re,x@7:uy.im\n", 2,
                     "no data rows (expected one row per test)");
}

TEST_F(RecordCsvTest, SteppedSineTableRoundTripIsBitExact) {
  SteppedSineTable t;
  t.freq_hz = {3.0, 0.1 + 0.2, 17.123456789012345};
  t.channels = {"f@7:uy", "v@7:uy", "a@3:rz"};
  t.values.resize(3, 3);
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Eigen::Index i = 0; i < 3; ++i)
    for (Eigen::Index c = 0; c < 3; ++c)
      t.values(i, c) = {uniform(random) * std::exp(20.0 * uniform(random)), uniform(random) / 3.0};
  t.values(1, 1) = {-0.0, std::numeric_limits<double>::denorm_min()};
  const std::string text = stepped_sine_csv(t, {"stepped sine", "two comments"});
  EXPECT_EQ(text.rfind("# stepped sine\n# two comments\nfreq_hz,f@7:uy.re,f@7:uy.im,v@7:uy.re,"
                       "v@7:uy.im,a@3:rz.re,a@3:rz.im\n",
                       0),
            0u)
      << text;
  const auto path = write(text, "table.csv");
  const SteppedSineTable back = read_stepped_sine(path);
  EXPECT_EQ(back.channels, t.channels);
  ASSERT_EQ(back.freq_hz.size(), 3u);
  ASSERT_EQ(back.values.rows(), 3);
  ASSERT_EQ(back.values.cols(), 3);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(same_bits(back.freq_hz[i], t.freq_hz[i])) << i;
    for (Eigen::Index c = 0; c < 3; ++c) {
      const auto e = static_cast<Eigen::Index>(i);
      EXPECT_TRUE(same_bits(back.values(e, c).real(), t.values(e, c).real())) << i << "," << c;
      EXPECT_TRUE(same_bits(back.values(e, c).imag(), t.values(e, c).imag())) << i << "," << c;
    }
  }
  // Rows are lines 4, 5, 6 (two comments and the header first); each test names its line.
  EXPECT_EQ(back.lines, (std::vector<int>{4, 5, 6}));
  const std::vector<identify::SineTest> tests = stepped_sine_tests(back, path);
  ASSERT_EQ(tests.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& row = std::get<identify::Phasors>(tests[i]);
    EXPECT_EQ(row.source, path.string() + ":" + std::to_string(4 + i));
    EXPECT_EQ(row.frequency_hz, t.freq_hz[i]);
    ASSERT_EQ(row.channels.size(), 3u);
    EXPECT_EQ(row.channels[0].quantity, Quantity::force);
    EXPECT_EQ(row.channels[1].quantity, Quantity::velocity);
    EXPECT_EQ(row.channels[2].quantity, Quantity::acceleration);
    EXPECT_EQ(row.channels[2].at, (fem::NodeDof{3, fem::Dof::rz}));
    EXPECT_EQ(row.channels[1].value, t.values(static_cast<Eigen::Index>(i), 1));
  }
}

// A table may state its phase convention: `# convention = x(t) = Re(X e^{iωt})` (jointid's, the
// default), `Re(X e^{-iωt})` or `Im(X e^{iωt})` (a sine reference). Read in jointid's: the
// signal each row's value describes in its own convention, sampled over a period, is the signal
// of the value read in jointid's; and a table written in another convention reads back exactly.
TEST_F(RecordCsvTest, SteppedSineTableMayStateItsPhaseConvention) {
  SteppedSineTable t;
  t.freq_hz = {3.0, 4.5};
  t.channels = {"f@7:uy", "x@7:uy"};
  t.values.resize(2, 2);
  t.values << std::complex<double>(0.0, -10.0), std::complex<double>(1e-3, -2e-3),
      std::complex<double>(7.0, 2.5), std::complex<double>(-4e-3, 5e-4);
  struct Convention {
    std::string comment;                                    // as a file states it
    std::function<double(std::complex<double>, double)> of; // x(t) from X and ωt, by hand
    std::function<std::complex<double>(std::complex<double>)> written; // X in that convention
  };
  const auto re_plus = [](std::complex<double> X, double wt) {
    return X.real() * std::cos(wt) - X.imag() * std::sin(wt);
  };
  const auto re_minus = [](std::complex<double> X, double wt) {
    return X.real() * std::cos(wt) + X.imag() * std::sin(wt);
  };
  const auto im_plus = [](std::complex<double> X, double wt) {
    return X.real() * std::sin(wt) + X.imag() * std::cos(wt);
  };
  const auto same = [](std::complex<double> X) { return X; };
  const auto conjugate = [](std::complex<double> X) { return std::conj(X); };
  const auto times_i = [](std::complex<double> X) { return std::complex(-X.imag(), X.real()); };
  const std::vector<Convention> conventions = {
      {"", re_plus, same},
      {"convention = x(t) = Re(X e^{i\u03c9t})", re_plus, same},
      {"convention = Re(X exp(+iwt))", re_plus, same},
      {"convention = x(t) = Re(X e^{-i\u03c9t})", re_minus, conjugate},
      {"convention=re(X\u00b7e^(-j\u03c9t))", re_minus, conjugate},
      {"convention = x(t) = Im(X e^{i\u03c9t})", im_plus, times_i},
      {"convention = Im(X*exp(j w t))", im_plus, times_i}};
  for (const Convention& c : conventions) {
    SCOPED_TRACE(c.comment);
    SteppedSineTable in_file = t;
    in_file.values = t.values.unaryExpr(c.written);
    std::vector<std::string> comments{"a table"};
    if (!c.comment.empty()) comments.push_back(c.comment);
    const SteppedSineTable back =
        read_stepped_sine(write(stepped_sine_csv(in_file, comments), "table.csv"));
    ASSERT_EQ(back.values.rows(), 2);
    ASSERT_EQ(back.values.cols(), 2);
    for (Eigen::Index i = 0; i < 2; ++i)
      for (Eigen::Index k = 0; k < 2; ++k) {
        EXPECT_EQ(back.values(i, k), t.values(i, k)) << i << "," << k; // exactly
        // The same signal: x(t) of the file's value in its convention, and of the value read.
        for (int step = 0; step < 8; ++step) {
          const double wt = 2.0 * std::numbers::pi * step / 8.0;
          const double scale = std::abs(t.values(i, k));
          EXPECT_NEAR(c.of(in_file.values(i, k), wt), re_plus(back.values(i, k), wt), 1e-15 * scale)
              << i << "," << k << " at ωt = " << wt;
        }
      }
  }
  // An unknown convention, or two that differ, are refused naming the line.
  const std::string header = "freq_hz,f@7:uy.re,f@7:uy.im,x@7:uy.re,x@7:uy.im\n3.0,0,-10,1,2\n";
  for (const auto& [text, line, part] : std::vector<std::tuple<std::string, int, std::string>>{
           {"# one\n# convention = Re(X e^{i\u03c9t + \u03c6})\n" + header, 2,
            "convention: expected x(t) = Re(X e^{i\u03c9t}) (jointid's, the default), x(t) = "
            "Re(X e^{-i\u03c9t}) or x(t) = Im(X e^{i\u03c9t}) (a sine reference), got "
            "\"Re(X e^{i\u03c9t + \u03c6})\""},
           {"# convention = cosine\n" + header, 1, "got \"cosine\""},
           {"# convention = Re(X e^{i\u03c9t})\n# convention = Re(X e^{-i\u03c9t})\n" + header, 2,
            "convention given twice, differently (first at line 1)"}}) {
    try {
      read_stepped_sine(write(text, "table.csv"));
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("table.csv:" + std::to_string(line) + ": convention"),
                std::string::npos)
          << message;
      EXPECT_NE(message.find(part), std::string::npos) << message;
    }
  }
  // The same convention twice, and a comment that only starts with the word, are fine.
  EXPECT_NO_THROW(read_stepped_sine(
      write("# convention = Re(X e^{iwt})\n# convention = x(t) = Re(X exp(i w t))\n"
            "# conventions differ between labs\n" +
                header,
            "table.csv")));
}

TEST_F(RecordCsvTest, SteppedSineWriterRefusesWhatTheReaderWouldRefuse) {
  SteppedSineTable t;
  t.freq_hz = {3.0, 4.0};
  t.channels = {"f@7:uy", "x@7:uy"};
  t.values = Eigen::MatrixXcd::Ones(2, 2);
  EXPECT_NO_THROW(stepped_sine_csv(t));
  SteppedSineTable bad = t;
  bad.values = Eigen::MatrixXcd::Ones(3, 2); // 3 rows for 2 frequencies
  EXPECT_THROW(stepped_sine_csv(bad), Error);
  bad = t;
  bad.channels.pop_back();
  EXPECT_THROW(stepped_sine_csv(bad), Error);
  bad = t;
  bad.values(1, 1) = {std::numeric_limits<double>::quiet_NaN(), 0.0};
  EXPECT_THROW(stepped_sine_csv(bad), Error);
  bad = t;
  bad.freq_hz[0] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(stepped_sine_csv(bad), Error);
}

TEST_F(RecordCsvTest, ReadTestsTellsRecordsFromTables) {
  const auto record = write(good_csv, "record.csv");
  const auto table = write(table_csv, "table.csv");
  const std::vector<identify::SineTest> tests = read_tests({table, record});
  ASSERT_EQ(tests.size(), 3u); // two rows, then one record, in the order given
  const auto* first = std::get_if<identify::Phasors>(&tests[0]);
  const auto* second = std::get_if<identify::Phasors>(&tests[1]);
  const auto* third = std::get_if<identify::Record>(&tests[2]);
  ASSERT_NE(first, nullptr);
  ASSERT_NE(second, nullptr);
  ASSERT_NE(third, nullptr);
  EXPECT_EQ(first->source, table.string() + ":3");
  EXPECT_EQ(second->source, table.string() + ":4");
  EXPECT_EQ(second->frequency_hz, 3.5);
  EXPECT_EQ(second->channels[1].value, std::complex<double>(-4e-3, -5e-4));
  EXPECT_EQ(third->source, record.string());
  EXPECT_EQ(*third->excitation_hz, 2.0);
  EXPECT_EQ(third->t.size(), 5);
}

TEST_F(RecordCsvTest, ReadTestsRefusesAFileGivenTwice) {
  const auto a = write(good_csv, "a.csv");
  const auto b = write(table_csv, "b.csv");
  auto error_of = [](const std::vector<std::filesystem::path>& paths) {
    try {
      read_tests(paths);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string e = error_of({a, b, a});
  EXPECT_NE(e.find(a.string()), std::string::npos) << e;
  EXPECT_NE(e.find("given twice"), std::string::npos) << e;
  // Another spelling of the same file: through "." and "..", and relative to the directory.
  const std::filesystem::path other = dir.path() / "." / "sub" / ".." / "b.csv";
  std::filesystem::create_directories(dir.path() / "sub");
  e = error_of({b, other});
  EXPECT_NE(e.find("given twice"), std::string::npos) << e;
  EXPECT_NE(e.find(other.string()), std::string::npos) << e;
  EXPECT_NE(e.find("also as " + b.string()), std::string::npos) << e;
  // Two different files with the same content are two tests.
  const auto copy = write(good_csv, "copy.csv");
  EXPECT_EQ(error_of({a, copy}), "");
}

TEST_F(RecordCsvTest, ReadTestsNamesAnUnknownFirstColumn) {
  const auto path =
      write("# neither kind\n\nfrequency,f@7:uy.re,f@7:uy.im\n3.0,0.0,-1.0\n", "odd.csv");
  try {
    read_tests({path});
    FAIL() << "expected io::Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("odd.csv:3:"), std::string::npos) << message;
    EXPECT_NE(message.find("'t'"), std::string::npos) << message;
    EXPECT_NE(message.find("'freq_hz'"), std::string::npos) << message;
    EXPECT_NE(message.find("\"frequency\""), std::string::npos) << message;
  }
  EXPECT_THROW(read_tests({dir / "missing.csv"}), Error);
}

TEST_F(RecordCsvTest, ByteOrderMarkIsAccepted) {
  const std::string bom = "\xEF\xBB\xBF";
  // A record whose first line is a comment, and one whose first line is the header.
  const identify::Record r = read_record(write(bom + good_csv, "bom_record.csv"));
  EXPECT_EQ(*r.excitation_hz, 2.0);
  EXPECT_EQ(r.channels.size(), 2u);
  const std::string bare = good_csv.substr(good_csv.find("t,f@7"));
  const identify::Record header_first = read_record(write(bom + bare, "bom_header.csv"));
  EXPECT_EQ(header_first.channels[0].name(), "f@7:uy");
  EXPECT_EQ(header_first.t.size(), 5);
  const SteppedSineTable t = read_stepped_sine(write(bom + table_csv, "bom_table.csv"));
  EXPECT_EQ(t.freq_hz.size(), 2u);
  const std::string table_bare = table_csv.substr(table_csv.find("freq_hz"));
  const auto table_path = write(bom + table_bare, "bom_table_header.csv");
  EXPECT_EQ(read_stepped_sine(table_path).channels[0], "f@7:uy");
  // read_tests tells the kinds apart behind the mark too; line numbers are unchanged.
  const auto tests = read_tests({dir / "bom_header.csv", table_path});
  ASSERT_EQ(tests.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<identify::Record>(tests[0]));
  EXPECT_EQ(identify::source_of(tests[1]), table_path.string() + ":2");
  // Only at the very start: elsewhere the mark is part of a field.
  EXPECT_THROW(read_record(write(test::replaced(good_csv, "t,f@7", bom + "t,f@7"), "late.csv")),
               Error);
}

// A record at f Hz: force 80 sin ωt + f3 cos 3ωt, x = 1e-3 + Re(X1 e^{iωt}) + Re(X3 e^{3iωt})
// and its velocity, `periods` periods of 200 samples.
identify::Record harmonic_record(double f, std::complex<double> X1, int periods, bool excitation,
                                 double f3) {
  const std::complex<double> X3 = 0.05 * X1 * std::polar(1.0, 0.8);
  const double w = 2.0 * std::numbers::pi * f;
  identify::Record r;
  r.source = "sine_" + std::to_string(f) + ".csv";
  if (excitation) r.excitation_hz = f;
  const int n = 200 * periods;
  r.t.resize(n);
  Eigen::VectorXd force(n), x(n), v(n);
  for (int i = 0; i < n; ++i) {
    const double t = i / (200.0 * f);
    r.t(i) = t;
    const std::complex<double> e1 = std::polar(1.0, w * t), e3 = std::polar(1.0, 3.0 * w * t);
    force(i) = 80.0 * std::sin(w * t) + f3 * std::cos(3.0 * w * t);
    x(i) = 1e-3 + (X1 * e1).real() + (X3 * e3).real();
    v(i) = (std::complex<double>(0.0, w) * X1 * e1).real() +
           (std::complex<double>(0.0, 3.0 * w) * X3 * e3).real();
  }
  r.channels.push_back({Quantity::force, {7, fem::Dof::uy}, force});
  r.channels.push_back({Quantity::displacement, {7, fem::Dof::uy}, x});
  r.channels.push_back({Quantity::velocity, {7, fem::Dof::uy}, v});
  return r;
}

TEST_F(RecordCsvTest, SteppedSineTableFromRecordsHoldsTheFundamentals) {
  // Whole periods, uniform sampling: the fundamental's fit is orthogonal to the mean and the
  // third harmonic, so the table holds the known fundamentals to rounding (1e-12 relative).
  // Without an excitation_hz the frequency is estimated from the force, here a pure sine (to
  // ≈ 1e-8 relative; 1e-6 asserted as in the harmonics tests), which turns the phase by at most
  // 2π · 3 periods · 1e-6: 1e-4 relative asserted on the values. (With a 5 % third harmonic
  // in the force of this 3-period record the estimate is off by 5e-5: not tested here.)
  const std::complex<double> X1a = std::polar(4e-3, 0.3), X1b = std::polar(9e-3, -2.0);
  const std::vector<identify::Record> records{harmonic_record(2.5, X1a, 4, true, 4.0),
                                              harmonic_record(3.7, X1b, 3, false, 0.0)};
  const SteppedSineTable t = identify::stepped_sine_table(records);
  EXPECT_EQ(t.channels, (std::vector<std::string>{"f@7:uy", "x@7:uy", "v@7:uy"}));
  ASSERT_EQ(t.freq_hz.size(), 2u);
  EXPECT_EQ(t.freq_hz[0], 2.5);
  EXPECT_NEAR(t.freq_hz[1], 3.7, 1e-6 * 3.7);
  const double tol[2] = {1e-12, 1e-4};
  const std::complex<double> X1[2] = {X1a, X1b};
  for (Eigen::Index i = 0; i < 2; ++i) {
    const double w = 2.0 * std::numbers::pi * (i == 0 ? 2.5 : 3.7);
    EXPECT_LE(std::abs(t.values(i, 0) - std::complex<double>(0.0, -80.0)), tol[i] * 80.0) << i;
    EXPECT_LE(std::abs(t.values(i, 1) - X1[i]), tol[i] * std::abs(X1[i])) << i;
    EXPECT_LE(std::abs(t.values(i, 2) - std::complex<double>(0.0, w) * X1[i]),
              tol[i] * w * std::abs(X1[i]))
        << i;
  }
  // Through the file and back, the rows measure to what the records measure.
  const auto path = write(stepped_sine_csv(t), "from_records.csv");
  const auto tests = read_tests({path});
  ASSERT_EQ(tests.size(), 2u);
  const identify::Measurement row = identify::measure(tests[0]);
  const identify::Measurement rec = identify::measure(records[0]);
  EXPECT_LE(std::abs(row.X(1, 0) - rec.X(1, 0)), 1e-12 * std::abs(X1a));
  EXPECT_LE(std::abs(row.F(1, 0) - rec.F(1, 0)), 1e-12 * 80.0);

  // Channels must match; a record must hold a period.
  std::vector<identify::Record> mixed = records;
  mixed[1].channels.pop_back();
  try {
    identify::stepped_sine_table(mixed);
    FAIL() << "differing channels accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(mixed[1].source), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("channels differ"), std::string::npos) << e.what();
  }
  identify::Record short_record = records[0];
  short_record.t.conservativeResize(100); // half a period
  for (auto& c : short_record.channels)
    c.samples.conservativeResize(100);
  try {
    identify::stepped_sine_table({short_record});
    FAIL() << "a record shorter than a period accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), short_record.source + ": shorter than one period of 2.5 Hz");
  }
  EXPECT_TRUE(identify::stepped_sine_table({}).freq_hz.empty());
}

// Fuzzing regressions (docs/fuzzing.md): stepped_sine_table let std::invalid_argument escape from
// fit_harmonics when the whole periods of a record hold 2 samples (7.1 Hz sampled at 16 Hz, the
// input fuzz_record_csv found), and a frequency above the sampling's reached an int conversion
// that overflowed.
TEST_F(RecordCsvTest, SteppedSineTableRefusesRecordsItCannotFit) {
  const std::string found = "# sine test\n"
                            "# excitation_hz = 7.1\n"
                            "t,f@7:uy,x@7:uy,a@4:rz\n"
                            "0,0,0.001,1\n"
                            "0.0625,7.07,0.0007,2\n"
                            "0.125,10,0,3\n"
                            "0.1875,7.07,-0.000707,8\n";
  const auto error_of = [&](const std::string& text) {
    const identify::Record record = read_record(write(text));
    try {
      identify::stepped_sine_table({record});
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  std::string e = error_of(found);
  EXPECT_NE(e.find("f3.4.csv: its whole periods of 7.1 Hz hold 2 samples; fitting the fundamental "
                   "needs at least 3"),
            std::string::npos)
      << e;
  e = error_of(test::replaced(found, "= 7.1", "= 1e300"));
  EXPECT_NE(e.find("f3.4.csv: the excitation, 1e+300 Hz, is not below the Nyquist frequency of "
                   "its sampling, 8 Hz (step 0.0625 s)"),
            std::string::npos)
      << e;
}

} // namespace
} // namespace jointid::io
