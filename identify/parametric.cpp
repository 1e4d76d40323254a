#include "identify/parametric.hpp"

#include "fem/constants.hpp"
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

bool is_log(const joints::ParameterInfo& info) {
  return info.low == 0.0 && std::isinf(info.high);
}
bool is_exponent(const joints::ParameterInfo& info) {
  return info.low == -1.0 && info.high == 0.0;
}

// One test's equivalent dynamic stiffness of a joint.
using Point = EquivalentStiffness;

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

bool interval_determines(const joints::ParameterInfo& info, double value, double lo, double hi) {
  if (!(std::isfinite(lo) && std::isfinite(hi) && hi > lo)) return false;
  if (is_log(info)) return lo > 0.0 && hi <= 100.0 * lo;
  if (is_exponent(info)) return hi - lo <= 0.5 * (info.high - info.low);
  return hi - lo <= 2.0 * std::abs(value);
}

Complex describing_function(const joints::Joint& j, std::size_t t, double a) {
  const double amplitude[1] = {a};
  return describing_functions(j, t, amplitude).front();
}

namespace {

// N(a) of the sliders under y = a cos θ, the steady loop's first harmonic in closed form: an
// element (k, φ) stuck (a ≤ φ) gives k; one that slips gives (k/π)(β − ½ sin 2β + i sin²β),
// cos β = 1 − 2φ/a (the in-phase part falls from k at a = φ; the quadrature part is the loop's
// area 4kφ(a − φ) over π a²).
Complex sliders_describing_function(const joints::Sliders& s, double a) {
  double re = 0.0, im = 0.0;
  for (int i = 0; i < s.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    const double k = s.stiffness[u], phi = s.reach[u];
    if (a <= phi) {
      re += k;
      continue;
    }
    const double cb = 1.0 - 2.0 * phi / a, beta = std::acos(cb), sb2 = 1.0 - cb * cb;
    re += k / std::numbers::pi * (beta - std::sqrt(sb2) * cb); // ½ sin 2β = sin β cos β
    im += k / std::numbers::pi * sb2;
  }
  return {re, im};
}

// N(a) of the clearance under y = a cos θ: 0 while a ≤ δ, then kg (1 − (2/π)(asin r +
// r √(1 − r²))), r = δ/a; real (the force is a single-valued function of y).
double gap_describing_function(double delta, double kg, double a) {
  if (a <= delta) return 0.0;
  const double r = delta / a;
  return kg * (1.0 - 2.0 / std::numbers::pi * (std::asin(r) + r * std::sqrt(1.0 - r * r)));
}

} // namespace

std::vector<Complex> describing_functions(const joints::Joint& j, std::size_t t,
                                          std::span<const double> amplitudes, int per_efold) {
  std::vector<Complex> out(amplitudes.size());
  if (amplitudes.empty()) return out;
  const bool gap = j.terms[t] == joints::Term::gap;
  joints::Sliders sliders;
  double delta = 0.0, kg = 0.0;
  if (gap) {
    delta = j.parameter(t, "delta"), kg = j.parameter(t, "kg");
  } else {
    sliders =
        j.terms[t] == joints::Term::jenkins
            ? joints::jenkins_sliders(j.parameter(t, "kt"), j.parameter(t, "fs"))
            : joints::iwan_sliders(j.parameter(t, "fs"), j.parameter(t, "kt"),
                                   j.parameter(t, "chi"), j.parameter(t, "beta"), j.iwan_sliders);
  }
  // The amplitudes N is computed at: every one, or a grid in ln a with the onsets of the
  // term's kinks among its nodes (where a slider of at least 5 % of the stiffness starts to
  // slip, or the gap closes: N's slope jumps there).
  std::vector<double> at(amplitudes.begin(), amplitudes.end());
  const auto [lo, hi] = std::minmax_element(amplitudes.begin(), amplitudes.end());
  if (per_efold > 0 && *lo > 0.0 && *hi > *lo) {
    const double span = std::log(*hi / *lo);
    const auto points = static_cast<std::size_t>(std::ceil(per_efold * span)) + 1;
    std::vector<double> nodes;
    for (std::size_t g = 0; g < points; ++g)
      nodes.push_back(*lo *
                      std::exp(span * static_cast<double>(g) / static_cast<double>(points - 1)));
    nodes.back() = *hi;
    const double total = gap ? 0.0 : sliders.stiffness_sum();
    if (gap && delta > *lo && delta < *hi) nodes.push_back(delta);
    for (int i = 0; i < sliders.size(); ++i) {
      const auto u = static_cast<std::size_t>(i);
      if (sliders.stiffness[u] >= 0.05 * total && sliders.reach[u] > *lo && sliders.reach[u] < *hi)
        nodes.push_back(sliders.reach[u]);
    }
    std::sort(nodes.begin(), nodes.end());
    if (nodes.size() < amplitudes.size()) at = std::move(nodes);
  }
  std::vector<Complex> N(at.size());
  for (std::size_t i = 0; i < at.size(); ++i)
    N[i] = gap ? Complex(gap_describing_function(delta, kg, at[i]), 0.0)
               : sliders_describing_function(sliders, at[i]);
  if (at.size() == amplitudes.size()) return N;
  // Linear in ln a between the grid's nodes.
  for (std::size_t i = 0; i < amplitudes.size(); ++i) {
    const auto above = std::upper_bound(at.begin(), at.end(), amplitudes[i]);
    const auto k =
        std::min(static_cast<std::size_t>(std::max<std::ptrdiff_t>(above - at.begin() - 1, 0)),
                 at.size() - 2);
    const double w =
        std::clamp(std::log(amplitudes[i] / at[k]) / std::log(at[k + 1] / at[k]), 0.0, 1.0);
    out[i] = (1.0 - w) * N[k] + w * N[k + 1];
  }
  return out;
}

EquivalentSine joint_equivalent_sine(const Measurement& m, const joints::Joint& j) {
  const int r = m.response_index({j.node, j.dof});
  const int rb = j.to_ground() ? -1 : m.response_index({j.node_b, j.dof});
  if (r < 0 || (!j.to_ground() && rb < 0)) return {nan, nan};
  auto deformation = [&](int k) { return rb < 0 ? m.X(k, r) : m.X(k, r) - m.X(k, rb); };
  const double w0 = 2.0 * std::numbers::pi * m.frequency_hz;
  if (m.kind != RecordKind::periodic) {
    if (!m.has_harmonic(1)) return {nan, nan};
    return {std::abs(deformation(1)), w0};
  }
  double power = 0.0, rate = 0.0;
  for (const int l : m.lines) {
    const double p = std::norm(deformation(l));
    power += p, rate += p * (w0 * l) * (w0 * l);
  }
  if (!(power > 0.0)) return {0.0, nan};
  return {std::sqrt(power), std::sqrt(rate / power)};
}

double joint_amplitude(const Measurement& m, const joints::Joint& j) {
  return joint_equivalent_sine(m, j).amplitude;
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

void check_one_parametric_term(const std::vector<joints::Joint>& joints) {
  for (const joints::Joint& J : joints) {
    std::vector<std::string> open;
    for (std::size_t t = 0; t < J.terms.size(); ++t)
      if (joints::has_parameters(J.terms[t]) && !J.fixed[t])
        open.emplace_back(joints::term_name(J.terms[t]));
    if (open.size() > 1)
      throw std::invalid_argument(fmt::format(
          "joint '{}': its terms {} both have parameters that are not fixed; output error "
          "identifies one parametric term of a joint at a time: give all the parameters of the "
          "others in 'values' and list them in 'fixed'",
          J.name, fmt::join(open, " and ")));
  }
}

// Step 2: the parameters of the terms Ts of J (their fixed ones held), concatenated, in their
// coordinates u that fit Σ N_T(a) + k + iωc to the points, sorted by amplitude (the joint's own
// k and c by least squares where open), from a few starts read off the data (every combination
// of each term's starts); empty when no start gives a finite misfit.
static Eigen::VectorXd best_fit(const joints::Joint& J, const std::vector<std::size_t>& Ts,
                                const std::vector<Point>& points, bool k_open, bool c_open,
                                double& best_cost) {
  // 2. Σ N(a) + k + iωc fitted to Z(a).
  std::vector<std::size_t> offset; // of each term's parameters in u
  std::vector<bool> free;
  Eigen::Index np = 0;
  joints::Joint trial = J;
  for (const std::size_t T : Ts) {
    const auto& info = joints::term_info(J.terms[T]).parameters;
    offset.push_back(static_cast<std::size_t>(np));
    np += static_cast<Eigen::Index>(info.size());
    for (std::size_t p = 0; p < info.size(); ++p)
      free.push_back(!(J.parameters.size() > T && J.parameters[T].size() == info.size() &&
                       J.parameters[T][p].fixed));
    if (trial.parameters.size() <= T || trial.parameters[T].size() != info.size())
      trial.set_parameters(T, std::vector<double>(info.size(), 0.0), false);
  }
  std::vector<double> amplitudes;
  for (const Point& P : points)
    amplitudes.push_back(P.amplitude);
  // Each point's misfit relative to its |Z|, but not below a tenth of the largest: a joint that
  // is a correction to a substructure fitted at low level (its stiffness there in the
  // substructure) has Z near 0 at small amplitudes, where relative errors would be its noise.
  double largest = 0.0;
  for (const Point& P : points)
    largest = std::max(largest, std::abs(P.Z));
  const auto misfit_scale = [&](const Point& P) {
    return std::max({std::abs(P.Z), 0.1 * largest, 1e-300});
  };
  const auto residual = [&](const Eigen::VectorXd& u, Eigen::VectorXd& r) -> bool {
    for (std::size_t i = 0; i < Ts.size(); ++i) {
      const auto& info = joints::term_info(J.terms[Ts[i]]).parameters;
      for (std::size_t p = 0; p < info.size(); ++p) {
        joints::Parameter& P = trial.parameters[Ts[i]][p];
        P.value = parameter_from_u(info[p], u(static_cast<Eigen::Index>(offset[i] + p)));
        P.given = true;
      }
    }
    try {
      joints::check_parameters(trial);
    } catch (const std::invalid_argument&) {
      return false;
    }
    const auto n = static_cast<Eigen::Index>(points.size());
    Eigen::VectorXcd e(n);
    for (Eigen::Index i = 0; i < n; ++i)
      e(i) = points[static_cast<std::size_t>(i)].Z;
    for (const std::size_t T : Ts) {
      const std::vector<Complex> N = describing_functions(trial, T, amplitudes, 24);
      for (Eigen::Index i = 0; i < n; ++i)
        e(i) -= N[static_cast<std::size_t>(i)];
    }
    // The joint's own k and c by least squares (each point weighted by 1/|Z|).
    double kw = 0.0, w = 0.0, cw = 0.0, wc = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Point& P = points[static_cast<std::size_t>(i)];
      const double wi = 1.0 / std::pow(misfit_scale(P), 2);
      kw += wi * e(i).real(), w += wi;
      cw += wi * P.omega * e(i).imag(), wc += wi * P.omega * P.omega;
    }
    const double k = k_open ? kw / w : 0.0, c = c_open ? cw / wc : 0.0;
    r.resize(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Point& P = points[static_cast<std::size_t>(i)];
      const Complex d = (e(i) - Complex(k, P.omega * c)) / misfit_scale(P);
      r(2 * i) = d.real(), r(2 * i + 1) = d.imag();
    }
    return r.allFinite();
  };

  // Starts read off the data.
  const Point &lo = points.front(), &hi = points.back();
  double dissipation = 0.0; // π a² Im Z: the dissipation per cycle, largest
  for (const Point& P : points)
    dissipation = std::max(dissipation, std::numbers::pi * P.amplitude * P.amplitude * P.Z.imag());
  // The stiffness lost by slip and gained by contact: from the smallest amplitude's to the
  // least and the largest over the points (a joint can first slip, then close a clearance).
  double least = lo.Z.real(), most = lo.Z.real(), at_least = lo.amplitude;
  for (const Point& P : points) {
    if (P.Z.real() < least) at_least = P.amplitude;
    least = std::min(least, P.Z.real()), most = std::max(most, P.Z.real());
  }
  const double lost = lo.Z.real() - least, gained = most - lo.Z.real();
  const double k_small = std::max(k_open ? lost : lo.Z.real(), 1e-3 * std::abs(lo.Z));
  const bool pair = Ts.size() > 1;
  // Each term's starts, then every combination of them.
  std::vector<std::vector<std::vector<double>>> each;
  for (const std::size_t T : Ts) {
    const joints::Term term = J.terms[T];
    const auto& info = joints::term_info(term).parameters;
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
      if (term == joints::Term::gap) {
        const double kg =
            std::max(gained > 0.0 ? 2.0 * (pair ? most - least : gained) : std::abs(hi.Z), 1e-300);
        // Beside a slip, the clearance closes about where the stiffness stops falling.
        starts.push_back({scale * (pair ? at_least : lo.amplitude), kg});
      }
    }
    each.push_back(std::move(starts));
  }
  std::vector<std::vector<double>> starts{{}};
  for (const auto& list : each) {
    std::vector<std::vector<double>> next;
    for (const auto& head : starts)
      for (const auto& tail : list) {
        std::vector<double> joined = head;
        joined.insert(joined.end(), tail.begin(), tail.end());
        next.push_back(std::move(joined));
      }
    starts = std::move(next);
  }
  std::vector<double> held(static_cast<std::size_t>(np)); // the fixed parameters' values
  for (std::size_t i = 0; i < Ts.size(); ++i)
    for (std::size_t p = 0; p < J.parameters_of(Ts[i]).size(); ++p)
      held[offset[i] + p] = J.parameters_of(Ts[i])[p].value;
  best_cost = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best;
  for (const auto& s : starts) {
    Eigen::VectorXd u(np), r, rn;
    for (std::size_t i = 0; i < Ts.size(); ++i) {
      const auto& info = joints::term_info(J.terms[Ts[i]]).parameters;
      for (std::size_t p = 0; p < info.size(); ++p) {
        const std::size_t q = offset[i] + p;
        u(static_cast<Eigen::Index>(q)) = parameter_to_u(info[p], !free[q] ? held[q] : s[q]);
      }
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
  return best;
}

joints::Joint fit_describing_function(const joints::Joint& J, std::size_t T,
                                      std::vector<EquivalentStiffness> points, bool k_open,
                                      bool c_open, std::string& note) {
  return fit_describing_functions(J, {T}, std::move(points), k_open, c_open, note);
}

joints::Joint fit_describing_functions(const joints::Joint& J, const std::vector<std::size_t>& Ts,
                                       std::vector<EquivalentStiffness> points, bool k_open,
                                       bool c_open, std::string& note) {
  std::vector<std::string> names;
  for (const std::size_t T : Ts)
    names.emplace_back(joints::term_name(J.terms[T]));
  const std::string what = fmt::format("{}", fmt::join(names, " and "));
  if (points.empty())
    throw std::invalid_argument("joint '" + J.name + "': no equivalent stiffness to fit its " +
                                what + " to");
  std::sort(points.begin(), points.end(),
            [](const Point& p, const Point& q) { return p.amplitude < q.amplitude; });
  double best_cost = 0.0;
  const Eigen::VectorXd best = best_fit(J, Ts, points, k_open, c_open, best_cost);
  if (best.size() == 0)
    throw std::invalid_argument("joint '" + J.name + "': the describing-function fit of its " +
                                what + " found no start");
  joints::Joint out = J;
  std::string values;
  Eigen::Index u = 0;
  for (const std::size_t T : Ts) {
    const joints::Term term = J.terms[T];
    const auto& info = joints::term_info(term).parameters;
    if (out.parameters.size() <= T || out.parameters[T].size() != info.size())
      out.set_parameters(T, std::vector<double>(info.size(), 0.0), false);
    for (std::size_t q = 0; q < info.size(); ++q) {
      joints::Parameter& P = out.parameters[T][q];
      P.value = parameter_from_u(info[q], best(u++));
      P.given = true;
      values += fmt::format("{}{}.{} = {:.4g}", values.empty() ? "" : ", ", joints::term_name(term),
                            info[q].name, P.value);
    }
    if (!out.given.empty()) out.given[T] = true;
  }
  joints::check_parameters(out); // out of its range: std::invalid_argument saying which
  note = fmt::format("joint '{}': {} started from a describing-function fit of the equivalent "
                     "stiffness and damping of {} test(s) at deformation amplitudes {:.3g} … "
                     "{:.3g} (relative misfit {:.2g}): {}",
                     J.name, what, points.size(), points.front().amplitude, points.back().amplitude,
                     std::sqrt(best_cost / static_cast<double>(2 * points.size())), values);
  return out;
}

DescribingFunctionStart describing_function_start(const frf::Substructure& sub,
                                                  const std::vector<joints::Joint>& joints,
                                                  const std::vector<Measurement>& tests,
                                                  const FitOptions& fit_options) {
  check_one_parametric_term(joints);
  DescribingFunctionStart start;
  start.joints = joints;
  std::vector<joints::Joint>& out = start.joints;
  std::vector<std::string>& notes = start.notes;
  for (std::size_t jj = 0; jj < joints.size(); ++jj) {
    const joints::Joint& J = joints[jj];
    std::vector<std::size_t> open;
    for (std::size_t t = 0; t < J.terms.size(); ++t)
      if (joints::has_parameters(J.terms[t]) && !J.fixed[t]) open.push_back(t);
    if (open.empty()) continue;
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
    std::vector<Point> points;
    int measured = 0;     // tests that measure the joint's deformation
    fem::Status refused;  // the first per-test fit's status that was not ok
    std::string left_out; // the first per-test fit refused as input, why
    for (const Measurement& m : tests) {
      const auto [a, omega] = joint_equivalent_sine(m, J);
      if (!(a > 0.0)) continue;
      ++measured;
      try {
        const FitResult r = fit(sub, model, {m}, fit_options);
        if (!r.status.ok()) {
          if (refused.ok()) refused = r.status.within(m.source + ": ");
          continue;
        }
        const double k = r.joints[jj].terms[0].value, c = r.joints[jj].terms[1].value;
        points.push_back({a, omega, Complex(k - k_fixed, omega * (c - c_fixed))});
      } catch (const std::invalid_argument& e) {
        // this test alone does not determine k and c: left out of the start
        if (left_out.empty()) left_out = e.what();
      }
    }
    const std::string what = fmt::format("joint '{}': the describing-function fit of its {} (the "
                                         "start of its output error)",
                                         J.name, joints::term_name(term));
    if (measured == 0)
      throw std::invalid_argument(what + " has no test that measures the joint's deformation: "
                                         "record the response at the joint's DOFs");
    if (points.empty()) {
      start.status =
          !refused.ok()
              ? refused.within(what + ": no test alone gives its equivalent stiffness and "
                                      "damping: ")
              : fem::Status::failure(fem::Status::Code::not_separable,
                                     what +
                                         ": no test alone gives its equivalent stiffness "
                                         "and damping (" +
                                         left_out + ")");
      start.joints = joints;
      return start;
    }
    std::sort(points.begin(), points.end(),
              [](const Point& p, const Point& q) { return p.amplitude < q.amplitude; });

    // 2. N(a) + k + iωc fitted to Z(a).
    const auto& info = joints::term_info(term).parameters;
    const auto np = static_cast<Eigen::Index>(info.size());
    const Point &lo = points.front(), &hi = points.back();
    double best_cost = std::numeric_limits<double>::infinity();
    const Eigen::VectorXd best = best_fit(J, {T}, points, k_open, c_open, best_cost);
    if (best.size() == 0) {
      start.status = fem::Status::failure(
          fem::Status::Code::not_converging,
          fmt::format("{}: no start gave a finite misfit over the {} test(s) at deformation "
                      "amplitudes {:.3g} … {:.3g}",
                      what, points.size(), lo.amplitude, hi.amplitude));
      start.joints = joints;
      return start;
    }
    if (out[jj].parameters.size() <= T || out[jj].parameters[T].size() != info.size())
      out[jj].set_parameters(T, std::vector<double>(info.size(), 0.0), false);
    std::string values;
    for (Eigen::Index p = 0; p < np; ++p) {
      const std::size_t q = static_cast<std::size_t>(p);
      joints::Parameter& P = out[jj].parameters[T][q];
      P.value = parameter_from_u(info[q], best(p));
      P.given = true;
      values += fmt::format("{}{}.{} = {:.4g}", values.empty() ? "" : ", ", joints::term_name(term),
                            info[q].name, P.value);
    }
    if (!out[jj].given.empty()) out[jj].given[T] = true;
    try { // the fit may run a parameter out of its range (fs → 0: the term vanishes)
      joints::check_parameters(out[jj]);
    } catch (const std::invalid_argument& e) {
      const double change = (hi.Z.real() - lo.Z.real()) / std::max(std::abs(lo.Z), 1e-300);
      start.status = fem::Status::failure(
          fem::Status::Code::not_converging,
          fmt::format("{}: the fit left the parameters' range ({}; {}): over the tests' "
                      "deformation amplitudes {:.3g} … {:.3g} the joint's equivalent stiffness "
                      "changes by {:.2g} % — the tests may not reach its {} (deformation beyond "
                      "{}): add tests at larger forces, or give the term's parameters and fix "
                      "them",
                      what, e.what(), values, lo.amplitude, hi.amplitude, 100.0 * change,
                      term == joints::Term::gap       ? "contact"
                      : term == joints::Term::jenkins ? "slip"
                                                      : "macroslip",
                      term == joints::Term::gap       ? "delta"
                      : term == joints::Term::jenkins ? "fs/kt"
                                                      : "phi_max"));
      start.joints = joints;
      return start;
    }
    notes.push_back(fmt::format(
        "joint '{}': {} started from a describing-function fit of the equivalent stiffness and "
        "damping of {} test(s) at deformation amplitudes {:.3g} … {:.3g} (relative misfit "
        "{:.2g}): {}",
        J.name, joints::term_name(term), points.size(), lo.amplitude, hi.amplitude,
        std::sqrt(best_cost / static_cast<double>(2 * points.size())), values));
  }
  return start;
}

} // namespace jointid::identify
