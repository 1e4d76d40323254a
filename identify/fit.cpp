#include "identify/fit.hpp"

#include "identify/harmonics.hpp"
#include "identify/statistics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace jointid::identify {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

std::string percent(double fraction) {
  std::ostringstream s;
  s.precision(3);
  s << 100.0 * fraction << " %";
  return s.str();
}

// Fraction of samples sitting at the channel's extreme values (a flat top: clipping). A
// displacement that is flat because the point is at rest (its measured velocity is zero, as
// in a friction joint's stick phase) is not clipped: pass that velocity to exempt it.
double clipped_fraction(const Eigen::VectorXd& x, const Eigen::VectorXd* velocity = nullptr) {
  const double hi = x.maxCoeff(), lo = x.minCoeff(),
               tol = 1e-9 * std::max(std::abs(hi), std::abs(lo));
  if (hi - lo <= tol) return 0.0;
  const double vmax = velocity ? velocity->cwiseAbs().maxCoeff() : 0.0;
  int at_edge = 0;
  for (int i = 0; i < x.size(); ++i) {
    const bool resting = velocity && std::abs((*velocity)(i)) <= 1e-6 * vmax;
    if ((hi - x(i) <= tol || x(i) - lo <= tol) && !resting) ++at_edge;
  }
  return static_cast<double>(at_edge) / x.size();
}

// Velocity from displacement by differentiating a many-harmonic fit (periodic signals).
Eigen::VectorXd derive_velocity(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double omega) {
  const int K = std::min(64, (static_cast<int>(t.size()) - 1) / 2);
  const Eigen::VectorXcd X = fit_harmonics(t, x, omega, K);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(t.size());
  for (int i = 0; i < t.size(); ++i)
    for (int k = 1; k <= K; ++k)
      v(i) +=
          (std::complex<double>(0.0, k * omega) * X(k) * std::polar(1.0, k * omega * t(i))).real();
  return v;
}

} // namespace

TestSpectrum extract_spectrum(const Record& r, const fem::DofMap& dofs,
                              const std::vector<joints::Joint>& joints, int K,
                              std::vector<std::string>& warnings, const FitOptions& options) {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(r.source + ": " + what); };
  TestSpectrum s;
  s.source = r.source;
  const auto forces = r.all(Quantity::force);
  if (forces.empty()) fail("no force channel (expected a column such as f@7:uy)");
  for (const Channel* c : forces) {
    try {
      s.force_equations.push_back(dofs.equation(c->at));
    } catch (const std::invalid_argument& e) {
      fail("force channel " + c->name() + ": " + e.what());
    }
  }
  s.frequency_hz =
      r.excitation_hz ? *r.excitation_hz : estimate_frequency(r.t, forces.front()->samples);
  if (!(s.frequency_hz > 0.0)) fail("excitation frequency must be > 0 Hz");
  const double omega = two_pi * s.frequency_hz;
  const int n = whole_period_samples(r.t, s.frequency_hz);
  if (n == 0)
    fail("shorter than one period of the excitation (" + std::to_string(s.frequency_hz) + " Hz)");
  if (n < 2 * (K + 1) * 4)
    fail("too few samples per period to resolve harmonic " + std::to_string(K));
  const Eigen::VectorXd t = r.t.head(n);
  const double periods = n * r.dt() * s.frequency_hz;
  if (periods < 2.0 - 1e-9)
    warnings.push_back(r.source + ": only " + std::to_string(static_cast<int>(periods)) +
                       " period; steady state cannot be checked (record at least 2)");

  for (const auto& c : r.channels) {
    const Channel* v =
        c.quantity == Quantity::displacement ? r.find(Quantity::velocity, c.at) : nullptr;
    const double clipped = clipped_fraction(c.samples, v ? &v->samples : nullptr);
    if (clipped > 0.01)
      warnings.push_back(r.source + ": channel " + c.name() + " looks clipped (" +
                         percent(clipped) + " of samples at its extremes)");
  }

  // Displacement and velocity at every joint DOF.
  const std::vector<int> set2 = joint_dof_set(joints, dofs);
  Eigen::MatrixXd x2(n, set2.size()), v2(n, set2.size());
  for (std::size_t i = 0; i < set2.size(); ++i) {
    const fem::NodeDof at = dofs.node_dof(set2[i]);
    const Channel* x = r.find(Quantity::displacement, at);
    if (!x) fail("no displacement channel x@" + fem::to_string(at) + " for a joint DOF");
    x2.col(i) = x->samples.head(n);
    if (const Channel* v = r.find(Quantity::velocity, at)) {
      v2.col(i) = v->samples.head(n);
    } else {
      v2.col(i) = derive_velocity(t, x2.col(i), omega);
      warnings.push_back(r.source + ": no velocity channel v@" + fem::to_string(at) +
                         "; velocity derived from displacement");
    }
  }
  Eigen::MatrixXd f(n, forces.size());
  for (std::size_t i = 0; i < forces.size(); ++i)
    f.col(i) = forces[i]->samples.head(n);
  s.F = fit_harmonics(t, f, omega, K);
  s.X2 = fit_harmonics(t, x2, omega, K);

  // Steady state: compare the fundamental over the first and the last half of the record.
  if (periods >= 2.0 - 1e-9) {
    const int half = whole_period_samples(t.head(n / 2), s.frequency_hz);
    if (half > 0) {
      const Eigen::VectorXcd a =
          fit_harmonics(t.head(half), Eigen::VectorXd(x2.col(0).head(half)), omega, 1);
      const Eigen::VectorXcd b =
          fit_harmonics(t.tail(half), Eigen::VectorXd(x2.col(0).tail(half)), omega, 1);
      const double change = std::abs(a(1) - b(1)) / std::max(std::abs(b(1)), 1e-300);
      if (change > options.steady_tolerance)
        warnings.push_back(r.source + ": not a steady state (first and last half differ by " +
                           percent(change) + ")");
    }
  }

  // Basis functions on the measured deformation y = x(node) − x(node_b), i.e. Y = X2 B.
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, set2);
  const Eigen::MatrixXd Y = x2 * B, Ydot = v2 * B;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const joints::Joint& j = joints[i];
    const Eigen::VectorXd y = Y.col(i), ydot = Ydot.col(i);
    if (j.term_index(joints::Term::fc) >= 0) {
      // While a dry-friction joint sticks (ẏ = 0) its force lies anywhere in [−fc, fc], but the
      // basis sign(ẏ) says 0: the stuck part of the record is not described by the model.
      const double vmax = ydot.cwiseAbs().maxCoeff();
      const double stuck = (ydot.array().abs() <= 1e-9 * vmax).cast<double>().mean();
      if (stuck > 0.002)
        warnings.push_back(
            r.source + ": joint '" + j.name + "' sticks for " + percent(stuck) +
            " of the record; the Coulomb basis sign(ydot) does not describe the force while stuck");
    }
    Eigen::MatrixXd g(n, j.terms.size());
    for (std::size_t term = 0; term < j.terms.size(); ++term)
      for (int i = 0; i < n; ++i)
        g(i, term) = joints::basis(j.terms[term], y(i), ydot(i));
    s.G.push_back(fit_harmonics(t, g, omega, K));
  }
  return s;
}

std::vector<joints::Joint>
FitResult::identified(const std::vector<joints::Joint>& model_joints) const {
  std::vector<joints::Joint> out = model_joints;
  for (std::size_t i = 0; i < out.size() && i < joints.size(); ++i)
    for (std::size_t t = 0; t < out[i].terms.size(); ++t)
      out[i].values[t] = joints[i].terms[t].value;
  return out;
}

FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<TestSpectrum>& tests,
              const FitOptions& o, std::vector<std::string> warnings) {
  if (joints.empty()) throw std::invalid_argument("identify: the model has no joints");
  if (tests.empty()) throw std::invalid_argument("identify: no tests");
  const std::vector<int> set2 = joint_dof_set(joints, dofs);
  const int n2 = static_cast<int>(set2.size());
  // Unknowns: the non-fixed terms of every joint.
  struct Unknown {
    int joint, term;
  };
  std::vector<Unknown> unknowns;
  for (std::size_t i = 0; i < joints.size(); ++i)
    for (std::size_t t = 0; t < joints[i].terms.size(); ++t)
      if (!joints[i].fixed[t]) unknowns.push_back({static_cast<int>(i), static_cast<int>(t)});
  const int nu = static_cast<int>(unknowns.size());
  if (nu == 0)
    throw std::invalid_argument("identify: every joint term is fixed; nothing to identify");
  // B: set-2 position of each joint's node (+1) and node_b (−1).
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, set2);

  std::vector<Eigen::RowVectorXd> rows;
  std::vector<double> rhs;
  for (const auto& test : tests) {
    for (int k : o.harmonics) {
      if (k < 0 || k >= test.F.rows())
        throw std::invalid_argument("identify: harmonic " + std::to_string(k) + " not extracted");
      const double w = two_pi * test.frequency_hz * k;
      const frf::CMatrix H22 = H(w, set2, set2), H2f = H(w, set2, test.force_equations);
      frf::CVector R = test.X2.row(k).transpose() - H2f * test.F.row(k).transpose();
      frf::CMatrix Qc(n2, nu);
      for (int u = 0; u < nu; ++u) {
        const auto [i, t] = unknowns[u];
        Qc.col(u) = -H22 * B.col(i).cast<frf::Complex>() * test.G[i](k, t);
      }
      for (std::size_t i = 0; i < joints.size(); ++i) // known terms go to the right-hand side
        for (std::size_t t = 0; t < joints[i].terms.size(); ++t)
          if (joints[i].fixed[t])
            R += H22 * B.col(i).cast<frf::Complex>() * test.G[i](k, t) * joints[i].values[t];
      for (int d = 0; d < n2; ++d) {
        rows.push_back(Qc.row(d).real());
        rhs.push_back(R(d).real());
        if (k != 0) { // the mean has no imaginary part
          rows.push_back(Qc.row(d).imag());
          rhs.push_back(R(d).imag());
        }
      }
    }
  }
  const int m = static_cast<int>(rows.size());
  if (m < nu)
    throw std::invalid_argument(
        "identify: " + std::to_string(m) + " equations for " + std::to_string(nu) +
        " unknowns; add tests at other frequencies or force levels, or more harmonics");
  Eigen::MatrixXd Q(m, nu);
  Eigen::VectorXd p(m);
  for (int r = 0; r < m; ++r)
    Q.row(r) = rows[r], p(r) = rhs[r];
  Eigen::VectorXd scale(nu);
  for (int u = 0; u < nu; ++u) {
    const double norm = Q.col(u).norm();
    if (!(norm > 0.0)) {
      const auto [i, t] = unknowns[u];
      throw std::invalid_argument(
          "identify: term '" + std::string(joints::term_name(joints[i].terms[t])) + "' of joint '" +
          joints[i].name + "' has no effect in these tests (its basis function is zero)");
    }
    scale(u) = 1.0 / norm;
  }
  const Eigen::MatrixXd Qs = Q * scale.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Qs, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  FitResult out;
  out.warnings = std::move(warnings);
  out.equations = m;
  out.unknowns = nu;
  out.condition_number =
      sv(nu - 1) > 0.0 ? sv(0) / sv(nu - 1) : std::numeric_limits<double>::infinity();
  if (!(out.condition_number < 1e13)) {
    Eigen::Index worst;
    svd.matrixV().col(nu - 1).cwiseAbs().maxCoeff(&worst);
    const auto [i, t] = unknowns[worst];
    throw std::invalid_argument(
        "identify: the unknowns cannot be separated by these tests (condition number " +
        std::to_string(out.condition_number) + "); term '" +
        std::string(joints::term_name(joints[i].terms[t])) + "' of joint '" + joints[i].name +
        "' is a combination of the others: vary frequency and force level, or drop a term");
  }
  const Eigen::VectorXd bs = svd.solve(p);
  const Eigen::VectorXd b = scale.asDiagonal() * bs;
  const Eigen::VectorXd residual = Q * b - p;
  out.residual_rms = std::sqrt(residual.squaredNorm() / m);
  out.residual_relative = residual.norm() / std::max(p.norm(), 1e-300);
  if (out.condition_number > 1e8)
    out.warnings.push_back("Q is ill-conditioned (condition number " +
                           std::to_string(out.condition_number) +
                           "): parameters may be poorly determined");
  const int redundancy = m - nu;
  const double sigma2 = redundancy > 0 ? residual.squaredNorm() / redundancy
                                       : std::numeric_limits<double>::quiet_NaN();
  const Eigen::MatrixXd Vs = svd.matrixV() * sv.cwiseInverse().asDiagonal();
  const double tq = redundancy > 0 ? student_t_quantile(0.975, redundancy)
                                   : std::numeric_limits<double>::quiet_NaN();
  if (redundancy == 0)
    out.warnings.push_back("as many equations as unknowns: no uncertainty estimate");

  int u = 0;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    JointEstimate je{joints[i].name, {}};
    for (std::size_t t = 0; t < joints[i].terms.size(); ++t) {
      TermEstimate te;
      te.term = joints[i].terms[t];
      if (joints[i].fixed[t]) {
        te.value = joints[i].values[t];
        te.fixed = true;
        te.std = 0.0;
        te.ci_low = te.ci_high = te.value;
      } else {
        te.value = b(u);
        te.std = scale(u) * std::sqrt(sigma2 * Vs.row(u).squaredNorm());
        te.ci_low = te.value - tq * te.std;
        te.ci_high = te.value + tq * te.std;
        if (redundancy > 0 && te.std > o.poorly_determined * std::abs(te.value))
          out.warnings.push_back(
              "joint '" + joints[i].name + "', term '" + std::string(joints::term_name(te.term)) +
              "': poorly determined (std " +
              percent(te.std / std::max(std::abs(te.value), 1e-300)) + " of its value)");
        ++u;
      }
      je.terms.push_back(te);
    }
    out.joints.push_back(std::move(je));
  }
  return out;
}

FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<Record>& records,
              const FitOptions& o) {
  if (records.empty()) throw std::invalid_argument("identify: no records");
  const int K = *std::max_element(o.harmonics.begin(), o.harmonics.end());
  std::vector<std::string> warnings;
  std::vector<TestSpectrum> tests;
  for (const auto& r : records)
    tests.push_back(extract_spectrum(r, dofs, joints, std::max(K, 1), warnings, o));
  return fit(H, dofs, joints, tests, o, std::move(warnings));
}

} // namespace jointid::identify
