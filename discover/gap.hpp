#pragma once
/// The disagreement between a model and the measurement (discover.hpp defines the terms): the
/// values compared, their squared difference and χ², the gap, and the noise level.
#include "discover/discover.hpp"
#include "identify/measurement.hpp"

#include <Eigen/Core>

#include <complex>
#include <limits>
#include <vector>

namespace jointid::discover::detail {

/// A value compared: test i, response j, harmonic k (a displacement, m or rad). A periodic
/// test's value is one of its lines (Measurement::lines): `row` is the line, `harmonic` the
/// group it is judged in — 1 for an excited line, 2 (1 when only the fundamental is compared)
/// for a line where only the joints put response (harmonics and combinations).
struct Entry {
  int test = 0, response = 0, harmonic = 0;
  std::complex<double> measured;
  double variance = 0.0;   ///< E|δX|² of the measurement noise, NaN when unknown
  double simulation = 0.0; ///< E|δX|² of the simulation's own error (harmonic truncation)
  double force = 0.0;      ///< E|δX_sim|² from the noise in the measured force that drives it
  int row = 0;             ///< the row of the simulated harmonics: k, or a periodic test's line
  bool line = false;       ///< a periodic test's line (else a harmonic of a sine test)
  /// The variance of the difference measured − simulated, and its real degrees of freedom.
  double total() const { return variance + simulation + force; }
  int dof() const { return harmonic == 0 ? 1 : 2; }
};

/// Every value compared, and what they add up to.
struct Compared {
  std::vector<Entry> entries;
  int tests = 0;           ///< the tests the entries come from
  int harmonics = 1;       ///< K: harmonics 0 … K are compared
  int values = 0;          ///< N: real values (harmonic 0 counts one, the others two)
  double measured2 = 0.0;  ///< Σ |X_meas|²
  bool noise_known = true; ///< every value's noise variance is known
  double noise_gap = std::numeric_limits<double>::quiet_NaN(); ///< the noise level, if known
};

/// The values of harmonics 0 … K at every response of every test: harmonic 0 only where the
/// mean displacement was measured, a table's harmonic 1 only; a periodic test's lines
/// (Measurement::lines, its mean not compared). The noise level is that of the
/// responses' own noise (estimate_simulation_error adds the force's). Throws
/// std::invalid_argument when every response is zero.
Compared compared_values(const std::vector<identify::Measurement>& tests, int harmonics);

/// Σ |X_meas − X_sim|² over the compared values, and χ² = Σ dof · |X_meas − X_sim|² / total
/// (NaN when the noise is unknown), with the real values N and Σ |X_meas|² they cover.
struct Misfit {
  double squared = 0.0;
  double chi2 = 0.0;
  int values = 0;         ///< N of the values summed; 0: all of the Compared's
  double measured2 = 0.0; ///< their Σ |X_meas|²; 0: all of the Compared's
};
/// X: per test, (K+1) × responses. The tests `left_out` (ascending; their re-simulation did not
/// converge) are not summed.
Misfit misfit(const Compared& compared, const std::vector<Eigen::MatrixXcd>& X,
              const std::vector<int>& left_out = {});

/// The gap of a squared misfit: sqrt(S / Σ |X_meas|²).
double gap(const Compared& compared, double squared);
/// The gap of a misfit, over the values it covers.
double gap(const Compared& compared, const Misfit& misfit);

/// The most tests a state may leave out of its comparison because their re-simulation did not
/// converge (even from the measured response): a tenth of them, rounded down. A model that
/// cannot re-simulate more is not compared at all: what it leaves out could be what decides.
int max_left_out(int tests);
/// The state can be compared: no more tests left out than max_left_out.
bool comparable(const Compared& compared, const State& state);
/// a ∪ b of two ascending lists of tests.
std::vector<int> united(const std::vector<int>& a, const std::vector<int>& b);

/// The noise level: the gap a perfect model would leave, from the responses' noise and the
/// measured force's, propagated (Entry::variance and Entry::force).
double noise_level(const Compared& compared);

/// χ² per value of each compared harmonic 0 … K (NaN where none is compared).
std::vector<double> chi2_by_harmonic(const Compared& compared,
                                     const std::vector<Eigen::MatrixXcd>& X);

/// At the noise level: the noise known, every test re-simulated, and its χ² per value within 3
/// standard deviations (√(2/N)) of 1, overall and for every compared harmonic on its own (so
/// that a misfit of the few large fundamentals is not averaged away by many small harmonics).
bool at_noise_level(const Compared& compared, const State& state);

} // namespace jointid::discover::detail
