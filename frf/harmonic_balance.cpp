#include "frf/harmonic_balance.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

double smooth_force(const joints::Joint& j, double y, double v, double width) {
  double g = 0.0;
  for (std::size_t t = 0; t < j.terms.size(); ++t)
    g += j.values[t] * (joints::is_dry_friction(j.terms[t]) ? std::tanh(v / width)
                                                            : joints::basis(j.terms[t], y, v));
  return g;
}

struct Problem {
  int K, nj, Nt;
  double omega;
  std::vector<CMatrix> Hyy; // per harmonic, nj × nj
  std::vector<CVector> HyF; // per harmonic, nj (response to the unit force harmonic)
  const std::vector<joints::Joint>* joints;
  double width;

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
  // Harmonics of the joint forces from the harmonics of the deformations (AFT).
  Eigen::MatrixXcd forces(const Eigen::MatrixXcd& Y) const {
    Eigen::MatrixXcd G = Eigen::MatrixXcd::Zero(K + 1, nj);
    for (int n = 0; n < Nt; ++n) {
      const double theta = two_pi * n / Nt;
      for (int j = 0; j < nj; ++j) {
        double y = Y(0, j).real(), v = 0.0;
        for (int k = 1; k <= K; ++k) {
          const Complex e = std::polar(1.0, k * theta);
          y += (Y(k, j) * e).real();
          v += (Complex(0.0, k * omega) * Y(k, j) * e).real();
        }
        const double g = smooth_force((*joints)[j], y, v, width);
        G(0, j) += g / Nt;
        for (int k = 1; k <= K; ++k)
          G(k, j) += 2.0 / Nt * g * std::polar(1.0, -k * theta);
      }
    }
    return G;
  }
  Eigen::VectorXd residual(const Eigen::VectorXd& z, double amplitude) const {
    const Eigen::MatrixXcd Y = unpack(z), G = forces(Y);
    Eigen::MatrixXcd R(K + 1, nj);
    for (int k = 0; k <= K; ++k) {
      const Complex Fk =
          k == 1 ? Complex(0.0, -amplitude) : Complex(0.0); // F0 sin ωt = Re(−i F0 e^{iωt})
      R.row(k) = (Y.row(k).transpose() - HyF[k] * Fk + Hyy[k] * G.row(k).transpose()).transpose();
    }
    Eigen::VectorXd r = pack(R);
    return r;
  }
};

bool newton(const Problem& P, Eigen::VectorXd& z, double amplitude, const HarmonicBalanceOptions& o,
            int& iterations, double& res_norm) {
  const int n = P.size();
  Eigen::VectorXd r = P.residual(z, amplitude);
  for (int it = 0; it < o.max_iterations; ++it) {
    ++iterations;
    const double scale = std::max(z.norm(), 1e-300);
    res_norm = r.norm() / scale;
    if (res_norm < o.tolerance) return true;
    Eigen::MatrixXd J(n, n);
    for (int c = 0; c < n; ++c) {
      const double dz = 1e-7 * std::max(std::abs(z(c)), 1e-6 * scale + 1e-12);
      Eigen::VectorXd zp = z;
      zp(c) += dz;
      J.col(c) = (P.residual(zp, amplitude) - r) / dz;
    }
    const Eigen::VectorXd step = J.fullPivLu().solve(-r);
    double t = 1.0;
    bool improved = false;
    for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
      const Eigen::VectorXd zt = z + t * step;
      const Eigen::VectorXd rt = P.residual(zt, amplitude);
      if (rt.norm() < r.norm()) {
        z = zt, r = rt, improved = true;
        break;
      }
    }
    if (!improved) return r.norm() / std::max(z.norm(), 1e-300) < o.tolerance;
  }
  res_norm = r.norm() / std::max(z.norm(), 1e-300);
  return res_norm < o.tolerance;
}

} // namespace

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

HarmonicBalanceResult
harmonic_balance(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                 const fem::DofMap& dofs, int force_equation, double amplitude, double frequency_hz,
                 std::span<const int> outputs, const HarmonicBalanceOptions& o) {
  if (o.harmonics < 1) throw std::invalid_argument("harmonic balance: need at least 1 harmonic");
  if (!(frequency_hz > 0.0))
    throw std::invalid_argument("harmonic balance: frequency must be > 0 Hz");
  if (!(o.friction_width > 0.0))
    throw std::invalid_argument("harmonic balance: friction_width must be > 0");
  Problem P;
  P.K = o.harmonics;
  P.nj = static_cast<int>(joints.size());
  P.Nt = o.time_samples > 0 ? o.time_samples : 32 * (o.harmonics + 1);
  P.omega = two_pi * frequency_hz;
  P.joints = &joints;
  P.width = o.friction_width;
  // Joint DOFs (node and node_b) and the B matrix restricted to them.
  const std::vector<int> jdofs = joints::joint_dof_set(joints, dofs);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, jdofs);
  const std::vector<int> force{force_equation};
  std::vector<CMatrix> HoB(P.K + 1);
  std::vector<CVector> HoF(P.K + 1);
  for (int k = 0; k <= P.K; ++k) {
    const double w = k * P.omega;
    const CMatrix Hjj = H.receptance(w, jdofs, jdofs), Hjf = H.receptance(w, jdofs, force);
    P.Hyy.push_back(B.transpose().cast<Complex>() * Hjj * B.cast<Complex>());
    P.HyF.push_back(B.transpose().cast<Complex>() * Hjf.col(0));
    HoB[k] = H.receptance(w, outputs, jdofs) * B.cast<Complex>();
    HoF[k] = H.receptance(w, outputs, force).col(0);
  }

  HarmonicBalanceResult out;
  out.frequency_hz = frequency_hz;
  // Start from the linear response of the substructure alone.
  Eigen::MatrixXcd Y0 = Eigen::MatrixXcd::Zero(P.K + 1, P.nj);
  Y0.row(1) = (P.HyF[1] * Complex(0.0, -amplitude)).transpose();
  Eigen::VectorXd z = P.pack(Y0);
  // Start from the linear response with the joints' linear terms.
  {
    CMatrix D = CMatrix::Identity(P.nj, P.nj);
    for (int j = 0; j < P.nj; ++j) {
      const auto& J = joints[j];
      Complex lin = 0.0;
      for (std::size_t t = 0; t < J.terms.size(); ++t) {
        if (J.terms[t] == joints::Term::k) lin += J.values[t];
        if (J.terms[t] == joints::Term::c) lin += Complex(0.0, P.omega) * J.values[t];
      }
      D.col(j) += P.Hyy[1].col(j) * lin;
    }
    Eigen::MatrixXcd Ylin = Eigen::MatrixXcd::Zero(P.K + 1, P.nj);
    Ylin.row(1) = D.partialPivLu().solve(P.HyF[1] * Complex(0.0, -amplitude)).transpose();
    z = P.pack(Ylin);
  }
  Eigen::VectorXd z_start = z;
  out.converged = newton(P, z, amplitude, o, out.iterations, out.residual);
  if (!out.converged) { // amplitude continuation from a small, nearly linear level
    z = z_start / o.continuation_steps;
    out.converged = true;
    for (int s = 1; s <= o.continuation_steps && out.converged; ++s)
      out.converged =
          newton(P, z, amplitude * s / o.continuation_steps, o, out.iterations, out.residual);
  }
  out.Y = P.unpack(z);
  const Eigen::MatrixXcd G = P.forces(out.Y);
  out.X.resize(P.K + 1, static_cast<int>(outputs.size()));
  for (int k = 0; k <= P.K; ++k) {
    const Complex Fk = k == 1 ? Complex(0.0, -amplitude) : Complex(0.0);
    out.X.row(k) = (HoF[k] * Fk - HoB[k] * G.row(k).transpose()).transpose();
  }
  return out;
}

} // namespace jointid::frf
