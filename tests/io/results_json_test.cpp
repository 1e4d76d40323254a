#include "io/results_json.hpp"

#include "io/files.hpp"
#include "io/test_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <limits>
#include <numbers>

namespace jointid::io {
namespace {

using nlohmann::json;

identify::FitResult sample_result() {
  identify::FitResult r;
  identify::JointEstimate tip{"tip", {}};
  identify::TermEstimate k;
  k.term = joints::Term::k;
  k.value = 4800.5;
  k.std = 1.25;
  k.ci_low = 4797.5;
  k.ci_high = 4803.5;
  identify::TermEstimate c;
  c.term = joints::Term::c;
  c.value = 20.0;
  c.std = 0.0;
  c.ci_low = c.ci_high = 20.0;
  c.fixed = true;
  identify::TermEstimate k3;
  k3.term = joints::Term::k3;
  k3.value = 1.6e8;
  k3.std = std::numeric_limits<double>::quiet_NaN(); // no redundancy
  k3.ci_low = k3.ci_high = std::numeric_limits<double>::quiet_NaN();
  tip.terms = {k, c, k3};
  r.joints = {tip, identify::JointEstimate{"root", {}}};
  r.equations = 40;
  r.unknowns = 4;
  r.condition_number = std::numeric_limits<double>::infinity();
  r.residual_rms = 1e-9;
  r.residual_relative = 2.5e-4;
  r.warnings = {"f19.8.csv: not a steady state"};
  return r;
}

TEST(IdentifyResultJson, HasTheContractShape) {
  const std::string text = identify_result_json(sample_result(), {"extra note"});
  const json j = json::parse(text);
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j["joints"].size(), 2u);
  const json& tip = j["joints"][0];
  EXPECT_EQ(tip["name"], "tip");
  ASSERT_EQ(tip["terms"].size(), 3u);
  const json& k = tip["terms"][0];
  EXPECT_EQ(k["term"], "k");
  EXPECT_EQ(k["effect"], "linear stiffness");
  EXPECT_EQ(k["value"].get<double>(), 4800.5);
  EXPECT_EQ(k["std"].get<double>(), 1.25);
  EXPECT_EQ(k["ci95"], json::array({4797.5, 4803.5}));
  EXPECT_EQ(k["fixed"], false);
  EXPECT_EQ(tip["terms"][1]["effect"], "viscous damping");
  EXPECT_EQ(tip["terms"][1]["fixed"], true);
  const json& k3 = tip["terms"][2];
  EXPECT_EQ(k3["effect"], "cubic stiffness");
  EXPECT_TRUE(k3["std"].is_null());
  EXPECT_TRUE(k3["ci95"][0].is_null());
  EXPECT_TRUE(k3["ci95"][1].is_null());
  EXPECT_EQ(j["joints"][1]["name"], "root");
  EXPECT_TRUE(j["joints"][1]["terms"].is_array());
  EXPECT_EQ(j["equations"], 40);
  EXPECT_EQ(j["unknowns"], 4);
  EXPECT_TRUE(j["condition_number"].is_null()); // infinite
  EXPECT_EQ(j["residual_rms"].get<double>(), 1e-9);
  EXPECT_EQ(j["residual_relative"].get<double>(), 2.5e-4);
  EXPECT_EQ(j["warnings"], json::array({"f19.8.csv: not a steady state", "extra note"}));
  // Keys in the contract's order.
  EXPECT_LT(text.find("\"joints\""), text.find("\"equations\""));
  EXPECT_LT(text.find("\"equations\""), text.find("\"unknowns\""));
  EXPECT_LT(text.find("\"residual_relative\""), text.find("\"warnings\""));
  EXPECT_LT(text.find("\"term\""), text.find("\"effect\""));
  EXPECT_EQ(text.find("NaN"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
}

TEST(IdentifyResultJson, NumbersRoundTripExactly) {
  identify::FitResult r = sample_result();
  r.joints[0].terms[0].value = 0.1 + 0.2;
  r.residual_rms = 5e-324;
  const json j = json::parse(identify_result_json(r));
  EXPECT_EQ(j["joints"][0]["terms"][0]["value"].get<double>(), 0.1 + 0.2);
  EXPECT_EQ(j["residual_rms"].get<double>(), 5e-324);
}

TEST(ModesJson, ListsFrequenciesInHertz) {
  fem::Modes modes;
  modes.omega =
      Eigen::Vector3d(2.0 * std::numbers::pi * 3.0, 2.0 * std::numbers::pi * 18.5, 1000.0);
  modes.phi = Eigen::MatrixXd::Identity(3, 3);
  const json all = json::parse(modes_json(modes));
  ASSERT_EQ(all["modes"].size(), 3u);
  EXPECT_EQ(all["modes"][0]["mode"], 1);
  EXPECT_DOUBLE_EQ(all["modes"][0]["frequency_hz"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(all["modes"][1]["frequency_hz"].get<double>(), 18.5);
  EXPECT_DOUBLE_EQ(all["modes"][2]["frequency_hz"].get<double>(),
                   1000.0 / (2.0 * std::numbers::pi));
  EXPECT_EQ(json::parse(modes_json(modes, 2))["modes"].size(), 2u);
}

TEST(WriteJson, WritesTheText) {
  test::TempDir dir;
  const auto path = dir / "result.json";
  const std::string text = identify_result_json(sample_result());
  write_json(path, text);
  EXPECT_EQ(test::read_text(path), text);
  EXPECT_THROW(write_json(dir / "no" / "result.json", text), Error);
}

} // namespace
} // namespace jointid::io
