#include "fem/modal.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace jointid::fem {

double Modes::frequency_hz(int r) const {
  return omega(r) / (2.0 * std::numbers::pi);
}

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

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

// y = (K − σM)⁻¹ x by a supernodal CHOLMOD factorisation with 64-bit indices (K − σM is SPD
// for σ < λ_min).
class ShiftInvert {
public:
  using Scalar = double;
  // groups: the node of every equation; the fill-reducing ordering is computed on the nodes.
  ShiftInvert(const SparseMatrix& K, const SparseMatrix& M, std::vector<int> groups,
              const CholeskyOptions& options, SparseModalStats& stats)
      : K_(K), M_(M), groups_(std::move(groups)), llt_(options), stats_(stats) {}
  Eigen::Index rows() const { return K_.rows(); }
  Eigen::Index cols() const { return K_.cols(); }
  void set_shift(double sigma) {
    const SparseMatrix A = K_ - sigma * M_;
    auto start = std::chrono::steady_clock::now();
    stats_.factor = llt_.analyze(A, groups_);
    stats_.analyze_s = seconds_since(start);
    start = std::chrono::steady_clock::now();
    try {
      llt_.factorize(A);
    } catch (const std::domain_error&) {
      throw std::invalid_argument(
          "shift-invert: K - sigma*M is not positive definite for sigma = " +
          std::to_string(sigma) +
          " (the shift must lie below the lowest eigenvalue and M must "
          "be positive definite)");
    }
    stats_.factorize_s = seconds_since(start);
    stats_.cholesky_peak_bytes = llt_.peak_memory_bytes();
  }
  void perform_op(const double* x_in, double* y_out) const {
    const auto start = std::chrono::steady_clock::now();
    llt_.solve(x_in, y_out);
    ++stats_.solves;
    stats_.solve_s += seconds_since(start);
  }

private:
  const SparseMatrix& K_;
  const SparseMatrix& M_;
  std::vector<int> groups_;
  SparseCholesky llt_;
  SparseModalStats& stats_;
};

Modes sparse_modes_count(const Assembled& s, const ModalOptions& o, int nev) {
  const int n = s.dofs.num_equations();
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  Modes out;
  out.sparse = SparseModalStats{};
  SparseModalStats& stats = *out.sparse;
  ShiftInvert op(s.K, s.M, s.dofs.equation_nodes(), o.cholesky, stats);
  Spectra::SparseSymMatProd<double> bop(s.M);
  const int ncv = std::min(n, std::max(2 * nev + 1, nev + 20));
  stats.ncv = ncv;
  Spectra::SymGEigsShiftSolver<ShiftInvert, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, bop, nev, ncv, sigma);
  const auto start = std::chrono::steady_clock::now();
  solver.init();
  solver.compute(Spectra::SortRule::LargestMagn, o.max_iterations, o.tolerance,
                 Spectra::SortRule::SmallestAlge);
  stats.lanczos_s = seconds_since(start);
  stats.restarts = static_cast<int>(solver.num_iterations());
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
