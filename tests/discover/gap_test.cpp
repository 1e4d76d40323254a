// The values compared and the gap on measurements made by hand: which harmonics count, N, the
// noise level, χ² per harmonic and the noise-level test at its boundary.
#include "discover/gap.hpp"

#include "constructed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace jointid {
namespace {

using namespace discover::detail;
using test::unknown;

TEST(ComparedValues, CountHarmonicsWithTheirNoise) {
  // Test a: harmonics 0 … 2, the mean measured: 1 + 2 + 2 = 5 values. Test b: its mean not
  // measured (derived from acceleration): harmonics 1, 2 only, 4 values.
  const Compared c = compared_values(
      {test::measurement("a", 3.0, 10.0, {0.3, {0.0, 4.0}, 0.0}, {0.01, 0.04, 0.04}),
       test::measurement("b", 3.5, 20.0, {0.5, 3.0, {0.0, 1.0}}, {0.01, 0.02, 0.02}, false)},
      2);
  ASSERT_EQ(c.entries.size(), 5u);
  EXPECT_EQ(c.values, 9);
  EXPECT_EQ(c.harmonics, 2);
  EXPECT_TRUE(c.noise_known);
  // Σ|X|² = 0.09 + 16 + 0 + 9 + 1 = 26.09; Σ variance = 0.01 + 0.04 + 0.04 + 0.02 + 0.02.
  EXPECT_NEAR(c.measured2, 26.09, 1e-12);
  EXPECT_NEAR(c.noise_gap, std::sqrt(0.13 / 26.09), 1e-15);
  EXPECT_EQ(c.entries[3].test, 1);
  EXPECT_EQ(c.entries[3].harmonic, 1);
  EXPECT_EQ(c.entries[0].dof(), 1);
  EXPECT_EQ(c.entries[1].dof(), 2);
}

TEST(ComparedValues, ATableGivesTheFundamentalAndNoNoiseLevel) {
  identify::Measurement m =
      test::measurement("row 3", 3.0, 10.0, {0.0, 2.0, 0.0}, {unknown, unknown, unknown}, false);
  m.fundamental_only = true;
  const Compared c = compared_values({m}, 2);
  ASSERT_EQ(c.entries.size(), 1u);
  EXPECT_EQ(c.values, 2);
  EXPECT_FALSE(c.noise_known);
  EXPECT_TRUE(std::isnan(c.noise_gap));
}

// A periodic test is compared at its lines, not at harmonics 0 … K: here lines 4 and 6 excited,
// 12 where only the joint puts response; lines 1 … 3, 5, 7 … 11 (noise) and the mean are not
// compared. The excited lines are judged as harmonic 1, the others as harmonic 2 (1 when only
// the fundamental is compared); the simulated value is read at the line's row.
TEST(ComparedValues, APeriodicTestAtItsLinesGroupedAsExcitedAndNot) {
  std::vector<std::complex<double>> X(13, 0.01);
  X[4] = 3.0, X[6] = {0.0, 4.0}, X[12] = 0.5;
  identify::Measurement m =
      test::measurement("multisine.csv", 0.25, 0.0, X, std::vector<double>(13, 0.02));
  m.kind = identify::RecordKind::periodic;
  m.lines = {4, 6, 12};
  m.excited_lines = {4, 6};
  const Compared c = compared_values({m}, 3);
  ASSERT_EQ(c.entries.size(), 3u);
  EXPECT_EQ(c.values, 6);
  const int rows[] = {4, 6, 12}, groups[] = {1, 1, 2};
  for (std::size_t e = 0; e < 3; ++e) {
    EXPECT_EQ(c.entries[e].row, rows[e]);
    EXPECT_EQ(c.entries[e].harmonic, groups[e]);
    EXPECT_TRUE(c.entries[e].line);
  }
  // Σ|X|² = 9 + 16 + 0.25; the noise level from the three lines' variances.
  EXPECT_NEAR(c.measured2, 25.25, 1e-12);
  EXPECT_NEAR(c.noise_gap, std::sqrt(0.06 / 25.25), 1e-15);
  EXPECT_EQ(compared_values({m}, 1).entries[2].harmonic, 1);
  // Simulated exactly at the excited lines, 0 at line 12: the misfit is line 12's alone.
  std::vector<std::complex<double>> sim(13, 0.0);
  sim[4] = 3.0, sim[6] = {0.0, 4.0};
  const Misfit f = misfit(c, test::simulated({sim}).X);
  EXPECT_NEAR(f.squared, 0.25, 1e-15);
  EXPECT_NEAR(f.chi2, 2.0 * 0.25 / 0.02, 1e-12);
  const std::vector<double> chi2 = chi2_by_harmonic(c, test::simulated({sim}).X);
  EXPECT_NEAR(chi2[1], 0.0, 1e-15);
  EXPECT_NEAR(chi2[2], 0.25 / 0.02, 1e-12);
  EXPECT_TRUE(std::isnan(chi2[0]) && std::isnan(chi2[3]));
}

TEST(ComparedValues, EveryResponseZeroIsRefused) {
  try {
    (void)compared_values({test::measurement("a", 3.0, 10.0, {0.0, 0.0}, {0.1, 0.1})}, 1);
    ADD_FAILURE() << "zero responses were accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "discover: every response is zero");
  }
}

TEST(Gap, MisfitAndNoiseLevelAgainstHandComputedValues) {
  Compared c =
      compared_values({test::measurement("a", 3.0, 10.0, {0.0, {3.0, 4.0}}, {0.5, 0.5}, false)}, 1);
  // Measured 3 + 4i, simulated 3: S = 16, |X|² = 25, gap 0.8; χ² = 2 · 16 / 0.5 = 64.
  const Misfit m = misfit(c, test::simulated({{0.0, 3.0}}).X);
  EXPECT_DOUBLE_EQ(m.squared, 16.0);
  EXPECT_DOUBLE_EQ(m.chi2, 64.0);
  EXPECT_DOUBLE_EQ(gap(c, m.squared), 0.8);
  // The simulation's own error and the force's noise widen the variance of the difference; the
  // force's noise also raises the noise level, the simulation's error does not.
  c.entries[0].simulation = 0.3, c.entries[0].force = 0.2;
  EXPECT_DOUBLE_EQ(misfit(c, test::simulated({{0.0, 3.0}}).X).chi2, 2.0 * 16.0 / 1.0);
  EXPECT_DOUBLE_EQ(noise_level(c), std::sqrt(0.7 / 25.0));
}

TEST(Gap, AtTheNoiseLevelOverallAndPerHarmonic) {
  // 50 tests of harmonics 1 and 2 (N = 200, 100 per harmonic), each harmonic's variance 1: an
  // error e contributes χ² = 2 |e|² over its two real values, |e|² per value.
  std::vector<identify::Measurement> tests;
  for (int i = 0; i < 50; ++i)
    tests.push_back(test::measurement("t", 3.0, 10.0, {0.0, 10.0, 1.0}, {1.0, 1.0, 1.0}, false));
  const Compared c = compared_values(tests, 2);
  ASSERT_EQ(c.values, 200);
  auto state = [&](std::complex<double> e1, std::complex<double> e2) {
    discover::State s = test::simulated(
        std::vector<std::vector<std::complex<double>>>(50, {0.0, 10.0 - e1, 1.0 - e2}));
    s.chi2 = misfit(c, s.X).chi2;
    return s;
  };
  // Errors of 1 everywhere: χ²/N = 1 exactly.
  EXPECT_TRUE(at_noise_level(c, state(1.0, 1.0)));
  const std::vector<double> per_harmonic = chi2_by_harmonic(c, state(1.0, 1.0).X);
  ASSERT_EQ(per_harmonic.size(), 3u);
  EXPECT_TRUE(std::isnan(per_harmonic[0]));
  EXPECT_DOUBLE_EQ(per_harmonic[1], 1.0);
  // The fundamentals at χ²/n = 1.44 (error 1.2): 1.44 > 1 + 3 √(2/100) = 1.424 on its own, while
  // the whole (χ²/N = 1.22 < 1 + 3 √(2/200) = 1.3) passes: not at the noise level.
  const discover::State s = state(1.2, 1.0);
  EXPECT_NEAR(s.chi2 / 200.0, 1.22, 1e-12);
  EXPECT_FALSE(at_noise_level(c, s));
  EXPECT_TRUE(at_noise_level(c, state(1.19, 1.0))) << "1.19² = 1.416 < 1.424";
  // Not converged, or the noise unknown: never at the noise level.
  discover::State unconverged = state(1.0, 1.0);
  unconverged.converged = false;
  EXPECT_FALSE(at_noise_level(c, unconverged));
}

} // namespace
} // namespace jointid
