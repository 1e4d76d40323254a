#include "discover/curves.hpp"

#include "discover/selection.hpp"
#include "discover/text.hpp"
#include "fem/constants.hpp"
#include "fem/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>

namespace jointid::discover::detail {

namespace {

// The tests swept through: grouped by force level (a sweep over frequency) or by frequency.
struct Sweeps {
  bool over_frequency = true;
  std::vector<double> frequency, level; ///< per test
  std::vector<int> group;               ///< per test
  std::vector<double> means;            ///< per group: its level (or frequency)
};

// One group's sweep, up or down.
ResponseCurve sweep(const Problem& problem, const State& state,
                    const frf::ModalSynthesis& synthesis, const Sweeps& s, std::size_t g,
                    bool down) {
  const auto& tests = problem.tests();
  const bool over_frequency = s.over_frequency;
  // The group's tests: their span, and the first one's force DOF and outputs.
  double lo = inf, hi = -inf;
  int first = -1, count = 0;
  for (std::size_t i = 0; i < tests.size(); ++i)
    if (s.group[i] == static_cast<int>(g)) {
      const double x = over_frequency ? s.frequency[i] : s.level[i];
      lo = std::min(lo, x), hi = std::max(hi, x);
      if (first < 0) first = static_cast<int>(i);
      ++count;
    }
  // At least a point between every two tests (a stepped sweep's resonance peak is as narrow as
  // its steps), up to four times the points asked.
  const int asked = problem.options().curve_points;
  const int points = std::clamp(2 * count - 1, asked, 4 * asked);
  const auto& m = tests[first];
  ResponseCurve c;
  c.over_frequency = over_frequency;
  c.descending = down;
  c.level = over_frequency ? s.means[g] : 0.0;
  c.frequency_hz = over_frequency ? 0.0 : s.means[g];
  for (std::size_t j = 0; j < m.response_at.size(); ++j) {
    c.channels.push_back(channel_name(m, j));
    c.X1.emplace_back();
  }
  if (hi <= lo) hi = lo * 1.001, lo *= 0.999;
  const std::vector<int> force{problem.force_equations(first).front()};
  const std::vector<int>& responses = problem.response_equations(first);
  std::optional<Eigen::MatrixXcd> previous;
  std::optional<frf::HarmonicBalance> fixed_frequency;
  for (int p = 0; p < points; ++p) {
    if (problem.options().checkpoint) problem.options().checkpoint();
    const double u = static_cast<double>(down ? points - 1 - p : p) / (points - 1);
    const double x = over_frequency ? lo + (hi - lo) * u : lo * std::pow(hi / lo, u);
    const double f = over_frequency ? x : s.means[g], amplitude = over_frequency ? s.means[g] : x;
    std::optional<frf::HarmonicBalance> at_f;
    if (over_frequency || !fixed_frequency)
      (over_frequency ? at_f : fixed_frequency)
          .emplace(synthesis, problem.layout(), problem.dofs(), force, responses, f,
                   problem.options().balance);
    const frf::HarmonicBalance& hb = over_frequency ? *at_f : *fixed_frequency;
    frf::HarmonicBalanceResult r;
    const Eigen::MatrixXcd F = frf::sine_force(amplitude);
    if (friction_problem(state.joints).empty()) {
      r = hb.solve(state.joints, F, previous ? &*previous : nullptr);
      if (!r.status.ok() && previous) r = hb.solve(state.joints, F);
    }
    c.x.push_back(x);
    c.converged.push_back(r.status.ok());
    for (std::size_t j = 0; j < c.channels.size(); ++j)
      c.X1[j].push_back(r.status.ok() ? r.X(1, static_cast<Eigen::Index>(j))
                                      : std::complex<double>(nan, nan));
    if (r.status.ok()) previous = r.Y;
  }
  if (down) { // ascending order, as the sweep up
    std::reverse(c.x.begin(), c.x.end());
    std::reverse(c.converged.begin(), c.converged.end());
    for (auto& X : c.X1)
      std::reverse(X.begin(), X.end());
  }
  return c;
}

} // namespace

std::pair<std::vector<int>, std::vector<double>> cluster(const std::vector<double>& v,
                                                         double tolerance) {
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::vector<double>> groups;
  for (double x : sorted)
    if (groups.empty() || x - groups.back().back() > tolerance * std::abs(x))
      groups.push_back({x});
    else
      groups.back().push_back(x);
  std::vector<double> means;
  for (const auto& g : groups)
    means.push_back(std::accumulate(g.begin(), g.end(), 0.0) / static_cast<double>(g.size()));
  std::vector<int> of(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t g = 0; g < groups.size(); ++g)
      if (v[i] >= groups[g].front() && v[i] <= groups[g].back()) of[i] = static_cast<int>(g);
  return {of, means};
}

std::vector<ResponseCurve> curves(const Problem& problem, const State& state) {
  std::vector<ResponseCurve> out;
  if (problem.options().curve_points < 2) return out;
  // A periodic broadband test is at no one frequency: there is no sine sweep through it.
  for (const auto& m : problem.tests())
    if (m.kind == identify::RecordKind::periodic) return out;
  Sweeps s;
  for (const auto& m : problem.tests())
    s.frequency.push_back(m.frequency_hz), s.level.push_back(identify::force_level(m));
  // Frequencies apart by 0.01 % are other frequencies: a stepped sine's steps near a resonance
  // are fine (0.25 Hz at 75 Hz is 0.33 %), and grouped by a coarser tolerance, step after step,
  // its whole sweep would be one "frequency". Force levels within 3 % are one level.
  auto [fg, fmeans] = cluster(s.frequency, 1e-4);
  auto [lg, lmeans] = cluster(s.level, 0.03);
  s.over_frequency = fmeans.size() >= lmeans.size();
  s.group = s.over_frequency ? lg : fg;
  s.means = s.over_frequency ? lmeans : fmeans;
  const frf::ModalSynthesis synthesis =
      state.damping_scale == 1.0 ? problem.synthesis()
                                 : problem.synthesis().with_damping_scale(state.damping_scale);
  std::vector<std::function<ResponseCurve()>> jobs;
  for (std::size_t g = 0; g < 2 * s.means.size(); ++g)
    jobs.push_back([&, g] { return sweep(problem, state, synthesis, s, g / 2, g % 2 == 1); });
  std::vector<ResponseCurve> both = fem::parallel_map(jobs);
  for (std::size_t g = 0; g < both.size(); g += 2) {
    const ResponseCurve& up = both[g];
    ResponseCurve& down = both[g + 1];
    double differs = 0.0;
    for (std::size_t j = 0; j < up.X1.size(); ++j)
      for (std::size_t p = 0; p < up.x.size(); ++p)
        if (up.converged[p] && down.converged[p])
          differs = std::max(differs, std::abs(up.X1[j][p] - down.X1[j][p]) /
                                          std::max(std::abs(up.X1[j][p]), 1e-300));
    out.push_back(std::move(both[g]));
    if (differs > 0.01) out.push_back(std::move(down));
  }
  return out;
}

} // namespace jointid::discover::detail
