#include "identify/design.hpp"

#include "fem/constants.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "joints/hysteresis.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace jointid::identify {

namespace {

double channel_rms(const Channel& c) {
  const double mean = c.samples.mean();
  return std::sqrt((c.samples.array() - mean).square().mean());
}

double rms_of(const Record& r, Quantity q, const fem::NodeDof& at) {
  const Channel* c = r.find(q, at);
  if (!c) throw std::logic_error("design: channel missing from a predicted record");
  return channel_rms(*c);
}

// The unknowns scaled to unit total information: the determinant's ratios do not change, its
// numerics do.
Eigen::VectorXd unit_scale(const std::vector<CandidateTest>& candidates, Eigen::Index nu) {
  Eigen::VectorXd total = Eigen::VectorXd::Zero(nu);
  for (const auto& c : candidates)
    if (c.usable) total += c.information.diagonal();
  Eigen::VectorXd s(nu);
  for (Eigen::Index u = 0; u < nu; ++u)
    s(u) = total(u) > 0.0 ? 1.0 / std::sqrt(total(u)) : 1.0;
  return s;
}

double log_det(const Eigen::MatrixXd& A) {
  const Eigen::LLT<Eigen::MatrixXd> llt(A);
  if (llt.info() != Eigen::Success) return -inf;
  const Eigen::VectorXd d = llt.matrixL().toDenseMatrix().diagonal();
  if ((d.array() <= 0.0).any()) return -inf;
  return 2.0 * d.array().log().sum();
}

// Σ Iᵢ over the tests; throws std::invalid_argument for a test that is not usable.
Eigen::MatrixXd total_information(const std::vector<CandidateTest>& candidates,
                                  const std::vector<int>& tests) {
  if (tests.empty()) throw std::invalid_argument("design: no tests");
  Eigen::MatrixXd A;
  for (int i : tests) {
    const CandidateTest& c = candidates.at(static_cast<std::size_t>(i));
    if (!c.usable)
      throw std::invalid_argument(
          fmt::format("design: the test at {} Hz, {} N was not predicted: {}", c.plan.frequency_hz,
                      c.plan.amplitude, c.reason));
    if (A.size() == 0) A = Eigen::MatrixXd::Zero(c.information.rows(), c.information.cols());
    A += c.information;
  }
  return A;
}

} // namespace

std::vector<DesignUnknown> design_unknowns(const std::vector<joints::Joint>& joints) {
  check_identifiable(joints);
  std::vector<DesignUnknown> out;
  for (const auto& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      if (!j.fixed[t]) out.push_back({j.name, j.terms[t], j.values[t]});
  return out;
}

std::vector<CandidateTest> predict_candidates(const frf::Substructure& sub,
                                              const std::vector<joints::Joint>& joints,
                                              const fem::NodeDof& force_at,
                                              const std::vector<SineTestPlan>& candidates,
                                              const DesignOptions& o) {
  if (!(o.noise > 0.0) || !std::isfinite(o.noise))
    throw std::invalid_argument(
        fmt::format("design: noise: expected a level > 0 (e.g. 0.01 for 1 %), got {}", o.noise));
  if (o.periods < 2)
    throw std::invalid_argument(
        fmt::format("design: periods: expected at least 2 per record, got {}", o.periods));
  if (o.harmonics.empty()) throw std::invalid_argument("design: no harmonics asked");
  const int K = *std::max_element(o.harmonics.begin(), o.harmonics.end());
  if (*std::min_element(o.harmonics.begin(), o.harmonics.end()) < 0 || K > o.balance.harmonics)
    throw std::invalid_argument(
        fmt::format("design: harmonics: expected 0 to {} (the prediction's harmonics), got {}",
                    o.balance.harmonics, fmt::join(o.harmonics, ",")));
  const int samples_per_period = o.samples_per_period != 0
                                     ? o.samples_per_period
                                     : std::max(256, 8 * (o.balance.harmonics + 1));
  if (samples_per_period < 4 * (o.balance.harmonics + 1))
    throw std::invalid_argument(fmt::format(
        "design: samples per period: expected at least {} for harmonics 0 to {}, got {}",
        4 * (o.balance.harmonics + 1), o.balance.harmonics, samples_per_period));
  if (candidates.empty()) throw std::invalid_argument("design: no candidate tests");
  if (design_unknowns(joints).empty())
    throw std::invalid_argument("design: every joint term is fixed; nothing to identify");

  SimulationOptions sim;
  sim.method = SimulationMethod::harmonic_balance;
  sim.periods = 2; // noise-free: the periods are equal; the noise is set below
  sim.steps_per_period = samples_per_period;
  sim.quantities = o.quantities;
  sim.balance = o.balance;
  if (o.progress) sim.progress = [&](double done) { o.progress(0.5 * done); };
  std::vector<SimulatedTest> tests = simulate_sine_tests(sub, joints, force_at, candidates, sim);
  // Solved again from the linear response: where the two differ, the test has coexisting
  // periodic responses (near a fold of a non-linear resonance) and a real test could land on
  // either; such a candidate is left out.
  sim.warm_start = false;
  if (o.progress) sim.progress = [&](double done) { o.progress(0.5 + 0.5 * done); };
  const std::vector<SimulatedTest> cold =
      simulate_sine_tests(sub, joints, force_at, candidates, sim);
  for (std::size_t i = 0; i < tests.size(); ++i) {
    if (tests[i].record.channels.empty()) continue;
    const auto& a = tests[i].record.channels;
    const auto& b = cold[i].record.channels;
    bool same = a.size() == b.size();
    for (std::size_t c = 0; same && c < a.size(); ++c)
      same = (a[c].samples - b[c].samples).cwiseAbs().maxCoeff() <=
             1e-6 * a[c].samples.cwiseAbs().maxCoeff();
    if (same) continue;
    tests[i].record.channels.clear();
    tests[i].warnings.insert(
        tests[i].warnings.begin(),
        "coexisting periodic responses (a sweep up and a start from the linear response reach "
        "different ones, or only one of them converges): a test here could land on either");
  }

  // The receptance the fit will use.
  const fem::DofMap& dofs = sub.dofs();
  std::vector<int> rows = joint_dof_set(joints, dofs);
  const int fe = dofs.equation(force_at);
  if (std::find(rows.begin(), rows.end(), fe) == rows.end()) rows.push_back(fe);
  double f_max = 0.0;
  for (const auto& c : candidates)
    f_max = std::max(f_max, c.frequency_hz);
  const frf::ModalSynthesis synthesis =
      sub.synthesis(rows, frf::synthesis_band_hz(f_max, std::max(K, 1)));
  if (!synthesis.status().ok()) { // no receptance: no candidate can be weighed
    std::vector<CandidateTest> out;
    for (const auto& test : tests) {
      CandidateTest c;
      c.plan = test.plan;
      c.reason = synthesis.status().reason;
      out.push_back(std::move(c));
    }
    return out;
  }
  const ReceptanceFn H = [&synthesis](double omega, std::span<const int> r,
                                      std::span<const int> c) {
    return synthesis.receptance(omega, r, c);
  };
  const std::vector<int> set2 = joint_dof_set(joints, dofs);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, set2);

  MeasureOptions mo;
  mo.harmonics = std::max(K, 1);
  mo.average_periods = true;
  std::vector<CandidateTest> out;
  for (auto& test : tests) {
    CandidateTest c;
    c.plan = test.plan;
    if (test.record.channels.empty()) {
      c.reason = !test.status.ok()       ? test.status.reason
                 : test.warnings.empty() ? "not predicted"
                                         : test.warnings.front();
      out.push_back(std::move(c));
      continue;
    }
    Measurement m = measure(test.record, mo);
    // The noise expected: a fraction of each channel's RMS, on every sample of `periods`
    // periods, averaged.
    m.periods_averaged = o.periods;
    m.averaging = o.periods;
    for (std::size_t r = 0; r < m.response_at.size(); ++r) {
      m.channel_noise[r] = o.noise * rms_of(test.record, m.measured_as[r], m.response_at[r]);
      if (std::isfinite(m.velocity_noise[r]))
        m.velocity_noise[r] = o.noise * rms_of(test.record, Quantity::velocity, m.response_at[r]);
    }
    for (std::size_t f = 0; f < m.force_at.size(); ++f)
      m.force_noise[f] = o.noise * rms_of(test.record, Quantity::force, m.force_at[f]);
    std::vector<std::string> warnings;
    const TestSpectrum ts = spectrum(m, dofs, joints, warnings);
    for (Eigen::Index j = 0; j < B.cols(); ++j)
      c.joint_amplitude.push_back(
          std::abs((ts.X2.row(1) * B.col(j).cast<std::complex<double>>())(0)));
    TestInformation info = information(H, dofs, joints, ts, o.harmonics);
    c.information = std::move(info.information);
    c.score = std::move(info.score);
    c.misfit = info.misfit;
    c.usable = c.information.allFinite() && c.score.allFinite();
    if (!c.usable) {
      c.reason = "its information is not finite";
    } else if (c.misfit > o.max_misfit) {
      c.usable = false;
      c.reason = fmt::format(
          "at the prior values its equations miss by {:.3g} noise standard deviations (limit "
          "{:.3g}): the basis functions do not describe the joints' forces here{}",
          c.misfit, o.max_misfit, warnings.empty() ? "" : " (" + warnings.front() + ")");
    }
    out.push_back(std::move(c));
  }
  return out;
}

double log_det_information(const std::vector<CandidateTest>& candidates,
                           const std::vector<int>& tests, const Eigen::VectorXd& scale) {
  const Eigen::MatrixXd A = total_information(candidates, tests);
  if (A.rows() != scale.size())
    throw std::invalid_argument("log_det_information: one scale per unknown expected");
  return log_det(scale.asDiagonal() * A * scale.asDiagonal());
}

Eigen::VectorXd predicted_std(const std::vector<CandidateTest>& candidates,
                              const std::vector<int>& tests) {
  const Eigen::MatrixXd A = total_information(candidates, tests);
  const Eigen::Index nu = A.rows();
  // Scaled to a unit diagonal, then an eigen-decomposition: directions with eigenvalues below
  // 1e-13 of the largest are not determined, and neither is any unknown they involve.
  Eigen::VectorXd s(nu);
  for (Eigen::Index u = 0; u < nu; ++u)
    s(u) = A(u, u) > 0.0 ? 1.0 / std::sqrt(A(u, u)) : 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s.asDiagonal() * A * s.asDiagonal());
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const Eigen::MatrixXd& V = eig.eigenvectors();
  const double floor = 1e-13 * std::max(lambda.maxCoeff(), 0.0);
  Eigen::VectorXd out(nu);
  for (Eigen::Index u = 0; u < nu; ++u) {
    if (s(u) == 0.0) {
      out(u) = inf;
      continue;
    }
    double var = 0.0;
    for (Eigen::Index e = 0; e < nu; ++e) {
      if (lambda(e) <= floor) {
        if (std::abs(V(u, e)) > 1e-6) var = inf;
        continue;
      }
      var += V(u, e) * V(u, e) / lambda(e);
    }
    out(u) = s(u) * std::sqrt(var);
  }
  return out;
}

Eigen::VectorXd predicted_bias(const std::vector<CandidateTest>& candidates,
                               const std::vector<int>& tests) {
  const Eigen::MatrixXd A = total_information(candidates, tests);
  Eigen::VectorXd score = Eigen::VectorXd::Zero(A.rows());
  for (int i : tests)
    score += candidates.at(static_cast<std::size_t>(i)).score;
  // Scaled to a unit diagonal (the unknowns' units differ by many orders).
  Eigen::VectorXd s(A.rows());
  for (Eigen::Index u = 0; u < A.rows(); ++u)
    s(u) = A(u, u) > 0.0 ? 1.0 / std::sqrt(A(u, u)) : 0.0;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(s.asDiagonal() * A * s.asDiagonal());
  if ((s.array() == 0.0).any() || ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-13))
    return Eigen::VectorXd::Constant(A.rows(), std::numeric_limits<double>::quiet_NaN());
  return s.asDiagonal() * ldlt.solve(Eigen::VectorXd(s.asDiagonal() * score));
}

Design choose_tests(const std::vector<CandidateTest>& candidates,
                    const std::vector<DesignUnknown>& unknowns, int n, double poorly_determined) {
  const auto nu = static_cast<Eigen::Index>(unknowns.size());
  std::vector<int> usable;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (candidates[i].usable) usable.push_back(static_cast<int>(i));
  if (n < 1 || n > static_cast<int>(usable.size()))
    throw std::invalid_argument(
        fmt::format("design: -n: expected 1 to {} (the candidates that could be predicted), got {}",
                    usable.size(), n));
  const Eigen::VectorXd scale = unit_scale(candidates, nu);
  std::vector<Eigen::MatrixXd> I(candidates.size());
  for (int i : usable)
    I[static_cast<std::size_t>(i)] = scale.asDiagonal() *
                                     candidates[static_cast<std::size_t>(i)].information *
                                     scale.asDiagonal();
  // A ridge of 1e-9 (each unknown's total information is 1) keeps the determinant finite while
  // fewer tests than unknowns are chosen; it decides nothing once the set determines them all.
  const Eigen::MatrixXd ridge = 1e-9 * Eigen::MatrixXd::Identity(nu, nu);
  Eigen::MatrixXd A = ridge;
  std::vector<int> chosen;
  std::vector<bool> in(candidates.size(), false);
  for (int step = 0; step < n; ++step) {
    int best = -1;
    double best_value = -inf;
    for (int j : usable) {
      if (in[static_cast<std::size_t>(j)]) continue;
      const double v = log_det(A + I[static_cast<std::size_t>(j)]);
      if (v > best_value) best_value = v, best = j;
    }
    chosen.push_back(best);
    in[static_cast<std::size_t>(best)] = true;
    A += I[static_cast<std::size_t>(best)];
  }
  // Exchanges: the best swap of one chosen test for one not chosen, while it helps.
  Design d;
  double current = log_det(A);
  for (int pass = 0; pass < 200; ++pass) {
    double best_value = current;
    int out_pos = -1, in_test = -1;
    for (std::size_t p = 0; p < chosen.size(); ++p) {
      const Eigen::MatrixXd without = A - I[static_cast<std::size_t>(chosen[p])];
      for (int j : usable) {
        if (in[static_cast<std::size_t>(j)]) continue;
        const double v = log_det(without + I[static_cast<std::size_t>(j)]);
        if (v > best_value + 1e-10 * (1.0 + std::abs(best_value)))
          best_value = v, out_pos = static_cast<int>(p), in_test = j;
      }
    }
    if (out_pos < 0) break;
    const int leaving = chosen[static_cast<std::size_t>(out_pos)];
    A += I[static_cast<std::size_t>(in_test)] - I[static_cast<std::size_t>(leaving)];
    in[static_cast<std::size_t>(leaving)] = false;
    in[static_cast<std::size_t>(in_test)] = true;
    chosen[static_cast<std::size_t>(out_pos)] = in_test;
    current = best_value;
    ++d.exchanges;
  }
  std::sort(chosen.begin(), chosen.end(), [&](int a, int b) {
    const auto& pa = candidates[static_cast<std::size_t>(a)].plan;
    const auto& pb = candidates[static_cast<std::size_t>(b)].plan;
    return std::pair(pa.frequency_hz, pa.amplitude) < std::pair(pb.frequency_hz, pb.amplitude);
  });
  d.chosen = chosen;
  Eigen::VectorXd prior_scale(nu);
  for (Eigen::Index u = 0; u < nu; ++u) {
    const double p = std::abs(unknowns[static_cast<std::size_t>(u)].prior);
    prior_scale(u) = p > 0.0 ? p : 1.0;
  }
  d.log_det = log_det_information(candidates, chosen, prior_scale);
  d.std = predicted_std(candidates, chosen);
  d.bias = predicted_bias(candidates, chosen);
  for (Eigen::Index u = 0; u < nu; ++u) {
    const DesignUnknown& x = unknowns[static_cast<std::size_t>(u)];
    if (!std::isfinite(d.std(u)))
      d.warnings.push_back(fmt::format(
          "{} of '{}' is not determined by any {} of these candidates: add candidates at other "
          "frequencies or force levels",
          joints::term_name(x.term), x.joint, n));
    else if (std::abs(d.bias(u)) > 0.5 * d.std(u))
      d.warnings.push_back(fmt::format(
          "{} of '{}': the chosen tests are predicted to bias it by {:.3g} % of its prior value "
          "({:.2g} standard deviations): in some of them the basis functions do not describe the "
          "joint's force (a lower misfit limit leaves them out)",
          joints::term_name(x.term), x.joint, 100.0 * d.bias(u) / std::abs(x.prior),
          std::abs(d.bias(u)) / d.std(u)));
    if (std::isfinite(d.std(u)) && d.std(u) > poorly_determined * std::abs(x.prior))
      d.warnings.push_back(fmt::format(
          "{} of '{}' stays poorly determined: the best {} tests give a standard deviation of "
          "{:.3g} % of its prior value ({:.4g}); add candidates (larger forces, other "
          "frequencies) or tests",
          joints::term_name(x.term), x.joint, n, 100.0 * d.std(u) / std::abs(x.prior), x.prior));
  }
  return d;
}

std::vector<ParametricLevel> parametric_levels(const std::vector<joints::Joint>& joints,
                                               const std::vector<CandidateTest>& candidates) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<ParametricLevel> out;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const joints::Joint& J = joints[j];
    for (std::size_t t = 0; t < J.terms.size(); ++t) {
      if (!joints::has_parameters(J.terms[t]) || J.fixed[t]) continue;
      joints::check_parameters(J); // every parameter needs its value (a prior guess)
      ParametricLevel level;
      level.joint = J.name;
      level.term = J.terms[t];
      const std::string name(joints::term_name(J.terms[t]));
      const int k_index = J.term_index(joints::Term::k);
      const bool k_open = k_index >= 0 && !J.fixed[static_cast<std::size_t>(k_index)];
      std::string below, above; // what the tests determine below and from the threshold
      if (J.terms[t] == joints::Term::jenkins) {
        level.regime = "slip";
        level.threshold = J.parameter(t, "fs") / J.parameter(t, "kt");
        below = fmt::format("the jenkins is a spring of stiffness jenkins.kt, {}jenkins.fs is "
                            "undetermined",
                            k_open ? "determined only as k + jenkins.kt; " : "");
        above = "jenkins.kt and jenkins.fs";
      } else if (J.terms[t] == joints::Term::iwan) {
        level.regime = "macroslip";
        level.threshold = joints::iwan_density(J.parameter(t, "fs"), J.parameter(t, "kt"),
                                               J.parameter(t, "chi"), J.parameter(t, "beta"))
                              .phi_max;
        below = fmt::format("its force depends only on k + iwan.kt, iwan.chi and the slip "
                            "density's scale: {}iwan.fs apart from iwan.beta are undetermined",
                            k_open ? "k apart from iwan.kt, and " : "");
        above =
            fmt::format("iwan.fs apart from iwan.beta{}", k_open ? ", k apart from iwan.kt" : "");
      } else {
        level.regime = "contact";
        level.threshold = J.parameter(t, "delta");
        below = "the gap gives no force: gap.delta and gap.kg are undetermined";
        above = "gap.delta and gap.kg";
      }
      // Per frequency: the smallest force that reaches the threshold, else the largest usable.
      std::map<double, std::pair<double, const CandidateTest*>> reach, largest;
      for (const CandidateTest& c : candidates) {
        if (!c.usable || j >= c.joint_amplitude.size()) continue;
        const double f = c.plan.frequency_hz, F = c.plan.amplitude;
        if (c.joint_amplitude[j] >= level.threshold && (!reach.contains(f) || F < reach[f].first))
          reach[f] = {F, &c};
        if (!largest.contains(f) || F > largest[f].first) largest[f] = {F, &c};
      }
      std::string levels;
      for (const auto& [f, big] : largest) {
        level.frequency_hz.push_back(f);
        if (reach.contains(f)) {
          level.lowest_force.push_back(reach[f].first);
          level.guess_force.push_back(nan);
          levels += fmt::format("{}at {:g} Hz from {:g} N", levels.empty() ? "" : "; ", f,
                                reach[f].first);
        } else {
          const double a = big.second->joint_amplitude[j];
          const double guess = a > 0.0 ? big.first * level.threshold / a : nan;
          level.lowest_force.push_back(nan);
          level.guess_force.push_back(guess);
          levels +=
              fmt::format("{}at {:g} Hz none of the candidates (the largest, {:g} N, "
                          "reaches {:.3g} of it; about {:.3g} N by linear scaling)",
                          levels.empty() ? "" : "; ", f, big.first, a / level.threshold, guess);
        }
      }
      level.sentence = fmt::format(
          "joint '{}': its {} reaches {} where its deformation exceeds {:.4g} (by the model's "
          "values): {}. Below that {}; tests that reach it determine {}",
          J.name, name, level.regime, level.threshold,
          levels.empty() ? std::string("no candidate could be predicted") : levels, below, above);
      out.push_back(std::move(level));
    }
  }
  return out;
}

} // namespace jointid::identify
