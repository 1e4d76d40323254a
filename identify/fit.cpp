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

} // namespace

TestSpectrum spectrum(const Measurement& m, const fem::DofMap& dofs,
                      const std::vector<joints::Joint>& joints,
                      std::vector<std::string>& warnings) {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(m.source + ": " + what); };
  auto channels = [&] {
    std::string names;
    for (const auto& at : m.force_at)
      names += (names.empty() ? "f@" : ", f@") + fem::to_string(at);
    for (std::size_t i = 0; i < m.response_at.size(); ++i)
      names += std::string(", ") + quantity_letter(m.measured_as[i]) + "@" +
               fem::to_string(m.response_at[i]);
    return names;
  };
  TestSpectrum s;
  s.source = m.source;
  s.frequency_hz = m.frequency_hz;
  s.fundamental_only = m.fundamental_only;
  for (const auto& at : m.force_at) {
    try {
      s.force_equations.push_back(dofs.equation(at));
    } catch (const std::invalid_argument& e) {
      fail("force channel f@" + fem::to_string(at) + ": " + e.what() +
           " (a force must act on a free DOF of the model)");
    }
  }
  s.F = m.F;

  // Displacement and velocity at every joint DOF.
  const std::vector<int> set2 = joint_dof_set(joints, dofs);
  const Eigen::Index n = m.t.size();
  Eigen::MatrixXd x2(n, set2.size()), v2(n, set2.size());
  s.X2.resize(m.X.rows(), static_cast<Eigen::Index>(set2.size()));
  for (std::size_t i = 0; i < set2.size(); ++i) {
    const fem::NodeDof at = dofs.node_dof(set2[i]);
    const int r = m.response_index(at);
    if (r < 0) {
      std::string joint;
      for (const auto& j : joints)
        if ((j.node == at.node || j.node_b == at.node) && j.dof == at.dof) joint = j.name;
      fail("no channel x@" + fem::to_string(at) + " (nor v@ or a@) for joint '" + joint +
           "' (identification needs the response at every joint DOF; the channels are " +
           channels() + ")");
    }
    x2.col(static_cast<Eigen::Index>(i)) = m.x.col(r);
    v2.col(static_cast<Eigen::Index>(i)) = m.v.col(r);
    s.X2.col(static_cast<Eigen::Index>(i)) = m.X.col(r);
  }
  const double omega = two_pi * m.frequency_hz;
  const int K = m.harmonics;

  // Basis functions on the measured deformation y = x(node) − x(node_b), i.e. Y = X2 B.
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, set2);
  const Eigen::MatrixXd Y = x2 * B, Ydot = v2 * B;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const joints::Joint& j = joints[i];
    const Eigen::VectorXd y = Y.col(static_cast<Eigen::Index>(i));
    Eigen::VectorXd ydot = Ydot.col(static_cast<Eigen::Index>(i));
    // A rate within 1e-9 of its largest value is rest (a stuck friction joint: the integrator's
    // rounding leaves ±1e-15 m/s there, whose sign would be noise).
    const double vmax = ydot.cwiseAbs().maxCoeff();
    for (Eigen::Index r = 0; r < n; ++r)
      if (std::abs(ydot(r)) <= 1e-9 * vmax) ydot(r) = 0.0;
    if (j.term_index(joints::Term::fc) >= 0 && !m.fundamental_only) {
      // While a dry-friction joint sticks (ẏ = 0) its force lies anywhere in [−fc, fc], but the
      // basis sign(ẏ) says 0: the stuck part of the record is not described by the model.
      const double stuck = (ydot.array() == 0.0).cast<double>().mean();
      if (stuck > 0.002)
        warnings.push_back(
            m.source + ": joint '" + j.name + "' sticks for " + percent(stuck) +
            " of the record; the Coulomb basis sign(ydot) does not describe the force while stuck");
    }
    Eigen::MatrixXd g(n, static_cast<Eigen::Index>(j.terms.size()));
    for (std::size_t term = 0; term < j.terms.size(); ++term)
      for (Eigen::Index r = 0; r < n; ++r)
        g(r, static_cast<Eigen::Index>(term)) = joints::basis(j.terms[term], y(r), ydot(r));
    s.G.push_back(fit_harmonics(m.t, g, omega, K));
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
      if (test.fundamental_only && k != 1) continue;
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

FitResult fit(const frf::Substructure& sub, const std::vector<joints::Joint>& joints,
              const std::vector<Measurement>& measurements, const FitOptions& o) {
  if (measurements.empty()) throw std::invalid_argument("identify: no tests");
  if (o.harmonics.empty()) throw std::invalid_argument("identify: no harmonics asked");
  // DOFs the model lacks are left out here: spectrum() names them with their test.
  std::vector<int> dofs = joint_dof_set(joints, sub.dofs());
  double f_max = 0.0;
  for (const auto& m : measurements) {
    f_max = std::max(f_max, m.frequency_hz);
    for (const auto& at : m.force_at)
      if (sub.dofs().state(at) == fem::DofMap::State::free) {
        const int e = sub.dofs().equation(at);
        if (std::find(dofs.begin(), dofs.end(), e) == dofs.end()) dofs.push_back(e);
      }
  }
  const int K = std::max(1, *std::max_element(o.harmonics.begin(), o.harmonics.end()));
  std::vector<std::string> notes;
  const frf::ModalSynthesis synthesis =
      sub.synthesis(dofs, frf::synthesis_band_hz(f_max, K), &notes);
  const ReceptanceFn H = [&synthesis](double omega, std::span<const int> rows,
                                      std::span<const int> cols) {
    return synthesis.receptance(omega, rows, cols);
  };
  FitResult result = fit(H, sub.dofs(), joints, measurements, o);
  result.warnings.insert(result.warnings.end(), notes.begin(), notes.end());
  return result;
}

MeasureOptions measure_options(const FitOptions& o) {
  MeasureOptions m;
  m.harmonics = std::max(1, *std::max_element(o.harmonics.begin(), o.harmonics.end()));
  m.steady_tolerance = o.steady_tolerance;
  return m;
}

FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints,
              const std::vector<Measurement>& measurements, const FitOptions& o) {
  if (measurements.empty()) throw std::invalid_argument("identify: no tests");
  if (o.harmonics.empty()) throw std::invalid_argument("identify: no harmonics asked");
  std::vector<std::string> warnings;
  std::vector<TestSpectrum> tests;
  int tables = 0;
  for (const auto& m : measurements) {
    warnings.insert(warnings.end(), m.warnings.begin(), m.warnings.end());
    tests.push_back(spectrum(m, dofs, joints, warnings));
    tables += m.fundamental_only ? 1 : 0;
  }
  if (tables > 0 && (o.harmonics.size() != 1 || o.harmonics[0] != 1))
    warnings.push_back(std::to_string(tables) +
                       " test(s) from stepped-sine tables give harmonic 1 only; their other "
                       "harmonics were not used");
  bool nonlinear = false;
  for (const auto& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      nonlinear = nonlinear || (!joints::is_linear(j.terms[t]) && !j.fixed[t]);
  if (tables > 0 && nonlinear)
    warnings.push_back(
        "stepped-sine tables give the fundamental only: the joints' basis functions are "
        "evaluated on the fundamental's sinusoid (a describing function), which neglects the "
        "response's own higher harmonics; non-linear terms may be biased by about their share "
        "(jointid discover identifies them by output error through the harmonic balance)");
  return fit(H, dofs, joints, tests, o, std::move(warnings));
}

FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<SineTest>& tests,
              const FitOptions& o) {
  if (tests.empty()) throw std::invalid_argument("identify: no tests");
  if (o.harmonics.empty()) throw std::invalid_argument("identify: no harmonics asked");
  return fit(H, dofs, joints, measure(tests, measure_options(o)), o);
}

FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<Record>& records,
              const FitOptions& o) {
  if (records.empty()) throw std::invalid_argument("identify: no records");
  return fit(H, dofs, joints, std::vector<SineTest>(records.begin(), records.end()), o);
}

} // namespace jointid::identify
