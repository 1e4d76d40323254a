#include "identify/sine_tests.hpp"

#include "fem/constants.hpp"
#include "fem/parallel.hpp"
#include "fem/time_integration.hpp"
#include "fem/transient.hpp"
#include "frf/time_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>

namespace jointid::identify {

namespace {

std::string compact(double value) {
  return fmt::format("{}", value);
}

void add_unique(std::vector<int>& list, int value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

// The derivative of a periodic signal sampled uniformly over whole periods, from the harmonics
// of its period (below the Nyquist frequency).
Eigen::VectorXd periodic_derivative(const Eigen::VectorXd& x, double omega, int periods) {
  const auto n = x.size();
  const auto per = n / periods; // samples per period
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(per);
  for (int p = 0; p < periods; ++p)
    mean += x.segment(p * per, per) / periods;
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(per);
  for (Eigen::Index k = 1; k <= (per - 1) / 2; ++k) {
    const double step = two_pi * static_cast<double>(k) / static_cast<double>(per);
    std::complex<double> X = 0.0;
    for (Eigen::Index i = 0; i < per; ++i)
      X += mean(i) * std::polar(1.0, -step * static_cast<double>(i));
    const std::complex<double> D = std::complex<double>(0.0, static_cast<double>(k) * omega) * X *
                                   (2.0 / static_cast<double>(per));
    for (Eigen::Index i = 0; i < per; ++i)
      dx(i) += (D * std::polar(1.0, step * static_cast<double>(i))).real();
  }
  return dx.replicate(periods, 1);
}

} // namespace

std::string joint_comment(const joints::Joint& j) {
  std::string text =
      fmt::format("joint '{}': {}:{} {}", j.name, j.node, fem::dof_name(j.dof),
                  j.to_ground() ? std::string("to ground") : fmt::format("to node {}", j.node_b));
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const auto& info = joints::term_info(j.terms[t]);
    if (info.parameters.empty()) {
      text += fmt::format("{} {} = {}", t == 0 ? ";" : ",", info.name, compact(j.values[t]));
      continue;
    }
    const auto list = j.parameters_of(t); // "iwan.fs = 3, iwan.kt = 10000, …"
    for (std::size_t p = 0; p < info.parameters.size(); ++p)
      text += fmt::format("{} {}.{} = {}", t == 0 && p == 0 ? ";" : ",", info.name,
                          info.parameters[p].name,
                          p < list.size() ? compact(list[p].value) : std::string("?"));
  }
  return text;
}

std::string sine_test_name(const SineTestPlan& plan) {
  return fmt::format("sine_f{}Hz_F{}N.csv", compact(plan.frequency_hz), compact(plan.amplitude));
}

std::vector<SimulatedTest> simulate_sine_tests(const frf::Substructure& sub,
                                               const std::vector<joints::Joint>& joints,
                                               const fem::NodeDof& force_at,
                                               const std::vector<SineTestPlan>& plans,
                                               const SimulationOptions& o) {
  // 1. Everything that can be checked before computing.
  if (plans.empty()) throw std::invalid_argument("simulate: no tests");
  for (const auto& p : plans) {
    if (!(std::isfinite(p.frequency_hz) && p.frequency_hz > 0.0))
      throw std::invalid_argument(
          fmt::format("simulate: expected frequencies > 0 Hz, got {}", p.frequency_hz));
    if (!(std::isfinite(p.amplitude) && p.amplitude > 0.0))
      throw std::invalid_argument(
          fmt::format("simulate: expected finite amplitudes > 0 (N or N m), got {}", p.amplitude));
  }
  std::set<std::string> names;
  for (const auto& p : plans)
    if (!names.insert(sine_test_name(p)).second)
      throw std::invalid_argument(fmt::format("simulate: the test at {} Hz, {} N is listed twice",
                                              compact(p.frequency_hz), compact(p.amplitude)));
  if (o.periods < 1)
    throw std::invalid_argument(
        fmt::format("simulate: periods: expected at least 1, got {}", o.periods));
  if (o.steps_per_period < 8)
    throw std::invalid_argument(
        fmt::format("simulate: steps per period: expected at least 8, got {}", o.steps_per_period));
  const int keep = o.samples_per_period > 0 ? o.samples_per_period : o.steps_per_period;
  if (keep < 8 || o.steps_per_period % keep != 0)
    throw std::invalid_argument(fmt::format(
        "simulate: samples per period: expected at least 8 and a divisor of the {} steps per "
        "period, got {}",
        o.steps_per_period, keep));
  const int stride = o.steps_per_period / keep;
  if (o.quantities.empty())
    throw std::invalid_argument("simulate: no response quantity asked (x, v or a)");
  for (Quantity q : o.quantities)
    if (q == Quantity::force)
      throw std::invalid_argument("simulate: force is always written; responses are x, v or a");
  const bool time_domain = o.method == SimulationMethod::time_integration;

  const fem::DofMap& dofs = sub.dofs();
  joints::validate_joints(joints, dofs);
  const int force_equation = dofs.equation(force_at);
  // Outputs: every joint DOF, then the force DOF, then the extra ones.
  std::vector<int> outputs = joints::joint_dof_set(joints, dofs);
  add_unique(outputs, force_equation);
  for (const auto& at : o.extra_outputs)
    add_unique(outputs, dofs.equation(at));
  const auto nout = static_cast<Eigen::Index>(outputs.size());

  auto make_test = [&](const SineTestPlan& plan, const Eigen::VectorXd& t,
                       const Eigen::VectorXd& force, const Eigen::MatrixXd& u,
                       const Eigen::MatrixXd& v) {
    SimulatedTest s;
    s.plan = plan;
    Record& r = s.record;
    r.source = sine_test_name(plan);
    r.excitation_hz = plan.frequency_hz;
    const auto n = static_cast<Eigen::Index>((t.size() + stride - 1) / stride);
    auto sampled = [&](const Eigen::VectorXd& x) {
      Eigen::VectorXd y(n);
      for (Eigen::Index i = 0; i < n; ++i)
        y(i) = x(i * stride);
      return y;
    };
    r.t = sampled(t);
    r.channels.push_back({Quantity::force, force_at, sampled(force)});
    const double omega = two_pi * plan.frequency_hz;
    for (Eigen::Index j = 0; j < nout; ++j) {
      const fem::NodeDof at = dofs.node_dof(outputs[j]);
      for (Quantity q : o.quantities) {
        if (q == Quantity::displacement) r.channels.push_back({q, at, sampled(u.col(j))});
        if (q == Quantity::velocity) r.channels.push_back({q, at, sampled(v.col(j))});
        if (q == Quantity::acceleration)
          r.channels.push_back({q, at, periodic_derivative(sampled(v.col(j)), omega, o.periods)});
      }
    }
    s.comments.push_back(fmt::format("sine force {} N (peak) at {} Hz on {}",
                                     compact(plan.amplitude), compact(plan.frequency_hz),
                                     fem::to_string(force_at)));
    for (const auto& j : joints)
      s.comments.push_back(joint_comment(j));
    return s;
  };

  // Progress: tests done so far, reported under a lock (parallel jobs finish in any order).
  std::mutex progress_lock;
  std::size_t finished = 0;
  auto one_done = [&] {
    if (!o.progress) return;
    const std::lock_guard<std::mutex> lock(progress_lock);
    o.progress(static_cast<double>(++finished) / static_cast<double>(plans.size()));
  };
  // A test without a record: its name and why.
  auto failed_test = [](const SineTestPlan& plan, fem::Status status) {
    SimulatedTest failed;
    failed.plan = plan;
    failed.record.source = sine_test_name(plan);
    failed.status = std::move(status);
    return failed;
  };
  std::vector<SimulatedTest> out;
  if (time_domain) {
    // Finite element models in full, [modal] models in their modal coordinates with their
    // residual flexibility (frf/time_model.hpp).
    frf::TimeDomainModel model;
    try {
      model = frf::time_domain_model(sub);
    } catch (const std::invalid_argument& e) { // measured FRFs
      throw std::invalid_argument(std::string("simulate: ") + e.what() +
                                  "; or simulate by harmonic balance");
    }
    if (!model.status.ok()) {
      for (const auto& plan : plans)
        out.push_back(failed_test(plan, model.status.within(fmt::format(
                                            "time integration at {} Hz, {} N: ",
                                            compact(plan.frequency_hz), compact(plan.amplitude)))));
      return out;
    }
    // How the substructure is integrated, when it is not one finite element model in full.
    std::string coordinates;
    if (!sub.system()) {
      for (std::size_t p = 0; p < model.parts.size(); ++p)
        coordinates += model.parts.size() == 1 ? model.parts[p]
                                               : fmt::format("{}substructure {}: {}", p ? "; " : "",
                                                             p + 1, model.parts[p]);
      coordinates = ", " + coordinates;
    }
    const joints::JointForces forces(joints, dofs);
    fem::SteadyStateOptions options;
    options.steps_per_period = o.steps_per_period;
    options.output_periods = o.periods;
    options.max_periods = std::max(options.max_periods, o.periods + 2);
    options.tolerance = o.steady_tolerance;
    std::vector<std::function<SimulatedTest()>> jobs;
    for (const auto& plan : plans)
      jobs.push_back([&, plan] {
        const fem::SteadyState s = fem::steady_state(
            model.model, &forces, {force_equation, plan.amplitude, plan.frequency_hz}, outputs,
            options);
        const bool periodic = s.status.ok();
        if (!periodic && s.status.code != fem::Status::Code::not_periodic) {
          one_done();
          return failed_test(plan, s.status.within(fmt::format("time integration at {} Hz, {} N: ",
                                                               compact(plan.frequency_hz),
                                                               compact(plan.amplitude))));
        }
        SimulatedTest test = make_test(plan, s.t, s.force, s.u, s.v);
        test.comments.push_back(fmt::format(
            "method: time{} (Newmark, average acceleration, {} steps per period{})", coordinates,
            o.steps_per_period,
            stride > 1 ? fmt::format(", every {}th step recorded", stride) : std::string()));
        test.comments.push_back(fmt::format(
            "periods run: {} from rest ({}; last period-to-period change {:.3g}); the record "
            "holds the last {}",
            s.periods_run, periodic ? "steady state reached" : "NOT periodic", s.period_change,
            o.periods));
        if (!periodic) {
          const std::string what =
              fmt::format("{}: not a periodic steady state after {} periods (last period-to-period "
                          "change {:.3g})",
                          test.record.source, s.periods_run, s.period_change);
          test.comments.push_back("WARNING: " + what);
          test.warnings.push_back(what);
        }
        one_done();
        return test;
      });
    out = fem::parallel_map(jobs);
  } else {
    double f_max = 0.0;
    for (const auto& p : plans)
      f_max = std::max(f_max, p.frequency_hz);
    std::vector<std::string> notes;
    const frf::ModalSynthesis synthesis =
        sub.synthesis(outputs, frf::synthesis_band_hz(f_max, o.balance.harmonics), &notes);
    if (!synthesis.status().ok()) {
      for (const auto& plan : plans)
        out.push_back(failed_test(plan, synthesis.status().within(fmt::format(
                                            "harmonic balance at {} Hz, {} N: ",
                                            compact(plan.frequency_hz), compact(plan.amplitude)))));
      return out;
    }
    // Each force level swept up in frequency, every solution the next one's start (a hardening
    // joint's response has a fold that a solve from the linear response can miss).
    std::vector<std::size_t> order(plans.size());
    for (std::size_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return std::pair(plans[a].amplitude, plans[a].frequency_hz) <
             std::pair(plans[b].amplitude, plans[b].frequency_hz);
    });
    std::vector<std::optional<SimulatedTest>> done(plans.size());
    std::optional<Eigen::MatrixXcd> previous;
    double previous_amplitude = -1.0;
    for (std::size_t i : order) {
      const SineTestPlan& plan = plans[i];
      if (plan.amplitude != previous_amplitude || !o.warm_start) previous.reset();
      previous_amplitude = plan.amplitude;
      const frf::HarmonicBalance problem(synthesis, joints, dofs, {force_equation}, outputs,
                                         plan.frequency_hz, o.balance);
      const Eigen::MatrixXcd F = frf::sine_force(plan.amplitude);
      frf::HarmonicBalanceResult hb = problem.solve(joints, F, previous ? &*previous : nullptr);
      if (!hb.status.ok() && previous) hb = problem.solve(joints, F);
      if (!hb.status.ok()) {
        done[i] = failed_test(
            plan, fem::Status::failure(
                      hb.status.code,
                      fmt::format("harmonic balance at {} Hz, {} N: no periodic solution found "
                                  "({}); simulate this test by time integration",
                                  compact(plan.frequency_hz), compact(plan.amplitude),
                                  hb.status.reason)));
        one_done();
        continue;
      }
      previous = hb.Y;
      const int samples = o.periods * o.steps_per_period;
      const double h = 1.0 / (plan.frequency_hz * o.steps_per_period);
      const double omega = two_pi * plan.frequency_hz;
      Eigen::VectorXd t(samples), force(samples);
      Eigen::MatrixXd u(samples, nout), v(samples, nout);
      for (int n = 0; n < samples; ++n) {
        t(n) = n * h;
        force(n) = plan.amplitude * std::sin(omega * t(n));
        for (Eigen::Index j = 0; j < nout; ++j) {
          u(n, j) = hb.displacement(static_cast<int>(j), t(n));
          v(n, j) = hb.velocity(static_cast<int>(j), t(n));
        }
      }
      SimulatedTest test = make_test(plan, t, force, u, v);
      test.comments.push_back(fmt::format(
          "method: hb (harmonic balance, harmonics 0 to {}{})", o.balance.harmonics,
          synthesis.has_residual() ? "; modal synthesis with residual flexibility" : ""));
      for (const auto& note : notes)
        test.comments.push_back(note);

      test.comments.push_back(fmt::format("harmonic balance: converged after {} iterations "
                                          "(relative residual {:.3g}); {} periods sampled from "
                                          "the harmonics",
                                          hb.iterations, hb.residual, o.periods));
      done[i] = std::move(test);
      one_done();
    }
    for (auto& t : done)
      out.push_back(std::move(*t));
  }
  return out;
}

void add_noise(Record& record, double level, std::uint64_t seed, bool force) {
  if (!(level >= 0.0) || !std::isfinite(level))
    throw std::invalid_argument(fmt::format("noise: expected a level >= 0, got {}", level));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (auto& c : record.channels) {
    if (c.quantity == Quantity::force && !force) continue;
    const double mean = c.samples.mean();
    const double rms = std::sqrt((c.samples.array() - mean).square().mean());
    for (Eigen::Index i = 0; i < c.samples.size(); ++i)
      c.samples(i) += level * rms * normal(rng);
  }
}

void add_noise(std::vector<SimulatedTest>& tests, double level, std::uint64_t seed) {
  if (level == 0.0) return;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    add_noise(tests[i].record, level, seed + i);
    tests[i].comments.push_back(fmt::format(
        "noise: white Gaussian, RMS {} of each channel's RMS, on every channel (seed {})", level,
        seed + i));
  }
}

std::vector<std::string> stepped_sine_comments(const std::vector<SimulatedTest>& tests) {
  std::vector<std::string> comments{"one sine test a row: fundamentals of the records"};
  if (tests.empty()) return comments;
  for (const auto& c : tests.front().comments)
    if (c.rfind("joint ", 0) == 0 || c.rfind("method", 0) == 0 || c.rfind("noise", 0) == 0)
      comments.push_back(c);
  return comments;
}

} // namespace jointid::identify
