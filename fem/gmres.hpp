#pragma once
/// Restarted GMRES with a right preconditioner, for the large linear systems that are only
/// available as products (a periodic test's harmonic balance: its Jacobian is a convolution,
/// applied by FFT in O(n log n) where the dense matrix would take O(n²) memory and its
/// factorisation O(n³)). Saad's algorithm: Arnoldi with modified Gram–Schmidt on A M⁻¹, the
/// small least-squares problem by Givens rotations, x = x₀ + M⁻¹ V y at each restart.
#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace jointid::fem {

struct GmresOptions {
  double tolerance = 1e-8;  ///< on |b − A x| / |b|
  int restart = 60;         ///< Krylov vectors kept before a restart
  int max_iterations = 600; ///< products with A, over all restarts
};

struct GmresResult {
  bool converged = false;
  int iterations = 0;    ///< products with A
  double residual = 0.0; ///< |b − A x| / |b| (the recurrence's estimate at the end of a cycle)
};

/// Solves A x = b from the x given (its start), with `apply(v, out)`: out = A v, and
/// `precondition(v, out)`: out ≈ A⁻¹ v (M⁻¹; the identity where there is none). b = 0 gives
/// x = 0. The residual is checked against the true |b − A x| at every restart.
template <class Apply, class Precondition>
GmresResult gmres(Apply&& apply, Precondition&& precondition, const Eigen::VectorXd& b,
                  Eigen::VectorXd& x, const GmresOptions& o = {}) {
  GmresResult out;
  const Eigen::Index n = b.size();
  const double b_norm = b.norm();
  if (x.size() != n) x = Eigen::VectorXd::Zero(n);
  if (b_norm == 0.0) {
    x.setZero();
    out.converged = true;
    return out;
  }
  const int m = std::max(1, o.restart);
  Eigen::MatrixXd V(n, m + 1), H = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd r(n), w(n), z(n), g(m + 1), cs(m), sn(m);
  while (true) {
    apply(x, w);
    r = b - w;
    const double beta = r.norm();
    out.residual = beta / b_norm;
    if (out.residual <= o.tolerance) {
      out.converged = true;
      return out;
    }
    if (out.iterations >= o.max_iterations || !std::isfinite(beta)) return out;
    V.col(0) = r / beta;
    g.setZero(), g(0) = beta, H.setZero();
    int j = 0;
    for (; j < m && out.iterations < o.max_iterations; ++j) {
      precondition(V.col(j), z);
      apply(z, w);
      ++out.iterations;
      for (int i = 0; i <= j; ++i) { // modified Gram–Schmidt
        H(i, j) = V.col(i).dot(w);
        w -= H(i, j) * V.col(i);
      }
      H(j + 1, j) = w.norm();
      if (H(j + 1, j) > 0.0) V.col(j + 1) = w / H(j + 1, j);
      for (int i = 0; i < j; ++i) { // the earlier rotations on the new column
        const double t = cs(i) * H(i, j) + sn(i) * H(i + 1, j);
        H(i + 1, j) = -sn(i) * H(i, j) + cs(i) * H(i + 1, j);
        H(i, j) = t;
      }
      const double d = std::hypot(H(j, j), H(j + 1, j));
      cs(j) = d > 0.0 ? H(j, j) / d : 1.0, sn(j) = d > 0.0 ? H(j + 1, j) / d : 0.0;
      H(j, j) = d, H(j + 1, j) = 0.0;
      g(j + 1) = -sn(j) * g(j), g(j) *= cs(j);
      const bool breakdown = !(d > 0.0) || !(std::abs(g(j + 1)) > 0.0);
      if (std::abs(g(j + 1)) <= o.tolerance * b_norm || breakdown) {
        ++j;
        break;
      }
    }
    // y = H⁻¹ g (upper triangular j × j), x += M⁻¹ V y
    Eigen::VectorXd y = g.head(j);
    for (int i = j - 1; i >= 0; --i) {
      if (H(i, i) == 0.0) {
        y(i) = 0.0;
        continue;
      }
      for (int c = i + 1; c < j; ++c)
        y(i) -= H(i, c) * y(c);
      y(i) /= H(i, i);
    }
    w.noalias() = V.leftCols(j) * y;
    precondition(w, z);
    x += z;
    if (!x.allFinite()) return out;
  }
}

} // namespace jointid::fem
