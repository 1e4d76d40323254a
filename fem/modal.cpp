#include "fem/modal.hpp"

#include <Eigen/Cholesky>
#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace jointid::fem {

double Modes::frequency_hz(int r) const {
  return omega(r) / (2.0 * std::numbers::pi);
}

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

double to_omega(double lambda) {
  return std::sqrt(std::max(lambda, 0.0));
}

Modes dense_modes(const Assembled& s, const ModalOptions& o) {
  const Eigen::MatrixXd K(s.K), M(s.M);
  Modes out;
  // Eigen's generalised solver factorises M without checking the factorisation (3.4), so a
  // massless DOF would come back as "success" with an infinite frequency: check M first.
  if (Eigen::LLT<Eigen::MatrixXd>(M).info() != Eigen::Success) {
    out.status = ModalStatus::numerical_issue; // M not positive definite
    return out;
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(K, M);
  if (solver.info() != Eigen::Success) {
    out.status = ModalStatus::numerical_issue;
    return out;
  }
  const Eigen::VectorXd& lambda = solver.eigenvalues();
  const int n = static_cast<int>(lambda.size());
  int count = o.num_modes > 0 ? std::min(o.num_modes, n) : n;
  if (o.max_frequency_hz > 0.0) {
    count = 0;
    while (count < n && to_omega(lambda(count)) < two_pi * o.max_frequency_hz)
      ++count;
  }
  out.omega = lambda.head(count).unaryExpr(&to_omega);
  out.phi = solver.eigenvectors().leftCols(count);
  return out;
}

// y = (K − σM)⁻¹ x by a supernodal CHOLMOD factorisation (K − σM is SPD for σ < λ_min).
class CholmodShiftInvert {
public:
  using Scalar = double;
  CholmodShiftInvert(const SparseMatrix& K, const SparseMatrix& M) : K_(K), M_(M) {}
  Eigen::Index rows() const { return K_.rows(); }
  Eigen::Index cols() const { return K_.cols(); }
  void set_shift(double sigma) {
    const SparseMatrix A = K_ - sigma * M_;
    llt_.analyzePattern(A);
    // Eigen's CHOLMOD wrapper uses 32-bit indices: a factor with more nonzeros than that
    // cannot be formed (CHOLMOD would overflow and crash). Its symbolic analysis predicts the
    // size, so say so instead.
    const double factor_nonzeros = llt_.cholmod().lnz;
    if (factor_nonzeros > 0.9 * std::numeric_limits<int>::max())
      throw std::invalid_argument(
          "sparse modal analysis: the Cholesky factor of K - sigma*M would have " +
          std::to_string(static_cast<long long>(factor_nonzeros)) + " nonzeros (about " +
          std::to_string(static_cast<long long>(factor_nonzeros * 8.0 / (1 << 30))) +
          " GiB), beyond the 32-bit indices of the CHOLMOD interface; the model is too large for "
          "this engine");
    llt_.factorize(A);
    if (llt_.info() != Eigen::Success)
      throw std::invalid_argument(
          "shift-invert: K - sigma*M is not positive definite for sigma = " +
          std::to_string(sigma) +
          " (the shift must lie below the lowest eigenvalue "
          "and M must be positive definite)");
  }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = llt_.solve(x);
  }

private:
  const SparseMatrix& K_;
  const SparseMatrix& M_;
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt_;
};

Modes sparse_modes_count(const Assembled& s, const ModalOptions& o, int nev) {
  const int n = s.dofs.num_equations();
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  CholmodShiftInvert op(s.K, s.M);
  Spectra::SparseSymMatProd<double> bop(s.M);
  const int ncv = std::min(n, std::max(2 * nev + 1, nev + 20));
  Spectra::SymGEigsShiftSolver<CholmodShiftInvert, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, bop, nev, ncv, sigma);
  solver.init();
  solver.compute(Spectra::SortRule::LargestMagn, o.max_iterations, o.tolerance,
                 Spectra::SortRule::SmallestAlge);
  Modes out;
  if (solver.info() != Spectra::CompInfo::Successful) {
    out.status = ModalStatus::not_converging;
    return out;
  }
  out.omega = solver.eigenvalues().unaryExpr(&to_omega);
  out.phi = solver.eigenvectors();
  return out;
}

Modes sparse_modes(const Assembled& s, const ModalOptions& o) {
  const int n = s.dofs.num_equations();
  if (o.max_frequency_hz <= 0.0) return sparse_modes_count(s, o, o.num_modes);
  // Every mode below f_max: grow the count until the highest mode found lies above f_max.
  int nev = std::max(o.num_modes, 8);
  while (true) {
    nev = std::min(nev, n - 1);
    Modes m = sparse_modes_count(s, o, nev);
    if (m.status != ModalStatus::success) return m;
    const double omega_max = two_pi * o.max_frequency_hz;
    if (m.omega(m.num_modes() - 1) >= omega_max || nev == n - 1) {
      int count = 0;
      while (count < m.num_modes() && m.omega(count) < omega_max)
        ++count;
      m.omega.conservativeResize(count);
      m.phi.conservativeResize(Eigen::NoChange, count);
      return m;
    }
    nev *= 2;
  }
}

} // namespace

Modes modal_analysis(const Assembled& s, const ModalOptions& o) {
  const int n = s.dofs.num_equations();
  if (o.num_modes < 0) throw std::invalid_argument("num_modes must be >= 0");
  if (o.max_frequency_hz <= 0.0 && o.num_modes > n)
    throw std::invalid_argument("asked for " + std::to_string(o.num_modes) +
                                " modes but the model has only " + std::to_string(n) +
                                " free DOFs");
  ModalEngine engine = o.engine;
  if (engine == ModalEngine::automatic)
    engine = n <= o.dense_limit ? ModalEngine::dense : ModalEngine::sparse;
  if (engine == ModalEngine::sparse) {
    if (o.max_frequency_hz <= 0.0 && (o.num_modes == 0 || o.num_modes >= n))
      throw std::invalid_argument("the sparse engine finds fewer modes than DOFs (" +
                                  std::to_string(n) +
                                  "); ask for fewer modes or use the dense engine");
    return sparse_modes(s, o);
  }
  return dense_modes(s, o);
}

} // namespace jointid::fem
