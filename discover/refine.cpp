#include "discover/refine.hpp"

#include "discover/selection.hpp"
#include "fem/constants.hpp"
#include "identify/parametric.hpp"
#include "identify/statistics.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace jointid::discover::detail {

namespace {

using Complex = std::complex<double>;

// Every named parameter in its range: a step far out in a parameter's coordinate saturates it
// (an exponent at −1, a logarithm's exponential at +∞), which no simulation takes.
bool in_range(const std::vector<joints::Joint>& joints) {
  for (const joints::Joint& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      const auto list = j.parameters_of(t);
      const auto& info = joints::term_info(j.terms[t]).parameters;
      for (std::size_t p = 0; p < list.size() && p < info.size(); ++p)
        if (!joints::in_range(info[p], list[p].value) || !(std::abs(list[p].value) < 1e100))
          return false;
    }
  return true;
}

// The Levenberg–Marquardt search of one refinement: the parameters (every non-fixed term), the
// weighted residual of a state, and the Jacobian by finite differences.
class OutputError {
public:
  OutputError(const Problem& problem, const Simulator& sim, const State& start)
      : problem_(problem), compared_(problem.compared()), sim_(sim) {
    for (std::size_t j = 0; j < start.joints.size(); ++j)
      for (std::size_t t = 0; t < start.joints[j].terms.size(); ++t) {
        if (start.joints[j].fixed[t]) continue;
        // A parametric term: each non-fixed parameter in its natural coordinate
        // (identify/parametric.hpp), which keeps it in its range.
        const auto list = start.joints[j].parameters_of(t);
        if (list.empty()) params_.push_back({j, t, -1});
        for (std::size_t q = 0; q < list.size(); ++q)
          if (!list[q].fixed) params_.push_back({j, t, static_cast<int>(q)});
      }
    for (const auto& e : compared_.entries)
      weight_.push_back(compared_.noise_known ? 1.0 / std::sqrt(e.total() / e.dof()) : 1.0);
  }

  Eigen::Index size() const { return static_cast<Eigen::Index>(params_.size()); }

  // Tests not simulated at all (ascending; set before compare_on): a first stage's.
  void skip(std::vector<int> tests) { skip_ = std::move(tests); }

  // The tests the search compares: those the start re-simulated (a trial must re-simulate every
  // one of them too).
  void compare_on(const State& begin, const std::vector<int>& held_out) {
    left_out_ = united(united(begin.failed, held_out), skip_);
    values_ = 0;
    for (const auto& e : compared_.entries)
      if (!std::binary_search(left_out_.begin(), left_out_.end(), e.test)) values_ += e.dof();
  }

  // Steps stay among physical models (no negative damping or friction); a start outside them
  // (an equation-error estimate biased by noise) is first brought back to zero damping there.
  State begin(const State& start) const {
    if (physical_problem(start.joints).empty()) return start;
    std::vector<joints::Joint> clamped = start.joints;
    clamp_dissipative(clamped);
    State begin = problem_.evaluate(clamped, sim_, &start);
    begin.fit = start.fit;
    return begin;
  }

  // Minimises the weighted misfit from `begin`; returns the state reached.
  State search(const State& start, const State& begin, int iterations) {
    const Eigen::Index p = size();
    b_.resize(p), step_.resize(p);
    joints_ = begin.joints;
    std::vector<bool> dissipative(p);
    for (Eigen::Index q = 0; q < p; ++q) {
      const joints::Term term = joints_[params_[q].joint].terms[params_[q].term];
      if (params_[q].parameter >= 0) { // a parameter, in its coordinate u
        b_(q) = coordinate(joints_, params_[q]);
        step_(q) = 1e-5 * std::max(1.0, std::abs(b_(q)));
        continue;
      }
      dissipative[q] = joints::term_info(term).nature == joints::Nature::dissipative;
      b_(q) = joints_[params_[q].joint].values[params_[q].term];
      // A finite-difference step of the parameter's own scale: its value, or (at 0, e.g. a
      // damping brought back to 0) its equation-error estimate and standard deviation.
      double scale = std::max(std::abs(b_(q)),
                              std::abs(start.joints[params_[q].joint].values[params_[q].term]));
      for (const auto& je : start.fit.joints)
        if (je.name == joints_[params_[q].joint].name)
          for (const auto& te : je.terms)
            if (te.term == term && std::isfinite(te.std)) scale = std::max(scale, te.std);
      step_(q) = 1e-5 * std::max(scale, 1e-12);
    }
    current_ = begin;
    r_ = residual(current_);
    cost_ = r_.squaredNorm();
    iterations_ = 0;
    double mu = 1e-3;
    J_.resize(r_.size(), p);
    for (int iteration = 0; iteration < iterations; ++iteration) {
      J_.setConstant(nan);
      if (!jacobian()) break; // keep what was reached
      const Eigen::MatrixXd A = J_.transpose() * J_;
      const Eigen::VectorXd g = J_.transpose() * r_;
      bool accepted = false;
      double gain = 0.0;
      for (int tries = 0; tries < 10 && !accepted; ++tries, mu *= 10.0) {
        Eigen::MatrixXd M = A;
        M.diagonal() += mu * A.diagonal() + Eigen::VectorXd::Constant(p, 1e-300);
        Eigen::VectorXd nb = b_ - M.ldlt().solve(g);
        for (Eigen::Index q = 0; q < p; ++q) // projected onto non-negative damping and friction
          if (dissipative[q]) nb(q) = std::max(nb(q), 0.0);
        const std::vector<joints::Joint> nj = joints_with(nb);
        if (!nb.allFinite() || !physical_problem(nj).empty() || !in_range(nj)) continue;
        State sn = problem_.evaluate(nj, sim_, &current_, skip_);
        if (!covers(sn)) continue;
        const Eigen::VectorXd rn = residual(sn);
        if (rn.squaredNorm() < cost_) {
          gain = (cost_ - rn.squaredNorm()) / cost_;
          b_ = nb, current_ = std::move(sn), r_ = rn, cost_ = r_.squaredNorm();
          mu = std::max(mu / 100.0, 1e-9); // (×10 on leaving the loop)
          accepted = true;
        }
      }
      iterations_ = iteration + 1;
      if (!accepted || gain < 1e-5) break; // a 0.001 % smaller misfit is no longer worth a step
    }
    return current_;
  }

  // The Levenberg–Marquardt iterations the last search() took.
  int iterations() const { return iterations_; }

  // The fit of the values reached: intervals from the Jacobian there, or NaN (undetermined)
  // when it cannot be formed, there is no redundancy, or the tests do not constrain them.
  identify::FitResult fit(const identify::FitResult& begin_fit) {
    const Eigen::Index p = size();
    const int values = values_;
    J_.setConstant(nan);
    const int dof = values - static_cast<int>(p);
    const bool formed = jacobian() && dof > 0;
    double s2 = formed ? cost_ / dof : nan;
    if (compared_.noise_known) s2 = std::max(s2, 1.0);
    std::vector<bool> undetermined(static_cast<std::size_t>(p), false);
    std::vector<std::string> said;
    const int nulls = microslip(undetermined, said);
    const Eigen::MatrixXd C = !formed ? Eigen::MatrixXd::Constant(p, p, nan)
                              : nulls > 0
                                  ? covariance_without(J_, s2, nulls)
                                  : covariance_of_determined(J_, s2, droppable(), undetermined);
    const double tq = formed ? identify::student_t_quantile(0.975, dof) : nan;
    identify::FitResult fit = begin_fit;
    fit.identifiability = said;
    std::size_t q = 0;
    fit.joints.clear();
    for (const auto& joint : current_.joints) {
      identify::JointEstimate je{joint.name, {}};
      for (std::size_t t = 0; t < joint.terms.size(); ++t) {
        identify::TermEstimate te;
        te.term = joint.terms[t];
        te.value = joint.values[t];
        te.fixed = joint.fixed[t];
        te.parameters = identify::parameters_of(joint, t);
        if (!te.parameters.empty()) { // its parameters, their intervals through u
          te.std = 0.0, te.ci_low = te.ci_high = te.value;
          if (te.fixed) {
            je.terms.push_back(te);
            continue;
          }
          for (identify::ParameterEstimate& pe : te.parameters) {
            if (pe.fixed) continue;
            const auto qi = static_cast<Eigen::Index>(q++);
            const Param& P = params_[static_cast<std::size_t>(qi)];
            const joints::ParameterInfo& pi = info(current_.joints, P);
            const double u = b_(qi),
                         su = std::isfinite(C(qi, qi)) ? std::sqrt(std::max(C(qi, qi), 0.0)) : nan;
            const double h = 1e-6 * std::max(1.0, std::abs(u));
            const double slope =
                (identify::parameter_from_u(pi, u + h) - identify::parameter_from_u(pi, u - h)) /
                (2.0 * h);
            pe.std = std::abs(slope) * su;
            const double a = identify::parameter_from_u(pi, u - tq * su),
                         b = identify::parameter_from_u(pi, u + tq * su);
            pe.ci_low = std::min(a, b), pe.ci_high = std::max(a, b);
            // An interval too wide to fix the parameter's scale is no result either.
            pe.determined = !undetermined[static_cast<std::size_t>(qi)] && std::isfinite(pe.std) &&
                            identify::interval_determines(pi, pe.value, pe.ci_low, pe.ci_high);
            // Never a value where the tests do not determine it (the model keeps one to
            // simulate with).
            if (!pe.determined) pe.value = pe.std = pe.ci_low = pe.ci_high = nan;
          }
          je.terms.push_back(te);
          continue;
        }
        if (!te.fixed) {
          const auto qi = static_cast<Eigen::Index>(q++);
          te.std = std::isfinite(C(qi, qi)) && !undetermined[static_cast<std::size_t>(qi)]
                       ? std::sqrt(std::max(C(qi, qi), 0.0))
                       : nan;
          te.determined = std::isfinite(te.std);
        }
        te.ci_low = te.value - tq * te.std;
        te.ci_high = te.value + tq * te.std;
        if (te.fixed) te.ci_low = te.ci_high = te.value;
        je.terms.push_back(te);
      }
      fit.joints.push_back(std::move(je));
    }
    fit.equations = values;
    fit.unknowns = static_cast<int>(p);
    fit.residual_relative = current_.gap;
    return fit;
  }

  // Every test the search compares was re-simulated by `trial`.
  bool covers(const State& trial) const {
    return std::isfinite(trial.criterion) &&
           std::includes(left_out_.begin(), left_out_.end(), trial.failed.begin(),
                         trial.failed.end());
  }

private:
  struct Param {
    std::size_t joint, term;
    int parameter; ///< of a parametric term; -1: the coefficient
  };

  // An iwan that stayed in microslip in every test (its largest deformation, bounded by Σ_k |Y_k|,
  // below its largest slip displacement phi_max): its force there depends only on k + kt, chi
  // and the density's scale R (joints/hysteresis.hpp), so fs apart from beta, and kt apart
  // from k (when k is identified too), are not determined. Marks them in `undetermined`, says
  // so in `said`, and returns the number of directions the tests do not see.
  int microslip(std::vector<bool>& undetermined, std::vector<std::string>& said) const {
    int nulls = 0;
    for (std::size_t j = 0; j < current_.joints.size(); ++j) {
      const joints::Joint& J = current_.joints[j];
      const int t = J.term_index(joints::Term::iwan);
      if (t < 0 || J.fixed[static_cast<std::size_t>(t)]) continue;
      const auto ti = static_cast<std::size_t>(t);
      const double phi_max = joints::iwan_density(J.parameter(ti, "fs"), J.parameter(ti, "kt"),
                                                  J.parameter(ti, "chi"), J.parameter(ti, "beta"))
                                 .phi_max;
      double peak = 0.0;
      for (const Eigen::MatrixXcd& Y : current_.Y)
        if (Y.cols() > static_cast<Eigen::Index>(j))
          peak = std::max(peak, Y.col(static_cast<Eigen::Index>(j)).cwiseAbs().sum());
      if (!(peak < phi_max)) continue;
      std::vector<std::string> names;
      bool k_open = false;
      for (std::size_t q = 0; q < params_.size(); ++q) {
        const Param& P = params_[q];
        if (P.joint != j) continue;
        if (P.parameter < 0 && J.terms[P.term] == joints::Term::k) k_open = true;
      }
      for (std::size_t q = 0; q < params_.size(); ++q) {
        const Param& P = params_[q];
        if (P.joint != j) continue;
        const std::string name = P.parameter < 0 ? std::string(joints::term_name(J.terms[P.term]))
                                                 : std::string(info(current_.joints, P).name);
        const bool lost = P.parameter < 0 ? J.terms[P.term] == joints::Term::k
                          : P.term == ti
                              ? (name == "fs" || name == "beta" || (k_open && name == "kt"))
                              : false;
        if (lost) undetermined[q] = true, names.push_back(name);
      }
      nulls += 1 + (k_open ? 1 : 0);
      said.push_back(fmt::format(
          "joint '{}': its iwan stayed in microslip in every test (largest deformation {:.3g}, "
          "below its largest slip displacement phi_max ≈ {:.3g}), where its force depends only "
          "on {}chi and the slip density's scale: {}iwan.fs apart from iwan.beta are "
          "undetermined (no value is given for them); a test whose deformation reaches beyond "
          "phi_max (macroslip) would determine them",
          J.name, peak, phi_max, k_open ? "k + kt, " : "kt, ",
          k_open ? "k apart from iwan.kt, and " : ""));
    }
    return nulls;
  }

  // The parametric terms' parameters: those that may be undetermined without failing the fit.
  std::vector<bool> droppable() const {
    std::vector<bool> out;
    for (const Param& P : params_)
      out.push_back(P.parameter >= 0);
    return out;
  }

  static const joints::ParameterInfo& info(const std::vector<joints::Joint>& j, const Param& p) {
    return joints::term_info(j[p.joint].terms[p.term])
        .parameters[static_cast<std::size_t>(p.parameter)];
  }
  static double coordinate(const std::vector<joints::Joint>& j, const Param& p) {
    return identify::parameter_to_u(
        info(j, p), j[p.joint].parameters[p.term][static_cast<std::size_t>(p.parameter)].value);
  }

  Eigen::VectorXd residual(const State& st) const {
    Eigen::VectorXd r(values_);
    Eigen::Index n = 0;
    for (std::size_t i = 0; i < compared_.entries.size(); ++i) {
      const auto& e = compared_.entries[i];
      if (std::binary_search(left_out_.begin(), left_out_.end(), e.test)) continue;
      const Complex err = e.measured - st.X[e.test](e.row, e.response);
      r(n++) = weight_[i] * err.real();
      if (e.harmonic != 0) r(n++) = weight_[i] * err.imag();
    }
    return r;
  }

  std::vector<joints::Joint> joints_with(const Eigen::VectorXd& b) const {
    std::vector<joints::Joint> j = joints_;
    for (Eigen::Index q = 0; q < size(); ++q) {
      const Param& P = params_[q];
      if (P.parameter < 0)
        j[P.joint].values[P.term] = b(q);
      else
        j[P.joint].parameters[P.term][static_cast<std::size_t>(P.parameter)].value =
            identify::parameter_from_u(info(j, P), b(q));
    }
    return j;
  }

  // The Jacobian at the current values: by implicit differentiation of every test's harmonic
  // balance (Problem::derivatives) over a forward step (backward where forward leaves the
  // physical models), else by re-simulating every test for that step; false where a column
  // cannot be formed.
  // Parameter q moved by +step, then by −step: the moves that stay physical and in range, in
  // that order (a parameter at its bound is differentiated from the side it can move to).
  std::vector<std::pair<double, std::vector<joints::Joint>>> moves(Eigen::Index q) const {
    std::vector<std::pair<double, std::vector<joints::Joint>>> out;
    for (double h : {step_(q), -step_(q)}) {
      Eigen::VectorXd bq = b_;
      bq(q) += h;
      std::vector<joints::Joint> jq = joints_with(bq);
      if (physical_problem(jq).empty() && in_range(jq)) out.emplace_back(h, std::move(jq));
    }
    return out;
  }

  bool jacobian() {
    std::vector<std::vector<joints::Joint>> moved;
    std::vector<double> steps;
    std::vector<Eigen::Index> column;
    for (Eigen::Index q = 0; q < size(); ++q)
      if (auto m = moves(q); !m.empty()) {
        steps.push_back(m.front().first), column.push_back(q);
        moved.push_back(std::move(m.front().second));
      }
    const auto D = problem_.derivatives(current_, moved, steps, sim_, left_out_);
    for (std::size_t m = 0; m < column.size(); ++m) {
      Eigen::Index n = 0;
      const Eigen::Index q = column[m];
      for (std::size_t i = 0; i < compared_.entries.size() && n >= 0; ++i) {
        const auto& e = compared_.entries[i];
        if (std::binary_search(left_out_.begin(), left_out_.end(), e.test)) continue;
        const auto& d = D[static_cast<std::size_t>(e.test)];
        if (d.size() <= m || d[m].size() == 0) {
          n = -1; // not formed for this test: re-simulate below
          break;
        }
        const Complex dx = d[m](e.row, e.response);
        J_(n++, q) = -weight_[i] * dx.real();
        if (e.harmonic != 0) J_(n++, q) = -weight_[i] * dx.imag();
      }
      if (n < 0) J_.col(q).setConstant(nan);
    }
    for (Eigen::Index q = 0; q < size(); ++q) {
      if (J_.col(q).allFinite()) continue;
      for (const auto& [h, jq] : moves(q)) {
        const State sq = problem_.evaluate(jq, sim_, &current_, skip_);
        if (!covers(sq)) continue;
        J_.col(q) = (residual(sq) - r_) / h;
        break;
      }
      if (!J_.col(q).allFinite()) return false;
    }
    return true;
  }

  const Problem& problem_;
  const Compared& compared_;
  const Simulator& sim_;
  std::vector<Param> params_;
  std::vector<double> weight_;
  std::vector<int> left_out_;         // tests the start could not re-simulate, ascending
  std::vector<int> skip_;             // tests not simulated, ascending
  int values_ = 0;                    // real values compared (of the other tests)
  std::vector<joints::Joint> joints_; // the layout and fixed values the parameters go into
  Eigen::VectorXd b_, step_, r_;
  Eigen::MatrixXd J_;
  State current_;
  double cost_ = 0.0;
  int iterations_ = 0;
};

} // namespace

Eigen::MatrixXd covariance(const Eigen::MatrixXd& J, double s2) {
  const Eigen::Index p = J.cols();
  Eigen::MatrixXd C = Eigen::MatrixXd::Constant(p, p, nan);
  if (!J.allFinite() || !std::isfinite(s2)) return C;
  // Columns scaled to unit norm: the parameters' units differ by many orders of magnitude (a
  // cubic stiffness of 1e9 N/m³ beside a damping of 1 N s/m), and unscaled, JᵀJ's small
  // singular values fall below the solver's rounding threshold and their variance comes out 0.
  Eigen::VectorXd scale(p);
  for (Eigen::Index q = 0; q < p; ++q) {
    const double norm = J.col(q).norm();
    if (!(norm > 0.0)) return C; // a parameter the tests do not see: undetermined
    scale(q) = 1.0 / norm;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J * scale.asDiagonal(), Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  // Parameters that act alike beyond what the Jacobian resolves: undetermined. Its columns are
  // forward differences of re-simulations solved to 1e-12 over a step of 1e-5 of the value,
  // good to about 1e-7 of their norm, which moves a singular value by as much (Weyl): below
  // 1e-6 of the largest, a singular value — and the variance it gives — is that error.
  if (!(sv(p - 1) > 1e-6 * sv(0))) return C;
  const Eigen::MatrixXd W = svd.matrixV() * sv.cwiseInverse().asDiagonal();
  return s2 * scale.asDiagonal() * (W * W.transpose()) * scale.asDiagonal();
}

static State refine_from(const Problem& problem, const State& start, const Simulator& sim,
                         const RefineScope& scope);

Eigen::MatrixXd covariance_without(const Eigen::MatrixXd& J, double s2, int nulls) {
  const Eigen::Index p = J.cols();
  Eigen::MatrixXd C = Eigen::MatrixXd::Constant(p, p, nan);
  if (!J.allFinite() || !std::isfinite(s2) || nulls >= p) return C;
  Eigen::VectorXd scale(p);
  for (Eigen::Index q = 0; q < p; ++q) {
    const double norm = J.col(q).norm();
    if (!(norm > 0.0)) return C;
    scale(q) = 1.0 / norm;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J * scale.asDiagonal(), Eigen::ComputeThinV);
  const Eigen::Index r = p - nulls;
  const Eigen::VectorXd& sv = svd.singularValues();
  if (!(sv(r - 1) > 1e-6 * sv(0))) return C;
  const Eigen::MatrixXd W = svd.matrixV().leftCols(r) * sv.head(r).cwiseInverse().asDiagonal();
  return s2 * scale.asDiagonal() * (W * W.transpose()) * scale.asDiagonal();
}

Eigen::MatrixXd covariance_of_determined(const Eigen::MatrixXd& J, double s2,
                                         const std::vector<bool>& droppable,
                                         std::vector<bool>& undetermined) {
  const Eigen::Index p = J.cols();
  undetermined.assign(static_cast<std::size_t>(p), false);
  Eigen::MatrixXd C = covariance(J, s2);
  if (p == 0 || std::isfinite(C(0, 0)) || !J.allFinite()) return C;
  std::vector<Eigen::Index> active(static_cast<std::size_t>(p));
  for (Eigen::Index q = 0; q < p; ++q)
    active[static_cast<std::size_t>(q)] = q;
  while (active.size() > 1) {
    // The direction the tests do not resolve: the smallest singular value's right vector of
    // the column-scaled Jacobian; the parameter that leans on it most is left undetermined.
    const auto n = static_cast<Eigen::Index>(active.size());
    Eigen::MatrixXd Js(J.rows(), n);
    for (Eigen::Index c = 0; c < n; ++c) {
      const auto col = J.col(active[static_cast<std::size_t>(c)]);
      Js.col(c) = col / std::max(col.norm(), 1e-300);
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeThinV);
    const Eigen::VectorXd v = svd.matrixV().col(n - 1).cwiseAbs();
    Eigen::Index worst = -1;
    for (Eigen::Index c = 0; c < n; ++c)
      if (droppable[static_cast<std::size_t>(active[static_cast<std::size_t>(c)])] &&
          (worst < 0 || v(c) > v(worst)))
        worst = c;
    if (worst < 0) return C; // only coefficients left: undetermined as they are
    undetermined[static_cast<std::size_t>(active[static_cast<std::size_t>(worst)])] = true;
    active.erase(active.begin() + worst);
    Eigen::MatrixXd Ja(J.rows(), static_cast<Eigen::Index>(active.size()));
    for (std::size_t c = 0; c < active.size(); ++c)
      Ja.col(static_cast<Eigen::Index>(c)) = J.col(active[c]);
    const Eigen::MatrixXd Ca = covariance(Ja, s2);
    if (!std::isfinite(Ca(0, 0))) continue;
    for (std::size_t a = 0; a < active.size(); ++a)
      for (std::size_t b = 0; b < active.size(); ++b)
        C(active[a], active[b]) = Ca(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
    return C;
  }
  return C;
}

std::optional<std::vector<joints::Joint>> nested_start(const Candidate& c, const State& candidate,
                                                       const State& now) {
  if (!c.term || c.refit || c.varies || joints::has_parameters(*c.term) ||
      candidate.joints.size() != now.joints.size() || candidate.damping_scale != now.damping_scale)
    return std::nullopt;
  std::vector<joints::Joint> js = candidate.joints;
  for (std::size_t j = 0; j < js.size(); ++j) {
    const joints::Joint& n = now.joints[j];
    if (js[j].name != n.name) return std::nullopt;
    for (std::size_t t = 0; t < js[j].terms.size(); ++t) {
      const int u = n.term_index(js[j].terms[t]);
      if (u >= 0) {
        const auto ui = static_cast<std::size_t>(u);
        js[j].values[t] = n.values[ui];
        if (t < js[j].parameters.size() && ui < n.parameters.size())
          js[j].parameters[t] = n.parameters[ui];
      } else if (js[j].name == c.joint && js[j].terms[t] == *c.term) {
        js[j].values[t] = 0.0;
      } else {
        return std::nullopt; // the candidate differs from the model now in more than the term
      }
    }
    // every term of the model now is the candidate's too
    for (const joints::Term t : n.terms)
      if (js[j].term_index(t) < 0) return std::nullopt;
  }
  return js;
}

State refine(const Problem& problem, const State& start, const Simulator& sim,
             const RefineScope& scope) {
  try {
    return refine_from(problem, start, sim, scope);
  } catch (const std::invalid_argument&) {
    return start; // a model the simulators refuse (out of range): the start stands
  }
}

State refine_from(const Problem& problem, const State& start, const Simulator& sim,
                  const RefineScope& scope) {
  OutputError search(problem, sim, start);
  if (search.size() == 0) return start;
  const State begin = search.begin(start);
  if (!std::isfinite(begin.criterion) || !physical_problem(begin.joints).empty()) return start;
  State from = begin;
  int iterations = scope.iterations;
  const int n = static_cast<int>(problem.tests().size());
  if (scope.spread > 0 && n > scope.spread) {
    // First stage: a spread of the tests (those the start re-simulated, not held out).
    OutputError first(problem, sim, start);
    first.skip(problem.outside_spread(static_cast<std::size_t>(scope.spread)));
    first.compare_on(begin, scope.held_out);
    const State reached = first.search(start, begin, scope.iterations);
    // Every test at the values reached; kept where it is no worse than the start on them.
    State all = problem.evaluate(reached.joints, sim, &begin);
    all.fit = begin.fit;
    if (all.failed == begin.failed && std::isfinite(all.criterion) && all.gap < begin.gap)
      from = std::move(all);
    // The first stage's iterations count against the budget: one that took them all is in a
    // slow valley (an iwan's parameters), where going on at n / spread times the cost of an
    // iteration buys little. The second stage takes what is left, and at least two.
    iterations = scope.spread_only ? 0 : std::max(2, scope.iterations - first.iterations());
  }
  search.compare_on(from, scope.held_out);
  State refined = search.search(start, from, iterations);
  if (scope.intervals) refined.fit = search.fit(begin.fit);
  return refined;
}

} // namespace jointid::discover::detail
