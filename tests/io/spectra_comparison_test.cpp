// compare.json: the fields `jointid compare` promises, numbers as written, non-finite as null.
#include "io/spectra_comparison.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <limits>

using namespace jointid;

TEST(CompareJson, HoldsEveryChannelWithItsSpectraAndDifferences) {
  identify::Comparison c;
  c.source = "rec.csv";
  c.f0_hz = 2.0;
  c.f1_hz = 40.0;
  c.sample_rate_hz = 256.0;
  c.segment = 1024;
  c.averages = 17;
  c.resolution_hz = 0.25;
  c.skip_s = 4.0;
  c.statistical_db = 1.49;
  c.notes = {"a note"};
  identify::ChannelComparison ch;
  ch.channel = "a@7:uy";
  ch.frequency_hz = Eigen::Vector2d(2.0, 2.25);
  ch.measured = Eigen::Vector2d(1e-3, 2e-3);
  ch.predicted = Eigen::Vector2d(1e-3, 4e-3);
  ch.difference_db = Eigen::Vector2d(0.0, std::numeric_limits<double>::quiet_NaN());
  ch.rms_db = 2.1;
  ch.max_db = 3.01;
  c.channels.push_back(ch);
  const auto j = nlohmann::json::parse(io::compare_json(c));
  EXPECT_EQ(j["record"], "rec.csv");
  EXPECT_EQ(j["band_hz"], nlohmann::json::array({2.0, 40.0}));
  EXPECT_EQ(j["segment"], 1024);
  EXPECT_EQ(j["averages"], 17);
  EXPECT_DOUBLE_EQ(j["statistical_db"].get<double>(), 1.49);
  ASSERT_EQ(j["channels"].size(), 1u);
  const auto& o = j["channels"][0];
  EXPECT_EQ(o["channel"], "a@7:uy");
  EXPECT_EQ(o["unit"], "(m/s^2)^2/Hz");
  EXPECT_DOUBLE_EQ(o["rms_difference_db"].get<double>(), 2.1);
  EXPECT_DOUBLE_EQ(o["max_difference_db"].get<double>(), 3.01);
  EXPECT_DOUBLE_EQ(o["predicted"][1].get<double>(), 4e-3);
  EXPECT_DOUBLE_EQ(o["frequency_hz"][1].get<double>(), 2.25);
  EXPECT_TRUE(o["difference_db"][1].is_null());
  EXPECT_NE(j["psd_convention"].get<std::string>().find("one-sided"), std::string::npos);
}

TEST(CompareJson, PsdUnitsFollowTheQuantityAndTheDof) {
  EXPECT_EQ(jointid::io::psd_unit("x@7:uy"), "m^2/Hz");
  EXPECT_EQ(jointid::io::psd_unit("x@1:rz"), "rad^2/Hz");
  EXPECT_EQ(jointid::io::psd_unit("v@3:rx"), "(rad/s)^2/Hz");
  EXPECT_EQ(jointid::io::psd_unit("a@3:ux"), "(m/s^2)^2/Hz");
  EXPECT_EQ(jointid::io::psd_unit("f@2:ry"), "(N m)^2/Hz");
  EXPECT_EQ(jointid::io::psd_unit("f@2:uz"), "N^2/Hz");
}
