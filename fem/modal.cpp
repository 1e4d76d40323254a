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
// for σ < λ_min). Factorises once per shift: Spectra calls set_shift in every solver's
// constructor, and a frequency band may need several solvers with the same shift.
class ShiftInvert {
public:
  using Scalar = double;
  ShiftInvert(const Assembled& s, const ModalOptions& o, SparseModalStats& stats)
      : system_(s), options_(o), llt_(o.cholesky), stats_(stats) {}
  Eigen::Index rows() const { return system_.K.rows(); }
  Eigen::Index cols() const { return system_.K.cols(); }
  void set_shift(double sigma) {
    if (factorized_ && sigma == sigma_) return;
    factorized_ = false;
    const SparseMatrix A = system_.K - sigma * system_.M;
    auto start = std::chrono::steady_clock::now();
    // The ordering is computed on the nodes: a node's DOFs share one adjacency.
    stats_.factor = llt_.analyze(A, system_.dofs.equation_nodes());
    stats_.analyze_s = seconds_since(start);
    start = std::chrono::steady_clock::now();
    try {
      llt_.factorize(A);
    } catch (const NotPositiveDefinite& e) {
      const NodeDof at = system_.dofs.node_dof(static_cast<int>(e.equation()));
      throw std::invalid_argument(
          "sparse modal analysis: K + (2 pi " + std::to_string(options_.shift_hz) +
          " Hz)^2 M is not positive definite; the factorisation broke down at " + to_string(at) +
          ". Look there for a DOF with neither stiffness nor mass (e.g. a rotation no element "
          "or spring holds), or a negative mass or stiffness");
    }
    stats_.factorize_s = seconds_since(start);
    stats_.cholesky_peak_bytes = llt_.peak_memory_bytes();
    sigma_ = sigma;
    factorized_ = true;
  }
  void perform_op(const double* x_in, double* y_out) const {
    const auto start = std::chrono::steady_clock::now();
    llt_.solve(x_in, y_out);
    ++stats_.solves;
    stats_.solve_s += seconds_since(start);
  }

private:
  const Assembled& system_;
  const ModalOptions& options_;
  SparseCholesky llt_;
  SparseModalStats& stats_;
  double sigma_ = 0.0;
  bool factorized_ = false;
};

// The nev lowest modes with the factorisation held by `op`.
Modes sparse_modes_count(const Assembled& s, const ModalOptions& o, ShiftInvert& op,
                         SparseModalStats& stats, int nev) {
  const int n = s.dofs.num_equations();
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  Spectra::SparseSymMatProd<double> bop(s.M);
  const int ncv = std::min(n, std::max(2 * nev + 1, nev + 20));
  stats.ncv = ncv;
  stats.solves = 0;
  stats.solve_s = 0.0;
  Spectra::SymGEigsShiftSolver<ShiftInvert, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, bop, nev, ncv, sigma);
  const auto start = std::chrono::steady_clock::now();
  solver.init();
  solver.compute(Spectra::SortRule::LargestMagn, o.max_iterations, o.tolerance,
                 Spectra::SortRule::SmallestAlge);
  stats.lanczos_s = seconds_since(start);
  stats.restarts = static_cast<int>(solver.num_iterations());
  Modes out;
  out.sparse = stats;
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
  SparseModalStats stats;
  ShiftInvert op(s, o, stats);
  if (o.max_frequency_hz <= 0.0) return sparse_modes_count(s, o, op, stats, o.num_modes);
  // Every mode below f_max: grow the count until the highest mode found lies above f_max.
  // The factorisation is reused; only the Lanczos iteration is repeated.
  int nev = std::max(o.num_modes, 8);
  while (true) {
    nev = std::min(nev, n - 1);
    Modes m = sparse_modes_count(s, o, op, stats, nev);
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
  // Spectra needs 1 <= nev < n: a model of one or two equations is solved densely.
  if (engine == ModalEngine::automatic || n <= 2)
    engine = n <= std::max(o.dense_limit, 2) ? ModalEngine::dense : ModalEngine::sparse;
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
