#include "discover/problem.hpp"

#include "discover/selection.hpp"
#include "discover/text.hpp"
#include "fem/constants.hpp"
#include "fem/parallel.hpp"
#include "identify/parametric.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>

namespace jointid::discover::detail {

namespace {

bool is_periodic(const identify::Measurement& m) {
  return m.kind == identify::RecordKind::periodic;
}

bool excited(const identify::Measurement& m, int k) {
  return std::binary_search(m.excited_lines.begin(), m.excited_lines.end(), k);
}

// Line (harmonic) k of force c drives the re-simulation: a sine test's fundamental, a periodic
// test's excited lines, and any other out of the force's noise (beyond 5 standard deviations:
// driven through a resonance, noise alone would give the model responses the structure never
// had).
//
// A periodic test tests thousands of lines against a variance estimated from a few periods (its
// ratio to that estimate has a heavy tail: with 8 periods one line in 40 000 exceeds 25 by
// chance): a line it does not excite must also exceed 1e-3 of the largest excited one (−60 dB)
// to drive it. (A ground-vibration test's record of 5 levels at 0.2 % noise had one such line,
// at 34 Hz, that more than doubled its balance.)
bool drives(const identify::Measurement& m, Eigen::Index k, Eigen::Index c) {
  if (is_periodic(m) ? excited(m, static_cast<int>(k)) : k == 1) return true;
  if (is_periodic(m)) {
    double largest = 0.0;
    for (int l : m.excited_lines)
      if (l < m.F.rows()) largest = std::max(largest, std::abs(m.F(l, c)));
    if (std::abs(m.F(k, c)) <= 1e-3 * largest) return false;
  }
  return !(m.F_variance.size() > 0 && std::norm(m.F(k, c)) <= 25.0 * m.F_variance(k, c));
}

// A periodic test's highest line that drives it.
int highest_driven(const identify::Measurement& m) {
  int top = m.excited_lines.back();
  for (Eigen::Index k = top + 1; k < m.F.rows(); ++k)
    for (Eigen::Index c = 0; c < m.F.cols(); ++c)
      if (m.F(k, c) != 0.0 && drives(m, k, c)) top = static_cast<int>(k);
  return top;
}

void add_unique(std::vector<int>& list, int value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

} // namespace

Problem::Problem(const frf::Substructure& sub, const std::vector<joints::Joint>& start,
                 const std::vector<identify::Measurement>& tests, const Options& o)
    : sub_(sub), dofs_(sub.dofs()), tests_(tests), o_(o) {
  if (tests.empty()) throw std::invalid_argument("discover: no tests");
  if (start.empty()) throw std::invalid_argument("discover: the model has no joints");
  if (o.harmonics.empty()) throw std::invalid_argument("discover: no harmonics to fit");
  for (int k : o.harmonics)
    if (k < 0) throw std::invalid_argument("discover: harmonics must be >= 0");
  K_ = std::max(1, *std::max_element(o.harmonics.begin(), o.harmonics.end()));
  if (o.balance.harmonics < K_)
    throw std::invalid_argument("discover: the harmonic balance needs at least as many "
                                "harmonics as are compared");
  joints::validate_joints(start, dofs_);
  layout_ = start;
  set_up_equations(start);
  set_up_drive_and_start(start);
  base_ = std::make_unique<frf::ModalSynthesis>(sub.synthesis(synthesis_dofs_, f_max_, &notes_));
  // Nothing can be re-simulated without the substructure's modes: the run ends here with their
  // status's reason (a numerical outcome, not bad input).
  if (!base_->status().ok())
    throw std::runtime_error("discover: the substructure: " + base_->status().reason);
  set_up_static_flexibility();
  compared_ = compared_values(tests, K_);
  preconditions_ = detail::preconditions(tests, compared_, o_, base_->num_modes() > 0);
  for (const auto& m : tests) {
    log_frequency_.push_back(std::log(m.frequency_hz));
    log_level_.push_back(std::log(std::max(identify::force_level(m), 1e-300)));
  }
}

int Problem::equation(const identify::Measurement& m, const std::string& what,
                      const fem::NodeDof& at) {
  // The record's channel is at fault, not the model: say what the model has.
  if (const std::string why = dofs_.why_not_free(at); !why.empty())
    throw std::invalid_argument(m.source + ": " + what + fem::to_string(at) + ": " + why);
  return dofs_.equation(at);
}

// Equations: the joints' DOFs, every force and every response of every test; the band the
// re-simulations need.
void Problem::set_up_equations(const std::vector<joints::Joint>& start) {
  synthesis_dofs_ = joints::joint_dof_set(start, dofs_);
  double f_max = 0.0, top = 0.0; // the sine tests' highest frequency; the periodic tests' band
  for (const auto& m : tests_) {
    if (is_periodic(m)) {
      // The lines compared, and the joints' harmonics and combinations of the excited lines up
      // to the K-th, at least the tenth: their harmonic balance at 1/T reaches that far. (A
      // cubic stiffness driven hard spreads its response far past three times the highest
      // excited line: on the cantilever's 90 N multisine test with k3, truncated at 3 times it
      // has no solution, at 5 times it is 17 % off the solution at 10 times.)
      const int driven = highest_driven(m);
      const int reach = std::max(m.lines.back(), std::max(K_, 10) * driven);
      if (reach > o_.max_balance_lines)
        throw std::invalid_argument(fmt::format(
            "discover: {} needs a harmonic balance of {} lines {} Hz apart (its highest line "
            "compared, {}, or {} times its highest driven line, {} at {} Hz, whichever is "
            "higher), more than the {} it may have (--max-balance-lines): a discovery "
            "takes thousands of solves, each of Newton iterations whose products grow with the "
            "lines (9216 lines: about 0.6 s a solve with a mildly non-linear joint, and many "
            "times that with a strongly non-linear one). Raise the limit, or use a record with "
            "fewer lines (a shorter period, a narrower excited band); this one can be "
            "identified (`jointid identify`: no re-simulation)",
            m.source, reach, number(m.frequency_hz), m.lines.back(), std::max(K_, 10), driven,
            number(driven * m.frequency_hz), o_.max_balance_lines));
      balance_harmonics_.push_back(reach);
      rows_.push_back(m.harmonics);
      top = std::max(top, frf::synthesis_band_hz(m.frequency_hz, 2 * reach)); // refined: twice
    } else {
      balance_harmonics_.push_back(-1); // the options' (set below)
      rows_.push_back(K_);
    }
    if (m.harmonics < K_ && !m.fundamental_only && !is_periodic(m))
      throw std::invalid_argument(m.source + ": measured to harmonic " +
                                  std::to_string(m.harmonics) + ", but " + std::to_string(K_) +
                                  " are compared");
    std::vector<int> forces, responses;
    for (const auto& at : m.force_at)
      forces.push_back(equation(m, "force channel f@", at));
    for (std::size_t j = 0; j < m.response_at.size(); ++j)
      responses.push_back(
          equation(m, std::string("channel ") + identify::quantity_letter(m.measured_as[j]) + "@",
                   m.response_at[j]));
    for (int e : forces)
      add_unique(synthesis_dofs_, e);
    for (int e : responses)
      add_unique(synthesis_dofs_, e);
    force_eq_.push_back(std::move(forces));
    response_eq_.push_back(std::move(responses));
    if (!is_periodic(m)) f_max = std::max(f_max, m.frequency_hz);
  }
  fit_to_measured_band(f_max);
  for (int& k : balance_harmonics_)
    if (k < 0) k = o_.balance.harmonics;
  f_max_ = std::max(top, frf::synthesis_band_hz(f_max, 2 * o_.balance.harmonics)); // refined: 2K
}

// Measured FRFs end at their band: the re-simulations keep to the harmonics whose doubles (the
// refined simulations) stay in it.
void Problem::fit_to_measured_band(double f_max) {
  const double top = sub_.band_top_hz(synthesis_dofs_);
  if (!std::isfinite(top)) return;
  // A periodic test's harmonic balance needs its lines, and the joints' response up to
  // max(K, 10) times its highest driven line, twice over for the refined simulation.
  for (std::size_t i = 0; i < tests_.size(); ++i)
    if (is_periodic(tests_[i]) &&
        2.0 * balance_harmonics_[i] * tests_[i].frequency_hz > top * (1.0 + 1e-12))
      throw std::invalid_argument(fmt::format(
          "{}: the measured FRFs reach {} Hz; this periodic test's re-simulation needs {} Hz "
          "(twice line {}: the joints' response up to {} times its highest driven line, "
          "doubled to estimate the simulation's own error). Measure the FRFs to that, or use "
          "fewer of its lines (--band)",
          tests_[i].source, top, 2.0 * balance_harmonics_[i] * tests_[i].frequency_hz,
          balance_harmonics_[i], std::max(K_, 10)));
  if (f_max <= 0.0) return; // periodic tests only
  const int reach = static_cast<int>(std::floor(top / f_max * (1.0 + 1e-12)));
  const int usable = std::min(o_.balance.harmonics, reach / 2);
  if (usable < K_)
    throw std::invalid_argument(fmt::format(
        "discover: the measured FRFs reach {} Hz; the re-simulations need harmonic {} (twice "
        "the {} compared, to estimate their own error) of the highest test frequency, {} Hz: "
        "{} Hz. Measure to that, or compare fewer harmonics",
        top, 2 * K_, K_, f_max, 2 * K_ * f_max));
  if (usable < o_.balance.harmonics) {
    notes_.push_back(fmt::format(
        "the measured FRFs reach {} Hz: the re-simulations use {} harmonics (not {}), so "
        "that the refined ones (twice as many) at {} Hz stay in the band",
        top, usable, o_.balance.harmonics, f_max));
    o_.balance.harmonics = usable;
  }
}

void Problem::set_up_drive_and_start(const std::vector<joints::Joint>& start) {
  // The force that drives each re-simulation: the measured harmonics (or lines) that drive it
  // (drives()), the others taken as 0.
  for (const auto& m : tests_) {
    Eigen::MatrixXcd F = m.F;
    for (Eigen::Index k = 0; k < F.rows(); ++k)
      for (Eigen::Index c = 0; c < F.cols(); ++c)
        if (!drives(m, k, c)) F(k, c) = 0.0;
    drive_.push_back(std::move(F));
  }
  // The measured joint deformations: the harmonic balance starts from them, so that it
  // finds the periodic solution on the measured branch (hardening joints have several).
  const std::vector<int> set2 = joints::joint_dof_set(start, dofs_);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(start, dofs_, set2);
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    const auto& m = tests_[i];
    const int K = balance_harmonics_[i];
    Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K + 1, B.cols());
    for (std::size_t d = 0; d < set2.size(); ++d) {
      const int r = m.response_index(dofs_.node_dof(set2[d]));
      if (r < 0)
        throw std::invalid_argument(m.source + ": no response channel at joint DOF " +
                                    fem::to_string(dofs_.node_dof(set2[d])) +
                                    " (discovery needs x, v or a at every joint DOF)");
      for (int k = 0; k <= std::min(m.harmonics, K); ++k) {
        if (!m.has_harmonic(k) || (k == 0 && !m.has_mean[r])) continue;
        Y.row(k) += m.X(k, r) * B.row(static_cast<Eigen::Index>(d)).cast<std::complex<double>>();
      }
    }
    measured_start_.push_back(std::move(Y));
  }
}

std::vector<int> Problem::all_tests() const {
  std::vector<int> all(tests_.size());
  for (std::size_t i = 0; i < all.size(); ++i)
    all[i] = static_cast<int>(i);
  return all;
}

std::vector<int> Problem::spread(std::size_t taken) const {
  const std::size_t n = tests_.size();
  if (taken >= n) return all_tests();
  std::vector<double> energy(n, 0.0);
  for (const Entry& e : compared_.entries)
    energy[static_cast<std::size_t>(e.test)] += std::norm(e.measured);
  std::vector<int> order = all_tests();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return energy[static_cast<std::size_t>(a)] > energy[static_cast<std::size_t>(b)];
  });
  std::vector<int> out(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(taken / 2));
  std::vector<int> rest(order.begin() + static_cast<std::ptrdiff_t>(taken / 2), order.end());
  std::sort(rest.begin(), rest.end());
  for (int j : even_spread(rest.size(), taken - out.size()))
    out.push_back(rest[static_cast<std::size_t>(j)]);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<int> Problem::outside_spread(std::size_t taken) const {
  const std::vector<int> kept = spread(taken);
  std::vector<int> out;
  for (int i = 0; i < static_cast<int>(tests_.size()); ++i)
    if (!std::binary_search(kept.begin(), kept.end(), i)) out.push_back(i);
  return out;
}

std::vector<std::string> Problem::sources(const std::vector<int>& tests) const {
  std::vector<std::string> out;
  for (int i : tests)
    out.push_back(tests_[static_cast<std::size_t>(i)].source);
  return out;
}

std::vector<int> Problem::nearest(int i, const std::vector<int>& candidates,
                                  std::size_t count) const {
  auto distance = [&](int j) {
    return std::abs(log_frequency_[j] - log_frequency_[i]) +
           std::abs(log_level_[j] - log_level_[i]);
  };
  std::vector<int> out = candidates;
  out.erase(std::remove(out.begin(), out.end(), i), out.end());
  const std::size_t n = std::min(count, out.size());
  std::partial_sort(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n), out.end(),
                    [&](int a, int b) { return distance(a) < distance(b); });
  out.resize(n);
  return out;
}

std::unique_ptr<Simulator> Problem::make_simulator(double scale, bool refined) const {
  const int harmonics = o_.balance.harmonics * (refined ? 2 : 1);
  auto s = std::make_unique<Simulator>(
      Simulator{scale, harmonics, scale == 1.0 ? *base_ : base_->with_damping_scale(scale), {}});
  frf::HarmonicBalanceOptions options = o_.balance;
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    options.harmonics = balance_harmonics_[i] * (refined ? 2 : 1);
    s->balance.emplace_back(s->synthesis, layout_, dofs_, force_eq_[i], response_eq_[i],
                            tests_[i].frequency_hz, options);
  }
  return s;
}

const Simulator& Problem::simulator(double scale, bool refined) {
  const int harmonics = o_.balance.harmonics * (refined ? 2 : 1);
  for (const auto& s : simulators_)
    if (s->scale == scale && s->harmonics == harmonics) return *s;
  simulators_.push_back(make_simulator(scale, refined));
  return *simulators_.back();
}

const Problem::Spectra& Problem::spectra(const std::vector<joints::Joint>& joints) const {
  std::string key;
  for (const auto& j : joints) {
    key += j.name + ':';
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      key += std::string(joints::term_name(j.terms[t])) + ',';
      // A parametric term's force (fixed) is in the spectrum: its parameters are in the key.
      for (const joints::Parameter& p : j.parameters_of(t))
        key += fmt::format("{:a},", p.value);
    }
    key += ';';
  }
  const std::lock_guard<std::mutex> lock(spectra_mutex_);
  auto& kept = spectra_[key];
  if (!kept) {
    auto made = std::make_unique<Spectra>();
    for (const auto& m : tests_) {
      made->warnings.emplace_back();
      made->tests.push_back(identify::spectrum(m, dofs_, joints, made->warnings.back()));
    }
    kept = std::move(made);
  }
  return *kept;
}

identify::FitResult Problem::identify(const std::vector<joints::Joint>& joints,
                                      const Simulator& sim, const std::vector<int>& use,
                                      const std::vector<int>* harmonics) const {
  // The parametric terms with their parameters as they are: their forces known (the
  // equation error identifies coefficients; their parameters are refined by output error).
  const std::vector<joints::Joint> held = identify::with_parametric_fixed(joints);
  const Spectra& all = spectra(held);
  std::vector<std::string> warnings;
  for (int i : use)
    warnings.insert(warnings.end(), all.warnings[i].begin(), all.warnings[i].end());
  std::vector<identify::TestSpectrum> subset;
  const bool every = use == all_tests();
  if (!every)
    for (int i : use)
      subset.push_back(all.tests[i]);
  const std::vector<identify::TestSpectrum>& spectra = every ? all.tests : subset;
  const identify::ReceptanceFn H = [&sim](double w, std::span<const int> rows,
                                          std::span<const int> cols) {
    return sim.synthesis.receptance(w, rows, cols);
  };
  identify::FitOptions fo;
  fo.harmonics = harmonics ? *harmonics : o_.harmonics;
  identify::FitResult fit = identify::fit(H, dofs_, held, spectra, fo, std::move(warnings));
  // Terms the tests cannot separate: this model cannot be identified (a refused candidate).
  if (!fit.status.ok()) throw std::invalid_argument("identify: " + fit.status.reason);
  return fit;
}

int Problem::parameters(const std::vector<joints::Joint>& joints, double scale) const {
  int p = scale != 1.0 ? 1 : 0;
  for (const auto& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      if (j.fixed[t]) continue;
      const auto params = j.parameters_of(t);
      p += params.empty() ? 1
                          : static_cast<int>(std::count_if(params.begin(), params.end(),
                                                           [](const auto& q) { return !q.fixed; }));
    }
  return p;
}

std::vector<int> even_spread(std::size_t n, std::size_t taken) {
  taken = std::min(n, taken);
  std::vector<int> out;
  for (std::size_t j = 0; j < taken; ++j)
    out.push_back(static_cast<int>(taken > 1 ? j * (n - 1) / (taken - 1) : 0));
  return out;
}

void Problem::set_up_static_flexibility() {
  const frf::ModalSynthesis& H = *base_;
  if (H.measured() || H.num_modes() == 0) return;
  const Eigen::VectorXd& w = H.natural_frequencies();
  if (!(w.minCoeff() > 1e-6 * w.maxCoeff())) return; // a rigid-body mode: no static flexibility
  const std::vector<int> set2 = joints::joint_dof_set(layout_, dofs_);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(layout_, dofs_, set2);
  const Eigen::MatrixXd G = B.transpose() * H.receptance(0.0, set2, set2).real() * B;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (G + G.transpose()));
  if (eig.info() != Eigen::Success) return;
  const Eigen::VectorXd& g = eig.eigenvalues();
  if (!(g.minCoeff() > 1e-12 * g.maxCoeff())) return; // joints whose ends cannot move apart
  flexibility_root_ =
      eig.eigenvectors() * g.cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
  stiffness_held_ = G.diagonal().cwiseInverse();
}

std::string Problem::stability_problem(const std::vector<joints::Joint>& joints) const {
  if (flexibility_root_.size() == 0 || joints.size() != layout_.size()) return {};
  const auto n = static_cast<Eigen::Index>(joints.size());
  Eigen::VectorXd k = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const joints::Joint& J = joints[static_cast<std::size_t>(j)];
    if (const int t = J.term_index(joints::Term::k); t >= 0)
      k(j) = J.values[static_cast<std::size_t>(t)];
  }
  if (k.minCoeff() >= 0.0) return {};
  // (Bᵀ H(0) B)⁻¹ + diag(k) positive definite ⇔ I + S diag(k) S positive definite, S its root.
  const Eigen::MatrixXd A =
      Eigen::MatrixXd::Identity(n, n) + flexibility_root_ * k.asDiagonal() * flexibility_root_;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
  if (eig.eigenvalues().minCoeff() > 0.0) return {};
  std::vector<std::string> which;
  for (Eigen::Index j = 0; j < n; ++j)
    if (k(j) < 0.0) {
      const joints::Joint& J = joints[static_cast<std::size_t>(j)];
      const std::string_view unit = joints::term_unit(joints::Term::k);
      which.push_back(fmt::format("'{}' keeps k = {} {} where the substructure holds {} {}", J.name,
                                  number(k(j)), unit, number(stiffness_held_(j)), unit));
    }
  return fmt::format("not physical: with its friction slipping and its gaps open, {}: the "
                     "structure has no stable state at rest (its response to any force that "
                     "makes the joint slip grows without bound)",
                     join(which));
}

State Problem::evaluate(const std::vector<joints::Joint>& joints, const Simulator& sim,
                        const State* warm, std::span<const int> skip) const {
  return evaluate_each(joints, {}, sim, warm, skip);
}

State Problem::evaluate_each(const std::vector<joints::Joint>& joints,
                             const std::vector<std::vector<joints::Joint>>& per_test,
                             const Simulator& sim, const State* warm,
                             std::span<const int> skip) const {
  State s;
  s.joints = joints;
  s.damping_scale = sim.scale;
  s.parameters = parameters(joints, sim.scale) +
                 (per_test.empty() ? 0 : static_cast<int>(per_test.size()) - 1);
  s.X.resize(tests_.size()); // NaN where not tried
  for (std::size_t i = 0; i < tests_.size(); ++i)
    s.X[i] = Eigen::MatrixXcd::Constant(rows_[i] + 1,
                                        static_cast<Eigen::Index>(response_eq_[i].size()), nan);
  s.Y.assign(tests_.size(), Eigen::MatrixXcd());
  const int limit = max_left_out(static_cast<int>(tests_.size()));
  // Every test from its own start, in parallel; then, in order, the tests that did not converge
  // from their neighbours solved before them (as a sweep would have been), and past `limit`
  // failures the rest dropped as not tried: the same state as solving one test after another.
  // Once more than `limit` have failed from their own start, the parallel pass stops starting
  // tests (a model that fails everywhere costs a tenth of the tests, not all); the ones the
  // ordered pass still needs it solves itself.
  std::atomic<int> failures{0};
  const auto own_start = [&](std::size_t i) {
    const Eigen::MatrixXcd* start = warm && i < warm->Y.size() ? &warm->Y[i] : nullptr;
    return solve(sim, static_cast<int>(i), per_test.empty() ? joints : per_test[i], start);
  };
  std::vector<std::function<std::optional<frf::HarmonicBalanceResult>()>> jobs;
  for (std::size_t i = 0; i < tests_.size(); ++i)
    jobs.push_back([&, i]() -> std::optional<frf::HarmonicBalanceResult> {
      if (std::binary_search(skip.begin(), skip.end(), static_cast<int>(i)) || failures > limit)
        return std::nullopt;
      frf::HarmonicBalanceResult r = own_start(i);
      if (!(r.status.ok() && r.X.allFinite())) ++failures;
      return r;
    });
  std::vector<std::optional<frf::HarmonicBalanceResult>> first = fem::parallel_map(jobs);
  std::vector<int> solved;
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    const int t = static_cast<int>(i);
    if (std::binary_search(skip.begin(), skip.end(), t)) continue;
    const std::vector<joints::Joint>& these = per_test.empty() ? joints : per_test[i];
    frf::HarmonicBalanceResult r = first[i] ? std::move(*first[i]) : own_start(i);
    // Where the model's steady state is far from the measured one (a fold the model has and
    // the structure had not), the nearest tests re-simulated — the neighbours of a stepped
    // sweep — are the start a sweep would have had.
    // (A periodic test's neighbour may have a balance of other lines: not a start for it.)
    if (!(r.status.ok() && r.X.allFinite()))
      for (int j : nearest(t, solved, 2)) {
        if (s.Y[j].rows() != sim.balance[i].options().harmonics + 1) continue;
        frf::HarmonicBalanceResult again = sim.balance[i].solve(these, drive_[i], &s.Y[j]);
        if (again.status.ok() && again.X.allFinite()) {
          r = std::move(again);
          break;
        }
      }
    // Else by continuation in the non-linear forces, from the linear response.
    if (!(r.status.ok() && r.X.allFinite()))
      if (frf::HarmonicBalanceResult again = by_continuation(sim, t, these);
          again.status.ok() && again.X.allFinite())
        r = std::move(again);
    s.X[i] = r.X.topRows(rows_[i] + 1);
    s.Y[i] = r.Y;
    if (r.status.ok() && r.X.allFinite()) {
      solved.push_back(t);
    } else {
      s.failed.push_back(t);
      s.failed_why.push_back(r.status.ok() ? std::string("the response is not finite")
                                           : r.status.reason);
      if (static_cast<int>(s.failed.size()) > limit) break; // not compared: the rest not tried
    }
  }
  s.converged = s.failed.empty();
  s.unstable = stability_problem(joints);
  if (skip.empty()) {
    score(s);
  } else { // on the tests simulated
    const std::vector<int> out = united(s.failed, std::vector<int>(skip.begin(), skip.end()));
    const Misfit m = misfit(compared_, s.X, out);
    s.gap = static_cast<int>(s.failed.size()) > limit ? inf : gap(compared_, m);
    s.chi2 = m.chi2;
    s.criterion = s.gap;
  }
  return s;
}

std::vector<std::vector<Eigen::MatrixXcd>>
Problem::derivatives(const State& at, const std::vector<std::vector<joints::Joint>>& moved,
                     const std::vector<double>& steps, const Simulator& sim,
                     std::span<const int> skip) const {
  using Derivatives = std::vector<Eigen::MatrixXcd>;
  std::vector<std::function<Derivatives()>> jobs;
  for (std::size_t i = 0; i < tests_.size(); ++i)
    jobs.push_back([&, i] {
      const int t = static_cast<int>(i);
      if (i >= at.Y.size() || at.Y[i].rows() != sim.balance[i].options().harmonics + 1 ||
          std::binary_search(at.failed.begin(), at.failed.end(), t) ||
          std::binary_search(skip.begin(), skip.end(), t))
        return Derivatives{};
      if (o_.checkpoint) o_.checkpoint();
      Derivatives d =
          sim.balance[i].output_derivatives(at.joints, drive_[i], at.Y[i], moved, steps);
      for (Eigen::MatrixXcd& column : d)
        if (column.size() > 0) column = column.topRows(rows_[i] + 1).eval();
      return d;
    });
  return fem::parallel_map(jobs);
}

frf::HarmonicBalanceResult Problem::solve(const Simulator& sim, int i,
                                          const std::vector<joints::Joint>& joints,
                                          const Eigen::MatrixXcd* warm) const {
  if (o_.checkpoint) o_.checkpoint();
  if (!friction_problem(joints).empty()) { // fc < 0: no steady state to speak of
    frf::HarmonicBalanceResult none;
    none.X = Eigen::MatrixXcd::Constant(sim.balance[i].options().harmonics + 1,
                                        response_eq_[i].size(), nan);
    return none;
  }
  frf::HarmonicBalanceResult r;
  if (warm && warm->rows() == sim.balance[i].options().harmonics + 1) {
    r = sim.balance[i].solve(joints, drive_[i], warm);
    if (r.status.ok()) return r;
  }
  r = sim.balance[i].solve(joints, drive_[i], &measured_start_[i]);
  if (!r.status.ok()) {
    frf::HarmonicBalanceResult again = sim.balance[i].solve(joints, drive_[i]);
    again.iterations += r.iterations;
    if (again.status.ok() || again.residual < r.residual) r = std::move(again);
  }
  return r;
}

frf::HarmonicBalanceResult
Problem::by_continuation(const Simulator& sim, int i,
                         const std::vector<joints::Joint>& joints) const {
  frf::HarmonicBalanceResult r;
  Eigen::MatrixXcd Y;
  for (const double s : {0.125, 0.25, 0.5, 0.75, 1.0}) {
    std::vector<joints::Joint> scaled = joints;
    for (joints::Joint& j : scaled)
      for (std::size_t t = 0; t < j.terms.size(); ++t) {
        const joints::Term term = j.terms[t];
        if (term == joints::Term::k || term == joints::Term::c) continue;
        if (!joints::has_parameters(term)) {
          j.values[t] *= s;
          continue;
        }
        for (const char* name : {"kt", "fs", "kg"}) {
          const int p = joints::parameter_index(term, name);
          if (p >= 0) j.parameters[t][static_cast<std::size_t>(p)].value *= s;
        }
      }
    r = sim.balance[static_cast<std::size_t>(i)].solve(scaled, drive_[static_cast<std::size_t>(i)],
                                                       Y.size() ? &Y : nullptr);
    if (!(r.status.ok() && r.X.allFinite())) return r;
    Y = r.Y;
  }
  return r;
}

void Problem::score(State& state) const {
  detail::score(state, compared_);
}

} // namespace jointid::discover::detail
