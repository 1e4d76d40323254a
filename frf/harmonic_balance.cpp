#include "frf/harmonic_balance.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

// A joint's force g and its derivatives, Coulomb friction regularised as fc·tanh(ẏ/width).
void joint_force(const joints::Joint& j, double y, double v, double width, double& g, double& gy,
                 double& gv) {
  g = gy = gv = 0.0;
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const double b = j.values[t];
    if (joints::is_dry_friction(j.terms[t])) {
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

// The equations of one solve. Unknowns z, per joint j, at offset j (2K + 1): Re Y_0, then
// Re Y_k, Im Y_k for k = 1 … K.
struct Equations {
  int K, nj, Nt;
  const std::vector<CMatrix>& Hyy;
  CMatrix HyF_F; // (K+1) × nj: H_yf(kω) F_k, the joints' response to the force alone
  const std::vector<joints::Joint>& joints;
  double width;
  // Per sample n: ∂y_n/∂z and ∂ẏ_n/∂z of one joint (Nt × (2K+1)), and the forward transform
  // from samples to packed harmonics ((2K+1) × Nt).
  const Eigen::MatrixXd& dy, &dv, &forward;

  int size() const { return nj * (2 * K + 1); }

  Eigen::MatrixXcd unpack(const Eigen::VectorXd& z) const {
    Eigen::MatrixXcd Y(K + 1, nj);
    for (int j = 0; j < nj; ++j) {
      const int o = j * (2 * K + 1);
      Y(0, j) = z(o);
      for (int k = 1; k <= K; ++k)
        Y(k, j) = Complex(z(o + 2 * k - 1), z(o + 2 * k));
    }
    return Y;
  }
  Eigen::VectorXd pack(const Eigen::MatrixXcd& Y) const {
    Eigen::VectorXd z(size());
    for (int j = 0; j < nj; ++j) {
      const int o = j * (2 * K + 1);
      z(o) = Y(0, j).real();
      for (int k = 1; k <= K; ++k)
        z(o + 2 * k - 1) = Y(k, j).real(), z(o + 2 * k) = Y(k, j).imag();
    }
    return z;
  }

  // Harmonics of the joint forces (K+1) × nj and, if asked, their derivatives with respect to
  // the joint's own unknowns (one (2K+1) × (2K+1) block per joint, packed like z).
  Eigen::MatrixXcd forces(const Eigen::VectorXd& z, std::vector<Eigen::MatrixXd>* dG) const {
    const int m = 2 * K + 1;
    Eigen::MatrixXcd G(K + 1, nj);
    Eigen::VectorXd g(Nt), gy(Nt), gv(Nt);
    for (int j = 0; j < nj; ++j) {
      const Eigen::VectorXd zj = z.segment(j * m, m);
      const Eigen::VectorXd y = dy * zj, v = dv * zj;
      for (int n = 0; n < Nt; ++n)
        joint_force(joints[j], y(n), v(n), width, g(n), gy(n), gv(n));
      const Eigen::VectorXd Gp = forward * g;
      G(0, j) = Gp(0);
      for (int k = 1; k <= K; ++k)
        G(k, j) = Complex(Gp(2 * k - 1), Gp(2 * k));
      if (dG)
        (*dG)[j] = forward * (gy.asDiagonal() * dy + gv.asDiagonal() * dv);
    }
    return G;
  }

  // R = z − pack(H_yf F) + pack(H_yy G(z)), and its Jacobian J = I + ∂pack(H_yy G)/∂z.
  Eigen::VectorXd residual(const Eigen::VectorXd& z, double load, Eigen::MatrixXd* J) const {
    std::vector<Eigen::MatrixXd> dG(J ? nj : 0);
    const Eigen::MatrixXcd G = forces(z, J ? &dG : nullptr);
    Eigen::MatrixXcd R(K + 1, nj);
    for (int k = 0; k <= K; ++k)
      R.row(k) = -load * HyF_F.row(k) + (Hyy[k] * G.row(k).transpose()).transpose();
    Eigen::VectorXd r = z + pack(R);
    if (J) {
      const int m = 2 * K + 1;
      J->setIdentity(size(), size());
      for (int a = 0; a < nj; ++a)
        for (int b = 0; b < nj; ++b)
          for (int k = 0; k <= K; ++k) {
            const Complex h = Hyy[k](a, b);
            if (k == 0) { // the mean is real
              J->block(a * m, b * m, 1, m) += h.real() * dG[b].row(0);
              continue;
            }
            const auto re = dG[b].row(2 * k - 1), im = dG[b].row(2 * k);
            J->block(a * m + 2 * k - 1, b * m, 1, m) += h.real() * re - h.imag() * im;
            J->block(a * m + 2 * k, b * m, 1, m) += h.imag() * re + h.real() * im;
          }
    }
    return r;
  }
};

bool newton(const Equations& P, Eigen::VectorXd& z, double load, const HarmonicBalanceOptions& o,
            int& iterations, double& res_norm) {
  const int n = P.size();
  Eigen::MatrixXd J(n, n);
  Eigen::VectorXd r = P.residual(z, load, &J);
  for (int it = 0; it < o.max_iterations; ++it) {
    ++iterations;
    res_norm = r.norm() / std::max(z.norm(), 1e-300);
    if (res_norm < o.tolerance) return true;
    const Eigen::VectorXd step = J.partialPivLu().solve(-r);
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
  res_norm = r.norm() / std::max(z.norm(), 1e-300);
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
  Nt_ = o.time_samples > 0 ? o.time_samples : 32 * (K_ + 1);
  frequency_hz_ = frequency_hz;
  omega_ = two_pi * frequency_hz;
  for (const auto& j : joints)
    layout_.push_back({j.node, j.node_b, j.dof});
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
  // Sample tables of one joint's deformation and rate: y_n = dy z, ẏ_n = dv z.
  const int m = 2 * K_ + 1;
  Eigen::MatrixXd dy(Nt_, m), dv(Nt_, m), forward(m, Nt_);
  for (int n = 0; n < Nt_; ++n) {
    const double theta = two_pi * n / Nt_;
    dy(n, 0) = 1.0;
    dv(n, 0) = 0.0;
    forward(0, n) = 1.0 / Nt_;
    for (int k = 1; k <= K_; ++k) {
      const double c = std::cos(k * theta), s = std::sin(k * theta);
      dy(n, 2 * k - 1) = c, dy(n, 2 * k) = -s;
      dv(n, 2 * k - 1) = -k * omega_ * s, dv(n, 2 * k) = -k * omega_ * c;
      forward(2 * k - 1, n) = 2.0 * c / Nt_, forward(2 * k, n) = -2.0 * s / Nt_;
    }
  }
  CMatrix Fk = CMatrix::Zero(K_ + 1, nf_);
  Fk.topRows(std::min<Eigen::Index>(F.rows(), K_ + 1)) =
      F.topRows(std::min<Eigen::Index>(F.rows(), K_ + 1));
  Fk.row(0) = Fk.row(0).real().cast<Complex>().eval(); // a mean force is real
  CMatrix HyF_F(K_ + 1, nj_);
  for (int k = 0; k <= K_; ++k)
    HyF_F.row(k) = (HyF_[k] * Fk.row(k).transpose()).transpose();
  const Equations P{K_,  nj_, Nt_, Hyy_, HyF_F, joints, options_.friction_width, dy, dv,
                    forward};

  HarmonicBalanceResult out;
  out.frequency_hz = frequency_hz_;
  Eigen::VectorXd z;
  if (start) {
    if (start->rows() != K_ + 1 || start->cols() != nj_)
      throw std::invalid_argument("harmonic balance: the start has the wrong shape");
    z = P.pack(*start);
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
    z = P.pack(Y);
  }
  const Eigen::VectorXd z_start = z;
  out.converged = newton(P, z, 1.0, options_, out.iterations, out.residual);
  if (!out.converged) { // load continuation from a small, nearly linear level
    const int steps = std::max(1, options_.continuation_steps);
    z = z_start / steps;
    out.converged = true;
    for (int s = 1; s <= steps && out.converged; ++s)
      out.converged = newton(P, z, static_cast<double>(s) / steps, options_, out.iterations,
                             out.residual);
  }
  out.Y = P.unpack(z);
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
