// jointid identify with a joint's jenkins, iwan or gap term not fixed: each term simulated by
// `jointid simulate` (time integration: exact slider states and contact, independent of the
// harmonic balance that output error fits with) at levels that reach slip or contact, with 1 %
// noise on every channel, and identified back by `--output-error` from no given parameter (a
// describing-function start). An iwan kept in microslip has what the tests do not determine
// said in words and flagged, never given a value; bad input is refused in one line.
#include "cli/run_jointid.hpp"
#include "io/cantilever_toml.hpp"
#include "io/test_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace jointid {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::expect_one_line_error;
using test::jointid;
using test::Outcome;

// The cantilever of the CLI tests with the joint "tip" (node 7 uy) given by its lines.
std::string cantilever_with(const std::string& joint) {
  std::string text = test::cantilever_toml();
  text.erase(text.find("[[joints]]"));
  return text + "[[joints]]\nname = \"tip\"\nnode = 7\ndof = \"uy\"\n" + joint;
}

// Records of `truth` (a joint's lines) at 2.6, 3.0 and 3.4 Hz (across the first resonance) and
// the forces given: time integration, 512 steps a period, 128 samples a period kept, 4 periods
// once steady, 1 % noise on every channel. The records' paths, sorted.
std::vector<std::string> simulate(const fs::path& dir, const std::string& truth,
                                  const std::string& forces, int seed) {
  const fs::path model = dir / "truth.toml", records = dir / "records";
  test::write_text(model, cantilever_with(truth));
  const Outcome run = jointid({"simulate",
                               model.string(),
                               "--force",
                               "7:uy",
                               "--freq",
                               "2.6,3,3.4",
                               "--amplitude",
                               forces,
                               "--steps-per-period",
                               "512",
                               "--samples-per-period",
                               "128",
                               "--periods",
                               "4",
                               "--noise",
                               "0.01",
                               "--seed",
                               std::to_string(seed),
                               "-o",
                               records.string()},
                              dir);
  EXPECT_EQ(run.status, 0) << run.err;
  std::vector<std::string> files;
  if (fs::is_directory(records))
    for (const auto& e : fs::directory_iterator(records))
      if (e.path().extension() == ".csv") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

// `jointid identify` of the joint `unknown` (its lines) from the records; the result file.
Outcome identify(const fs::path& dir, const std::string& unknown,
                 const std::vector<std::string>& records, bool output_error = true) {
  const fs::path model = dir / "unknown.toml";
  test::write_text(model, cantilever_with(unknown));
  std::vector<std::string> args{"identify", model.string()};
  args.insert(args.end(), records.begin(), records.end());
  args.insert(args.end(), {"--harmonics", "1,2,3", "-o", (dir / "result.json").string()});
  if (output_error) args.push_back("--output-error");
  return jointid(args, dir);
}

// With fixed seeds each run is one draw; several values are checked in each, so the 95 %
// interval is widened to 99.9 % (3.29 standard deviations rather than 1.96): a true interval
// misses it once in a thousand.
constexpr double widen = 3.29 / 1.96;

void expect_within_interval(const json& entry, double truth, const std::string& name) {
  ASSERT_TRUE(entry["determined"].get<bool>()) << name << ": " << entry.dump();
  const double value = entry["value"].get<double>();
  const double lo = entry["ci95"][0].get<double>(), hi = entry["ci95"][1].get<double>();
  EXPECT_LT(lo, value) << name;
  EXPECT_GT(hi, value) << name;
  EXPECT_LE(std::abs(value - truth), widen * std::max(value - lo, hi - value))
      << name << " = " << value << " [" << lo << ", " << hi << "], truth " << truth;
}

// The sentence gives `label` (e.g. "k + iwan.kt = ") a value and its interval,
// "<value> [<low>, <high>]", and the (widened) interval holds the truth.
void expect_combination(const std::string& said, const std::string& label, double truth) {
  const auto at = said.find(label);
  ASSERT_NE(at, std::string::npos) << said;
  std::size_t used = 0;
  const double value = std::stod(said.substr(at + label.size()), &used);
  const std::string rest = said.substr(at + label.size() + used);
  ASSERT_EQ(rest.rfind(" [", 0), 0u) << said;
  const double lo = std::stod(rest.substr(2)), hi = std::stod(rest.substr(rest.find(", ") + 2));
  EXPECT_LE(std::abs(value - truth), widen * std::max(value - lo, hi - value)) << said;
}

struct TermCase {
  std::string term;
  std::vector<std::pair<std::string, double>> truth; // "<term>.<parameter>", value
  std::string forces;                                // N, reaching slip or contact
};

void identified_back(const TermCase& c, int seed) {
  const test::TempDir dir;
  std::string values = "values = { k = 4800.0, c = 20.0";
  for (const auto& [name, v] : c.truth)
    values += ", \"" + name + "\" = " + std::to_string(v);
  const std::string terms = "terms = [\"k\", \"c\", \"" + c.term + "\"]\n";
  const auto records = simulate(dir.path(), terms + values + " }\n", c.forces, seed);
  ASSERT_FALSE(records.empty());
  // Nothing given: k, c and every parameter of the term are identified.
  const Outcome run = identify(dir.path(), terms, records);
  ASSERT_EQ(run.status, 0) << run.err;
  const json j = json::parse(test::read_text(dir.path() / "result.json"));
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["interval_method"], "output error");
  const json& terms_out = j["joints"][0]["terms"];
  expect_within_interval(terms_out[0], 4800.0, "k");
  expect_within_interval(terms_out[1], 20.0, "c");
  EXPECT_EQ(terms_out[2]["term"], c.term);
  for (const auto& [name, v] : c.truth) {
    ASSERT_TRUE(terms_out[2]["parameters"].contains(name)) << terms_out[2].dump();
    expect_within_interval(terms_out[2]["parameters"][name], v, name);
    // the printed table gives it, "<term>.<parameter>", with its interval, in a term column as
    // wide as its longest entry: the effect column starts where the header's does
    const std::size_t at = run.out.find("tip          " + name + " ");
    ASSERT_NE(at, std::string::npos) << run.out;
    const std::size_t header = run.out.rfind("joint", at);
    ASSERT_NE(header, std::string::npos) << run.out;
    const std::size_t effect = run.out.find("effect", header) - header;
    const std::string line = run.out.substr(at, run.out.find('\n', at) - at);
    ASSERT_GT(line.size(), effect) << run.out;
    EXPECT_EQ(line[effect - 1], ' ') << run.out;
    EXPECT_NE(line[effect], ' ') << run.out;
    EXPECT_EQ(line.substr(13, effect - 13).find_first_not_of(name + " "), std::string::npos)
        << run.out;
  }
  EXPECT_TRUE(j["identifiability"].empty()) << j["identifiability"].dump();
  // the start is said
  EXPECT_NE(run.err.find("started from a describing-function fit"), std::string::npos) << run.err;
}

// Slip begins at fs/kt = 3e-4 m for the jenkins, the iwan's macroslip at φ_max ≈ 7.6e-4 m
// (fs (1 + β) / (kt (β + (χ + 1)/(χ + 2)))), contact at δ = 5e-3 m: the largest forces drive
// the tip (k = 4800 N/m plus the beam, near resonance) well beyond each.
TEST(IdentifyParametric, JenkinsSimulatedInTimeIsIdentifiedBack) {
  identified_back({"jenkins", {{"jenkins.kt", 1.0e4}, {"jenkins.fs", 3.0}}, "2,8,20"}, 11);
}

TEST(IdentifyParametric, IwanSimulatedInTimeIsIdentifiedBack) {
  identified_back({"iwan",
                   {{"iwan.fs", 3.0}, {"iwan.kt", 1.0e4}, {"iwan.chi", -0.5}, {"iwan.beta", 0.1}},
                   "2,8,20"},
                  21);
}

TEST(IdentifyParametric, GapSimulatedInTimeIsIdentifiedBack) {
  identified_back({"gap", {{"gap.delta", 5e-3}, {"gap.kg", 2e4}}, "10,40"}, 31);
}

TEST(IdentifyParametric, IwanInMicroslipSaysWhatTheTestsDoNotDetermine) {
  // 0.5 and 1 N keep the iwan below macroslip: its force depends on k + kt, chi and the slip
  // density's scale R alone. iwan.fs, iwan.kt, iwan.beta and k have no value (null, flagged
  // undetermined, "undetermined" in the table); the combinations are said in words with their
  // intervals, k + kt = 14800 N/m among them; chi is determined; the command succeeds.
  const test::TempDir dir;
  const std::string terms = "terms = [\"k\", \"c\", \"iwan\"]\n";
  const auto records = simulate(dir.path(),
                                terms + "values = { k = 4800.0, c = 20.0, \"iwan.fs\" = 3.0, "
                                        "\"iwan.kt\" = 1.0e4, \"iwan.chi\" = -0.5, "
                                        "\"iwan.beta\" = 0.1 }\n",
                                "0.5,1", 41);
  const Outcome run = identify(dir.path(), terms, records);
  ASSERT_EQ(run.status, 0) << run.err;
  const json j = json::parse(test::read_text(dir.path() / "result.json"));
  const json& t = j["joints"][0]["terms"];
  for (const char* name : {"iwan.fs", "iwan.kt", "iwan.beta"}) {
    EXPECT_FALSE(t[2]["parameters"][name]["determined"].get<bool>()) << name;
    EXPECT_TRUE(t[2]["parameters"][name]["value"].is_null()) << name;
  }
  EXPECT_FALSE(t[0]["determined"].get<bool>()); // k apart from kt
  EXPECT_TRUE(t[0]["value"].is_null());
  expect_within_interval(t[2]["parameters"]["iwan.chi"], -0.5, "iwan.chi");
  ASSERT_EQ(j["identifiability"].size(), 1u);
  const std::string said = j["identifiability"][0];
  EXPECT_NE(said.find("microslip"), std::string::npos) << said;
  EXPECT_NE(said.find("iwan.fs apart from iwan.beta are undetermined"), std::string::npos) << said;
  expect_combination(said, "k + iwan.kt = ", 14800.0);
  EXPECT_NE(run.out.find("undetermined"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("not determined: joint 'tip': its iwan"), std::string::npos) << run.out;
}

// The sentence of `identify` that says what a jenkins that never slipped or a gap that never
// closed leaves undetermined: its term's undetermined parameters, null in results.json and
// flagged, and the combination the tests determine with its interval holding the truth.
json never_engaged(const std::string& truth_values, const std::string& term, int seed,
                   std::string& said) {
  const test::TempDir dir;
  const std::string terms = "terms = [\"k\", \"c\", \"" + term + "\"]\n";
  const auto records = simulate(dir.path(), terms + truth_values, "0.5,1", seed);
  const Outcome run = identify(dir.path(), terms, records);
  EXPECT_EQ(run.status, 0) << run.err;
  if (run.status != 0) return json();
  const json j = json::parse(test::read_text(dir.path() / "result.json"));
  EXPECT_EQ(j["identifiability"].size(), 1u) << j["identifiability"].dump();
  if (j["identifiability"].empty()) return json();
  said = j["identifiability"][0];
  EXPECT_NE(run.out.find("not determined: joint 'tip': its " + term), std::string::npos) << run.out;
  return j;
}

TEST(IdentifyParametric, AJenkinsThatNeverSlipsSaysWhatTheTestsDetermine) {
  // fs/kt = 1e-3 m, beyond the tip's deformation at 0.5 and 1 N: the slider sticks, the joint is
  // k + kt = 14800 N/m in every test; fs and k apart from kt are undetermined.
  std::string said;
  const json j = never_engaged(
      "values = { k = 4800.0, c = 20.0, \"jenkins.kt\" = 1.0e4, \"jenkins.fs\" = 10.0 }\n",
      "jenkins", 51, said);
  ASSERT_FALSE(j.is_null());
  const json& t = j["joints"][0]["terms"];
  for (const char* name : {"jenkins.fs", "jenkins.kt"}) {
    EXPECT_FALSE(t[2]["parameters"][name]["determined"].get<bool>()) << name;
    EXPECT_TRUE(t[2]["parameters"][name]["value"].is_null()) << name;
  }
  EXPECT_TRUE(t[0]["value"].is_null()); // k apart from kt
  expect_within_interval(t[1], 20.0, "c");
  EXPECT_NE(said.find("its jenkins never slipped in any test"), std::string::npos) << said;
  EXPECT_NE(said.find("k apart from jenkins.kt, and jenkins.fs are undetermined"),
            std::string::npos)
      << said;
  expect_combination(said, "k + jenkins.kt = ", 14800.0);
}

TEST(IdentifyParametric, AGapThatNeverClosesSaysItsParametersAreUndetermined) {
  // delta = 5e-3 m, far beyond the tip's deformation at 0.5 and 1 N: the gap exerts no force,
  // k and c are the joint's, delta and kg undetermined.
  std::string said;
  const json j = never_engaged(
      "values = { k = 4800.0, c = 20.0, \"gap.delta\" = 5.0e-3, \"gap.kg\" = 2.0e4 }\n", "gap", 61,
      said);
  ASSERT_FALSE(j.is_null());
  const json& t = j["joints"][0]["terms"];
  for (const char* name : {"gap.delta", "gap.kg"}) {
    EXPECT_FALSE(t[2]["parameters"][name]["determined"].get<bool>()) << name;
    EXPECT_TRUE(t[2]["parameters"][name]["value"].is_null()) << name;
  }
  expect_within_interval(t[0], 4800.0, "k");
  expect_within_interval(t[1], 20.0, "c");
  EXPECT_NE(said.find("its gap never closed in any test"), std::string::npos) << said;
  EXPECT_NE(said.find("gap.delta and gap.kg are undetermined"), std::string::npos) << said;
  EXPECT_NE(said.find("delta exceeds"), std::string::npos) << said;
}

TEST(IdentifyParametric, RefusesWhatOutputErrorCannotTake) {
  const test::TempDir dir;
  const fs::path records = dir.path() / "records";
  fs::create_directories(records);
  const fs::path record = records / "r.csv"; // never read: the model is refused first
  test::write_text(record, "t,f@7:uy,x@7:uy\n0,0,0\n");
  // Without --output-error a non-fixed parametric term is named with what it needs, at the
  // line of its [[joints]] table.
  const std::string jenkins = "terms = [\"k\", \"c\", \"jenkins\"]\n";
  const std::string text = cantilever_with(jenkins);
  const auto line = std::count(text.begin(), text.begin() + text.find("[[joints]]"), '\n') + 1;
  const std::string at = (dir.path() / "unknown.toml").string() + ":" + std::to_string(line) + ":";
  const Outcome plain = identify(dir.path(), jenkins, {record.string()}, false);
  expect_one_line_error(plain, at);
  expect_one_line_error(plain, "joint 'tip': term 'jenkins' is not fixed: its parameters (kt, "
                               "fs) enter the joint's force non-linearly and need --output-error");
  EXPECT_FALSE(fs::exists(dir.path() / "result.json"));
  // Two parametric terms not fixed at one joint: output error takes one at a time.
  const Outcome two =
      identify(dir.path(), "terms = [\"k\", \"jenkins\", \"gap\"]\n", {record.string()});
  expect_one_line_error(two, at);
  expect_one_line_error(two, "joint 'tip': its terms jenkins and gap both have parameters that "
                             "are not fixed; output error identifies one parametric term of a "
                             "joint at a time");
  // One of them fixed: accepted up to the records (this one has no noise to weigh by).
  const Outcome one =
      identify(dir.path(),
               "terms = [\"k\", \"jenkins\", \"gap\"]\nvalues = { \"gap.delta\" = 5e-3, "
               "\"gap.kg\" = 2e4 }\nfixed = [\"gap\"]\n",
               {record.string()});
  EXPECT_NE(one.status, 0);
  EXPECT_EQ(one.err.find("both have parameters"), std::string::npos) << one.err;
  EXPECT_FALSE(fs::exists(dir.path() / "result.json"));
}

} // namespace
} // namespace jointid
