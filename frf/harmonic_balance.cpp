#include "frf/harmonic_balance.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

// A joint's smooth force g and its derivatives. Coulomb friction is left out when it is
// handled exactly (`width` = 0), else regularised as fc·tanh(ẏ/width).
void joint_force(const joints::Joint& j, double y, double v, double width, double& g, double& gy,
                 double& gv) {
  g = gy = gv = 0.0;
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const double b = j.values[t];
    if (joints::is_dry_friction(j.terms[t])) {
      if (width == 0.0) continue;
      const double th = std::tanh(v / width);
      g += b * th;
      gv += b * (1.0 - th * th) / width;
    } else {
      g += b * joints::basis(j.terms[t], y, v);
      gy += b * joints::basis_dy(j.terms[t], y, v);
      gv += b * joints::basis_dydot(j.terms[t], y, v);
    }
  }
}

// A joint with exact dry friction: its limit, its augmentation r (N s/m) and a compliance c
// (m/N) that puts its residual rows in metres like the others.
struct Friction {
  int joint;
  double limit, r, c;
};

// The equations of one solve. Unknowns z: per joint j, at offset j (2K + 1), Re Y_0, then
// Re Y_k, Im Y_k for k = 1 … K; then per friction joint f, at offset (nj + f)(2K + 1), its
// force harmonics Λ packed the same way (N).
struct Equations {
  int K, nj, Nt;
  const std::vector<CMatrix>& Hyy;
  CMatrix HyF_F; // (K+1) × nj: H_yf(kω) F_k, the joints' response to the force alone
  const std::vector<joints::Joint>& joints;
  double width; // 0: friction exact
  std::vector<Friction> friction;
  // Per sample n: ∂y_n/∂z and ∂ẏ_n/∂z of one joint (Nt × (2K+1)), and the forward transform
  // from samples to packed harmonics ((2K+1) × Nt).
  const Eigen::MatrixXd &dy, &dv, &forward;
  // cos(pθ_n) and sin(pθ_n), p = 0 … 2K, for the harmonics of sample weights (Nt × (2K+1)).
  const Eigen::MatrixXd &cos2, &sin2;
  double omega;

  // forward · diag(wy) · dy + forward · diag(wv) · dv, the derivative of the harmonics of a
  // signal w_y(t) y(t) + w_v(t) ẏ(t) with respect to the packed harmonics of y, from the
  // harmonics W_p = (1/Nt) Σ w(θ_n) e^{−ipθ_n}, p ≤ 2K, of the weights (product-to-sum: a
  // product of harmonics j and k has harmonics k ± j). O(Nt K + K²) instead of O(Nt K²).
  Eigen::MatrixXd product(const Eigen::VectorXd* wy, const Eigen::VectorXd* wv) const {
    const int M = m();
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(M, M);
    auto add = [&](const Eigen::VectorXd& w, bool rate) {
      const Eigen::VectorXd re = cos2.transpose() * w / Nt, im = -(sin2.transpose() * w) / Nt;
      auto Re = [&](int p) { return re(std::abs(p)); };
      auto Im = [&](int p) { return p < 0 ? -im(-p) : im(p); };
      // The columns of y's own harmonics: 0, cos jθ, −sin jθ.
      Eigen::MatrixXd E(M, M);
      E(0, 0) = Re(0);
      for (int j = 1; j <= K; ++j)
        E(0, 2 * j - 1) = Re(j), E(0, 2 * j) = Im(j);
      for (int k = 1; k <= K; ++k) {
        E(2 * k - 1, 0) = 2.0 * Re(k);
        E(2 * k, 0) = 2.0 * Im(k);
        for (int j = 1; j <= K; ++j) {
          E(2 * k - 1, 2 * j - 1) = Re(k - j) + Re(k + j);
          E(2 * k - 1, 2 * j) = Im(k + j) - Im(k - j);
          E(2 * k, 2 * j - 1) = Im(k + j) + Im(k - j);
          E(2 * k, 2 * j) = Re(k - j) - Re(k + j);
        }
      }
      if (!rate) {
        D += E;
        return;
      }
      // ẏ's columns: d/dt cos jθ = jω (−sin jθ), d/dt (−sin jθ) = −jω cos jθ.
      for (int j = 1; j <= K; ++j) {
        D.col(2 * j - 1) += j * omega * E.col(2 * j);
        D.col(2 * j) -= j * omega * E.col(2 * j - 1);
      }
    };
    if (wy) add(*wy, false);
    if (wv) add(*wv, true);
    return D;
  }

  int m() const { return 2 * K + 1; }
  int size() const { return (nj + static_cast<int>(friction.size())) * m(); }

  Eigen::MatrixXcd unpack(const Eigen::VectorXd& z, int blocks, int first = 0) const {
    Eigen::MatrixXcd Y(K + 1, blocks);
    for (int j = 0; j < blocks; ++j) {
      const int o = (first + j) * m();
      Y(0, j) = z(o);
      for (int k = 1; k <= K; ++k)
        Y(k, j) = Complex(z(o + 2 * k - 1), z(o + 2 * k));
    }
    return Y;
  }
  void pack(const Eigen::MatrixXcd& Y, Eigen::VectorXd& z, int first = 0) const {
    for (int j = 0; j < Y.cols(); ++j) {
      const int o = (first + j) * m();
      z(o) = Y(0, j).real();
      for (int k = 1; k <= K; ++k)
        z(o + 2 * k - 1) = Y(k, j).real(), z(o + 2 * k) = Y(k, j).imag();
    }
  }

  // Harmonics of the joints' smooth forces (K+1) × nj and, if asked, their derivatives with
  // respect to the joint's own unknowns (one (2K+1) × (2K+1) block per joint, packed like z).
  Eigen::MatrixXcd forces(const Eigen::VectorXd& z, std::vector<Eigen::MatrixXd>* dG) const {
    Eigen::MatrixXcd G(K + 1, nj);
    Eigen::VectorXd g(Nt), gy(Nt), gv(Nt);
    for (int j = 0; j < nj; ++j) {
      const Eigen::VectorXd zj = z.segment(j * m(), m());
      const Eigen::VectorXd y = dy * zj, v = dv * zj;
      for (int n = 0; n < Nt; ++n)
        joint_force(joints[j], y(n), v(n), width, g(n), gy(n), gv(n));
      const Eigen::VectorXd Gp = forward * g;
      G(0, j) = Gp(0);
      for (int k = 1; k <= K; ++k)
        G(k, j) = Complex(Gp(2 * k - 1), Gp(2 * k));
      if (dG) (*dG)[j] = product(&gy, &gv);
    }
    for (std::size_t f = 0; f < friction.size(); ++f) // exact friction forces, as unknowns
      G.col(friction[f].joint) += unpack(z, 1, nj + static_cast<int>(f)).col(0);
    return G;
  }

  // Adds ∂pack(H_yy(kω) G_k)/∂(unknowns of joint b's force) = `d` (packed rows) to the rows of
  // joint a, columns `col`.
  void add_coupling(Eigen::MatrixXd& J, int a, int b, int col, const Eigen::MatrixXd& d) const {
    for (int k = 0; k <= K; ++k) {
      const Complex h = Hyy[k](a, b);
      if (k == 0) { // the mean is real
        J.block(a * m(), col, 1, m()) += h.real() * d.row(0);
        continue;
      }
      const auto re = d.row(2 * k - 1), im = d.row(2 * k);
      J.block(a * m() + 2 * k - 1, col, 1, m()) += h.real() * re - h.imag() * im;
      J.block(a * m() + 2 * k, col, 1, m()) += h.imag() * re + h.real() * im;
    }
  }

  // R = [z_Y − pack(H_yf F) + pack(H_yy G(z)); c (Λ − AFT[proj(λ + r ẏ)])] and its
  // (generalised) Jacobian.
  Eigen::VectorXd residual(const Eigen::VectorXd& z, double load, Eigen::MatrixXd* J) const {
    std::vector<Eigen::MatrixXd> dG(J ? nj : 0);
    const Eigen::MatrixXcd G = forces(z, J ? &dG : nullptr);
    Eigen::MatrixXcd R(K + 1, nj);
    for (int k = 0; k <= K; ++k)
      R.row(k) = -load * HyF_F.row(k) + (Hyy[k] * G.row(k).transpose()).transpose();
    Eigen::VectorXd r = z;
    Eigen::VectorXd packed(nj * m());
    pack(R, packed);
    r.head(nj * m()) += packed;
    if (J) {
      J->setIdentity(size(), size());
      for (int a = 0; a < nj; ++a)
        for (int b = 0; b < nj; ++b)
          add_coupling(*J, a, b, b * m(), dG[b]);
      const Eigen::MatrixXd unit = Eigen::MatrixXd::Identity(m(), m());
      for (std::size_t f = 0; f < friction.size(); ++f)
        for (int a = 0; a < nj; ++a)
          add_coupling(*J, a, friction[f].joint, (nj + static_cast<int>(f)) * m(), unit);
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const Friction& fr = friction[f];
      const int o = (nj + static_cast<int>(f)) * m(), oy = fr.joint * m();
      const Eigen::VectorXd lambda = dy * z.segment(o, m()), v = dv * z.segment(oy, m());
      Eigen::VectorXd p(Nt), stick(Nt);
      for (int n = 0; n < Nt; ++n) {
        const double trial = lambda(n) + fr.r * v(n);
        stick(n) = std::abs(trial) < fr.limit ? 1.0 : 0.0;
        p(n) = std::clamp(trial, -fr.limit, fr.limit);
      }
      r.segment(o, m()) = fr.c * (z.segment(o, m()) - forward * p);
      if (J) {
        J->block(o, o, m(), m()) =
            fr.c * (Eigen::MatrixXd::Identity(m(), m()) - product(&stick, nullptr));
        J->block(o, oy, m(), m()) = -fr.c * fr.r * product(nullptr, &stick);
      }
    }
    return r;
  }

  // |z| with the force unknowns in metres (through each friction joint's compliance).
  double norm(const Eigen::VectorXd& z) const {
    double s = z.head(nj * m()).squaredNorm();
    for (std::size_t f = 0; f < friction.size(); ++f)
      s += std::pow(friction[f].c, 2) *
           z.segment((nj + static_cast<int>(f)) * m(), m()).squaredNorm();
    return std::sqrt(s);
  }
};

bool newton(const Equations& P, Eigen::VectorXd& z, double load, const HarmonicBalanceOptions& o,
            int& iterations, double& res_norm) {
  const int n = P.size();
  Eigen::MatrixXd J(n, n);
  Eigen::VectorXd r = P.residual(z, load, &J);
  for (int it = 0; it < o.max_iterations; ++it) {
    ++iterations;
    res_norm = r.norm() / std::max(P.norm(z), 1e-300);
    if (res_norm < o.tolerance) return true;
    // A friction joint stuck for the whole period leaves its mean position and mean force a
    // one-parameter family: J is singular. Take the least-norm step there.
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(J);
    Eigen::VectorXd step;
    if (lu.isInvertible()) {
      step = lu.solve(-r);
    } else {
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(J);
      cod.setThreshold(1e-13);
      step = cod.solve(-r);
    }
    double t = 1.0;
    bool improved = false;
    for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
      const Eigen::VectorXd zt = z + t * step;
      const Eigen::VectorXd rt = P.residual(zt, load, nullptr);
      if (rt.allFinite() && rt.norm() < r.norm()) {
        z = zt, improved = true;
        break;
      }
    }
    if (!improved) return res_norm < o.tolerance;
    r = P.residual(z, load, &J);
  }
  res_norm = r.norm() / std::max(P.norm(z), 1e-300);
  return res_norm < o.tolerance;
}

} // namespace

Eigen::MatrixXcd sine_force(double amplitude) {
  Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(2, 1);
  F(1, 0) = Complex(0.0, -amplitude); // F0 sin ωt = Re(−i F0 e^{iωt})
  return F;
}

double HarmonicBalanceResult::displacement(int j, double t) const {
  const double omega = two_pi * frequency_hz;
  double x = X(0, j).real();
  for (int k = 1; k < X.rows(); ++k)
    x += (X(k, j) * std::polar(1.0, k * omega * t)).real();
  return x;
}

double HarmonicBalanceResult::velocity(int j, double t) const {
  const double omega = two_pi * frequency_hz;
  double v = 0.0;
  for (int k = 1; k < X.rows(); ++k)
    v += (Complex(0.0, k * omega) * X(k, j) * std::polar(1.0, k * omega * t)).real();
  return v;
}

HarmonicBalance::HarmonicBalance(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                                 const fem::DofMap& dofs, std::vector<int> force_equations,
                                 std::vector<int> outputs, double frequency_hz,
                                 const HarmonicBalanceOptions& o)
    : options_(o) {
  if (o.harmonics < 1) throw std::invalid_argument("harmonic balance: need at least 1 harmonic");
  if (!(frequency_hz > 0.0))
    throw std::invalid_argument("harmonic balance: frequency must be > 0 Hz");
  if (!(o.friction_width > 0.0))
    throw std::invalid_argument("harmonic balance: friction_width must be > 0");
  if (o.time_samples != 0 && o.time_samples < 2 * o.harmonics + 2)
    throw std::invalid_argument("harmonic balance: time_samples must be 0 or > 2 harmonics + 1");
  K_ = o.harmonics;
  nj_ = static_cast<int>(joints.size());
  nf_ = static_cast<int>(force_equations.size());
  Nt_ = o.time_samples > 0 ? o.time_samples : 16 * (K_ + 1);
  frequency_hz_ = frequency_hz;
  omega_ = two_pi * frequency_hz;
  for (const auto& j : joints)
    layout_.push_back({j.node, j.node_b, j.dof});
  // Sample tables of one joint's deformation and rate, y_n = dy z and ẏ_n = dv z, and the
  // transform from samples to packed harmonics.
  const int m = 2 * K_ + 1;
  dy_.resize(Nt_, m), dv_.resize(Nt_, m), forward_.resize(m, Nt_);
  for (int n = 0; n < Nt_; ++n) {
    const double theta = two_pi * n / Nt_;
    dy_(n, 0) = 1.0;
    dv_(n, 0) = 0.0;
    forward_(0, n) = 1.0 / Nt_;
    for (int k = 1; k <= K_; ++k) {
      const double c = std::cos(k * theta), s = std::sin(k * theta);
      dy_(n, 2 * k - 1) = c, dy_(n, 2 * k) = -s;
      dv_(n, 2 * k - 1) = -k * omega_ * s, dv_(n, 2 * k) = -k * omega_ * c;
      forward_(2 * k - 1, n) = 2.0 * c / Nt_, forward_(2 * k, n) = -2.0 * s / Nt_;
    }
  }
  cos2_.resize(Nt_, 2 * K_ + 1), sin2_.resize(Nt_, 2 * K_ + 1);
  for (int n = 0; n < Nt_; ++n)
    for (int p = 0; p <= 2 * K_; ++p) {
      const double a = two_pi * (static_cast<long long>(p) * n % Nt_) / Nt_;
      cos2_(n, p) = std::cos(a), sin2_(n, p) = std::sin(a);
    }
  // Joint DOFs (node and node_b) and the B matrix restricted to them.
  const std::vector<int> jdofs = joints::joint_dof_set(joints, dofs);
  const Eigen::MatrixXcd B = joints::joint_coordinates_on(joints, dofs, jdofs).cast<Complex>();
  for (int k = 0; k <= K_; ++k) {
    const double w = k * omega_;
    Hyy_.push_back(B.transpose() * H.receptance(w, jdofs, jdofs) * B);
    HyF_.push_back(B.transpose() * H.receptance(w, jdofs, force_equations));
    HoB_.push_back(H.receptance(w, outputs, jdofs) * B);
    HoF_.push_back(H.receptance(w, outputs, force_equations));
  }
}

HarmonicBalanceResult HarmonicBalance::solve(const std::vector<joints::Joint>& joints,
                                             const Eigen::MatrixXcd& F,
                                             const Eigen::MatrixXcd* start) const {
  if (static_cast<int>(joints.size()) != nj_)
    throw std::invalid_argument("harmonic balance: the joints differ from the layout");
  for (int j = 0; j < nj_; ++j)
    if (joints[j].node != layout_[j].node || joints[j].node_b != layout_[j].node_b ||
        joints[j].dof != layout_[j].dof || joints[j].values.size() != joints[j].terms.size())
      throw std::invalid_argument("harmonic balance: joint '" + joints[j].name +
                                  "' differs from the layout it was set up for");
  if (F.cols() != nf_)
    throw std::invalid_argument("harmonic balance: " + std::to_string(F.cols()) +
                                " force columns for " + std::to_string(nf_) + " force equations");
  const Eigen::MatrixXd &dy = dy_, &dv = dv_, &forward = forward_;
  CMatrix Fk = CMatrix::Zero(K_ + 1, nf_);
  Fk.topRows(std::min<Eigen::Index>(F.rows(), K_ + 1)) =
      F.topRows(std::min<Eigen::Index>(F.rows(), K_ + 1));
  Fk.row(0) = Fk.row(0).real().cast<Complex>().eval(); // a mean force is real
  CMatrix HyF_F(K_ + 1, nj_);
  for (int k = 0; k <= K_; ++k)
    HyF_F.row(k) = (HyF_[k] * Fk.row(k).transpose()).transpose();
  const bool exact = options_.exact_friction;
  std::vector<Friction> friction;
  for (int j = 0; j < nj_; ++j) {
    const int t = joints[j].term_index(joints::Term::fc);
    if (t < 0 || !exact) continue;
    const double limit = joints[j].values[t];
    if (!(limit >= 0.0))
      throw std::invalid_argument("harmonic balance: joint '" + joints[j].name +
                                  "': Coulomb friction fc must be >= 0 N, got " +
                                  std::to_string(limit));
    // Scales: the joint's dynamic compliance at the fundamental, c = |H_yy(ω)_jj|, and r = 1 /
    // (ω c), so that r ẏ is a force of the size the structure's dynamic stiffness gives.
    const double c = std::max(std::abs(Hyy_[1](j, j)), 1e-300);
    friction.push_back({j, limit, 1.0 / (omega_ * c), c});
  }
  const Equations P{
      K_,       nj_, Nt_, Hyy_,    HyF_F, joints, exact ? 0.0 : options_.friction_width,
      friction, dy,  dv,  forward, cos2_, sin2_,  omega_};

  HarmonicBalanceResult out;
  out.frequency_hz = frequency_hz_;
  Eigen::VectorXd z;
  if (start) {
    if (start->rows() != K_ + 1 || start->cols() != nj_)
      throw std::invalid_argument("harmonic balance: the start has the wrong shape");
    z = Eigen::VectorXd::Zero(P.size());
    P.pack(*start, z);
  } else {
    // The linear response with the joints' linear terms (degree 1 in the term table).
    Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K_ + 1, nj_);
    for (int k = 0; k <= K_; ++k) {
      CMatrix D = CMatrix::Identity(nj_, nj_);
      for (int j = 0; j < nj_; ++j) {
        Complex lin = 0.0;
        for (std::size_t t = 0; t < joints[j].terms.size(); ++t) {
          const joints::TermInfo& info = joints::term_info(joints[j].terms[t]);
          if (info.degree != 1) continue;
          lin += info.nature == joints::Nature::conservative
                     ? Complex(joints[j].values[t])
                     : Complex(0.0, k * omega_) * joints[j].values[t];
        }
        D.col(j) += Hyy_[k].col(j) * lin;
      }
      Y.row(k) = D.partialPivLu().solve(HyF_F.row(k).transpose()).transpose();
    }
    Y.row(0) = Y.row(0).real().cast<Complex>().eval();
    z = Eigen::VectorXd::Zero(P.size());
    P.pack(Y, z);
  }
  // Friction forces to start. From a given start: what its motion demands of them, Λ = H_yy⁻¹
  // (H_yf F − Y) − G_smooth, which the projection then brings within ±fc (for a converged start,
  // its own friction forces). From the linear start: the slip law fc sign(ẏ) — that start
  // balances the force without friction, so it would demand Λ ≈ 0, every sample would then
  // stick wherever r|ẏ| < fc, and with every sample stuck the mean friction force is
  // indeterminate (a singular Jacobian: Newton fails at once, e.g. 10 N at 3 Hz on the paper's
  // cantilever with fc = 3 N).
  if (!friction.empty()) {
    const Eigen::MatrixXcd Y = P.unpack(z, nj_), G = P.forces(z, nullptr);
    for (int k = 0; k <= K_ && start; ++k) {
      const CVector need =
          Hyy_[k].fullPivLu().solve((HyF_F.row(k) - Y.row(k)).transpose()) - G.row(k).transpose();
      for (std::size_t f = 0; f < friction.size(); ++f) {
        Eigen::MatrixXcd L = P.unpack(z, 1, nj_ + static_cast<int>(f));
        L(k, 0) = k == 0 ? Complex(need(friction[f].joint).real()) : need(friction[f].joint);
        P.pack(L, z, nj_ + static_cast<int>(f));
      }
    }
    for (std::size_t f = 0; f < friction.size() && !start; ++f) {
      const Eigen::VectorXd v = dv * z.segment(friction[f].joint * (2 * K_ + 1), 2 * K_ + 1);
      Eigen::VectorXd slip(Nt_);
      for (int n = 0; n < Nt_; ++n)
        slip(n) = v(n) > 0.0 ? friction[f].limit : v(n) < 0.0 ? -friction[f].limit : 0.0;
      z.segment((nj_ + static_cast<int>(f)) * (2 * K_ + 1), 2 * K_ + 1) = forward * slip;
    }
  }
  const Eigen::VectorXd z_start = z;
  out.converged = newton(P, z, 1.0, options_, out.iterations, out.residual);
  if (!out.converged) { // load continuation from a small, nearly linear level
    const int steps = std::max(1, options_.continuation_steps);
    z = z_start / steps;
    out.converged = true;
    for (int s = 1; s <= steps && out.converged; ++s)
      out.converged =
          newton(P, z, static_cast<double>(s) / steps, options_, out.iterations, out.residual);
  }
  out.Y = P.unpack(z, nj_);
  out.G = P.forces(z, nullptr);
  out.X.resize(K_ + 1, HoB_.empty() ? 0 : HoB_[0].rows());
  for (int k = 0; k <= K_; ++k)
    out.X.row(k) =
        (HoF_[k] * Fk.row(k).transpose() - HoB_[k] * out.G.row(k).transpose()).transpose();
  return out;
}

HarmonicBalanceResult
harmonic_balance(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                 const fem::DofMap& dofs, int force_equation, double amplitude, double frequency_hz,
                 std::span<const int> outputs, const HarmonicBalanceOptions& o) {
  const HarmonicBalance problem(H, joints, dofs, {force_equation},
                                std::vector<int>(outputs.begin(), outputs.end()), frequency_hz, o);
  return problem.solve(joints, sine_force(amplitude));
}

} // namespace jointid::frf
