// The diagnosis on disagreements made by hand: two tests at one frequency and two force levels,
// measured against a linear model's simulation. A response whose receptance falls with the level
// (a hardening joint) against one that is the same at both levels (a linear model error); the
// words the diagnosis chooses for each, and the rule that a non-linear term must beat a linear
// correction by more than ln N.
#include "discover/diagnosis.hpp"

#include "constructed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace jointid {
namespace {

using joints::Term;
using namespace discover::detail;
using test::candidate;

// The linear model's receptance at 3 Hz, m/N: real, and 2⁻¹⁰ so that X = R F and X / F are exact.
constexpr double H = 0.0009765625;

std::string all(const discover::Diagnosis& d) {
  std::string s;
  for (const auto& f : d.findings)
    s += f + "\n";
  return s;
}

bool says(const discover::Diagnosis& d, const std::string& words) {
  return all(d).find(words) != std::string::npos;
}

// Tests at 10 N and 40 N, 3 Hz, harmonics 0 … 2 (the mean not measured), the fundamental's
// receptance `R10` and `R40` and a second harmonic of `even` × the fundamental; the noise's
// standard deviation 1e-6 m on every harmonic.
std::vector<identify::Measurement> tests(double R10, double R40, double even = 0.0) {
  std::vector<identify::Measurement> out;
  for (auto [name, F, R] : {std::tuple{"f10", 10.0, R10}, std::tuple{"f40", 40.0, R40}})
    out.push_back(
        test::measurement(name, 3.0, F, {0.0, R * F, even * R * F}, {1e-12, 1e-12, 1e-12}, false));
  return out;
}

// The linear model: X = H F, no harmonics.
discover::State linear_model(double gap) {
  discover::State s = test::simulated({{0.0, 10.0 * H, 0.0}, {0.0, 40.0 * H, 0.0}});
  s.gap = gap;
  return s;
}

discover::Candidate explaining(std::optional<Term> term, double share, double criterion,
                               double value = 1.0) {
  discover::Candidate c = candidate(term, 0.1, criterion);
  c.explained = share;
  c.value = value;
  return c;
}

TEST(Diagnosis, AReceptanceThatFallsWithLevelIsNonLinearConservativeAtTheJoint) {
  // Measured receptance 0.96 H at 10 N, 0.8 H at 40 N: 20 % apart, where the noise allows
  // 1e-6 √(1/10² + 1/40²) / (0.8 H) = 0.0132 %.
  const auto measured = tests(0.96 * H, 0.8 * H);
  const Compared c = compared_values(measured, 2);
  ASSERT_EQ(c.values, 8);
  // The best non-linear term (k3, criterion 20) beats the best linear (the damping scale, 400)
  // by far more than ln 8.
  const std::vector<discover::Candidate> ranking{explaining(std::nullopt, 0.10, 400.0),
                                                 explaining(Term::k3, 0.97, 20.0, 1.6e8),
                                                 explaining(Term::c2, 0.20, 300.0)};
  const discover::Diagnosis d = diagnose(c, measured, linear_model(0.25), ranking, nullptr, {});
  ASSERT_TRUE(d.level_dependent.has_value());
  EXPECT_TRUE(*d.level_dependent);
  EXPECT_EQ(d.joint, "tip");
  EXPECT_EQ(d.nature, "conservative");
  EXPECT_EQ(d.channel, "x@7:uy");
  // ‖e‖/‖X‖ over the tests: errors 0.04 H·10 and 0.2 H·40 against 0.96 H·10 and 0.8 H·40.
  EXPECT_NEAR(d.channel_error, std::sqrt((0.16 + 64.0) / (0.96 * 0.96 * 100.0 + 0.64 * 1600.0)),
              1e-12);
  EXPECT_NEAR(d.linear_explains, 0.10, 1e-15);
  EXPECT_NEAR(d.nonlinear_explains, 0.97, 1e-15);
  EXPECT_TRUE(says(d, "At 3 Hz the measured receptance at x@7:uy changes by 20 % between "
                      "force amplitudes 10 and 40, far beyond what the noise allows (about "
                      "0.0132 %)."))
      << all(d);
  EXPECT_TRUE(says(d, "The disagreement changes with force level (non-linear): the best linear "
                      "correction (substructure damping) explains 10 % of it, the best "
                      "non-linear term (k3 at 'tip') 97 %."))
      << all(d);
  EXPECT_TRUE(says(d, "It sits at joint 'tip': terms at 'tip' explain 97 %; the substructure at "
                      "most 10 %."))
      << all(d);
  EXPECT_TRUE(says(d, "Conservative: a stiffness term (k3 at 'tip') explains 97 %, the best "
                      "damping term (c2 at 'tip') 20 % (hardening: the resonance rises with "
                      "level)."))
      << all(d);
  EXPECT_TRUE(says(d, "No even harmonics beyond the noise: the missing force is symmetric."))
      << all(d);
}

TEST(Diagnosis, TestsAtOneForceLevelNeverSayTheDisagreementChangesWithLevel) {
  // The same disagreement and ranking as above, from tests that the preconditions found to be
  // at one force level: the level dependence cannot be seen, and nothing may claim it.
  const auto measured = tests(0.96 * H, 0.8 * H);
  const Compared c = compared_values(measured, 2);
  const std::vector<discover::Candidate> ranking{explaining(std::nullopt, 0.10, 400.0),
                                                 explaining(Term::k3, 0.97, 20.0, 1.6e8),
                                                 explaining(Term::c2, 0.20, 300.0)};
  Preconditions one_level;
  one_level.several_levels = false;
  const discover::Diagnosis d =
      diagnose(c, measured, linear_model(0.25), ranking, nullptr, one_level);
  EXPECT_FALSE(d.level_dependent.has_value());
  EXPECT_FALSE(says(d, "changes with force level")) << all(d);
  EXPECT_FALSE(says(d, "with level")) << all(d);
  EXPECT_TRUE(says(d, "The tests are all at one force level: they cannot tell whether the "
                      "disagreement changes with the level."))
      << all(d);
}

TEST(Diagnosis, AReceptanceTheSameAtBothLevelsIsALinearModelError) {
  // Measured X = 1.125 H F at both levels: the noise explains the change (0); the damping scale
  // explains 95 %. k3's criterion is lower, 49 against 50, but by less than ln 8 = 2.08: one
  // parameter's worth is not evidence of a non-linear effect.
  const auto measured = tests(1.125 * H, 1.125 * H);
  const Compared c = compared_values(measured, 2);
  const std::vector<discover::Candidate> ranking{explaining(std::nullopt, 0.95, 50.0),
                                                 explaining(Term::k3, 0.96, 49.0, 1e7)};
  const discover::Diagnosis d = diagnose(c, measured, linear_model(0.1), ranking, nullptr, {});
  ASSERT_TRUE(d.level_dependent.has_value());
  EXPECT_FALSE(*d.level_dependent);
  EXPECT_EQ(d.joint, "substructure");
  EXPECT_EQ(d.nature, "");
  EXPECT_TRUE(says(d, "changes by 0 % between force amplitudes 10 and 40, which the noise "
                      "explains"))
      << all(d);
  EXPECT_TRUE(says(d, "The disagreement does not change with force level: a linear model error. "
                      "The best linear correction (substructure damping) explains 95 % of it, "
                      "the best non-linear term (k3 at 'tip') 96 %; no non-linear term does "
                      "better."))
      << all(d);
  EXPECT_TRUE(says(d, "It sits at the substructure: its damping explains 95 %; terms at 'tip' at "
                      "most 96 %."))
      << all(d);
}

TEST(Diagnosis, ANonLinearTermMustBeatALinearCorrectionByMoreThanLnN) {
  // N = 8: ln 8 = 2.0794.
  EXPECT_FALSE(changes_with_level(50.0, 48.0, 8));
  EXPECT_TRUE(changes_with_level(50.0, 47.9, 8));
  EXPECT_FALSE(changes_with_level(50.0, 50.0 - 0.99 * std::log(1000.0), 1000));
  EXPECT_TRUE(changes_with_level(50.0, 50.0 - 1.01 * std::log(1000.0), 1000));
}

TEST(Diagnosis, EvenHarmonicsInEveryTestPointToAnAsymmetricForce) {
  // A second harmonic of 5 % of the fundamental in both tests, which the model lacks.
  const auto measured = tests(0.96 * H, 0.8 * H, 0.05);
  const Compared c = compared_values(measured, 2);
  const std::vector<discover::Candidate> ranking{explaining(std::nullopt, 0.10, 400.0),
                                                 explaining(Term::k2, 0.90, 20.0, 5e4)};
  const discover::Diagnosis d = diagnose(c, measured, linear_model(0.25), ranking, nullptr, {});
  EXPECT_TRUE(d.even_harmonics);
  EXPECT_TRUE(d.asymmetric);
  EXPECT_NEAR(d.even_content, 0.05, 1e-12);
  EXPECT_TRUE(says(d, "Even harmonics: the measured response at x@7:uy holds a second harmonic of "
                      "5 % of its fundamental in f40 (and 1 other tests) that the model does "
                      "not produce"))
      << all(d);
  EXPECT_TRUE(says(d, ": an asymmetric force (k2 explains 90 %)."));
}

TEST(Diagnosis, NothingAdmissibleSaysNothingIsMissing) {
  const auto measured = tests(H, H);
  const Compared c = compared_values(measured, 2);
  std::vector<discover::Candidate> ranking{explaining(Term::k3, 0.01, 60.0)};
  ranking[0].rejected = "explains too little";
  const discover::Diagnosis d = diagnose(c, measured, linear_model(0.001), ranking, nullptr, {});
  EXPECT_FALSE(d.level_dependent.has_value());
  EXPECT_TRUE(says(d, "No candidate explains a significant share of the disagreement: nothing is "
                      "missing that these tests can reveal."))
      << all(d);
}

TEST(Diagnosis, LevelEvidenceWithoutNoiseGivesNoVerdict) {
  auto measured = tests(0.96 * H, 0.8 * H);
  for (auto& m : measured)
    m.X_variance.setConstant(test::unknown);
  EXPECT_EQ(level_evidence(measured),
            (std::vector<std::string>{"At 3 Hz the measured receptance at x@7:uy changes by "
                                      "20 % between force amplitudes 10 and 40."}));
  // Levels less than 1.5× apart, or frequencies 0.5 % apart, are not compared.
  measured[1].F(1, 0) = 14.0;
  EXPECT_TRUE(level_evidence(measured).empty());
}

// What a joint does against its amplitude, from each test's equivalent stiffness: points made
// from the describing function of a known joint (k = 4800 N/m, c = 20 N s/m and the term),
// amplitudes spread geometrically as a sweep's are, frequencies 2 … 5 Hz.
discover::JointBehaviour behaviour_of(Term term, const std::vector<double>& parameters, double a0,
                                      double a1, double k3 = 0.0) {
  joints::Joint j{"tip",          7, 0, fem::Dof::uy, {Term::k, Term::c}, {4800.0, 20.0},
                  {false, false}, {}};
  if (k3 != 0.0) {
    j.terms.push_back(Term::k3), j.values.push_back(k3), j.fixed.push_back(false);
  } else if (!parameters.empty()) {
    j.terms.push_back(term), j.values.push_back(1.0), j.fixed.push_back(false);
    j.parameters.resize(3);
    j.set_parameters(2, parameters);
  }
  std::vector<identify::EquivalentStiffness> points;
  std::vector<std::string> names;
  const int n = 21;
  for (int i = 0; i < n; ++i) {
    // Amplitude and frequency shuffled against each other (i·8 mod 21), as in a sweep at levels.
    const double a = a0 * std::pow(a1 / a0, ((i * 8) % n) / (n - 1.0));
    const double w = 2.0 * std::numbers::pi * (2.0 + 3.0 * i / (n - 1.0));
    points.push_back({a, w, joint_describing_function(j, a, w)});
    names.push_back(std::to_string(i));
  }
  return behaviour("tip", points, names);
}

TEST(JointBehaviour, AJenkinsSlidingIsMacroslip) {
  // kt 5000 N/m, fs 5 N: it slides beyond 1 mm; D = 4 fs (a − fs/kt) grows as a: power 1.
  const auto b = behaviour_of(Term::jenkins, {5000.0, 5.0}, 0.003, 0.06);
  EXPECT_EQ(b.behaviour, "macroslip") << b.finding;
  EXPECT_NEAR(b.slope, 1.0, 0.2) << b.finding;
  // The stuck spring is lost as it slides: a Jenkins element's k_eq = kt/π (β − sin 2β / 2),
  // cos β = 1 − 2 fs/(kt a), beside k: 4800 + 1459.1 at 3 mm, 4800 + 18.0 at 6 cm.
  const auto jenkins_k = [](double a) {
    const double beta = std::acos(1.0 - 2.0 * 5.0 / (5000.0 * a));
    return 4800.0 + 5000.0 / std::numbers::pi * (beta - std::sin(2.0 * beta) / 2.0);
  };
  EXPECT_NEAR(b.stiffness_change, jenkins_k(0.06) / jenkins_k(0.003) - 1.0, 1e-3);
  EXPECT_NE(b.finding.find("macroslip"), std::string::npos);
}

TEST(JointBehaviour, AStiffnessNearZeroAtSmallAmplitudesChangesInNewtonsPerMetreNotPerCent) {
  // A substructure fitted to a low-level test holds the stuck joint's stiffness: the joint is a
  // correction, k = -kt beside its Jenkins element, about 0 at small amplitudes. Its change is
  // said from one value to the other (a per cent of about 0 would be anything).
  joints::Joint j{"tip",
                  7,
                  0,
                  fem::Dof::uy,
                  {Term::k, Term::c, Term::jenkins},
                  {-5000.0, 0.0, 1.0},
                  {false, false, false},
                  {}};
  j.parameters.resize(3);
  j.set_parameters(2, {5000.0, 5.0});
  std::vector<identify::EquivalentStiffness> points;
  std::vector<std::string> names;
  for (int i = 0; i < 8; ++i) {
    const double a = 5e-4 * std::pow(40.0, i / 7.0), w = 2.0 * std::numbers::pi * 3.0;
    points.push_back({a, w, joint_describing_function(j, a, w)});
    names.push_back(std::to_string(i));
  }
  const auto b = behaviour("tip", points, names);
  EXPECT_LT(std::abs(b.stiffness.front()), 1e-6 * 5000.0) << b.finding; // stuck at 0.5 mm
  EXPECT_NE(b.finding.find("stiffness falls from"), std::string::npos) << b.finding;
  EXPECT_EQ(b.finding.find("stiffness falls by"), std::string::npos) << b.finding;
}

TEST(JointBehaviour, AnIwanInMicroslipGrowsAsThreePlusChi) {
  // fs 100 N, kt 3000 N/m, beta 0.1: phi_max = 8.5 cm, beyond every amplitude; chi = −0.5, so
  // D ∝ a^2.5 (Segalman), against viscous damping's a².
  const auto b = behaviour_of(Term::iwan, {100.0, 3000.0, -0.5, 0.1}, 0.002, 0.05);
  EXPECT_EQ(b.behaviour, "microslip") << b.finding;
  EXPECT_NEAR(b.slope, 2.5, 0.15) << b.finding;
  EXPECT_NE(b.finding.find("chi"), std::string::npos);
}

TEST(JointBehaviour, AGapIsAClearanceWhereContactIsMade) {
  // delta 1 cm, kg 5000 N/m: no dissipation of its own, the stiffness constant up to 1 cm.
  const auto b = behaviour_of(Term::gap, {0.01, 5000.0}, 0.002, 0.05);
  EXPECT_EQ(b.behaviour, "clearance") << b.finding;
  EXPECT_NEAR(b.contact_amplitude, 0.01, 0.002) << b.finding;
  EXPECT_GT(b.stiffness_change, 0.3);
}

TEST(JointBehaviour, ADampingThatGrowsBesideAHardeningIsNotNamedMicroslip) {
  // A ground-vibration test's joint: c2 = 500 N s²/m² (D = 8/3 c2 ω² a³: power 3, as a
  // microslip's with chi = 0) beside k3 = 1.6e8 N/m³ (k_eq = k + 3/4 k3 a²: it rises). Slip
  // would soften the joint: the finding must not name microslip.
  joints::Joint j{"tip",
                  7,
                  0,
                  fem::Dof::uy,
                  {Term::k, Term::c, Term::c2, Term::k3},
                  {4800.0, 20.0, 500.0, 1.6e8},
                  {false, false, false, false},
                  {}};
  std::vector<identify::EquivalentStiffness> points;
  std::vector<std::string> names;
  for (int i = 0; i < 8; ++i) {
    const double a = 5e-4 * std::pow(6.0, i / 7.0), w = 2.0 * std::numbers::pi * 4.5;
    points.push_back({a, w, joint_describing_function(j, a, w)});
    names.push_back(std::to_string(i));
  }
  const auto b = behaviour("tip", points, names);
  EXPECT_NEAR(b.slope, 3.0, 0.15) << b.finding;
  const auto k_eq = [](double a) { return 4800.0 + 0.75 * 1.6e8 * a * a; };
  EXPECT_NEAR(b.stiffness_change, k_eq(3e-3) / k_eq(5e-4) - 1.0, 1e-9) << b.finding; // 0.217
  EXPECT_EQ(b.behaviour, "") << b.finding;
  EXPECT_EQ(b.finding.find("microslip"), std::string::npos) << b.finding;
  EXPECT_NE(b.finding.find("not slip alone"), std::string::npos) << b.finding;
  // The same dissipation with a stiffness that falls (an Iwan's microslip) is still named so:
  // AnIwanInMicroslipGrowsAsThreePlusChi.
}

TEST(JointBehaviour, ACubicStiffnessOrAViscousJointIsNeitherSlipNorClearance) {
  // k3 stiffens from zero amplitude on (k_eq = k + 3/4 k3 a²): not a contact closing.
  const auto cubic = behaviour_of(Term::k3, {}, 0.002, 0.05, 1.6e8);
  EXPECT_EQ(cubic.behaviour, "") << cubic.finding;
  EXPECT_TRUE(std::isnan(cubic.contact_amplitude));
  const auto linear = behaviour_of(Term::k, {}, 0.002, 0.05);
  EXPECT_EQ(linear.behaviour, "") << linear.finding;
  EXPECT_NE(linear.finding.find("no sign of slip"), std::string::npos);
  // One amplitude: nothing to say about a trend.
  EXPECT_TRUE(behaviour_of(Term::jenkins, {5000.0, 5.0}, 0.01, 0.01).finding.empty());
}

} // namespace
} // namespace jointid
