#pragma once
/// Internal to jointid_frf (not part of the API): the harmonic-balance equations at one
/// frequency, shared by HarmonicBalance::solve() and the frequency continuation.
#include "frf/harmonic_balance.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace jointid::frf::detail {

constexpr double two_pi = 2.0 * std::numbers::pi;

// A joint's smooth force g and its derivatives. Coulomb friction is left out when it is
// handled exactly (`width` = 0), else regularised as fc·tanh(ẏ/width).
inline void joint_force(const joints::Joint& j, double y, double v, double width, double& g,
                        double& gy, double& gv) {
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
  CMatrix Fk;    // (K+1) × n_forces: the force harmonics
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

/// Newton's method (least-norm steps where J is singular, backtracking) on R(z) = 0 at the
/// given load factor; true when |R| / |z| < options.tolerance. Counts into `iterations`.
bool newton(const Equations& equations, Eigen::VectorXd& z, double load,
            const HarmonicBalanceOptions& options, int& iterations, double& residual);

} // namespace jointid::frf::detail
