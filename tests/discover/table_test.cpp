// Discovery on stepped-sine tables of more tests than a refinement's first stage takes (its
// spread: RefineScope::spread), where a parametric first addition makes discovery screen that
// path on the spread and follow it in full only where it is kept (discover.cpp). The tables are
// the bolted beam's stand-in (tests/support/bolted_beam.hpp): 6 force levels × 21 frequencies
// around the first mode, 1 % noise on every phasor, noise not stated (a table's).
#include "discover/discover.hpp"

#include "discover/problem.hpp"
#include "discover/refine.hpp"
#include "support/bolted_beam.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace jointid {
namespace {

using joints::Term;

// The table's rows as the sine tests `jointid discover TABLE` measures (io::stepped_sine_tests
// makes the same from a file), each row's source its index.
std::vector<identify::Measurement> measured(const identify::SteppedSineTable& table) {
  std::vector<identify::SineTest> tests;
  for (std::size_t i = 0; i < table.freq_hz.size(); ++i) {
    identify::Phasors row;
    row.source = "table.csv:" + std::to_string(i + 1);
    row.frequency_hz = table.freq_hz[i];
    for (std::size_t c = 0; c < table.channels.size(); ++c) {
      const identify::Channel ch = identify::parse_channel_name(table.channels[c]);
      row.channels.push_back(
          {ch.quantity, ch.at,
           table.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c))});
    }
    tests.emplace_back(std::move(row));
  }
  return identify::measure(tests, {.harmonics = 1});
}

const discover::Step* step_adding(const discover::Result& r, Term term) {
  for (const auto& s : r.steps)
    if (s.added.joint == "bolt" && s.added.term == term) return &s;
  return nullptr;
}

double value_in(const discover::State& state, Term term) {
  const joints::Joint& j = state.joints.front();
  const int t = j.term_index(term);
  return t < 0 ? std::numeric_limits<double>::quiet_NaN() : j.values[static_cast<std::size_t>(t)];
}

std::string described(const discover::Result& r) {
  std::string s = "steps:";
  for (const auto& step : r.steps) {
    s += ' ';
    s += step.added.name();
    s += ';';
  }
  for (const auto& f : r.diagnosis.findings) {
    s += '\n';
    s += f;
  }
  s += "\nstop: ";
  s += r.stop_reason;
  return s;
}

struct Table {
  fem::Model model = test::bolted_beam();
  frf::Substructure sub{model};
  std::vector<identify::Measurement> tests;
  explicit Table(const joints::Joint& truth)
      : tests(measured(test::stepped_sine_table(
            model, truth, test::stepped_sine_plan(6, 0.1, 1.5, 21, 66.0, 86.0)))) {}
};

TEST(DiscoverTable, ACubicJointsTableKeepsTheCoefficientPathOverTheScreenedIwan) {
  // The truth: k3 and c3 (a softening stiffness, a damping that grows with amplitude). The iwan
  // does both at once and is the best first addition; its path is screened on 96 of the 126
  // tests, and the coefficient path, k3 and c3, ends clearly lower and is kept. Its first two
  // steps are the hidden terms, their values within 5 % of the truth (the 1 % noise on force and
  // response, unweighted near the resonance, leaves 3–4 %), the gap at 6.5 % of the start's.
  // Beyond them, terms that explain a few per cent of what is left may follow (the noise level
  // is unknown to a table); they are not asserted.
  const Table d(test::bolt_truth());
  ASSERT_GT(d.tests.size(), 96u);
  const discover::Result r = discover::discover(d.sub, {test::bolt_start()}, d.tests);
  SCOPED_TRACE(described(r));
  ASSERT_GE(r.steps.size(), 2u);
  const discover::Step* k3 = step_adding(r, Term::k3);
  const discover::Step* c3 = step_adding(r, Term::c3);
  ASSERT_TRUE(k3 && c3);
  EXPECT_LT(std::max(k3 - r.steps.data(), c3 - r.steps.data()), 2);
  const discover::State& both = r.states[2];
  EXPECT_NEAR(value_in(both, Term::k3), -3e9, 0.05 * 3e9);
  EXPECT_NEAR(value_in(both, Term::c3), 10.0, 0.05 * 10.0);
  EXPECT_LT(r.gap[2], 0.1 * r.gap[0]);
  // The diagnosis says the parametric path was screened and lost clearly.
  bool said = false;
  for (const auto& f : r.diagnosis.findings)
    said = said || (f.find("the second is kept") != std::string::npos &&
                    f.find("screened past its first step") != std::string::npos &&
                    f.find("by more than") != std::string::npos);
  EXPECT_TRUE(said);
}

TEST(DiscoverTable, AnIwansTableKeepsTheIwanWithItsFullRefinement) {
  // The truth: an iwan in microslip beside k and c. Its path is screened past the first step
  // and kept (the coefficient path adds the iwan too, so is moot), so it is followed again in
  // full: the model discovery ends at is the iwan alone, refined on all 126 tests — the output
  // error from it on every test moves no value by more than 0.1 of its standard deviation.
  joints::Joint truth = test::bolt({Term::k, Term::c, Term::iwan}, {2e4, 2.0, 1.0});
  truth.parameters.resize(3);
  truth.set_parameters(2, {2.0, 2e4, -0.5, 0.1});
  const Table d(truth);
  const discover::Result r = discover::discover(d.sub, {test::bolt_start()}, d.tests);
  SCOPED_TRACE(described(r));
  ASSERT_EQ(r.steps.size(), 1u);
  ASSERT_TRUE(r.steps[0].added.term.has_value());
  EXPECT_EQ(*r.steps[0].added.term, Term::iwan);
  EXPECT_LT(r.gap.back(), 0.1 * r.gap.front());
  discover::detail::Problem problem(d.sub, {test::bolt_start()}, d.tests, discover::Options{});
  const discover::detail::Simulator& sim = problem.simulator(r.states.back().damping_scale);
  discover::State at = problem.evaluate(r.states.back().joints, sim);
  at.fit = r.states.back().fit;
  discover::detail::RefineScope one_stage;
  one_stage.spread = 0;
  const discover::State again = discover::detail::refine(problem, at, sim, one_stage);
  int checked = 0;
  for (const auto& te : at.fit.joints.front().terms) {
    const int t = at.joints.front().term_index(te.term);
    if (te.parameters.empty() && std::isfinite(te.std)) {
      EXPECT_NEAR(again.joints.front().values[static_cast<std::size_t>(t)], te.value, 0.1 * te.std)
          << joints::term_name(te.term);
      ++checked;
    }
    for (const auto& pe : te.parameters)
      if (pe.determined) {
        EXPECT_NEAR(again.joints.front().parameter(static_cast<std::size_t>(t), pe.name), pe.value,
                    0.1 * pe.std)
            << pe.name;
        ++checked;
      }
  }
  EXPECT_GE(checked, 4);
}

} // namespace
} // namespace jointid
