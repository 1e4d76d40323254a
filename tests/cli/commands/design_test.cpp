// jointid design with a joint's parametric term not fixed: the D-optimal choice for the
// coefficient terms beside it, and the force levels at which the term reaches its regime (an
// iwan's macroslip) said in words and in design.json.
#include "cli/run_jointid.hpp"
#include "io/cantilever_toml.hpp"
#include "io/test_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

namespace jointid {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string with_joint(const std::string& joint) {
  std::string text = test::cantilever_toml();
  text.erase(text.find("[[joints]]"));
  return text + "[[joints]]\nname = \"tip\"\nnode = 7\ndof = \"uy\"\n" + joint;
}

TEST(DesignParametric, SaysWhichForcesReachMacroslip) {
  // φ_max = fs (1 + β) / (kt (β + (χ + 1)/(χ + 2))) = 3.3e-4 / (0.1 + 1/3) m (Segalman).
  const test::TempDir dir;
  const fs::path model = dir.path() / "iwan.toml";
  test::write_text(model, with_joint("terms = [\"k\", \"c\", \"iwan\"]\nvalues = { k = 4800.0, "
                                     "c = 20.0, \"iwan.fs\" = 3.0, \"iwan.kt\" = 1.0e4, "
                                     "\"iwan.chi\" = -0.5, \"iwan.beta\" = 0.1 }\n"));
  const fs::path out = dir.path() / "design";
  const test::Outcome run =
      test::jointid({"design", model.string(), "--force", "7:uy", "--freq", "1,3", "--amplitude",
                     "0.5,2,8", "-n", "2", "-o", out.string()},
                    dir.path());
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("parametric term: joint 'tip': its iwan reaches macroslip where its "
                         "deformation exceeds 0.0007615"),
            std::string::npos)
      << run.out;
  const json j = json::parse(test::read_text(out / "design.json"));
  ASSERT_EQ(j["parametric"].size(), 1u);
  const json& p = j["parametric"][0];
  EXPECT_EQ(p["joint"], "tip");
  EXPECT_EQ(p["term"], "iwan");
  EXPECT_EQ(p["regime"], "macroslip");
  const double phi_max = 3.0 * 1.1 / (1.0e4 * (0.1 + 1.0 / 3.0));
  EXPECT_NEAR(p["threshold"].get<double>(), phi_max, 1e-9 * phi_max);
  ASSERT_EQ(p["levels"].size(), 2u);
  EXPECT_EQ(p["levels"][0]["freq_hz"], 1.0);
  // the unknowns chosen for are the coefficient terms beside it
  ASSERT_EQ(j["unknowns"].size(), 2u);
  EXPECT_EQ(j["unknowns"][0]["term"], "k");

  // Its only unknown the parametric term: nothing for the D-optimal choice, said so.
  test::write_text(model, with_joint("terms = [\"k\", \"iwan\"]\nvalues = { k = 4800.0, "
                                     "\"iwan.fs\" = 3.0, \"iwan.kt\" = 1.0e4, \"iwan.chi\" = "
                                     "-0.5, \"iwan.beta\" = 0.1 }\nfixed = [\"k\"]\n"));
  test::expect_one_line_error(
      test::jointid({"design", model.string(), "--force", "7:uy", "--freq", "1,3", "--amplitude",
                     "0.5,2,8", "-n", "2", "-o", (dir.path() / "design2").string()},
                    dir.path()),
      "every joint term but the parametric ones (jenkins, iwan, gap) is fixed");
}

} // namespace
} // namespace jointid
