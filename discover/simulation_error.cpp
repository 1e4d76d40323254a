// What a perfect model would still miss, besides the response's own noise (Problem):
//  - the simulation's error: every test solved again with twice the harmonics, and twice the
//    difference taken as the truncation error of the solution used (for an error falling like
//    1/K — dry friction: the switching times of a truncated velocity — that is what remains;
//    smooth joints' error falls exponentially and is negligible); or, where the model has dry
//    friction and the substructure is a finite element model, the difference from time
//    integration with exact stick–slip (for an even spread of at most 24 tests: the others
//    take the harmonic balance's);
//  - the noise of the measured force that drives the simulation, propagated through the model:
//    the fundamental of each force perturbed by its standard deviation, in phase and in
//    quadrature, E|δX|² = (|ΔX_re|² + |ΔX_im|²) / 2; a periodic test's excited lines all at once,
//    each by its own standard deviation (a line's response comes from its own force, the others'
//    reaching it only through the joints' non-linearity: a second-order effect of the noise).
#include "discover/problem.hpp"

#include "fem/constants.hpp"
#include "fem/parallel.hpp"
#include "fem/time_integration.hpp"
#include "identify/harmonics.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>

namespace jointid::discover::detail {

namespace {

using Complex = std::complex<double>;

bool has_friction(const std::vector<joints::Joint>& joints) {
  for (const auto& j : joints)
    if (j.term_index(joints::Term::fc) >= 0) return true;
  return false;
}

} // namespace

void Problem::propagate_force_noise(const State& s, const Simulator& sim) {
  // Per test (in parallel), the responses to its forces perturbed.
  std::vector<std::function<std::vector<Eigen::MatrixXcd>()>> jobs;
  for (std::size_t i = 0; i < tests_.size(); ++i)
    jobs.push_back([&, i] {
      std::vector<Eigen::MatrixXcd> moved;
      if (o_.checkpoint) o_.checkpoint();
      const auto& m = tests_[i];
      const bool periodic = m.kind == identify::RecordKind::periodic;
      const std::vector<int> lines = periodic ? m.excited_lines : std::vector<int>{1};
      for (Eigen::Index c = 0; c < drive_[i].cols(); ++c) {
        const double v = m.F_variance.size() > 0 ? m.F_variance(lines.front(), c) : nan;
        if (!(v > 0.0) || !compared_.noise_known) continue;
        for (Complex unit : {Complex(1.0, 0.0), Complex(0.0, 1.0)}) {
          Eigen::MatrixXcd F = drive_[i];
          for (int k : lines)
            F(k, c) += std::sqrt(m.F_variance(k, c)) * unit;
          frf::HarmonicBalanceResult r =
              sim.balance[i].solve(s.joints, F, s.Y[i].size() > 0 ? &s.Y[i] : nullptr);
          if (r.status.ok()) moved.push_back(std::move(r.X));
        }
      }
      return moved;
    });
  const std::vector<std::vector<Eigen::MatrixXcd>> moved = fem::parallel_map(jobs);
  for (auto& e : compared_.entries) {
    e.force = 0.0;
    for (const Eigen::MatrixXcd& X : moved[static_cast<std::size_t>(e.test)])
      e.force += 0.5 * std::norm(X(e.row, e.response) - s.X[e.test](e.row, e.response));
  }
}

double Problem::estimate_simulation_error(State& s) {
  const Simulator& fine = simulator(s.damping_scale, true);
  const Simulator& sim = simulator(s.damping_scale);
  propagate_force_noise(s, sim);
  // The simulation's error: against time integration with exact stick–slip where the model
  // has dry friction and the substructure is a finite element model (the harmonic balance of
  // a discontinuous force converges slowly with the harmonics), else against the harmonic
  // balance with twice the harmonics.
  std::vector<Eigen::MatrixXcd> exact;
  if (has_friction(s.joints)) exact = time_integrated(s);
  // Per test (in parallel), the reference and the factor on the difference from it.
  std::vector<std::function<std::pair<Eigen::MatrixXcd, double>()>> jobs;
  for (std::size_t i = 0; i < tests_.size(); ++i)
    jobs.push_back([&, i]() -> std::pair<Eigen::MatrixXcd, double> {
      if (o_.checkpoint) o_.checkpoint();
      // Time integration from rest may settle on another branch than the measured one (a
      // jump): a difference beyond 5 % of a fundamental is a different solution, not the
      // harmonic balance's error, and the refined harmonic balance is the reference there.
      bool same_branch = i < exact.size() && exact[i].size() > 0;
      if (same_branch)
        for (Eigen::Index j = 0; j < exact[i].cols(); ++j)
          same_branch = same_branch &&
                        std::abs(exact[i](1, j) - s.X[i](1, j)) <= 0.05 * std::abs(s.X[i](1, j));
      if (same_branch) return {exact[i], 1.0};
      Eigen::MatrixXcd start = Eigen::MatrixXcd::Zero(fine.balance[i].options().harmonics + 1,
                                                      static_cast<Eigen::Index>(layout_.size()));
      start.topRows(measured_start_[i].rows()) = measured_start_[i];
      frf::HarmonicBalanceResult r = fine.balance[i].solve(s.joints, drive_[i], &start);
      if (!r.status.ok()) r = fine.balance[i].solve(s.joints, drive_[i]);
      return {r.status.ok() ? std::move(r.X) : Eigen::MatrixXcd(), 4.0}; // twice the difference
    });
  const std::vector<std::pair<Eigen::MatrixXcd, double>> references = fem::parallel_map(jobs);
  double E = 0.0;
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    const auto& [reference, factor] = references[i];
    for (auto& e : compared_.entries)
      if (e.test == static_cast<int>(i)) {
        e.simulation =
            reference.size() > 0
                ? factor * std::norm(reference(e.row, e.response) - s.X[i](e.row, e.response))
                : 0.0;
        E += e.simulation;
      }
  }
  // The noise level: the response's noise and the force's, propagated.
  if (compared_.noise_known) compared_.noise_gap = noise_level(compared_);
  score(s);
  return std::sqrt(E / compared_.measured2);
}

// Every test's (of an even spread of at most max_time_integrated) steady state by implicit time
// integration of the finite element model with the state's joints (exact stick–slip), driven by the
// measured fundamental force: F0 sin ωt with F0 = |F_1|, its harmonics then turned by the force's
// phase. Harmonics 0 … K at the responses; an empty matrix where that is not possible (a modal
// substructure, several forces, modal damping above the dense limit, no steady state).
std::vector<Eigen::MatrixXcd> Problem::time_integrated(const State& s) const {
  std::vector<Eigen::MatrixXcd> out(tests_.size());
  const fem::Assembled* system = sub_.system();
  if (!system) return out;
  fem::SparseMatrix C;
  try {
    const fem::Outcome<fem::SparseMatrix> damping = sub_.damping_matrix();
    if (!damping.status.ok()) return out;
    C = damping.value * s.damping_scale;
  } catch (const std::exception&) {
    return out;
  }
  const joints::JointForces forces(s.joints, dofs_);
  // An even spread of at most max_time_integrated tests (in the order given: a table's levels
  // and frequencies, records in turn).
  std::vector<bool> integrated(tests_.size(), false);
  for (int i : even_spread(tests_.size(), max_time_integrated))
    integrated[static_cast<std::size_t>(i)] = true;
  std::vector<std::function<Eigen::MatrixXcd()>> jobs;
  for (std::size_t i = 0; i < tests_.size(); ++i)
    jobs.push_back([&, i]() -> Eigen::MatrixXcd {
      if (!integrated[i]) return {};
      if (o_.checkpoint) o_.checkpoint();
      const auto& m = tests_[i];
      // One force, a pure sine: what the integrator's load can be.
      if (force_eq_[i].size() != 1 || m.kind == identify::RecordKind::periodic) return {};
      for (Eigen::Index k = 0; k < drive_[i].rows(); ++k)
        if (k != 1 && std::abs(drive_[i](k, 0)) > 0.0) return {};
      const Complex F1 = drive_[i](1, 0);
      // 512 steps a period: a period error of (ωh)²/12 = 1.3e-5, well below the harmonic
      // balance's friction error this estimates (at 256 the friction cases' estimates moved
      // enough to change what discovery adds). Steady when a period differs from the one before
      // by less than 1e-6 of the response: a transient decaying by 2πζ a period is then below
      // 1e-6 / (2πζ), 5e-5 at ζ = 0.3 %.
      fem::SteadyStateOptions o;
      o.steps_per_period = 512;
      o.output_periods = 1;
      o.tolerance = 1e-6;
      const fem::SteadyState ss = fem::steady_state(
          *system, C, &forces, {force_eq_[i][0], std::abs(F1), m.frequency_hz}, response_eq_[i], o);
      if (!ss.status.ok()) return {};
      Eigen::MatrixXcd X =
          identify::fit_harmonics(ss.t, ss.u, 2.0 * std::numbers::pi * m.frequency_hz, K_);
      const Complex turn = F1 / Complex(0.0, -std::abs(F1)); // sin → the measured phase
      for (int k = 1; k <= K_; ++k)
        X.row(k) *= std::pow(turn, k);
      return X;
    });
  return fem::parallel_map(jobs);
}

} // namespace jointid::discover::detail
