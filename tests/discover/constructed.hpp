#pragma once
// Inputs made by hand for the unit tests of discovery's parts: measurements whose harmonics are
// given, candidates with given numbers, and states that simulate given harmonics.
#include "discover/discover.hpp"

#include <Eigen/Core>

#include <complex>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace jointid::test {

inline constexpr double unknown = std::numeric_limits<double>::quiet_NaN();

// A sine test driven and measured at 7:uy (displacement): the force's fundamental F1, the
// response's harmonics 0 … K (K = X.size() − 1) with their noise variances (NaN: unknown).
inline identify::Measurement measurement(const std::string& source, double frequency_hz,
                                         std::complex<double> F1,
                                         const std::vector<std::complex<double>>& X,
                                         const std::vector<double>& variance,
                                         bool has_mean = true) {
  identify::Measurement m;
  m.source = source;
  m.frequency_hz = frequency_hz;
  m.harmonics = static_cast<int>(X.size()) - 1;
  m.force_at = {{7, fem::Dof::uy}};
  m.F = Eigen::MatrixXcd::Zero(m.harmonics + 1, 1);
  m.F(1, 0) = F1;
  m.F_variance = Eigen::MatrixXd::Constant(m.harmonics + 1, 1, unknown);
  m.response_at = {{7, fem::Dof::uy}};
  m.measured_as = {identify::Quantity::displacement};
  m.X.resize(m.harmonics + 1, 1);
  m.X_variance.resize(m.harmonics + 1, 1);
  for (int k = 0; k <= m.harmonics; ++k)
    m.X(k, 0) = X[k], m.X_variance(k, 0) = variance[k];
  m.has_mean = {has_mean};
  return m;
}

// A state whose simulated harmonics are X (one column per test: harmonics 0 … K at 7:uy).
inline discover::State simulated(const std::vector<std::vector<std::complex<double>>>& X,
                                 int parameters = 2) {
  discover::State s;
  s.parameters = parameters;
  for (const auto& test : X) {
    Eigen::MatrixXcd x(static_cast<Eigen::Index>(test.size()), 1);
    for (std::size_t k = 0; k < test.size(); ++k)
      x(static_cast<Eigen::Index>(k), 0) = test[k];
    s.X.push_back(x);
  }
  return s;
}

// A candidate at joint 'tip' (or the substructure's damping scale: no term) with given numbers.
inline discover::Candidate candidate(std::optional<joints::Term> term, double gap, double criterion,
                                     double ci_low = 1.0, double ci_high = 2.0) {
  discover::Candidate c;
  c.joint = term ? "tip" : "substructure";
  c.term = term;
  c.value = 0.5 * (ci_low + ci_high);
  c.std = (ci_high - ci_low) / 3.92;
  c.ci_low = ci_low;
  c.ci_high = ci_high;
  c.gap = gap;
  c.criterion = criterion;
  return c;
}

} // namespace jointid::test
