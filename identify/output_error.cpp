#include "identify/output_error.hpp"

#include "fem/constants.hpp"
#include "identify/harmonics.hpp"
#include "identify/parametric.hpp"
#include "identify/statistics.hpp"
#include "joints/basis.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace jointid::identify {

namespace {

using Complex = std::complex<double>;

// One compared value: harmonic k of the displacement (or, from a separate velocity channel, of
// the velocity: ikω X_k) at output `out` of test `test`.
struct Entry {
  int test, k, out;
  bool velocity;
  Complex measured;
  double sigma; // of each of its real and imaginary parts (of the real mean for k = 0)
};

// One test as the output-error fit drives and compares it.
struct Test {
  std::unique_ptr<frf::HarmonicBalance> balance;
  Eigen::MatrixXcd F;           // harmonics of the forces, the fundamental replaced
  std::vector<int> outputs;     // response equations compared
  Eigen::VectorXcd F1_measured; // per force channel
  Eigen::VectorXd F1_sigma;     // per force channel, each part
  mutable Eigen::MatrixXcd Y;   // the last solution (warm start)
};

} // namespace

FitResult output_error(const frf::ModalSynthesis& H, const fem::DofMap& dofs,
                       const std::vector<joints::Joint>& joints,
                       const std::vector<Measurement>& measurements, const FitResult& start,
                       const OutputErrorOptions& o) {
  if (!start.status.ok()) return start; // nothing to refine: its status passed up
  if (measurements.empty()) throw std::invalid_argument("output error: no tests");
  if (o.harmonics.empty()) throw std::invalid_argument("output error: no harmonics to compare");
  const int K = *std::max_element(o.harmonics.begin(), o.harmonics.end());
  if (o.balance.harmonics < K)
    throw std::invalid_argument("output error: the harmonic balance needs at least the " +
                                std::to_string(K) + " harmonics compared");
  std::vector<joints::Joint> model = start.identified(joints);
  for (const joints::Joint& j : model)
    joints::check_parameters(j); // a parametric term's start: every parameter has a value

  // The parameters: every non-fixed term (a parametric term's non-fixed parameters, each in
  // its natural coordinate: identify/parametric.hpp), then Re and Im of each test's force
  // fundamentals.
  struct Param {
    std::size_t joint, term;
    int parameter = -1; // of a parametric term
  };
  std::vector<Param> params;
  for (std::size_t j = 0; j < model.size(); ++j)
    for (std::size_t t = 0; t < model[j].terms.size(); ++t) {
      if (joints::has_parameters(model[j].terms[t])) {
        const auto list = model[j].parameters_of(t);
        for (std::size_t p = 0; p < list.size(); ++p)
          if (!list[p].fixed) params.push_back({j, t, static_cast<int>(p)});
        continue;
      }
      if (!model[j].fixed[t]) params.push_back({j, t});
    }
  const auto info_of = [&](const Param& p) -> const joints::ParameterInfo& {
    return joints::term_info(model[p.joint].terms[p.term])
        .parameters[static_cast<std::size_t>(p.parameter)];
  };
  const auto np = static_cast<Eigen::Index>(params.size());

  const std::vector<int> set2 = joint_dof_set(model, dofs);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(model, dofs, set2);
  // The tests, the compared entries and the nuisances.
  std::vector<Test> tests;
  std::vector<Entry> entries;
  Eigen::Index nuisances = 0;
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    if (m.fundamental_only || m.X_variance.size() == 0 || m.F_variance.size() == 0)
      throw std::invalid_argument(m.source + ": output error needs the record's noise (a "
                                             "stepped-sine table's is unknown)");
    Test t;
    std::vector<int> forces;
    std::vector<Eigen::Index> force_columns;
    for (std::size_t c = 0; c < m.force_at.size(); ++c)
      if (dofs.state(m.force_at[c]) == fem::DofMap::State::free) {
        forces.push_back(dofs.equation(m.force_at[c]));
        force_columns.push_back(static_cast<Eigen::Index>(c));
      }
    if (forces.empty())
      throw std::invalid_argument(m.source + ": no force on a free DOF of the model");
    const auto nf = static_cast<Eigen::Index>(forces.size());
    t.F = Eigen::MatrixXcd::Zero(m.F.rows(), nf);
    t.F1_measured.resize(nf);
    t.F1_sigma.resize(nf);
    for (Eigen::Index c = 0; c < nf; ++c) {
      const Eigen::Index mc = force_columns[static_cast<std::size_t>(c)];
      for (Eigen::Index k = 0; k < m.F.rows(); ++k) {
        const double var = m.F_variance(k, mc);
        if (k == 1 || !(std::norm(m.F(k, mc)) <= 25.0 * var)) t.F(k, c) = m.F(k, mc);
      }
      const double var = m.F_variance(1, mc);
      if (!(std::isfinite(var) && var > 0.0))
        throw std::invalid_argument(m.source +
                                    ": output error needs the noise of force channel f@" +
                                    fem::to_string(m.force_at[static_cast<std::size_t>(mc)]) +
                                    " (a record of two or more whole periods)");
      t.F1_measured(c) = m.F(1, mc);
      t.F1_sigma(c) = std::sqrt(var / 2.0);
    }
    nuisances += 2 * nf;
    for (std::size_t r = 0; r < m.response_at.size(); ++r) {
      if (dofs.state(m.response_at[r]) != fem::DofMap::State::free) continue;
      const int out = static_cast<int>(t.outputs.size());
      bool used = false;
      const auto rc = static_cast<Eigen::Index>(r);
      for (const int k : o.harmonics) {
        if (k > m.harmonics || (k == 0 && !m.has_mean[r])) continue;
        const double var = m.X_variance(k, rc);
        if (!(std::isfinite(var) && var > 0.0)) continue;
        entries.push_back(
            {static_cast<int>(i), k, out, false, m.X(k, rc), std::sqrt(k == 0 ? var : var / 2.0)});
        used = true;
      }
      // A separately measured velocity carries its own noise: its harmonics are data too.
      const double sv = r < m.velocity_noise.size() ? m.velocity_noise[r] : nan;
      if (std::isfinite(sv) && sv > 0.0 && m.t.size() > 2 * K) {
        const double omega = 2.0 * std::numbers::pi * m.frequency_hz;
        const Eigen::VectorXcd V = fit_harmonics(m.t, Eigen::VectorXd(m.v.col(rc)), omega, K);
        const double var =
            4.0 * sv * sv / (static_cast<double>(m.t.size()) * std::max(m.averaging, 1e-300));
        for (const int k : o.harmonics)
          if (k >= 1 && k <= m.harmonics) {
            entries.push_back({static_cast<int>(i), k, out, true, V(k), std::sqrt(var / 2.0)});
            used = true;
          }
      }
      if (used) t.outputs.push_back(dofs.equation(m.response_at[r]));
    }
    if (t.outputs.empty())
      throw std::invalid_argument(m.source + ": no response harmonic with a known noise to "
                                             "compare (output error)");
    t.balance = std::make_unique<frf::HarmonicBalance>(H, model, dofs, forces, t.outputs,
                                                       m.frequency_hz, o.balance);
    // The first Newton guess: the measured joint deformations, so that the harmonic balance
    // finds the periodic solution on the measured branch (a hardening joint has several).
    t.Y = Eigen::MatrixXcd::Zero(o.balance.harmonics + 1, static_cast<Eigen::Index>(model.size()));
    for (std::size_t d = 0; d < set2.size(); ++d) {
      const int r = m.response_index(dofs.node_dof(set2[d]));
      if (r < 0) continue;
      for (int k = 1; k <= std::min(m.harmonics, o.balance.harmonics); ++k)
        t.Y.row(k) += m.X(k, r) * B.row(static_cast<Eigen::Index>(d)).cast<Complex>();
    }
    tests.push_back(std::move(t));
  }
  const Eigen::Index n_data = [&] {
    Eigen::Index n = 0;
    for (const Entry& e : entries)
      n += e.k == 0 ? 1 : 2;
    return n;
  }();
  const Eigen::Index n_theta = np + nuisances, n_res = n_data + nuisances;

  // θ → joints and forces; the residual r(θ) (data, then the nuisances' measurements).
  Eigen::VectorXd theta(n_theta), step(n_theta);
  std::vector<bool> dissipative(static_cast<std::size_t>(np));
  for (Eigen::Index q = 0; q < np; ++q) {
    const Param& p = params[static_cast<std::size_t>(q)];
    if (p.parameter >= 0) {
      theta(q) = parameter_to_u(
          info_of(p),
          model[p.joint].parameters[p.term][static_cast<std::size_t>(p.parameter)].value);
      step(q) = 1e-6 * std::max(1.0, std::abs(theta(q)));
      dissipative[static_cast<std::size_t>(q)] = false;
      continue;
    }
    theta(q) = model[p.joint].values[p.term];
    dissipative[static_cast<std::size_t>(q)] =
        joints::term_info(model[p.joint].terms[p.term]).nature == joints::Nature::dissipative;
    double scale = std::abs(theta(q));
    for (const auto& je : start.joints)
      if (je.name == model[p.joint].name)
        for (const auto& te : je.terms)
          if (te.term == model[p.joint].terms[p.term] && std::isfinite(te.std))
            scale = std::max(scale, te.std);
    step(q) = 1e-6 * std::max(scale, 1e-300);
    if (dissipative[static_cast<std::size_t>(q)]) theta(q) = std::max(theta(q), 0.0);
  }
  {
    Eigen::Index at = np;
    for (const Test& t : tests)
      for (Eigen::Index c = 0; c < t.F1_measured.size(); ++c) {
        theta(at) = t.F1_measured(c).real();
        theta(at + 1) = t.F1_measured(c).imag();
        step(at) = step(at + 1) = 1e-6 * std::max(std::abs(t.F1_measured(c)), 1e-300);
        at += 2;
      }
  }
  const auto joints_at = [&](const Eigen::VectorXd& th) {
    std::vector<joints::Joint> js = model;
    for (Eigen::Index q = 0; q < np; ++q) {
      const Param& p = params[static_cast<std::size_t>(q)];
      if (p.parameter >= 0)
        js[p.joint].parameters[p.term][static_cast<std::size_t>(p.parameter)].value =
            parameter_from_u(info_of(p), th(q));
      else
        js[p.joint].values[p.term] = th(q);
    }
    return js;
  };
  // The simulated outputs of test i at θ (nullopt when the harmonic balance fails; `failure`
  // then holds its status).
  fem::Status failure;
  const auto simulate =
      [&](std::size_t i, const Eigen::VectorXd& th,
          const std::vector<joints::Joint>& js) -> std::optional<Eigen::MatrixXcd> {
    const Test& t = tests[i];
    Eigen::Index at = np;
    for (std::size_t k = 0; k < i; ++k)
      at += 2 * tests[k].F1_measured.size();
    Eigen::MatrixXcd F = t.F;
    for (Eigen::Index c = 0; c < F.cols(); ++c)
      F(1, c) = Complex(th(at + 2 * c), th(at + 2 * c + 1));
    frf::HarmonicBalanceResult r;
    try { // a step may take a parameter out of its range (fs → 0 by underflow): not a point
      r = t.balance->solve(js, F, t.Y.size() > 0 ? &t.Y : nullptr);
    } catch (const std::invalid_argument& e) {
      failure = fem::Status::failure(fem::Status::Code::not_converging, e.what());
      return std::nullopt;
    }
    if (!r.status.ok()) {
      failure = r.status;
      return std::nullopt;
    }
    t.Y = r.Y;
    return r.X;
  };
  const auto simulated = [&](const Entry& e, const std::vector<Eigen::MatrixXcd>& X) {
    const Complex x = X[static_cast<std::size_t>(e.test)](e.k, e.out);
    if (!e.velocity) return x;
    const double omega =
        2.0 * std::numbers::pi * measurements[static_cast<std::size_t>(e.test)].frequency_hz;
    return Complex(0.0, e.k * omega) * x;
  };
  const auto residual_of = [&](const std::vector<Eigen::MatrixXcd>& X, const Eigen::VectorXd& th) {
    Eigen::VectorXd r(n_res);
    Eigen::Index n = 0;
    for (const Entry& e : entries) {
      const Complex d = simulated(e, X) - e.measured;
      r(n++) = d.real() / e.sigma;
      if (e.k != 0) r(n++) = d.imag() / e.sigma;
    }
    Eigen::Index at = np;
    for (const Test& t : tests)
      for (Eigen::Index c = 0; c < t.F1_measured.size(); ++c) {
        r(n++) = (th(at) - t.F1_measured(c).real()) / t.F1_sigma(c);
        r(n++) = (th(at + 1) - t.F1_measured(c).imag()) / t.F1_sigma(c);
        at += 2;
      }
    return r;
  };
  const auto evaluate = [&](const Eigen::VectorXd& th, std::vector<Eigen::MatrixXcd>& X) -> bool {
    const std::vector<joints::Joint> js = joints_at(th);
    X.resize(tests.size());
    for (std::size_t i = 0; i < tests.size(); ++i) {
      auto x = simulate(i, th, js);
      if (!x) return false;
      X[i] = std::move(*x);
    }
    return true;
  };

  std::vector<Eigen::MatrixXcd> X(tests.size());
  {
    const std::vector<joints::Joint> js = joints_at(theta);
    for (std::size_t i = 0; i < tests.size(); ++i) {
      auto x = simulate(i, theta, js);
      if (!x) { // no start for the iteration: a status, no estimates
        FitResult failed;
        failed.status = failure.within(measurements[i].source +
                                       ": output error: the harmonic balance does not converge "
                                       "at the equation-error estimate: ");
        failed.warnings = start.warnings;
        return failed;
      }
      X[i] = std::move(*x);
    }
  }
  Eigen::VectorXd r = residual_of(X, theta);
  double cost = r.squaredNorm();

  // The Jacobian by forward differences: a term moves every test, a force only its own test.
  Eigen::MatrixXd J(n_res, n_theta);
  const auto jacobian = [&]() -> bool {
    J.setZero();
    for (Eigen::Index q = 0; q < n_theta; ++q) {
      bool done = false;
      for (const double h : {step(q), -step(q)}) {
        Eigen::VectorXd tq = theta;
        tq(q) += h;
        if (q < np && dissipative[static_cast<std::size_t>(q)] && tq(q) < 0.0) continue;
        std::vector<Eigen::MatrixXcd> Xq = X;
        bool ok = true;
        if (q < np) {
          ok = evaluate(tq, Xq);
        } else {
          std::size_t i = 0;
          Eigen::Index at = np;
          while (at + 2 * tests[i].F1_measured.size() <= q)
            at += 2 * tests[i].F1_measured.size(), ++i;
          const auto x = simulate(i, tq, joints_at(tq));
          ok = x.has_value();
          if (ok) Xq[i] = *x;
        }
        if (!ok) continue;
        J.col(q) = (residual_of(Xq, tq) - r) / h;
        done = true;
        break;
      }
      if (!done) return false;
    }
    // Leave the warm starts at θ.
    std::vector<Eigen::MatrixXcd> again;
    (void)evaluate(theta, again);
    return true;
  };

  int iterations = 0;
  double mu = 1e-3;
  bool stalled = false;
  for (; iterations < o.max_iterations; ++iterations) {
    if (!jacobian()) {
      stalled = true;
      break;
    }
    // Levenberg–Marquardt on the column-scaled problem.
    const Eigen::VectorXd scale = J.colwise().norm().cwiseMax(1e-300).transpose();
    const Eigen::MatrixXd Js = J * scale.cwiseInverse().asDiagonal();
    const Eigen::MatrixXd A = Js.transpose() * Js;
    const Eigen::VectorXd g = Js.transpose() * r;
    bool accepted = false;
    double gain = 0.0;
    for (int tries = 0; tries < 12 && !accepted; ++tries) {
      Eigen::MatrixXd M = A;
      M.diagonal().array() += mu;
      Eigen::VectorXd next = theta - scale.cwiseInverse().asDiagonal() * M.ldlt().solve(g);
      for (Eigen::Index q = 0; q < np; ++q)
        if (dissipative[static_cast<std::size_t>(q)]) next(q) = std::max(next(q), 0.0);
      std::vector<Eigen::MatrixXcd> Xn;
      if (next.allFinite() && evaluate(next, Xn)) {
        const Eigen::VectorXd rn = residual_of(Xn, next);
        if (rn.squaredNorm() < cost) {
          gain = (cost - rn.squaredNorm()) / cost;
          theta = next, X = std::move(Xn), r = rn, cost = r.squaredNorm();
          mu = std::max(mu / 10.0, 1e-12);
          accepted = true;
          break;
        }
      }
      (void)evaluate(theta, Xn); // the warm starts back at θ
      mu *= 10.0;
    }
    if (!accepted || gain < 1e-10) break;
  }
  if (!jacobian()) stalled = true;

  // The result: values, and intervals from (Jᵀ J)⁻¹ widened by χ²/dof above 1.
  FitResult out = start;
  const Eigen::Index dof = n_res - n_theta;
  const double chi2 = dof > 0 ? cost / static_cast<double>(dof) : nan;
  Eigen::MatrixXd C = Eigen::MatrixXd::Constant(n_theta, n_theta, nan);
  if (!stalled && dof > 0) { // on the column-scaled Jacobian: the units differ by many decades
    const Eigen::VectorXd s = J.colwise().norm().cwiseMax(1e-300).transpose().cwiseInverse();
    const Eigen::MatrixXd Js = J * s.asDiagonal();
    C = std::max(chi2, 1.0) * s.asDiagonal() *
        (Js.transpose() * Js).completeOrthogonalDecomposition().pseudoInverse() * s.asDiagonal();
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(Js).singularValues();
    out.singular_values.assign(sv.data(), sv.data() + sv.size());
    out.condition_number = sv(sv.size() - 1) > 0.0 ? sv(0) / sv(sv.size() - 1) : nan;
  }
  const double tq = dof > 0 ? student_t_quantile(0.975, static_cast<double>(dof)) : nan;
  const std::vector<joints::Joint> identified = joints_at(theta);
  std::vector<std::string> poorly;
  // An iwan that stayed in microslip in every test: its force there depends only on k + kt,
  // chi and the slip density's scale R (joints/hysteresis.hpp), so kt apart from k and fs apart
  // from beta are not determined: they are said so (no value), the combinations reported.
  const auto combination = [&](const auto& f) { // value, std and 95 % interval of f(joints)
    const double v = f(identified);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n_theta);
    for (Eigen::Index k = 0; k < np; ++k) {
      Eigen::VectorXd tk = theta;
      tk(k) += step(k);
      g(k) = (f(joints_at(tk)) - v) / step(k);
    }
    const double sd = std::sqrt(std::max(g.dot(C * g), 0.0));
    return std::array<double, 4>{v, sd, v - tq * sd, v + tq * sd};
  };
  // The largest deformation of joint j over the tests (a bound: Σ|Y_k| at the estimate).
  const auto peak_of = [&](std::size_t j) {
    double peak = 0.0;
    for (const Test& test : tests)
      peak = std::max(peak, test.Y.col(static_cast<Eigen::Index>(j)).cwiseAbs().sum());
    return peak;
  };
  const auto microslip = [&](std::size_t j, const joints::Joint& J, JointEstimate& je) {
    const int t = J.term_index(joints::Term::iwan);
    if (t < 0 || je.terms[static_cast<std::size_t>(t)].parameters.empty()) return;
    auto& pars = je.terms[static_cast<std::size_t>(t)].parameters;
    if (std::all_of(pars.begin(), pars.end(), [](const ParameterEstimate& p) { return p.fixed; }))
      return;
    const auto ti = static_cast<std::size_t>(t);
    const auto density = [ti, j](const std::vector<joints::Joint>& js) {
      return joints::iwan_density(js[j].parameter(ti, "fs"), js[j].parameter(ti, "kt"),
                                  js[j].parameter(ti, "chi"), js[j].parameter(ti, "beta"));
    };
    const double phi_max = density(identified).phi_max;
    const double peak = peak_of(j);
    const int k_index = J.term_index(joints::Term::k);
    const bool k_open = k_index >= 0 && !J.fixed[static_cast<std::size_t>(k_index)];
    // The estimate's φ_max itself is poorly told where the tests barely reach it: a fit may
    // settle just short of the largest deformation. The tests determine fs apart from beta only
    // if they tell the estimate from an iwan that stays in microslip in every test: the same
    // model refitted by output error with φ_max held at twice the largest deformation (fs and
    // beta fixed there, beyond which the force does not depend on them) must miss the data by
    // more than χ²₂(95 %) = 5.99 (scaled by χ²/dof above 1).
    std::string alternative;
    const auto fs_at = static_cast<std::size_t>(joints::parameter_index(joints::Term::iwan, "fs"));
    const auto beta_at =
        static_cast<std::size_t>(joints::parameter_index(joints::Term::iwan, "beta"));
    if (peak >= phi_max) {
      if (pars[fs_at].fixed || pars[beta_at].fixed || !std::isfinite(chi2)) return;
      const joints::IwanDensity d = density(identified);
      const double chi = d.chi, kt = identified[j].parameter(ti, "kt");
      const double beta = identified[j].parameter(ti, "beta");
      const auto A_of = [&](double phi) { return d.R * std::pow(phi, chi + 1.0) / (chi + 1.0); };
      double phi = 2.0 * peak, beta_alt = beta, kt_alt = kt;
      if (k_open) {
        kt_alt = A_of(phi) * (1.0 + beta);
      } else { // kt is determined (k fixed): S' = kt − A(φ') >= 0 bounds φ'
        phi = std::min(phi, std::pow(kt * (chi + 1.0) / d.R, 1.0 / (chi + 1.0)));
        beta_alt = kt / A_of(phi) - 1.0;
      }
      if (!(phi > 1.01 * peak) || !std::isfinite(kt_alt) || !(beta_alt >= 0.0)) return;
      const double shape = beta_alt + (chi + 1.0) / (chi + 2.0);
      // The same k + kt, chi and R, in microslip: the start of the constrained refit.
      std::vector<joints::Joint> js = identified;
      auto& P = js[j].parameters[ti];
      P[fs_at].value = A_of(phi) * phi * shape, P[fs_at].fixed = true;
      P[beta_at].value = beta_alt, P[beta_at].fixed = true;
      P[static_cast<std::size_t>(joints::parameter_index(joints::Term::iwan, "kt"))].value = kt_alt;
      if (k_open) js[j].values[static_cast<std::size_t>(k_index)] += kt - kt_alt;
      FitResult start_alt = start;
      for (std::size_t i = 0; i < js.size() && i < start_alt.joints.size(); ++i)
        for (std::size_t u = 0; u < js[i].terms.size() && u < start_alt.joints[i].terms.size(); ++u)
          start_alt.joints[i].terms[u].value = js[i].values[u];
      FitResult refit;
      try {
        refit = output_error(H, dofs, js, measurements, start_alt, o);
      } catch (const std::invalid_argument&) {
        return; // the refit left the parameters' ranges: the estimate stands
      }
      if (!refit.status.ok() || !std::isfinite(refit.chi2_per_dof)) return;
      const double cost_alt =
          refit.chi2_per_dof * static_cast<double>(refit.equations + nuisances - refit.unknowns);
      const double worse = (cost_alt - cost) / std::max(chi2, 1.0);
      if (!(worse <= 5.99)) return;
      alternative = fmt::format(
          "the tests do not tell its estimate (phi_max ≈ {:.3g}, below the largest deformation "
          "{:.3g}) from an iwan that stays in microslip in every test (refitted with phi_max "
          "{:.3g}: χ² larger by only {:.2g}, below 5.99); ",
          phi_max, peak, phi, worse);
    }
    std::vector<std::string> undetermined{"fs", "beta"};
    if (k_open) undetermined.push_back("kt");
    for (ParameterEstimate& p : pars)
      if (!p.fixed &&
          std::find(undetermined.begin(), undetermined.end(), p.name) != undetermined.end()) {
        p.value = p.std = p.ci_low = p.ci_high = nan;
        p.determined = false;
        std::erase(poorly, fmt::format("iwan.{} of '{}'", p.name, je.name));
      }
    std::string said;
    if (k_open) {
      auto& kt = je.terms[static_cast<std::size_t>(k_index)];
      kt.value = kt.std = kt.ci_low = kt.ci_high = nan;
      kt.determined = false;
      std::erase(poorly, fmt::format("k of '{}'", je.name));
      const auto sum = combination([&](const std::vector<joints::Joint>& js) {
        return js[j].values[static_cast<std::size_t>(k_index)] + js[j].parameter(ti, "kt");
      });
      said += fmt::format("k + iwan.kt = {:.5g} [{:.5g}, {:.5g}], ", sum[0], sum[2], sum[3]);
    }
    const auto R = combination([&](const std::vector<joints::Joint>& js) { return density(js).R; });
    said += fmt::format("the slip density's scale R = {:.5g} [{:.5g}, {:.5g}] (N/m^(chi+2))", R[0],
                        R[2], R[3]);
    out.identifiability.push_back(fmt::format(
        "joint '{}': {}, where its force depends only on k + kt, chi and the density's scale R: "
        "the tests determine {} and iwan.chi; {}iwan.fs apart from iwan.beta are undetermined (no "
        "value is given for them): a test whose deformation reaches beyond phi_max (macroslip) "
        "would determine them",
        je.name,
        alternative.empty()
            ? fmt::format("its iwan stayed in microslip in every test (largest deformation "
                          "{:.3g}, below the largest slip displacement phi_max ≈ {:.3g})",
                          peak, phi_max)
            : "its iwan did not reach macroslip distinguishably: " + alternative +
                  "as far as these tests tell it stayed in microslip",
        said, k_open ? "k apart from iwan.kt, and " : ""));
  };
  // A jenkins that never slipped, or a gap that never closed, in any test: the first acts as
  // its spring kt alone (k + kt is what the tests determine; fs only has a lower bound), the
  // second not at all (delta only has a lower bound, kg none). Said so, the combination given;
  // the undetermined parameters have no value.
  const auto never_engaged = [&](std::size_t j, const joints::Joint& J, JointEstimate& je) {
    for (const joints::Term term : {joints::Term::jenkins, joints::Term::gap}) {
      const int t = J.term_index(term);
      if (t < 0 || je.terms[static_cast<std::size_t>(t)].parameters.empty()) continue;
      const auto ti = static_cast<std::size_t>(t);
      auto& pars = je.terms[ti].parameters;
      const double peak = peak_of(j);
      const bool jenkins = term == joints::Term::jenkins;
      const double kt = jenkins ? identified[j].parameter(ti, "kt") : 0.0;
      const double reach =
          jenkins ? identified[j].parameter(ti, "fs") / kt : identified[j].parameter(ti, "delta");
      // A gap whose contact force stays negligible (the fit may close it at no stiffness, kg → 0,
      // where delta has no effect either): below 1e-6 of the joint's spring force.
      const double contact =
          jenkins ? 0.0 : identified[j].parameter(ti, "kg") * std::max(0.0, peak - reach);
      const int k_index = J.term_index(joints::Term::k);
      const bool no_force =
          !jenkins && k_index >= 0 &&
          contact <=
              1e-6 * std::abs(identified[j].values[static_cast<std::size_t>(k_index)]) * peak;
      if (!(peak < reach) && !no_force) continue; // it slips, or makes contact, in some test
      const bool kt_fixed =
          jenkins &&
          pars[static_cast<std::size_t>(joints::parameter_index(joints::Term::jenkins, "kt"))]
              .fixed;
      const bool k_open =
          jenkins && !kt_fixed && k_index >= 0 && !J.fixed[static_cast<std::size_t>(k_index)];
      std::vector<std::string> undetermined =
          jenkins ? std::vector<std::string>{"fs"} : std::vector<std::string>{"delta", "kg"};
      if (k_open) undetermined.push_back("kt");
      std::string names; // listed as undetermined ("k apart from jenkins.kt" says kt's)
      for (ParameterEstimate& p : pars)
        if (!p.fixed &&
            std::find(undetermined.begin(), undetermined.end(), p.name) != undetermined.end()) {
          p.value = p.std = p.ci_low = p.ci_high = nan;
          p.determined = false;
          const std::string name = fmt::format("{}.{}", joints::term_name(term), p.name);
          std::erase(poorly, fmt::format("{} of '{}'", name, je.name));
          if (!(k_open && p.name == "kt")) names += (names.empty() ? "" : " and ") + name;
        }
      std::string said;
      if (k_open) {
        auto& k = je.terms[static_cast<std::size_t>(k_index)];
        k.value = k.std = k.ci_low = k.ci_high = nan;
        k.determined = false;
        std::erase(poorly, fmt::format("k of '{}'", je.name));
        const auto sum = combination([&](const std::vector<joints::Joint>& js) {
          return js[j].values[static_cast<std::size_t>(k_index)] + js[j].parameter(ti, "kt");
        });
        said = fmt::format("the tests determine k + jenkins.kt = {:.5g} [{:.5g}, {:.5g}] N/m; k "
                           "apart from jenkins.kt{} {} undetermined",
                           sum[0], sum[2], sum[3], names.empty() ? "" : ", and " + names,
                           names.empty() ? "is" : "are");
      } else if (!names.empty()) {
        said = fmt::format("{} {} undetermined", names,
                           names.find(" and ") == std::string::npos ? "is" : "are");
      } else {
        continue; // nothing of it was identified
      }
      out.identifiability.push_back(fmt::format(
          "joint '{}': its {} in any test ({}), where {}: {} (no value is given for them; the "
          "tests show only that {} exceeds {:.3g} m{}): a test whose deformation reaches beyond "
          "it would determine them",
          je.name, jenkins ? "jenkins never slipped" : "gap never closed",
          peak < reach
              ? fmt::format("largest deformation {:.3g} m, below {} ≈ {:.3g} m", peak,
                            jenkins ? "its slip displacement fs/kt" : "its clearance delta", reach)
              : fmt::format("largest deformation {:.3g} m; the fit leaves it no contact "
                            "force: kg (peak − delta) = {:.3g} N",
                            peak, contact),
          jenkins ? "it acts as its spring kt alone" : "it exerts no force", said,
          jenkins ? "fs/kt" : "delta", peak, jenkins ? "" : " or that kg is negligible"));
    }
  };
  out.joints.clear();
  Eigen::Index q = 0;
  for (std::size_t j = 0; j < identified.size(); ++j) {
    JointEstimate je{identified[j].name, {}};
    for (std::size_t t = 0; t < identified[j].terms.size(); ++t) {
      TermEstimate te;
      te.term = identified[j].terms[t];
      te.parameters = parameters_of(identified[j], t);
      te.value = identified[j].values[t];
      te.fixed = identified[j].fixed[t];
      if (!te.parameters.empty()) { // a parametric term: its parameters, intervals through u
        te.std = 0.0, te.ci_low = te.ci_high = te.value;
        const auto& info = joints::term_info(te.term).parameters;
        for (std::size_t p = 0; p < te.parameters.size(); ++p) {
          ParameterEstimate& pe = te.parameters[p];
          if (pe.fixed) continue;
          const double u = theta(q),
                       su = std::isfinite(C(q, q)) ? std::sqrt(std::max(C(q, q), 0.0)) : nan;
          const double h = 1e-6 * std::max(1.0, std::abs(u));
          const double slope =
              (parameter_from_u(info[p], u + h) - parameter_from_u(info[p], u - h)) / (2.0 * h);
          pe.std = std::abs(slope) * su;
          const double a = parameter_from_u(info[p], u - tq * su),
                       b = parameter_from_u(info[p], u + tq * su);
          pe.ci_low = std::min(a, b), pe.ci_high = std::max(a, b);
          // A value at its bound (e.g. 0) with an interval to infinity is not a result.
          pe.determined =
              std::isfinite(pe.std) && pe.std <= o.poorly_determined * std::abs(pe.value) &&
              std::isfinite(pe.ci_low) && std::isfinite(pe.ci_high) && pe.ci_high > pe.ci_low;
          if (!pe.determined)
            poorly.push_back(
                fmt::format("{}.{} of '{}'", joints::term_name(te.term), pe.name, je.name));
          ++q;
        }
        je.terms.push_back(te);
        continue;
      }
      if (te.fixed) {
        te.std = 0.0;
        te.ci_low = te.ci_high = te.value;
      } else {
        te.std = std::isfinite(C(q, q)) ? std::sqrt(std::max(C(q, q), 0.0)) : nan;
        te.ci_low = te.value - tq * te.std;
        te.ci_high = te.value + tq * te.std;
        te.determined = std::isfinite(te.std) && te.std <= o.poorly_determined * std::abs(te.value);
        if (!te.determined)
          poorly.push_back(fmt::format("{} of '{}'", joints::term_name(te.term), je.name));
        ++q;
      }
      je.terms.push_back(te);
    }
    microslip(j, identified[j], je);
    never_engaged(j, identified[j], je);
    out.joints.push_back(std::move(je));
  }
  double misfit = 0.0, size = 0.0; // of the displacement values (m)
  for (const Entry& e : entries)
    if (!e.velocity) {
      misfit += std::norm(simulated(e, X) - e.measured);
      size += std::norm(e.measured);
    }
  out.equations = static_cast<int>(n_data);
  out.unknowns = static_cast<int>(n_theta);
  const auto n_x =
      std::count_if(entries.begin(), entries.end(), [](const Entry& e) { return !e.velocity; });
  out.residual_rms = n_x > 0 ? std::sqrt(misfit / static_cast<double>(n_x)) : nan;
  out.residual_relative = size > 0.0 ? std::sqrt(misfit / size) : nan;
  out.chi2_per_dof = chi2;
  out.interval_method = "output error";
  out.warnings.push_back(fmt::format(
      "output error: {} Levenberg–Marquardt iteration(s) from the equation-error estimate, "
      "χ²/dof {:.3g} over {} values (harmonics {} of the displacement, and of the velocity where "
      "it was measured, each weighted by its noise; the force fundamentals estimated with "
      "theirs){}",
      iterations, chi2, n_data, fmt::join(o.harmonics, ", "),
      stalled ? "; stopped: the harmonic balance did not converge near the estimate, the "
                "intervals are unknown"
              : ""));
  if (chi2 > 3.0)
    out.warnings.push_back(fmt::format(
        "output error: the model misses the data by more than their noise (χ²/dof {:.3g}): the "
        "intervals are widened by its square root, {:.3g}; a bias of the model (e.g. a missing "
        "term, or a simulation unlike the rig) is not in them",
        chi2, std::sqrt(chi2)));
  for (const std::string& p : poorly)
    out.warnings.push_back(fmt::format(
        "{} is poorly determined by output error (standard deviation above {} % of its value)", p,
        100.0 * o.poorly_determined));
  return out;
}

FitResult output_error(const frf::Substructure& sub, const std::vector<joints::Joint>& joints,
                       const std::vector<Measurement>& tests, const FitOptions& fit_options,
                       const OutputErrorOptions& o) {
  for (const Measurement& m : tests)
    if (m.kind == RecordKind::periodic)
      throw std::invalid_argument(
          m.source + ": a periodic broadband test: output error re-simulates each test by the "
                     "harmonic balance of one excitation frequency, which this test is not; "
                     "identify it by equation error (without --output-error)");
  // A parametric term's parameters start from a describing-function fit; the coefficient
  // terms from the equation error with that term's force known.
  const DescribingFunctionStart described =
      describing_function_start(sub, joints, tests, fit_options);
  if (!described.status.ok()) { // its reason names the joint and the term
    FitResult failed;
    failed.status = described.status;
    failed.warnings = described.notes;
    return failed;
  }
  const std::vector<std::string>& started = described.notes;
  const std::vector<joints::Joint>& begin = described.joints;
  const FitResult start = fit(sub, with_parametric_fixed(begin), tests, fit_options);
  if (!start.status.ok()) return start;
  std::vector<std::string> left_out; // their warnings are in the fit's already
  const std::vector<Measurement> usable_tests = usable(tests, left_out);
  std::vector<int> equations = joint_dof_set(joints, sub.dofs());
  double f_max = 0.0;
  for (const Measurement& m : usable_tests) {
    f_max = std::max(f_max, m.frequency_hz);
    for (const auto* list : {&m.force_at, &m.response_at})
      for (const fem::NodeDof& at : *list)
        if (sub.dofs().state(at) == fem::DofMap::State::free) {
          const int e = sub.dofs().equation(at);
          if (std::find(equations.begin(), equations.end(), e) == equations.end())
            equations.push_back(e);
        }
  }
  std::vector<std::string> notes;
  const frf::ModalSynthesis H =
      sub.synthesis(equations, frf::synthesis_band_hz(f_max, o.balance.harmonics), &notes);
  if (!H.status().ok()) {
    FitResult failed;
    failed.status = H.status();
    failed.warnings = std::move(notes);
    return failed;
  }
  FitResult out = output_error(H, sub.dofs(), begin, usable_tests, start, o);
  out.warnings.insert(out.warnings.begin(), started.begin(), started.end());
  for (const std::string& note : notes) // those of the fit's own synthesis are there already
    if (std::find(out.warnings.begin(), out.warnings.end(), note) == out.warnings.end())
      out.warnings.push_back(note);
  return out;
}

} // namespace jointid::identify
