#include "identify/record.hpp"

#include <gtest/gtest.h>

using namespace jointid;
using namespace jointid::identify;

TEST(Record, ParsesChannelNames) {
  const Channel c = parse_channel_name("v@12:rz");
  EXPECT_EQ(c.quantity, Quantity::velocity);
  EXPECT_EQ(c.at.node, 12);
  EXPECT_EQ(c.at.dof, fem::Dof::rz);
  EXPECT_EQ(c.name(), "v@12:rz");
}

TEST(Record, RejectsBadChannelNamesWithAReason) {
  for (const char* bad : {"x7:uy", "q@7:uy", "x@seven:uy", "x@7:uw", "x@7"}) {
    try {
      parse_channel_name(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(Record, FindsChannels) {
  Record r;
  r.channels.push_back({Quantity::force, {7, fem::Dof::uy}, {}});
  r.channels.push_back({Quantity::displacement, {7, fem::Dof::uy}, {}});
  EXPECT_NE(r.find(Quantity::displacement, {7, fem::Dof::uy}), nullptr);
  EXPECT_EQ(r.find(Quantity::velocity, {7, fem::Dof::uy}), nullptr);
  EXPECT_EQ(r.all(Quantity::force).size(), 1u);
}
