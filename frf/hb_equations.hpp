#pragma once
/// Internal to jointid_frf (not part of the API): the harmonic-balance equations at one
/// frequency, shared by HarmonicBalance::solve() and the frequency continuation.
#include "frf/harmonic_balance.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

namespace jointid::frf::detail {

constexpr double two_pi = 2.0 * std::numbers::pi;

// A joint's smooth force g and its derivatives at one time (the stability check's). Coulomb
// friction is left out when it is handled exactly (`width` = 0), else regularised as
// fc·tanh(ẏ/width), as in add_joint_forces() below.
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

// A joint's smooth force g and its derivatives at the n time samples y, ẏ, added to the
// columns of g (n × 3: g, ∂g/∂y, ∂g/∂ẏ). Coulomb friction is left out when it is handled
// exactly (`width` = 0), else regularised as fc·tanh(ẏ/width).
inline void add_joint_forces(const joints::Joint& j, const double* y, const double* v, int n,
                             double width, Eigen::MatrixXd& g) {
  const auto size = static_cast<std::size_t>(n);
  const std::span<const double> ys(y, size), vs(v, size);
  const std::span<double> gs(g.col(0).data(), size), gys(g.col(1).data(), size),
      gvs(g.col(2).data(), size);
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const double b = j.values[t];
    if (!joints::is_dry_friction(j.terms[t])) {
      joints::add_samples(j.terms[t], b, ys, vs, gs, gys, gvs);
      continue;
    }
    if (width == 0.0) continue;
    for (std::size_t i = 0; i < size; ++i) {
      const double th = std::tanh(vs[i] / width);
      gs[i] += b * th;
      gvs[i] += b * (1.0 - th * th) / width;
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
// force harmonics Λ packed the same way (N). residual() works in scratch arrays of its own
// (sized once): a Newton iteration allocates nothing, and one Equations serves one thread.
struct Equations {
  int K, nj, Nt;
  const std::vector<CMatrix>& Hyy;
  CMatrix HyF_F; // (K+1) × nj: H_yf(kω) F_k, the joints' response to the force alone
  CMatrix Fk;    // (K+1) × n_forces: the force harmonics
  const std::vector<joints::Joint>& joints;
  double width; // 0: friction exact
  std::vector<Friction> friction;
  // Per sample n: ∂y_n/∂z and ∂ẏ_n/∂z of one joint (Nt × (2K+1)), both stacked (2Nt × (2K+1),
  // one product gives y and ẏ), and the forward transform from samples to packed harmonics
  // ((2K+1) × Nt).
  const Eigen::MatrixXd &dy, &dv, &dyv, &forward;
  // cos(pθ_n) beside sin(pθ_n), p = 0 … 2K (Nt × (4K+2)): the harmonics of sample weights.
  const Eigen::MatrixXd& trig;
  double omega;

  struct Scratch {
    Eigen::VectorXd yv, harmonics, lambda, clamped;
    // At the point of the last residual(): per joint, g, ∂g/∂y, ∂g/∂ẏ at the samples (Nt × 3);
    // per friction joint, 1 where a sample sticks (Nt). jacobian() reads them.
    std::vector<Eigen::MatrixXd> g;
    std::vector<Eigen::VectorXd> stick;
    Eigen::MatrixXd weights; // (4K+2) × 2: cos and sin sums of the columns ∂g/∂y, ∂g/∂ẏ
    Eigen::MatrixXd E, D;
    Eigen::MatrixXcd G; // (K+1) × nj: the joint forces' harmonics
  };
  mutable Scratch work{};

  Scratch& scratch() const {
    if (work.yv.size() != 2 * Nt) {
      work.yv.resize(2 * Nt);
      work.lambda.resize(Nt), work.clamped.resize(Nt);
      work.g.assign(static_cast<std::size_t>(nj), Eigen::MatrixXd(Nt, 3));
      work.stick.assign(friction.size(), Eigen::VectorXd(Nt));
      work.harmonics.resize(m());
      work.weights.resize(2 * m(), 2);
      work.E.resize(m(), m()), work.D.resize(m(), m());
    }
    return work;
  }

  // D += forward · diag(w) · dy (rate = false) or forward · diag(w) · dv (rate = true): the
  // derivative of the harmonics of a signal w(t) y(t) or w(t) ẏ(t) with respect to the packed
  // harmonics of y, from the harmonics W_p = (1/Nt) Σ w(θ_n) e^{−ipθ_n}, p ≤ 2K, of the weights
  // (product-to-sum: a product of harmonics j and k has harmonics k ± j). O(Nt K + K²) instead
  // of O(Nt K²). `sums` = trigᵀ w, the column of the weight's cosine and sine sums.
  template <class Sums> void add_product(const Sums& sums, bool rate, Eigen::MatrixXd& D) const {
    Scratch& s = scratch();
    const double* cs = sums.data();
    const double* sn = cs + m();
    const double scale = 1.0 / Nt;
    auto Re = [&](int p) { return scale * cs[std::abs(p)]; };
    auto Im = [&](int p) { return p < 0 ? scale * sn[-p] : -scale * sn[p]; };
    // The columns of y's own harmonics: 0, cos jθ, −sin jθ.
    Eigen::MatrixXd& E = s.E;
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

  // Packed harmonics of joint j's smooth force (m) at z; its samples are kept for jacobian().
  void smooth_force(const Eigen::VectorXd& z, int j, Eigen::VectorXd& harmonics) const {
    Scratch& s = scratch();
    Eigen::MatrixXd& g = s.g[static_cast<std::size_t>(j)];
    s.yv.noalias() = dyv * z.segment(j * m(), m());
    g.setZero();
    add_joint_forces(joints[j], s.yv.data(), s.yv.data() + Nt, Nt, width, g);
    harmonics.noalias() = forward * g.col(0);
  }

  // Harmonics of the joints' forces (K+1) × nj at z, into G: the smooth forces (their samples
  // kept for jacobian()) and the exact friction forces (unknowns).
  void force_harmonics(const Eigen::VectorXd& z, Eigen::MatrixXcd& G) const {
    Scratch& s = scratch();
    G.resize(K + 1, nj);
    for (int j = 0; j < nj; ++j) {
      smooth_force(z, j, s.harmonics);
      G(0, j) = s.harmonics(0);
      for (int k = 1; k <= K; ++k)
        G(k, j) = Complex(s.harmonics(2 * k - 1), s.harmonics(2 * k));
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const int o = (nj + static_cast<int>(f)) * m(), j = friction[f].joint;
      G(0, j) += z(o);
      for (int k = 1; k <= K; ++k)
        G(k, j) += Complex(z(o + 2 * k - 1), z(o + 2 * k));
    }
  }
  Eigen::MatrixXcd forces(const Eigen::VectorXd& z) const {
    Eigen::MatrixXcd G;
    force_harmonics(z, G);
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

  // r = [z_Y − pack(H_yf F) + pack(H_yy G(z)); c (Λ − AFT[proj(λ + r ẏ)])], sized by the caller
  // (size()), and, if asked, its (generalised) Jacobian there (as jacobian()).
  void residual(const Eigen::VectorXd& z, double load, Eigen::VectorXd& r,
                Eigen::MatrixXd* J) const {
    Scratch& s = scratch();
    r = z;
    // Per joint a: its rows get Σ_b H_yy(kω)_ab G_b,k, with G_b the smooth force of joint b
    // plus its friction unknowns.
    Eigen::MatrixXcd& G = s.G;
    force_harmonics(z, G);
    for (int a = 0; a < nj; ++a) {
      const int o = a * m();
      for (int k = 0; k <= K; ++k) {
        Complex v = -load * HyF_F(k, a);
        for (int b = 0; b < nj; ++b)
          v += Hyy[k](a, b) * G(k, b);
        if (k == 0) {
          r(o) += v.real();
        } else {
          r(o + 2 * k - 1) += v.real();
          r(o + 2 * k) += v.imag();
        }
      }
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const Friction& fr = friction[f];
      const int o = (nj + static_cast<int>(f)) * m(), oy = fr.joint * m();
      s.lambda.noalias() = dy * z.segment(o, m());
      s.yv.tail(Nt).noalias() = dv * z.segment(oy, m());
      Eigen::VectorXd& stick = s.stick[f];
      for (int n = 0; n < Nt; ++n) {
        const double trial = s.lambda(n) + fr.r * s.yv(Nt + n);
        stick(n) = std::abs(trial) < fr.limit ? 1.0 : 0.0;
        s.clamped(n) = std::clamp(trial, -fr.limit, fr.limit);
      }
      s.harmonics.noalias() = forward * s.clamped;
      r.segment(o, m()) = fr.c * (z.segment(o, m()) - s.harmonics);
    }
    if (J) jacobian(*J);
  }

  // The (generalised) Jacobian of the residual at the point of the last residual() call, from
  // the samples it kept: Newton needs it only where it takes a step from.
  void jacobian(Eigen::MatrixXd& J) const {
    Scratch& s = scratch();
    J.setIdentity(size(), size());
    for (int b = 0; b < nj; ++b) {
      const Eigen::MatrixXd& g = s.g[static_cast<std::size_t>(b)];
      s.weights.noalias() = trig.transpose().lazyProduct(g.rightCols(2)); // small: no packing
      s.D.setZero();
      add_product(s.weights.col(0), false, s.D);
      add_product(s.weights.col(1), true, s.D);
      for (int a = 0; a < nj; ++a)
        add_coupling(J, a, b, b * m(), s.D);
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const Friction& fr = friction[f];
      const int o = (nj + static_cast<int>(f)) * m(), oy = fr.joint * m();
      for (int a = 0; a < nj; ++a)
        add_coupling(J, a, fr.joint, o, Eigen::MatrixXd::Identity(m(), m()));
      // c (I − P_stick) and −c r P'_stick
      s.weights.col(0).noalias() = trig.transpose() * s.stick[f];
      s.D.setZero();
      add_product(s.weights.col(0), false, s.D);
      J.block(o, o, m(), m()) = fr.c * (Eigen::MatrixXd::Identity(m(), m()) - s.D);
      s.D.setZero();
      add_product(s.weights.col(0), true, s.D);
      J.block(o, oy, m(), m()) = -fr.c * fr.r * s.D;
    }
  }

  Eigen::VectorXd residual(const Eigen::VectorXd& z, double load, Eigen::MatrixXd* J) const {
    Eigen::VectorXd r(size());
    if (J) J->resize(size(), size());
    residual(z, load, r, J);
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
