#include "identify/parametric.hpp"

#include "joints/hysteresis.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace jointid::identify {

namespace {

using Complex = std::complex<double>;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

bool is_log(const joints::ParameterInfo& info) {
  return info.low == 0.0 && std::isinf(info.high);
}
bool is_exponent(const joints::ParameterInfo& info) {
  return info.low == -1.0 && info.high == 0.0;
}

} // namespace

double parameter_to_u(const joints::ParameterInfo& info, double p) {
  if (is_log(info)) return std::log(std::max(p, 1e-300));
  if (is_exponent(info)) {
    const double s = std::clamp(-p, 1e-9, 1.0 - 1e-9); // s = 1/(1 + e^{−u})
    return std::log(s / (1.0 - s));
  }
  return p;
}

double parameter_from_u(const joints::ParameterInfo& info, double u) {
  if (is_log(info)) return std::exp(u);
  if (is_exponent(info)) return -1.0 / (1.0 + std::exp(-u));
  return u;
}

Complex describing_function(const joints::Joint& j, std::size_t t, double a, int samples) {
  const auto n = static_cast<std::size_t>(samples);
  std::vector<double> y(n), g(n);
  for (std::size_t s = 0; s < n; ++s)
    y[s] = a * std::cos(2.0 * std::numbers::pi * static_cast<double>(s) / samples);
  if (j.terms[t] == joints::Term::gap) {
    for (std::size_t s = 0; s < n; ++s)
      g[s] = joints::gap_force(j.parameter(t, "delta"), j.parameter(t, "kg"), y[s]);
  } else {
    const joints::Sliders sliders =
        j.terms[t] == joints::Term::jenkins
            ? joints::jenkins_sliders(j.parameter(t, "kt"), j.parameter(t, "fs"))
            : joints::iwan_sliders(j.parameter(t, "fs"), j.parameter(t, "kt"),
                                   j.parameter(t, "chi"), j.parameter(t, "beta"), j.iwan_sliders);
    joints::LoopWork work;
    joints::steady_loop(sliders, y, false, g, nullptr, work);
  }
  Complex G1 = 0.0; // g = Re(G₁ e^{iθ}) + …
  for (std::size_t s = 0; s < n; ++s)
    G1 += g[s] *
          std::polar(2.0 / samples, -2.0 * std::numbers::pi * static_cast<double>(s) / samples);
  return G1 / a;
}

double joint_amplitude(const Measurement& m, const joints::Joint& j) {
  const int r = m.response_index({j.node, j.dof});
  if (r < 0 || !m.has_harmonic(1)) return nan;
  Complex Y = m.X(1, r);
  if (!j.to_ground()) {
    const int rb = m.response_index({j.node_b, j.dof});
    if (rb < 0) return nan;
    Y -= m.X(1, rb);
  }
  return std::abs(Y);
}

std::vector<joints::Joint> with_parametric_fixed(std::vector<joints::Joint> joints) {
  for (joints::Joint& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      if (joints::has_parameters(j.terms[t])) {
        for (joints::Parameter& p : j.parameters[t])
          p.fixed = true;
        j.fixed[t] = true;
      }
  return joints;
}

joints::Joint fit_describing_function(const joints::Joint& J, std::size_t T,
                                      std::vector<EquivalentStiffness> points, bool k_open,
                                      bool c_open, std::string& note) {
  using Point = EquivalentStiffness;
  const joints::Term term = J.terms[T];
  if (points.empty())
    throw std::invalid_argument("joint '" + J.name + "': no equivalent stiffness to fit its " +
                                std::string(joints::term_name(term)) + " to");
  std::sort(points.begin(), points.end(),
            [](const Point& p, const Point& q) { return p.amplitude < q.amplitude; });
  joints::Joint out = J;
  // 2. N(a) + k + iωc fitted to Z(a).
  const auto& info = joints::term_info(term).parameters;
  const auto np = static_cast<Eigen::Index>(info.size());
  std::vector<bool> free(info.size());
  for (std::size_t p = 0; p < info.size(); ++p)
    free[p] = !(J.parameters.size() > T && J.parameters[T].size() == info.size() &&
                J.parameters[T][p].fixed);
  joints::Joint trial = J;
  if (trial.parameters.size() <= T || trial.parameters[T].size() != info.size())
    trial.set_parameters(T, std::vector<double>(info.size(), 0.0), false);
  const auto residual = [&](const Eigen::VectorXd& u, Eigen::VectorXd& r) -> bool {
    for (Eigen::Index p = 0; p < np; ++p) {
      joints::Parameter& P = trial.parameters[T][static_cast<std::size_t>(p)];
      P.value = parameter_from_u(info[static_cast<std::size_t>(p)], u(p));
      P.given = true;
    }
    try {
      joints::check_parameters(trial);
    } catch (const std::invalid_argument&) {
      return false;
    }
    const auto n = static_cast<Eigen::Index>(points.size());
    Eigen::VectorXcd e(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Point& P = points[static_cast<std::size_t>(i)];
      e(i) = P.Z - describing_function(trial, T, P.amplitude);
    }
    // The joint's own k and c by least squares (each point weighted by 1/|Z|).
    double kw = 0.0, w = 0.0, cw = 0.0, wc = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Point& P = points[static_cast<std::size_t>(i)];
      const double wi = 1.0 / std::max(std::norm(P.Z), 1e-300);
      kw += wi * e(i).real(), w += wi;
      cw += wi * P.omega * e(i).imag(), wc += wi * P.omega * P.omega;
    }
    const double k = k_open ? kw / w : 0.0, c = c_open ? cw / wc : 0.0;
    r.resize(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Point& P = points[static_cast<std::size_t>(i)];
      const Complex d = (e(i) - Complex(k, P.omega * c)) / std::max(std::abs(P.Z), 1e-300);
      r(2 * i) = d.real(), r(2 * i + 1) = d.imag();
    }
    return r.allFinite();
  };

  // Starts read off the data.
  const Point &lo = points.front(), &hi = points.back();
  double dissipation = 0.0; // π a² Im Z: the dissipation per cycle, largest
  for (const Point& P : points)
    dissipation = std::max(dissipation, std::numbers::pi * P.amplitude * P.amplitude * P.Z.imag());
  const double lost = lo.Z.real() - hi.Z.real(), gained = -lost;
  const double k_small = std::max(k_open ? lost : lo.Z.real(), 1e-3 * std::abs(lo.Z));
  std::vector<std::vector<double>> starts;
  if (J.parameters.size() > T && J.parameters[T].size() == info.size() &&
      std::all_of(J.parameters[T].begin(), J.parameters[T].end(),
                  [](const joints::Parameter& p) { return p.given; })) {
    std::vector<double> given;
    for (const joints::Parameter& p : J.parameters[T])
      given.push_back(p.value);
    starts.push_back(given);
  }
  for (const double scale : {0.3, 1.0, 3.0}) {
    const double fs = std::max(scale * dissipation / (4.0 * hi.amplitude), 1e-300);
    if (term == joints::Term::jenkins) starts.push_back({std::max(k_small, 1e-300), fs});
    if (term == joints::Term::iwan)
      for (const double chi : {-0.6, -0.2})
        starts.push_back({3.0 * fs, std::max(k_small, 1e-300), chi, 0.1});
    if (term == joints::Term::gap)
      starts.push_back(
          {scale * lo.amplitude, std::max(gained > 0.0 ? 2.0 * gained : std::abs(hi.Z), 1e-300)});
  }
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best;
  for (const auto& s : starts) {
    Eigen::VectorXd u(np), r, rn;
    for (Eigen::Index p = 0; p < np; ++p) {
      const std::size_t q = static_cast<std::size_t>(p);
      const bool keep = !free[q] && J.parameters.size() > T;
      u(p) = parameter_to_u(info[q], keep ? J.parameters[T][q].value : s[q]);
    }
    if (!residual(u, r)) continue;
    double cost = r.squaredNorm(), mu = 1e-2;
    for (int it = 0; it < 60; ++it) {
      Eigen::MatrixXd Jm = Eigen::MatrixXd::Zero(r.size(), np);
      for (Eigen::Index p = 0; p < np; ++p) {
        if (!free[static_cast<std::size_t>(p)]) continue;
        const double h = 1e-6 * std::max(1.0, std::abs(u(p)));
        Eigen::VectorXd up = u;
        up(p) += h;
        if (residual(up, rn)) {
          Jm.col(p) = (rn - r) / h;
        } else {
          up(p) = u(p) - h;
          if (residual(up, rn)) Jm.col(p) = (r - rn) / h;
        }
      }
      const Eigen::MatrixXd A = Jm.transpose() * Jm;
      const Eigen::VectorXd g = Jm.transpose() * r;
      bool accepted = false;
      for (int tries = 0; tries < 10 && !accepted; ++tries) {
        Eigen::MatrixXd M = A;
        M.diagonal().array() += mu * (1.0 + A.diagonal().array());
        const Eigen::VectorXd next = u - M.ldlt().solve(g);
        if (next.allFinite() && residual(next, rn) && rn.squaredNorm() < cost) {
          const double gain = (cost - rn.squaredNorm()) / cost;
          u = next, r = rn, cost = rn.squaredNorm(), mu = std::max(mu / 10.0, 1e-10);
          accepted = true;
          if (gain < 1e-12) it = 1000;
        } else {
          mu *= 10.0;
        }
      }
      if (!accepted) break;
    }
    (void)residual(u, r); // r at u, trial's parameters too
    if (r.squaredNorm() < best_cost) best_cost = r.squaredNorm(), best = u;
  }
  if (best.size() == 0)
    throw std::invalid_argument("joint '" + J.name + "': the describing-function fit of its " +
                                std::string(joints::term_name(term)) + " found no start");
  if (out.parameters.size() <= T || out.parameters[T].size() != info.size())
    out.set_parameters(T, std::vector<double>(info.size(), 0.0), false);
  std::string values;
  for (Eigen::Index p = 0; p < np; ++p) {
    const std::size_t q = static_cast<std::size_t>(p);
    joints::Parameter& P = out.parameters[T][q];
    P.value = parameter_from_u(info[q], best(p));
    P.given = true;
    values += fmt::format("{}{}.{} = {:.4g}", values.empty() ? "" : ", ", joints::term_name(term),
                          info[q].name, P.value);
  }
  if (!out.given.empty()) out.given[T] = true;
  note = fmt::format(
      "joint '{}': {} started from a describing-function fit of the equivalent stiffness and "
      "damping of {} test(s) at deformation amplitudes {:.3g} … {:.3g} (relative misfit "
      "{:.2g}): {}",
      J.name, joints::term_name(term), points.size(), lo.amplitude, hi.amplitude,
      std::sqrt(best_cost / static_cast<double>(2 * points.size())), values);
  return out;
}

std::vector<joints::Joint> describing_function_start(const frf::Substructure& sub,
                                                     const std::vector<joints::Joint>& joints,
                                                     const std::vector<Measurement>& tests,
                                                     const FitOptions& fit_options,
                                                     std::vector<std::string>& notes) {
  std::vector<joints::Joint> out = joints;
  for (std::size_t jj = 0; jj < joints.size(); ++jj) {
    const joints::Joint& J = joints[jj];
    std::vector<std::size_t> open;
    for (std::size_t t = 0; t < J.terms.size(); ++t)
      if (joints::has_parameters(J.terms[t]) && !J.fixed[t]) open.push_back(t);
    if (open.empty()) continue;
    if (open.size() > 1)
      throw std::invalid_argument("joint '" + J.name +
                                  "': one parametric term at a time is identified (" +
                                  std::to_string(open.size()) +
                                  " are not fixed); give the others' parameters and fix them");
    const std::size_t T = open[0];
    const joints::Term term = J.terms[T];

    // 1. Each test alone: this joint as k + c (with its fixed terms), the others as they are
    // with their parametric terms at their given values held.
    joints::Joint linear = J;
    linear.terms.clear(), linear.values.clear(), linear.fixed.clear(), linear.given.clear();
    linear.parameters.clear();
    double k_fixed = 0.0, c_fixed = 0.0;
    bool k_open = false, c_open = false;
    for (std::size_t t = 0; t < J.terms.size(); ++t) {
      if (t == T) continue;
      if (J.terms[t] == joints::Term::k || J.terms[t] == joints::Term::c) {
        const bool is_k = J.terms[t] == joints::Term::k;
        if (J.fixed[t])
          (is_k ? k_fixed : c_fixed) += J.values[t];
        else
          (is_k ? k_open : c_open) = true;
        continue;
      }
      if (!J.fixed[t]) continue; // other unknown coefficient terms start at 0
      linear.terms.push_back(J.terms[t]);
      linear.values.push_back(J.values[t]);
      linear.fixed.push_back(true);
      linear.parameters.push_back(J.parameters.size() > t ? J.parameters[t]
                                                          : std::vector<joints::Parameter>{});
    }
    linear.terms.insert(linear.terms.begin(), {joints::Term::k, joints::Term::c});
    linear.values.insert(linear.values.begin(), {0.0, 0.0});
    linear.fixed.insert(linear.fixed.begin(), {false, false});
    linear.parameters.insert(linear.parameters.begin(), 2, {});
    if (!linear.has_parametric_terms()) linear.parameters.clear();
    std::vector<joints::Joint> model = with_parametric_fixed(joints);
    model[jj] = linear;
    std::vector<EquivalentStiffness> points;
    for (const Measurement& m : tests) {
      const double a = joint_amplitude(m, J);
      if (!(a > 0.0)) continue;
      try {
        const FitResult r = fit(sub, model, {m}, fit_options);
        if (!r.status.ok()) continue;
        const double omega = 2.0 * std::numbers::pi * m.frequency_hz;
        const double k = r.joints[jj].terms[0].value, c = r.joints[jj].terms[1].value;
        points.push_back({a, omega, Complex(k - k_fixed, omega * (c - c_fixed))});
      } catch (const std::invalid_argument&) {
        continue; // this test alone does not determine k and c: left out of the start
      }
    }
    if (points.empty())
      throw std::invalid_argument("joint '" + J.name +
                                  "': no test alone gives its equivalent "
                                  "stiffness and damping (the start of the " +
                                  std::string(joints::term_name(term)) +
                                  "'s output error): measure the joint's DOFs");
    std::string note;
    out[jj] = fit_describing_function(out[jj], T, std::move(points), k_open, c_open, note);
    notes.push_back(std::move(note));
  }
  return out;
}

} // namespace jointid::identify
