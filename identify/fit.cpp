#include "identify/fit.hpp"

#include "fem/assert.hpp"
#include "fem/constants.hpp"
#include "fem/fft.hpp"
#include "fem/text.hpp"
#include "identify/harmonics.hpp"
#include "identify/statistics.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace jointid::identify {

namespace {

// The force of parametric term t of joint j (parameters checked) at the samples y: a gap's
// directly, a hysteretic term's steady loop over the samples taken as one period. Its
// derivative ∂g/∂y at the samples (the stuck elements' stiffness for sliders) into `slope` if
// given.
template <class Out>
void parametric_force(const joints::Joint& j, std::size_t t, const Eigen::VectorXd& y, Out&& g,
                      Eigen::VectorXd* slope = nullptr) {
  joints::check_parameters(j);
  const Eigen::Index n = y.size();
  if (slope) slope->setZero(n);
  if (j.terms[t] == joints::Term::gap) {
    const double delta = j.parameter(t, "delta"), kg = j.parameter(t, "kg");
    for (Eigen::Index r = 0; r < n; ++r) {
      double d;
      g(r) = joints::gap_force(delta, kg, y(r), &d);
      if (slope) (*slope)(r) = d;
    }
    return;
  }
  const joints::Sliders sliders =
      j.terms[t] == joints::Term::jenkins
          ? joints::jenkins_sliders(j.parameter(t, "kt"), j.parameter(t, "fs"))
          : joints::iwan_sliders(j.parameter(t, "fs"), j.parameter(t, "kt"), j.parameter(t, "chi"),
                                 j.parameter(t, "beta"), j.iwan_sliders);
  std::vector<double> ys(y.data(), y.data() + n), gs(static_cast<std::size_t>(n));
  std::vector<joints::LoopEntry> entries;
  joints::LoopWork work;
  joints::steady_loop(sliders, ys, false, gs, slope ? &entries : nullptr, work);
  for (Eigen::Index r = 0; r < n; ++r)
    g(r) = gs[static_cast<std::size_t>(r)];
  if (slope)
    for (const joints::LoopEntry& e : entries)
      if (e.n == e.m) (*slope)(e.n) += e.value;
}

// Lines 0 … K of a joint's basis functions on one period of its deformation y and rate ẏ (N
// samples each). A broadband deformation makes basis functions with kinks (ẏ|ẏ|, sign ẏ) rich
// far above the band, and sampled at the record's rate their content above its Nyquist
// frequency would fold onto the lines (by 1e-4 of a term's force for ẏ|ẏ| of a 1–8 Hz multisine
// at 256 Hz): y and ẏ are interpolated to four times the samples (their spectra zero-padded,
// exact for a band-limited signal) before the basis functions see them. A term with named
// parameters (held at its values) gives its force there: a hysteretic term's steady loop over
// the interpolated period.
Eigen::MatrixXcd basis_lines(const joints::Joint& joint, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& ydot, double t0, double omega, int K) {
  constexpr int oversampling = 4;
  const auto N = static_cast<int>(y.size()), M = oversampling * N;
  fem::RealFft coarse(N), fine(M);
  auto interpolate = [&](const Eigen::VectorXd& x) {
    const Eigen::VectorXcd S = coarse.forward(x);
    Eigen::VectorXcd padded = Eigen::VectorXcd::Zero(M / 2 + 1);
    const Eigen::Index keep = (N - 1) / 2; // below Nyquist (its bin is ambiguous: left out)
    padded.head(keep + 1) = S.head(keep + 1);
    return Eigen::VectorXd(fine.inverse(padded) / N);
  };
  const Eigen::VectorXd yu = interpolate(y), vu = interpolate(ydot);
  Eigen::MatrixXd g(M, static_cast<Eigen::Index>(joint.terms.size()));
  for (std::size_t term = 0; term < joint.terms.size(); ++term) {
    const auto c = static_cast<Eigen::Index>(term);
    if (joints::has_parameters(joint.terms[term])) {
      parametric_force(joint, term, yu, g.col(c));
      continue;
    }
    for (Eigen::Index r = 0; r < M; ++r)
      g(r, c) = joints::basis(joint.terms[term], yu(r), vu(r));
  }
  return period_harmonics(g, t0, omega, K);
}

} // namespace

void check_identifiable(const std::vector<joints::Joint>& joints) {
  for (const joints::Joint& j : joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      if (!joints::has_parameters(j.terms[t]) || j.fixed[t]) continue;
      const std::string name(joints::term_name(j.terms[t]));
      throw std::invalid_argument(
          "joint '" + j.name + "': the parameters of term '" + name + "' (" +
          joints::parameter_names(j.terms[t]) +
          ") enter its force non-linearly: the equation error takes the term only as a known "
          "force (all of its parameters in 'values' and \"" +
          name +
          "\" in 'fixed'); output error identifies them, started from a describing-function "
          "fit (identify::output_error)");
    }
}

std::vector<ParameterEstimate> parameters_of(const joints::Joint& j, std::size_t t) {
  std::vector<ParameterEstimate> out;
  const auto list = j.parameters_of(t);
  const auto& info = joints::term_info(j.terms[t]).parameters;
  for (std::size_t p = 0; p < list.size() && p < info.size(); ++p) {
    const double v = list[p].value;
    out.push_back({std::string(info[p].name), v, 0.0, v, v, list[p].fixed, true});
  }
  return out;
}

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
  check_identifiable(joints);
  TestSpectrum s;
  s.source = m.source;
  s.frequency_hz = m.frequency_hz;
  s.fundamental_only = m.fundamental_only;
  for (const auto& at : m.force_at) {
    // The record's channel is at fault, not the model: say what the model has.
    if (const std::string why = dofs.why_not_free(at); !why.empty())
      fail("force channel f@" + fem::to_string(at) + ": " + why +
           "; a force must act on a free DOF of the model");
    s.force_equations.push_back(dofs.equation(at));
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
  const bool periodic = m.kind == RecordKind::periodic;
  s.lines = m.lines;

  // Basis functions on the measured deformation y = x(node) − x(node_b), i.e. Y = X2 B.
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, set2);
  const Eigen::MatrixXd Y = x2 * B, Ydot = v2 * B;
  s.y.resize(n, static_cast<Eigen::Index>(joints.size()));
  s.ydot.resize(n, static_cast<Eigen::Index>(joints.size()));
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
    if (periodic) {
      s.G.push_back(basis_lines(j, y, ydot, m.t(0), omega, K));
    } else {
      Eigen::MatrixXd g(n, static_cast<Eigen::Index>(j.terms.size()));
      for (std::size_t term = 0; term < j.terms.size(); ++term) {
        const auto c = static_cast<Eigen::Index>(term);
        if (joints::has_parameters(j.terms[term])) { // its force (fixed): the right-hand side's
          parametric_force(j, term, y, g.col(c));
          continue;
        }
        for (Eigen::Index r = 0; r < n; ++r)
          g(r, c) = joints::basis(j.terms[term], y(r), ydot(r));
      }
      s.G.push_back(fit_harmonics(m.t, g, omega, K));
    }
    s.y.col(static_cast<Eigen::Index>(i)) = y;
    s.ydot.col(static_cast<Eigen::Index>(i)) = ydot;
  }

  // The noise, per analysed sample (averaging P periods divides a sample's variance by P). A
  // scatter below 1e-8 of a channel's amplitude is not measurement noise (a simulated record's
  // periods agree to 1e-10): the noise is then taken as unknown.
  const double P = m.averaging;
  s.t = m.t;
  s.derived_harmonics = m.derived_harmonics;
  s.noise_known = !m.fundamental_only;
  auto meaningful = [](double sigma, double amplitude) {
    return sigma > 1e-8 * amplitude && std::isfinite(sigma);
  };
  // A channel's own amplitude: its displacement's fundamental (a periodic test: its largest
  // line) times (kω)^power.
  auto largest = [&](const Eigen::MatrixXcd& A, Eigen::Index column, int power) {
    if (!periodic) return std::abs(A(1, column)) * std::pow(omega, power);
    double a = 0.0;
    for (int k : m.lines)
      a = std::max(a, std::abs(A(k, column)) * std::pow(k * omega, power));
    return a;
  };
  for (std::size_t i = 0; i < set2.size(); ++i) {
    const int r = m.response_index(dofs.node_dof(set2[i]));
    const Quantity q = m.measured_as[r];
    const int power = q == Quantity::displacement ? 0 : q == Quantity::velocity ? 1 : 2;
    s.x_power.push_back(power);
    s.x_variance.push_back(std::pow(m.channel_noise[r], 2) / P);
    s.v_variance.push_back(std::pow(m.velocity_noise[r], 2) / P);
    s.noise_known = s.noise_known && meaningful(m.channel_noise[r], largest(m.X, r, power));
  }
  for (std::size_t f = 0; f < m.force_noise.size(); ++f) {
    s.f_variance.push_back(m.force_noise[f] * m.force_noise[f] / P);
    s.noise_known = s.noise_known &&
                    meaningful(m.force_noise[f], largest(m.F, static_cast<Eigen::Index>(f), 0));
  }
  if (periodic) {
    // The noise of a periodic test is the scatter of its periods: each one's equations.
    s.noise_known = s.noise_known && m.periods.size() >= 2;
    if (s.noise_known) {
      const auto L = static_cast<Eigen::Index>(m.lines.size());
      for (const auto& period : m.periods) {
        TestSpectrum::Period q;
        q.F = period.F;
        q.X2.resize(L, static_cast<Eigen::Index>(set2.size()));
        Eigen::MatrixXd px(n, set2.size()), pv(n, set2.size());
        for (std::size_t i = 0; i < set2.size(); ++i) {
          const int r = m.response_index(dofs.node_dof(set2[i]));
          q.X2.col(static_cast<Eigen::Index>(i)) = period.X.col(r);
          px.col(static_cast<Eigen::Index>(i)) = period.x.col(r);
          pv.col(static_cast<Eigen::Index>(i)) = period.v.col(r);
        }
        const Eigen::MatrixXd PY = px * B, PYdot = pv * B;
        for (std::size_t i = 0; i < joints.size(); ++i) {
          const Eigen::MatrixXcd all =
              basis_lines(joints[i], PY.col(static_cast<Eigen::Index>(i)),
                          PYdot.col(static_cast<Eigen::Index>(i)), m.t(0), omega, K);
          Eigen::MatrixXcd at_lines(L, all.cols());
          for (Eigen::Index l = 0; l < L; ++l)
            at_lines.row(l) = all.row(m.lines[static_cast<std::size_t>(l)]);
          q.G.push_back(std::move(at_lines));
        }
        s.periods.push_back(std::move(q));
      }
    }
  }
  return s;
}

std::vector<joints::Joint>
FitResult::identified(const std::vector<joints::Joint>& model_joints) const {
  if (!status.ok()) throw std::invalid_argument("identify: " + status.reason);
  std::vector<joints::Joint> out = model_joints;
  for (std::size_t i = 0; i < out.size() && i < joints.size(); ++i)
    for (std::size_t t = 0; t < out[i].terms.size(); ++t)
      out[i].values[t] = joints[i].terms[t].value;
  return out;
}

namespace {

using Complex = std::complex<double>;

// One equation of Q b = p: a real or imaginary part of the complex equation of set-2 DOF d at
// harmonic k of a test.
struct Row {
  int test, k, d;
  bool imaginary;
};

// The receptances one test's equations at harmonic k use: H22 B (set-2 DOFs × joints) and H2f.
struct Receptances {
  frf::CMatrix H22B, H2f;
};

// Periodic signals over a test's analysed span (whole periods, uniform) and the spectral
// operators that derive one from another: (ikω)^q on harmonics 1 … M.
class Spectral {
public:
  Spectral(const Eigen::VectorXd& t, double omega, int M) : omega_(omega), M_(M) {
    const auto N = t.size();
    E_.resize(N, M);
    for (Eigen::Index n = 0; n < N; ++n)
      for (int k = 1; k <= M; ++k)
        E_(n, k - 1) = std::polar(1.0, k * omega * t(n));
  }
  // (ikω)^q u for q ≠ 0 (the derivative q = 1, integrals q < 0; the mean dropped); u itself
  // for q = 0.
  Eigen::VectorXd apply(const Eigen::VectorXd& u, int q) const {
    if (q == 0) return u;
    const auto N = static_cast<double>(u.size());
    Eigen::VectorXcd U = (2.0 / N) * (E_.adjoint() * u.cast<Complex>());
    for (int k = 1; k <= M_; ++k)
      U(k - 1) *= std::pow(Complex(0.0, k * omega_), q);
    return (E_ * U).real();
  }
  // Its transpose: (ikω)^q is symmetric for even q and antisymmetric for odd q on whole
  // periods of uniform samples.
  Eigen::VectorXd apply_transposed(const Eigen::VectorXd& u, int q) const {
    return (q % 2 == 0 ? 1.0 : -1.0) * apply(u, q);
  }
  // The variance of one sample of (ikω)^q applied to white noise of unit variance.
  double gain(int q, Eigen::Index N) const {
    if (q == 0) return 1.0;
    double g = 0.0;
    for (int k = 1; k <= M_; ++k)
      g += std::pow(k * omega_, 2.0 * q);
    return 2.0 * g / static_cast<double>(N);
  }

private:
  Eigen::MatrixXcd E_; // N × M: e^{ikωt_n}
  double omega_;
  int M_;
};

// The covariance of one test's equations (its rows of Q b − p, in order) from the measurement
// noise, at the joint values `joints`. Each row is linear in the noise of the analysed samples
// of every channel: through the measured displacement X2 and force F, and through the basis
// functions evaluated on the noisy deformation (δg = ∂g/∂y δy + ∂g/∂ẏ δẏ: errors in
// variables). Dry friction's sign(ẏ) has no derivative: a sample whose rate is within the noise
// of zero flips with probability Φ(−|ẏ|/σ), an independent variance 4 fc² p (1 − p) per sample.
Eigen::MatrixXd equation_covariance(const TestSpectrum& ts, const std::vector<Row>& rows,
                                    const std::map<int, Receptances>& at_k,
                                    const std::vector<joints::Joint>& joints,
                                    const Eigen::MatrixXd& B) {
  const Eigen::Index N = ts.t.size(), n2 = B.rows(), nj = B.cols();
  const double omega = two_pi * ts.frequency_hz;
  const int M = std::max(ts.derived_harmonics, 1);
  const Spectral op(ts.t, omega, M);
  // The joints' force derivatives at the samples, and the friction flip variance.
  Eigen::MatrixXd gy = Eigen::MatrixXd::Zero(N, nj), gv = gy, flip = gy;
  for (Eigen::Index j = 0; j < nj; ++j) {
    const auto& J = joints[static_cast<std::size_t>(j)];
    // Variance of a sample of the joint's rate: its DOFs' velocity noise.
    double var_rate = 0.0;
    for (Eigen::Index d = 0; d < n2; ++d) {
      if (B(d, j) == 0.0) continue;
      const auto dd = static_cast<std::size_t>(d);
      var_rate +=
          B(d, j) * B(d, j) *
          (std::isfinite(ts.v_variance[dd]) ? ts.v_variance[dd]
                                            : ts.x_variance[dd] * op.gain(1 - ts.x_power[dd], N));
    }
    for (std::size_t t = 0; t < J.terms.size(); ++t)
      if (joints::has_parameters(J.terms[t])) { // (fixed) its slope, stuck elements' for sliders
        Eigen::VectorXd g(N), slope;
        parametric_force(J, t, ts.y.col(j), g, &slope);
        gy.col(j) += slope;
      }
    for (Eigen::Index n = 0; n < N; ++n) {
      const double y = ts.y(n, j), v = ts.ydot(n, j);
      for (std::size_t t = 0; t < J.terms.size(); ++t) {
        if (joints::has_parameters(J.terms[t])) continue;
        if (joints::is_dry_friction(J.terms[t])) {
          const double pflip =
              var_rate > 0.0 ? 0.5 * std::erfc(std::abs(v) / std::sqrt(2.0 * var_rate)) : 0.0;
          flip(n, j) += 4.0 * J.values[t] * J.values[t] * pflip * (1.0 - pflip);
        } else {
          gy(n, j) += J.values[t] * joints::basis_dy(J.terms[t], y, v);
          gv(n, j) += J.values[t] * joints::basis_dydot(J.terms[t], y, v);
        }
      }
    }
  }
  // Noise sources, one block of N samples each: per set-2 DOF its displacement's channel, then
  // the separately measured velocity channels, the force channels, and the friction flips.
  const auto nf = static_cast<Eigen::Index>(ts.f_variance.size());
  std::vector<Eigen::Index> v_block(static_cast<std::size_t>(n2), -1);
  Eigen::Index blocks = n2;
  for (Eigen::Index d = 0; d < n2; ++d)
    if (std::isfinite(ts.v_variance[static_cast<std::size_t>(d)]))
      v_block[static_cast<std::size_t>(d)] = blocks++;
  const Eigen::Index f_block = blocks, flip_block = blocks + nf;
  blocks += nf + nj;
  Eigen::VectorXd variance(blocks * N);
  for (Eigen::Index d = 0; d < n2; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    variance.segment(d * N, N).setConstant(ts.x_variance[dd]);
    if (v_block[dd] >= 0) variance.segment(v_block[dd] * N, N).setConstant(ts.v_variance[dd]);
  }
  for (Eigen::Index f = 0; f < nf; ++f)
    variance.segment((f_block + f) * N, N).setConstant(ts.f_variance[static_cast<std::size_t>(f)]);
  for (Eigen::Index j = 0; j < nj; ++j)
    variance.segment((flip_block + j) * N, N) = flip.col(j);

  const auto nr = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(nr, blocks * N);
  for (Eigen::Index r = 0; r < nr; ++r) {
    const Row& row = rows[static_cast<std::size_t>(r)];
    const Receptances& R = at_k.at(row.k);
    // a_k(n) = (c_k / N) e^{−ikωt_n}: harmonic k of a signal is a_kᵀ u.
    Eigen::VectorXcd a(N);
    for (Eigen::Index n = 0; n < N; ++n)
      a(n) = (row.k == 0 ? 1.0 : 2.0) / static_cast<double>(N) *
             std::polar(1.0, -row.k * omega * ts.t(n));
    auto part = [&](const Eigen::VectorXcd& w) -> Eigen::VectorXd {
      return row.imaginary ? Eigen::VectorXd(w.imag()) : Eigen::VectorXd(w.real());
    };
    // Functionals on the displacement and velocity used at every set-2 DOF.
    for (Eigen::Index d = 0; d < n2; ++d) {
      Eigen::VectorXcd on_x = Eigen::VectorXcd::Zero(N), on_v = on_x;
      for (Eigen::Index j = 0; j < nj; ++j) {
        if (B(d, j) == 0.0) continue;
        const Complex h = -R.H22B(row.d, j) * B(d, j);
        on_x += h * a.cwiseProduct(gy.col(j).cast<Complex>());
        on_v += h * a.cwiseProduct(gv.col(j).cast<Complex>());
      }
      if (d == row.d) on_x -= a; // − δX2
      // Onto the channels: x = (ikω)^−p s, and v = (ikω)^(1−p) s unless measured on its own.
      const auto dd = static_cast<std::size_t>(d);
      const int p = ts.x_power[dd];
      Eigen::VectorXd on_source = op.apply_transposed(part(on_x), -p);
      if (v_block[dd] >= 0)
        W.block(r, v_block[dd] * N, 1, N) += part(on_v).transpose();
      else
        on_source += op.apply_transposed(part(on_v), 1 - p);
      W.block(r, d * N, 1, N) += on_source.transpose();
    }
    for (Eigen::Index f = 0; f < nf; ++f) // + H2f δF
      W.block(r, (f_block + f) * N, 1, N) += part(R.H2f(row.d, f) * a).transpose();
    for (Eigen::Index j = 0; j < nj; ++j) // − H22 B δg of the flips
      W.block(r, (flip_block + j) * N, 1, N) += part(-R.H22B(row.d, j) * a).transpose();
  }
  return W * variance.asDiagonal() * W.transpose();
}

// The non-fixed terms of the joints, in the order of the unknowns: (joint, term).
std::vector<std::pair<int, int>> unknowns_of(const std::vector<joints::Joint>& joints) {
  std::vector<std::pair<int, int>> u;
  for (std::size_t i = 0; i < joints.size(); ++i)
    for (std::size_t t = 0; t < joints[i].terms.size(); ++t)
      if (!joints[i].fixed[t]) u.push_back({static_cast<int>(i), static_cast<int>(t)});
  return u;
}

// What the tests leave undetermined, in words. `S` (unknowns × unknowns, scaled back) gives the
// shape of the covariance: correlations come from S Sᵀ.
std::vector<std::string> explain_identifiability(const FitResult& result,
                                                 const std::vector<joints::Joint>& joints,
                                                 const std::vector<std::pair<int, int>>& unknowns,
                                                 const std::vector<TestSpectrum>& tests,
                                                 const Eigen::MatrixXd& B, const Eigen::VectorXd& b,
                                                 const Eigen::MatrixXd& S, const FitOptions& o) {
  std::vector<std::string> out;
  const auto nu = static_cast<Eigen::Index>(unknowns.size());
  const Eigen::MatrixXd cov = S * S.transpose();
  auto name = [&](Eigen::Index u) {
    const auto [i, t] = unknowns[static_cast<std::size_t>(u)];
    return std::string(joints::term_name(joints[i].terms[t])) + " of '" + joints[i].name + "'";
  };
  auto estimate = [&](Eigen::Index u) -> const TermEstimate& {
    const auto [i, t] = unknowns[static_cast<std::size_t>(u)];
    return result.joints[i].terms[t];
  };
  // A test's main line for a joint: the fundamental, or a periodic test's line where the
  // joint's deformation is largest.
  auto deformation = [&](const TestSpectrum& test, int joint, int k) {
    return (test.X2.row(k) * B.col(joint).cast<std::complex<double>>())(0);
  };
  auto main_line = [&](const TestSpectrum& test, int joint) {
    int best = 1;
    for (int k : test.lines)
      if (std::abs(deformation(test, joint, k)) > std::abs(deformation(test, joint, best)))
        best = k;
    return best;
  };
  // Per joint and test: the main line of the deformation and of each term's force b_t g_t.
  auto force_share = [&](Eigen::Index u, std::string& where) {
    const auto [i, t] = unknowns[static_cast<std::size_t>(u)];
    double best = 0.0;
    for (const auto& test : tests) {
      if (test.G[i].rows() < 2) continue;
      const int k = main_line(test, i);
      std::complex<double> total = 0.0;
      for (std::size_t tt = 0; tt < joints[i].terms.size(); ++tt) {
        const double value = joints[i].fixed[tt] ? joints[i].values[tt] : 0.0;
        total += test.G[i](k, static_cast<Eigen::Index>(tt)) * value;
      }
      for (Eigen::Index v = 0; v < nu; ++v)
        if (unknowns[static_cast<std::size_t>(v)].first == i)
          total += test.G[i](k, unknowns[static_cast<std::size_t>(v)].second) * b(v);
      const double share = std::abs(test.G[i](k, t) * b(u)) / std::max(std::abs(total), 1e-300);
      if (share > best) best = share, where = test.source;
    }
    return best;
  };
  auto amplitude_range = [&](int joint, bool rate) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (const auto& test : tests) {
      const int k = main_line(test, joint);
      const double a =
          std::abs(deformation(test, joint, k)) * (rate ? two_pi * k * test.frequency_hz : 1.0);
      lo = std::min(lo, a), hi = std::max(hi, a);
    }
    return std::pair{lo, hi};
  };
  std::vector<std::pair<Eigen::Index, Eigen::Index>> said; // pairs already explained
  for (Eigen::Index u = 0; u < nu; ++u) {
    if (estimate(u).determined) continue;
    std::string where;
    const double share = force_share(u, where);
    // The most correlated other unknown.
    Eigen::Index partner = -1;
    double corr = 0.0;
    for (Eigen::Index v = 0; v < nu; ++v) {
      if (v == u) continue;
      const double c = cov(u, v) / std::sqrt(cov(u, u) * cov(v, v));
      if (std::abs(c) > std::abs(corr)) corr = c, partner = v;
    }
    const std::string relative =
        percent(estimate(u).std / std::max(std::abs(estimate(u).value), 1e-300));
    if (share < 0.01) {
      out.push_back(name(u) + " is not determined (std " + relative +
                    " of its value): at most its force is " + percent(share) +
                    " of the joint's (in " + where +
                    "); tests at larger amplitudes would bring it out");
    } else if (partner >= 0 && std::abs(corr) > 0.95) {
      if (std::find(said.begin(), said.end(), std::pair{partner, u}) != said.end()) continue;
      said.push_back({u, partner});
      const auto [i, t] = unknowns[static_cast<std::size_t>(u)];
      const auto [pi, pt] = unknowns[static_cast<std::size_t>(partner)];
      const auto nature = joints::term_info(joints[i].terms[t]).nature;
      const bool same_joint = i == pi;
      std::string why;
      if (same_joint && nature == joints::term_info(joints[pi].terms[pt]).nature) {
        const bool rate = nature == joints::Nature::dissipative;
        const auto [lo, hi] = amplitude_range(i, rate);
        if (hi < 1.3 * lo)
          why = fmt::format("; all tests have about the same {} amplitude at '{}' ({:.3g} to "
                            "{:.3g} {}): vary the force level",
                            rate ? "velocity" : "displacement", joints[i].name, lo, hi,
                            rate ? "m/s" : "m");
      }
      out.push_back(fmt::format("{} and {} are not separated by these tests: their estimates "
                                "are {:.0f} % correlated (std {} of its value){}",
                                name(u), name(partner), 100.0 * std::abs(corr), relative, why));
    } else {
      out.push_back(name(u) + " is poorly determined (std " + relative +
                    " of its value, above the " + percent(o.poorly_determined) + " asked)");
    }
  }
  if (result.condition_number > 1e8)
    out.push_back(fmt::format("the equations are ill-conditioned (condition number {:.3g}): the "
                              "smallest singular value is {:.3g} of the largest",
                              result.condition_number, 1.0 / result.condition_number));
  return out;
}

// The equations Q b = p of the tests (rows: real and imaginary parts per set-2 DOF, harmonic and
// test) for the non-fixed terms, known terms moved to the right-hand side, and the receptances
// each test's rows use (for their noise covariance).
struct Equations {
  Eigen::MatrixXd Q;
  Eigen::VectorXd p;
  std::vector<Row> rows;
  std::vector<std::map<int, Receptances>> receptances; // per test, per harmonic
};

Equations equations(const ReceptanceFn& H, const std::vector<int>& set2, const Eigen::MatrixXd& B,
                    const std::vector<joints::Joint>& joints,
                    const std::vector<TestSpectrum>& tests, const std::vector<int>& harmonics) {
  const auto unknowns = unknowns_of(joints);
  const auto nu = static_cast<Eigen::Index>(unknowns.size());
  const auto n2 = static_cast<Eigen::Index>(set2.size());
  std::vector<Eigen::RowVectorXd> q_rows;
  std::vector<double> rhs;
  Equations eq;
  eq.receptances.resize(tests.size());
  for (std::size_t ti = 0; ti < tests.size(); ++ti) {
    const auto& test = tests[ti];
    for (int k : test.lines.empty() ? harmonics : test.lines) {
      if (test.fundamental_only && k != 1) continue;
      if (k < 0 || k >= test.F.rows())
        throw std::invalid_argument("identify: harmonic " + std::to_string(k) + " not extracted");
      const double w = two_pi * test.frequency_hz * k;
      const frf::CMatrix H22 = H(w, set2, set2), H2f = H(w, set2, test.force_equations);
      eq.receptances[ti][k] = {H22 * B.cast<Complex>(), H2f};
      frf::CVector R = test.X2.row(k).transpose() - H2f * test.F.row(k).transpose();
      frf::CMatrix Qc(n2, nu);
      for (Eigen::Index u = 0; u < nu; ++u) {
        const auto [i, t] = unknowns[static_cast<std::size_t>(u)];
        Qc.col(u) = -H22 * B.col(i).cast<Complex>() * test.G[static_cast<std::size_t>(i)](k, t);
      }
      for (std::size_t i = 0; i < joints.size(); ++i) // known terms go to the right-hand side
        for (std::size_t t = 0; t < joints[i].terms.size(); ++t)
          if (joints[i].fixed[t])
            R += H22 * B.col(static_cast<Eigen::Index>(i)).cast<Complex>() *
                 test.G[i](k, static_cast<Eigen::Index>(t)) * joints[i].values[t];
      for (int d = 0; d < n2; ++d) {
        q_rows.push_back(Qc.row(d).real());
        rhs.push_back(R(d).real());
        eq.rows.push_back({static_cast<int>(ti), k, d, false});
        if (k != 0) { // the mean has no imaginary part
          q_rows.push_back(Qc.row(d).imag());
          rhs.push_back(R(d).imag());
          eq.rows.push_back({static_cast<int>(ti), k, d, true});
        }
      }
    }
  }
  const auto m = static_cast<Eigen::Index>(q_rows.size());
  eq.Q.resize(m, nu);
  eq.p.resize(m);
  for (Eigen::Index r = 0; r < m; ++r)
    eq.Q.row(r) = q_rows[static_cast<std::size_t>(r)], eq.p(r) = rhs[static_cast<std::size_t>(r)];
  return eq;
}

// The noise covariance C of one test's rows `idx` of `eq`, at the joints' values `at`,
// regularised as the fit whitens with it.
Eigen::MatrixXd test_covariance(const Equations& eq, const std::vector<int>& idx,
                                const TestSpectrum& test, std::size_t ti,
                                const std::vector<joints::Joint>& at, const Eigen::MatrixXd& B) {
  std::vector<Row> these;
  for (int r : idx)
    these.push_back(eq.rows[static_cast<std::size_t>(r)]);
  Eigen::MatrixXd C = equation_covariance(test, these, eq.receptances[ti], at, B);
  C.diagonal().array() += 1e-12 * C.diagonal().mean() + 1e-300;
  return C;
}

// The covariance of the rows `block` (one line k of a periodic test, in order) from the scatter
// of its periods' equations Q b − p at the joints' values `at`. With P periods the sample
// covariance S has P − 1 degrees of freedom: the rows' full covariance is used where P − 1 is
// at least twice their number q, else only its diagonal (q = 1); S is scaled by
// (P − 1)/(P − q − 2) where that is defined, so that E[C⁻¹] is the true inverse (a Wishart
// matrix's inverse is biased by that factor): χ² is then not inflated by the estimate's own
// scatter.
Eigen::MatrixXd scatter_covariance(const Equations& eq, const std::vector<int>& block,
                                   const TestSpectrum& test, std::size_t ti,
                                   const std::vector<joints::Joint>& at, const Eigen::MatrixXd& B) {
  const int k = eq.rows[static_cast<std::size_t>(block.front())].k;
  const auto line = static_cast<Eigen::Index>(
      std::lower_bound(test.lines.begin(), test.lines.end(), k) - test.lines.begin());
  const Receptances& R = eq.receptances[ti].at(k);
  const auto P = static_cast<Eigen::Index>(test.periods.size());
  const auto q = static_cast<Eigen::Index>(block.size());
  Eigen::MatrixXd E(q, P); // each period's rows
  for (Eigen::Index p = 0; p < P; ++p) {
    const TestSpectrum::Period& period = test.periods[static_cast<std::size_t>(p)];
    // − H22 B g − X2 + H2f F, with g each joint's force at this line.
    Eigen::VectorXcd g(B.cols());
    for (Eigen::Index j = 0; j < B.cols(); ++j) {
      const auto& J = at[static_cast<std::size_t>(j)];
      Complex sum = 0.0;
      for (std::size_t t = 0; t < J.terms.size(); ++t)
        sum +=
            J.values[t] * period.G[static_cast<std::size_t>(j)](line, static_cast<Eigen::Index>(t));
      g(j) = sum;
    }
    const Eigen::VectorXcd r =
        -R.H22B * g - period.X2.row(line).transpose() + R.H2f * period.F.row(line).transpose();
    for (Eigen::Index i = 0; i < q; ++i) {
      const Row& row = eq.rows[static_cast<std::size_t>(block[static_cast<std::size_t>(i)])];
      E(i, p) = row.imaginary ? r(row.d).imag() : r(row.d).real();
    }
  }
  const Eigen::MatrixXd centred = E.colwise() - E.rowwise().mean();
  Eigen::MatrixXd C = centred * centred.transpose() / static_cast<double>(P - 1) / P;
  const bool full = P - 1 >= 2 * q;
  if (!full) C = Eigen::MatrixXd(C.diagonal().asDiagonal());
  const Eigen::Index dims = full ? q : 1;
  if (P - dims - 2 >= 1) C *= static_cast<double>(P - 1) / static_cast<double>(P - dims - 2);
  C.diagonal().array() += 1e-12 * C.diagonal().mean() + 1e-300;
  return C;
}

// How one test's rows `idx` are whitened: blocks of them (positions in idx) with the Cholesky
// factor of their covariance. A sine test is one block; a periodic test one per line.
struct Whitening {
  std::vector<std::vector<int>> blocks;
  std::vector<Eigen::LLT<Eigen::MatrixXd>> factors;

  // C^{-1/2} applied to the test's rows (in idx order).
  Eigen::MatrixXd apply(const Eigen::MatrixXd& rows) const {
    Eigen::MatrixXd out(rows.rows(), rows.cols());
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      Eigen::MatrixXd part(static_cast<Eigen::Index>(blocks[b].size()), rows.cols());
      for (std::size_t i = 0; i < blocks[b].size(); ++i)
        part.row(static_cast<Eigen::Index>(i)) = rows.row(blocks[b][i]);
      part = factors[b].matrixL().solve(part);
      for (std::size_t i = 0; i < blocks[b].size(); ++i)
        out.row(blocks[b][i]) = part.row(static_cast<Eigen::Index>(i));
    }
    return out;
  }
};

Whitening test_whitening(const Equations& eq, const std::vector<int>& idx, const TestSpectrum& test,
                         std::size_t ti, const std::vector<joints::Joint>& at,
                         const Eigen::MatrixXd& B) {
  Whitening w;
  if (test.periods.empty()) {
    w.blocks.emplace_back(idx.size());
    for (std::size_t i = 0; i < idx.size(); ++i)
      w.blocks[0][i] = static_cast<int>(i);
    w.factors.emplace_back(test_covariance(eq, idx, test, ti, at, B));
    return w;
  }
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const int k = eq.rows[static_cast<std::size_t>(idx[i])].k;
    if (i == 0 || eq.rows[static_cast<std::size_t>(idx[i - 1])].k != k) w.blocks.emplace_back();
    w.blocks.back().push_back(static_cast<int>(i));
  }
  for (const auto& block : w.blocks) {
    std::vector<int> rows;
    for (int i : block)
      rows.push_back(idx[static_cast<std::size_t>(i)]);
    w.factors.emplace_back(scatter_covariance(eq, rows, test, ti, at, B));
  }
  return w;
}
} // namespace

FitResult fit(const ReceptanceFn& H, const fem::DofMap& dofs,
              const std::vector<joints::Joint>& joints, const std::vector<TestSpectrum>& tests,
              const FitOptions& o, std::vector<std::string> warnings) {
  if (joints.empty()) throw std::invalid_argument("identify: the model has no joints");
  if (tests.empty()) throw std::invalid_argument("identify: no tests");
  check_identifiable(joints);
  const std::vector<int> set2 = joint_dof_set(joints, dofs);
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
  auto name_of = [&](int u) {
    const auto [i, t] = unknowns[static_cast<std::size_t>(u)];
    return std::string(joints::term_name(joints[i].terms[t])) + " of '" + joints[i].name + "'";
  };

  // 1. The equations, row by row, and what their noise covariance needs.
  Equations eq = equations(H, set2, B, joints, tests, o.harmonics);
  const int m = static_cast<int>(eq.rows.size());
  if (m < nu)
    throw std::invalid_argument(
        "identify: " + std::to_string(m) + " equations for " + std::to_string(nu) +
        " unknowns; add tests at other frequencies or force levels, or more harmonics");
  const Eigen::MatrixXd& Q = eq.Q;
  const Eigen::VectorXd& p = eq.p;
  const std::vector<Row>& rows = eq.rows;
  JOINTID_ASSERT(Q.rows() == m && Q.cols() == nu && p.size() == m,
                 "Q b = p: one row of Q and p per equation, one column of Q per unknown");
  for (int u = 0; u < nu; ++u)
    if (!(Q.col(u).norm() > 0.0))
      throw std::invalid_argument("identify: term " + name_of(u) +
                                  " has no effect in these tests (its basis function is zero)");

  // The terms that cannot be told apart, all of them: the near-null space of the column-scaled
  // Q (right singular vectors whose singular value is below 1e-13 of the largest) holds the
  // combinations that have no effect; a term takes part when its share of them (the norm of its
  // row there) is at least a tenth of the largest share. An unrelated term's share is of the
  // order of the rounding (1e-10 at most), a twin's 1/sqrt(2): the set does not depend on it.
  auto inseparable_reason = [&](const Eigen::VectorXd& sv, const Eigen::MatrixXd& V,
                                double condition) {
    Eigen::Index null = 0;
    while (null < nu && !(sv(nu - 1 - null) > 1e-13 * sv(0)))
      ++null;
    null = std::max<Eigen::Index>(null, 1);
    const Eigen::VectorXd share = V.rightCols(null).rowwise().norm();
    std::vector<std::string> names;
    for (int u = 0; u < nu; ++u)
      if (share(u) >= 0.1 * share.maxCoeff()) names.push_back(name_of(u));
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i)
      list += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
    if (names.size() < 2)
      return fmt::format("the unknowns cannot be separated by these tests (condition number "
                         "{:.3g}): term {} has almost no effect of its own: vary frequency and "
                         "force level, or drop it",
                         condition, list);
    const std::string combinations =
        null == 1 ? std::string("a combination of them has")
                  : fmt::format("{} independent combinations of them have", null);
    return fmt::format("the unknowns cannot be separated by these tests (condition number "
                       "{:.3g}): terms {} act alike ({} no effect in these tests), so none of "
                       "them can be told from the others: vary frequency and force level, or "
                       "drop one of them",
                       condition, list, combinations);
  };

  // 2. Least squares of the column-scaled (and, with the noise, whitened) equations by SVD.
  struct Solution {
    Eigen::VectorXd b, scale, sv;
    Eigen::MatrixXd V;
    double condition = 0.0;
    std::string inseparable; // why the unknowns cannot be separated (empty: they can)
  };
  auto solve = [&](const Eigen::MatrixXd& A, const Eigen::VectorXd& y) {
    Solution sol;
    sol.scale.resize(nu);
    for (int u = 0; u < nu; ++u)
      sol.scale(u) = 1.0 / A.col(u).norm();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A * sol.scale.asDiagonal(),
                                                Eigen::ComputeThinU | Eigen::ComputeThinV);
    sol.sv = svd.singularValues();
    sol.V = svd.matrixV();
    sol.condition =
        sol.sv(nu - 1) > 0.0 ? sol.sv(0) / sol.sv(nu - 1) : std::numeric_limits<double>::infinity();
    if (!(sol.condition < 1e13)) {
      sol.inseparable = inseparable_reason(sol.sv, sol.V, sol.condition);
      sol.b = Eigen::VectorXd::Constant(nu, nan);
      return sol;
    }
    sol.b = sol.scale.asDiagonal() * svd.solve(y);
    return sol;
  };
  // Unknowns that cannot be separated: a status, every value NaN (nothing is returned as if
  // it were determined).
  auto inseparable = [&](const Solution& sol) {
    FitResult out;
    out.status = fem::Status::failure(fem::Status::Code::not_separable, sol.inseparable);
    out.warnings = warnings;
    out.equations = m;
    out.unknowns = nu;
    out.condition_number = sol.condition;
    out.singular_values.assign(sol.sv.data(), sol.sv.data() + sol.sv.size());
    out.interval_method = "none";
    out.chi2_per_dof = nan;
    out.residual_rms = out.residual_relative = nan;
    for (std::size_t i = 0; i < joints.size(); ++i) {
      JointEstimate je{joints[i].name, {}};
      for (std::size_t t = 0; t < joints[i].terms.size(); ++t) {
        TermEstimate te;
        te.term = joints[i].terms[t];
        te.parameters = parameters_of(joints[i], t);
        te.fixed = joints[i].fixed[t];
        te.value = te.fixed ? joints[i].values[t] : nan;
        te.std = te.fixed ? 0.0 : nan;
        te.ci_low = te.ci_high = te.value;
        te.determined = te.fixed;
        je.terms.push_back(te);
      }
      out.joints.push_back(std::move(je));
    }
    out.identifiability.push_back(sol.inseparable);
    return out;
  };
  auto with_values = [&](const Eigen::VectorXd& b) {
    std::vector<joints::Joint> js = joints;
    for (int u = 0; u < nu; ++u)
      js[static_cast<std::size_t>(unknowns[u].joint)]
          .values[static_cast<std::size_t>(unknowns[u].term)] = b(u);
    return js;
  };
  Solution sol = solve(Q, p);
  if (!sol.inseparable.empty()) return inseparable(sol);

  // 3. With the noise known everywhere: generalised least squares, its covariance at the
  //    ordinary estimate first, then once more at the weighted one.
  const bool propagated =
      o.propagate_noise &&
      std::all_of(tests.begin(), tests.end(), [](const TestSpectrum& t) { return t.noise_known; });
  std::vector<Whitening> whiten(tests.size());
  std::vector<std::vector<int>> test_rows(tests.size());
  for (int r = 0; r < m; ++r)
    test_rows[static_cast<std::size_t>(rows[static_cast<std::size_t>(r)].test)].push_back(r);
  Eigen::MatrixXd Qw = Q;
  Eigen::VectorXd pw = p;
  if (propagated) {
    for (int pass = 0; pass < 2; ++pass) {
      const std::vector<joints::Joint> at = with_values(sol.b);
      for (std::size_t ti = 0; ti < tests.size(); ++ti) {
        const auto& idx = test_rows[ti];
        if (idx.empty()) continue;
        whiten[ti] = test_whitening(eq, idx, tests[ti], ti, at, B);
        Eigen::MatrixXd Qi(static_cast<Eigen::Index>(idx.size()), nu);
        Eigen::VectorXd pi(static_cast<Eigen::Index>(idx.size()));
        for (std::size_t r = 0; r < idx.size(); ++r)
          Qi.row(static_cast<Eigen::Index>(r)) = Q.row(idx[r]),
          pi(static_cast<Eigen::Index>(r)) = p(idx[r]);
        Qi = whiten[ti].apply(Qi);
        pi = whiten[ti].apply(pi);
        for (std::size_t r = 0; r < idx.size(); ++r)
          Qw.row(idx[r]) = Qi.row(static_cast<Eigen::Index>(r)),
          pw(idx[r]) = pi(static_cast<Eigen::Index>(r));
      }
      sol = solve(Qw, pw);
      if (!sol.inseparable.empty()) return inseparable(sol);
    }
  }

  FitResult out;
  out.warnings = std::move(warnings);
  out.equations = m;
  out.unknowns = nu;
  out.condition_number = sol.condition;
  out.singular_values.assign(sol.sv.data(), sol.sv.data() + sol.sv.size());
  const Eigen::VectorXd& b = sol.b;
  const Eigen::VectorXd residual = Q * b - p;
  out.residual_rms = std::sqrt(residual.squaredNorm() / m);
  out.residual_relative = residual.norm() / std::max(p.norm(), 1e-300);
  if (out.condition_number > 1e8)
    out.warnings.push_back(fmt::format(
        "Q is ill-conditioned (condition number {:.3g}): parameters may be poorly determined",
        out.condition_number));
  const int redundancy = m - nu;
  // The variance factor: the weighted residual's χ² per degree of freedom, at least 1 (a misfit
  // beyond the noise widens the intervals, never narrows them); without the noise, the plain
  // residual variance.
  double factor = nan;
  if (redundancy > 0) {
    if (propagated) {
      out.chi2_per_dof = (Qw * b - pw).squaredNorm() / redundancy;
      factor = std::max(1.0, out.chi2_per_dof);
    } else {
      out.chi2_per_dof = nan;
      factor = residual.squaredNorm() / redundancy;
    }
  }
  out.interval_method = propagated ? "propagated noise" : "residual";
  const Eigen::MatrixXd Vs = sol.V * sol.sv.cwiseInverse().asDiagonal();
  const double tq = redundancy > 0 ? student_t_quantile(0.975, redundancy) : nan;
  if (redundancy == 0)
    out.warnings.push_back("as many equations as unknowns: no uncertainty estimate");

  int u = 0;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    JointEstimate je{joints[i].name, {}};
    for (std::size_t t = 0; t < joints[i].terms.size(); ++t) {
      TermEstimate te;
      te.term = joints[i].terms[t];
      te.parameters = parameters_of(joints[i], t);
      if (joints[i].fixed[t]) {
        te.value = joints[i].values[t];
        te.fixed = true;
        te.std = 0.0;
        te.ci_low = te.ci_high = te.value;
      } else {
        te.value = b(u);
        te.std = sol.scale(u) * std::sqrt(factor * Vs.row(u).squaredNorm());
        te.ci_low = te.value - tq * te.std;
        te.ci_high = te.value + tq * te.std;
        te.determined = !(redundancy > 0 && te.std > o.poorly_determined * std::abs(te.value));
        if (!te.determined)
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
  out.identifiability = explain_identifiability(out, joints, unknowns_of(joints), tests, B, b,
                                                sol.scale.asDiagonal() * Vs, o);
  return out;
}

TestInformation information(const ReceptanceFn& H, const fem::DofMap& dofs,
                            const std::vector<joints::Joint>& joints, const TestSpectrum& test,
                            const std::vector<int>& harmonics) {
  if (!test.noise_known)
    throw std::invalid_argument("information: the noise of test " + test.source + " is not known");
  const std::vector<int> set2 = joint_dof_set(joints, dofs);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, set2);
  const std::vector<TestSpectrum> one{test};
  const Equations eq = equations(H, set2, B, joints, one, harmonics);
  std::vector<int> idx(eq.rows.size());
  for (std::size_t r = 0; r < idx.size(); ++r)
    idx[r] = static_cast<int>(r);
  const auto unknowns = unknowns_of(joints);
  Eigen::VectorXd b(static_cast<Eigen::Index>(unknowns.size()));
  for (std::size_t u = 0; u < unknowns.size(); ++u)
    b(static_cast<Eigen::Index>(u)) = joints[static_cast<std::size_t>(unknowns[u].first)]
                                          .values[static_cast<std::size_t>(unknowns[u].second)];
  const Whitening C = test_whitening(eq, idx, test, 0, joints, B);
  const Eigen::MatrixXd W = C.apply(eq.Q);                             // C^-1/2 Q
  const Eigen::VectorXd w = C.apply(Eigen::VectorXd(eq.p - eq.Q * b)); // C^-1/2 r
  TestInformation out;
  out.information = W.transpose() * W;
  out.score = W.transpose() * w;
  out.rows = static_cast<int>(idx.size());
  out.misfit = out.rows > 0 ? std::sqrt(w.squaredNorm() / out.rows) : 0.0;
  return out;
}

FitResult fit(const frf::Substructure& sub, const std::vector<joints::Joint>& joints,
              const std::vector<Measurement>& measurements, const FitOptions& o) {
  if (measurements.empty()) throw std::invalid_argument("identify: no tests");
  if (o.harmonics.empty()) throw std::invalid_argument("identify: no harmonics asked");
  // DOFs the model lacks are left out here: spectrum() names them with their test.
  std::vector<int> dofs = joint_dof_set(joints, sub.dofs());
  const int K = std::max(1, *std::max_element(o.harmonics.begin(), o.harmonics.end()));
  double f_max = 0.0; // the highest frequency an equation uses
  for (const auto& m : measurements) {
    if (!m.left_out.empty()) continue;
    f_max = std::max(f_max, m.frequency_hz * (m.lines.empty() ? K : m.lines.back()));
    for (const auto& at : m.force_at)
      if (sub.dofs().state(at) == fem::DofMap::State::free) {
        const int e = sub.dofs().equation(at);
        if (std::find(dofs.begin(), dofs.end(), e) == dofs.end()) dofs.push_back(e);
      }
  }
  std::vector<std::string> notes;
  const frf::ModalSynthesis synthesis =
      sub.synthesis(dofs, frf::synthesis_band_hz(f_max, 1), &notes);
  if (!synthesis.status().ok()) {
    FitResult failed;
    failed.status = synthesis.status();
    failed.warnings = std::move(notes);
    return failed;
  }
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
  m.average_periods = o.average_periods;
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
    if (!m.left_out.empty()) continue; // its warning says why
    // Response channels on DOFs the model does not have, or holds fixed, are not used: said.
    for (std::size_t r = 0; r < m.response_at.size(); ++r) {
      const std::string why = dofs.why_not_free(m.response_at[r]);
      if (why.empty()) continue;
      warnings.push_back(fmt::format("{}: channel {}@{}: {}; the channel is not used", m.source,
                                     quantity_letter(m.measured_as[r]),
                                     fem::to_string(m.response_at[r]), why));
    }
    tests.push_back(spectrum(m, dofs, joints, warnings));
    tables += m.fundamental_only ? 1 : 0;
  }
  if (tests.empty())
    throw std::invalid_argument("identify: every test is left out (" +
                                std::to_string(measurements.size()) + "; the warnings say why)");
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
