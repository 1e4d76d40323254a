#include "discover/gap.hpp"

#include "fem/constants.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

namespace jointid::discover::detail {

namespace {} // namespace

Compared compared_values(const std::vector<identify::Measurement>& tests, int harmonics) {
  Compared c;
  c.tests = static_cast<int>(tests.size());
  c.harmonics = harmonics;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const auto& m = tests[i];
    const bool periodic = m.kind == identify::RecordKind::periodic;
    for (std::size_t j = 0; j < m.response_at.size(); ++j)
      for (int k : periodic ? m.lines : std::vector<int>()) {
        const bool excited = std::binary_search(m.excited_lines.begin(), m.excited_lines.end(), k);
        Entry e{static_cast<int>(i), static_cast<int>(j), excited ? 1 : std::min(2, harmonics),
                m.X(k, static_cast<Eigen::Index>(j)),
                m.X_variance(k, static_cast<Eigen::Index>(j))};
        e.row = k;
        e.line = true;
        c.entries.push_back(e);
        c.values += 2;
        c.measured2 += std::norm(e.measured);
        if (!(e.variance > 0.0)) c.noise_known = false;
      }
    for (std::size_t j = 0; j < m.response_at.size() && !periodic; ++j)
      for (int k = 0; k <= harmonics; ++k) {
        if (!m.has_harmonic(k) || (k == 0 && !m.has_mean[j])) continue;
        c.entries.push_back({static_cast<int>(i), static_cast<int>(j), k,
                             m.X(k, static_cast<Eigen::Index>(j)),
                             m.X_variance(k, static_cast<Eigen::Index>(j)), 0.0, 0.0, k});
        c.values += k == 0 ? 1 : 2;
        c.measured2 += std::norm(c.entries.back().measured);
        if (!(c.entries.back().variance > 0.0)) c.noise_known = false;
      }
  }
  if (!(c.measured2 > 0.0)) throw std::invalid_argument("discover: every response is zero");
  if (c.noise_known) c.noise_gap = noise_level(c);
  return c;
}

Misfit misfit(const Compared& compared, const std::vector<Eigen::MatrixXcd>& X,
              const std::vector<int>& left_out) {
  Misfit m;
  for (const auto& e : compared.entries) {
    if (std::binary_search(left_out.begin(), left_out.end(), e.test)) continue;
    const double d = std::norm(e.measured - X[e.test](e.row, e.response));
    m.squared += d;
    m.chi2 += compared.noise_known ? e.dof() * d / e.total() : 0.0;
    m.values += e.dof();
    m.measured2 += std::norm(e.measured);
  }
  if (!compared.noise_known) m.chi2 = nan;
  return m;
}

double gap(const Compared& compared, double squared) {
  return std::sqrt(squared / compared.measured2);
}

double gap(const Compared& compared, const Misfit& misfit) {
  return std::sqrt(misfit.squared /
                   (misfit.measured2 > 0.0 ? misfit.measured2 : compared.measured2));
}

int max_left_out(int tests) {
  return tests / 10;
}

bool comparable(const Compared& compared, const State& state) {
  return static_cast<int>(state.failed.size()) <= max_left_out(compared.tests);
}

std::vector<int> united(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out;
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

double noise_level(const Compared& compared) {
  double noise2 = 0.0;
  for (const auto& e : compared.entries)
    noise2 += e.variance + e.force;
  return std::sqrt(noise2 / compared.measured2);
}

std::vector<double> chi2_by_harmonic(const Compared& compared,
                                     const std::vector<Eigen::MatrixXcd>& X) {
  const int K = compared.harmonics;
  std::vector<double> chi2(K + 1, 0.0), n(K + 1, 0.0);
  for (const auto& e : compared.entries) {
    chi2[e.harmonic] += e.dof() * std::norm(e.measured - X[e.test](e.row, e.response)) / e.total();
    n[e.harmonic] += e.dof();
  }
  for (int k = 0; k <= K; ++k)
    chi2[k] = n[k] > 0 ? chi2[k] / n[k] : nan;
  return chi2;
}

bool at_noise_level(const Compared& compared, const State& state) {
  const int N = compared.values, K = compared.harmonics;
  if (!compared.noise_known || !state.converged) return false;
  if (!(state.chi2 / N <= 1.0 + 3.0 * std::sqrt(2.0 / N))) return false;
  std::vector<double> n(K + 1, 0.0);
  for (const auto& e : compared.entries)
    n[e.harmonic] += e.dof();
  const std::vector<double> chi2 = chi2_by_harmonic(compared, state.X);
  for (int k = 0; k <= K; ++k)
    if (n[k] > 0 && !(chi2[k] <= 1.0 + 3.0 * std::sqrt(2.0 / n[k]))) return false;
  return true;
}

} // namespace jointid::discover::detail
