#include "fem/modal.hpp"

#include "fem/assert.hpp"
#include "fem/block_lanczos.hpp"
#include "fem/constants.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <array>
#include <barrier>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace jointid::fem {

double Modes::frequency_hz(int r) const {
  return omega(r) / (2.0 * std::numbers::pi);
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double to_omega(double lambda) {
  return std::sqrt(std::max(lambda, 0.0));
}

// The lowest `count` of the eigenvalues `lambda` (ascending) below o.max_frequency_hz, or
// o.num_modes of them (0 = all).
int wanted_count(const Eigen::VectorXd& lambda, const ModalOptions& o) {
  const int n = static_cast<int>(lambda.size());
  if (o.max_frequency_hz <= 0.0) return o.num_modes > 0 ? std::min(o.num_modes, n) : n;
  int count = 0;
  while (count < n && to_omega(lambda(count)) < two_pi * o.max_frequency_hz)
    ++count;
  return count;
}

// DOFs with mass: M's rank (a positive semi-definite M has a zero row where its diagonal is zero).
int massive_dofs(const Assembled& s) {
  return static_cast<int>((s.M.diagonal().array() != 0.0).count());
}

// A DOF with a zero diagonal in both K and M (neither stiffness nor mass), if any: -1 if none.
int bare_equation(const Assembled& s) {
  for (int i = 0; i < s.K.rows(); ++i)
    if (s.K.coeff(i, i) == 0.0 && s.M.coeff(i, i) == 0.0) return i;
  return -1;
}

std::invalid_argument not_positive_definite(const Assembled& s, double shift_hz, int equation) {
  const std::string where =
      equation >= 0 ? "; it breaks down at " + to_string(s.dofs.node_dof(equation)) : "";
  return std::invalid_argument(
      "modal analysis: K + (2 pi " + std::to_string(shift_hz) +
      " Hz)^2 M is not positive definite" + where +
      ". Look there for a DOF with neither stiffness nor mass (e.g. a rotation no element or "
      "spring holds), or a negative mass or stiffness");
}

Modes dense_modes(const Assembled& s, const ModalOptions& o) {
  const Eigen::MatrixXd K(s.K), M(s.M);
  Modes out;
  if (Eigen::LLT<Eigen::MatrixXd>(M).info() == Eigen::Success) {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(K, M);
    if (solver.info() != Eigen::Success) {
      out.status = Status::failure(Status::Code::numerical_issue,
                                   "the dense generalised eigensolver (K, M) did not succeed");
      return out;
    }
    const Eigen::VectorXd& lambda = solver.eigenvalues();
    // Eigen reports success even when the reduction L⁻¹KL⁻ᵀ overflowed (a mass many decades
    // below the stiffness): its eigenvalues are then NaN.
    if (!lambda.allFinite()) {
      out.status = Status::failure(Status::Code::numerical_issue,
                                   "the dense generalised eigensolver (K, M) gave eigenvalues that "
                                   "are not finite (a mass too small for its stiffness?)");
      return out;
    }
    const int count = wanted_count(lambda, o);
    out.omega = lambda.head(count).unaryExpr(&to_omega);
    out.phi = solver.eigenvectors().leftCols(count);
    return out;
  }
  // M is singular (massless DOFs, e.g. rotations of a lumped-mass model), so Eigen's solver,
  // which factorises M, cannot be used (3.4 does not even check that factorisation). Solve the
  // shifted, inverted problem M φ = μ (K − σM) φ instead, as the sparse engine does: K − σM is
  // positive definite for σ < 0 whenever every DOF has stiffness or mass, ω² = σ + 1/μ, and a
  // massless DOF gives μ = 0, an infinite frequency, which is not a mode of the structure (its
  // static condensation gives the same finite modes). Kept for singular M only: for the finite
  // modes the direct solution is more accurate when the frequencies span many decades.
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  const Eigen::MatrixXd A = K - sigma * M;
  if (Eigen::LLT<Eigen::MatrixXd>(A).info() != Eigen::Success)
    throw not_positive_definite(s, o.shift_hz, bare_equation(s));
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(M, A);
  if (solver.info() != Eigen::Success) {
    out.status =
        Status::failure(Status::Code::numerical_issue,
                        "the dense generalised eigensolver (M, K - sigma M) did not succeed");
    return out;
  }
  // μ ascending: the finite modes are the positive μ from the largest down. μ at rounding level
  // (relative to the largest) belongs to a massless DOF.
  const Eigen::VectorXd& mu = solver.eigenvalues();
  if (!mu.allFinite()) {
    out.status = Status::failure(Status::Code::numerical_issue,
                                 "the dense generalised eigensolver (M, K - sigma M) gave "
                                 "eigenvalues that are not finite");
    return out;
  }
  const int n = static_cast<int>(mu.size());
  const double floor = 1e3 * std::numeric_limits<double>::epsilon() * mu.cwiseAbs().maxCoeff();
  int finite = 0;
  while (finite < n && mu(n - 1 - finite) > floor)
    ++finite;
  Eigen::VectorXd lambda(finite);
  for (int r = 0; r < finite; ++r)
    lambda(r) = sigma + 1.0 / mu(n - 1 - r);
  const int count = wanted_count(lambda, o);
  out.omega = lambda.head(count).unaryExpr(&to_omega);
  out.phi.resize(K.rows(), count);
  for (int r = 0; r < count; ++r) // φᵀ(K − σM)φ = 1 from the solver, so φᵀMφ = μ
    out.phi.col(r) = solver.eigenvectors().col(n - 1 - r) / std::sqrt(mu(n - 1 - r));
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
      throw not_positive_definite(system_, options_.shift_hz, static_cast<int>(e.equation()));
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
    ++stats_.right_hand_sides;
    stats_.solve_s += seconds_since(start);
  }
  /// X = (K − σM)⁻¹ B for a block: one pass over the factor.
  void solve_block(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) const {
    const auto start = std::chrono::steady_clock::now();
    X.resize(B.rows(), B.cols());
    llt_.solve(B.data(), X.data(), B.cols());
    ++stats_.solves;
    stats_.right_hand_sides += B.cols();
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

// The factor of K − σM and M, as the block Lanczos iteration sees them.
class BlockPencil final : public ShiftInvertPencil {
public:
  BlockPencil(const ShiftInvert& op, const SparseMatrix& M) : op_(op), M_(M) {}
  Eigen::Index rows() const override { return M_.rows(); }
  void solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) override { op_.solve_block(B, X); }
  // Y = M X, reading M once for the whole block (Eigen's product reads it once per column) and
  // rows shared among the cores: M is symmetric, so row i of M X is column i of M times X,
  // gathered from rows of X held row-major (one cache line per row for 8 columns). Two of
  // these per block, against one solve: the row-major copy is kept between calls (a new
  // 64 MB block at 10⁶ DOFs costs more in page faults than the product), and each core
  // writes its rows of Y straight into the column-major result.
  void mass(const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) const override {
    const Eigen::Index n = M_.rows(), b = X.cols();
    if (n < 1000 || b < 2 || !M_.isCompressed()) {
      Y.noalias() = M_ * X;
      return;
    }
    Y.resize(n, b);
    if (rows_.size() < n * b) rows_.resize(n * b);
    double* xr = rows_.data();
    const auto* outer = M_.outerIndexPtr();
    const auto* inner = M_.innerIndexPtr();
    const double* value = M_.valuePtr();
    const auto threads =
        static_cast<Eigen::Index>(std::max(1u, std::thread::hardware_concurrency()));
    std::barrier<> transposed(threads);
    auto part = [&](Eigen::Index t) {
      const Eigen::Index first = n * t / threads, last = n * (t + 1) / threads;
      for (Eigen::Index i = first; i < last; ++i)
        for (Eigen::Index c = 0; c < b; ++c)
          xr[i * b + c] = X(i, c);
      transposed.arrive_and_wait();
      // The block's width known to the compiler for the usual 8 columns.
      auto product = [&]<int B>(std::integral_constant<int, B>) {
        const Eigen::Index w = B > 0 ? B : b;
        std::conditional_t<(B > 0), std::array<double, (B > 0 ? B : 1)>, std::vector<double>> y{};
        if constexpr (B == 0) y.resize(static_cast<std::size_t>(w));
        for (Eigen::Index i = first; i < last; ++i) {
          std::fill(y.begin(), y.end(), 0.0);
          for (auto k = outer[i]; k < outer[i + 1]; ++k) {
            const double* x = xr + static_cast<Eigen::Index>(inner[k]) * w;
            const double v = value[k];
            for (Eigen::Index c = 0; c < w; ++c)
              y[c] += v * x[c];
          }
          for (Eigen::Index c = 0; c < w; ++c)
            Y(i, c) = y[c];
        }
      };
      if (b == 8)
        product(std::integral_constant<int, 8>{});
      else
        product(std::integral_constant<int, 0>{});
    };
    std::vector<std::jthread> pool;
    for (Eigen::Index t = 1; t < threads; ++t)
      pool.emplace_back(part, t);
    part(0);
  }

private:
  const ShiftInvert& op_;
  const SparseMatrix& M_;
  mutable Eigen::VectorXd rows_; // X row-major, n × b
};

// With massless DOFs the Krylov space of (K − σM)⁻¹M has at most as many dimensions as M
// has massive DOFs (its rank); a larger basis breaks down into M's null space.
int checked_massive_dofs(const Assembled& s, int nev) {
  const int massive = massive_dofs(s);
  if (nev >= massive)
    throw std::invalid_argument("the sparse engine finds fewer modes than DOFs with mass (" +
                                std::to_string(massive) +
                                "); ask for fewer modes or use the dense engine");
  return massive;
}

void reset_iteration_stats(SparseModalStats& stats) {
  stats.solves = 0;
  stats.right_hand_sides = 0;
  stats.solve_s = 0.0;
}

// The nev lowest modes by thick-restart block Lanczos on the factorisation held by `op`.
Modes block_lanczos_modes(const Assembled& s, const ModalOptions& o, ShiftInvert& op,
                          SparseModalStats& stats, int nev) {
  const int n = s.dofs.num_equations();
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  const int massive = checked_massive_dofs(s, nev);
  reset_iteration_stats(stats);
  BlockLanczosOptions bo;
  bo.nev = nev;
  bo.block_size = o.block_size;
  bo.max_basis = o.basis_vectors;
  bo.max_dimension = massive;
  bo.tolerance = o.tolerance;
  bo.max_restarts = o.max_iterations;
  bo.purify = massive < n; // see fem/block_lanczos.hpp
  op.set_shift(sigma);     // factorises K − σM unless a previous pass did
  BlockPencil pencil(op, s.M);
  const auto start = std::chrono::steady_clock::now();
  BlockLanczosResult r = block_lanczos(pencil, bo);
  stats.lanczos_s = seconds_since(start);
  stats.method = "block Lanczos";
  stats.block_size = r.block_size;
  stats.ncv = r.max_basis;
  stats.restarts = r.restarts;
  Modes out;
  out.sparse = stats;
  if (!r.status.ok()) {
    std::ostringstream reason;
    reason << "block shift-invert Lanczos did not converge to " << nev << " modes in "
           << o.max_iterations << " restarts (tolerance " << o.tolerance << "; "
           << r.converged_count << " of " << nev << " converged)";
    out.status = Status::failure(Status::Code::not_converging, reason.str());
    return out;
  }
  // θ descending is λ = σ + 1/θ ascending.
  out.omega = r.theta.unaryExpr([sigma](double theta) { return to_omega(sigma + 1.0 / theta); });
  out.phi = std::move(r.vectors);
  return out;
}

// The nev lowest modes by Spectra's shift-invert Lanczos on the factorisation held by `op`.
Modes spectra_modes(const Assembled& s, const ModalOptions& o, ShiftInvert& op,
                    SparseModalStats& stats, int nev) {
  const int n = s.dofs.num_equations();
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  Spectra::SparseSymMatProd<double> bop(s.M);
  const int massive = checked_massive_dofs(s, nev);
  const int ncv =
      std::min(massive, o.basis_vectors > 0 ? o.basis_vectors : std::max(2 * nev + 1, nev + 20));
  stats.method = "Spectra";
  stats.block_size = 1;
  stats.ncv = ncv;
  reset_iteration_stats(stats);
  Spectra::SymGEigsShiftSolver<ShiftInvert, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, bop, nev, ncv, sigma);
  const auto start = std::chrono::steady_clock::now();
  // A singular M (massless DOFs) makes the M-inner product of the Lanczos basis semi-definite:
  // components in M's null space are invisible to it and grow unchecked. Keep them out: start
  // from (K − σM)⁻¹ M r, which has none (exact arithmetic), and purify the eigenvectors at the
  // end (below). A positive semi-definite M is singular exactly when a diagonal entry is zero.
  const bool singular_mass = massive < n;
  if (singular_mass) {
    const Eigen::VectorXd r = s.M * Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
    Eigen::VectorXd start_vector(n);
    op.perform_op(r.data(), start_vector.data());
    solver.init(start_vector.data());
  } else {
    solver.init();
  }
  solver.compute(Spectra::SortRule::LargestMagn, o.max_iterations, o.tolerance,
                 Spectra::SortRule::SmallestAlge);
  stats.lanczos_s = seconds_since(start);
  stats.restarts = static_cast<int>(solver.num_iterations());
  Modes out;
  out.sparse = stats;
  if (solver.info() != Spectra::CompInfo::Successful) {
    std::ostringstream reason;
    reason << "shift-invert Lanczos (Spectra) did not converge to " << nev << " modes in "
           << o.max_iterations << " restarts (tolerance " << o.tolerance << ")";
    out.status = Status::failure(Status::Code::not_converging, reason.str());
    return out;
  }
  out.omega = solver.eigenvalues().unaryExpr(&to_omega);
  out.phi = solver.eigenvectors();
  if (singular_mass) { // φ ← (K − σM)⁻¹ M φ removes M's null space, then φᵀMφ = 1 again
    for (int r = 0; r < out.num_modes(); ++r) {
      const Eigen::VectorXd mphi = s.M * out.phi.col(r);
      Eigen::VectorXd pure(n);
      op.perform_op(mphi.data(), pure.data());
      out.phi.col(r) = pure / std::sqrt(pure.dot(s.M * pure));
    }
  }
  return out;
}

// What every engine guarantees of modes it reports as ok (debug asserts): one shape per
// frequency, the frequencies ascending.
Modes checked(Modes m) {
  JOINTID_ASSERT(!m.status.ok() || m.phi.cols() == m.omega.size(),
                 "one mode shape per natural frequency");
  for (int r = 1; m.status.ok() && r < m.num_modes(); ++r)
    JOINTID_ASSERT(m.omega(r - 1) <= m.omega(r), "natural frequencies in ascending order");
  return m;
}

// The nev lowest modes with the factorisation held by `op`, by the method asked for.
Modes sparse_modes_count(const Assembled& s, const ModalOptions& o, ShiftInvert& op,
                         SparseModalStats& stats, int nev) {
  if (o.sparse_method == SparseMethod::spectra) return spectra_modes(s, o, op, stats, nev);
  return block_lanczos_modes(s, o, op, stats, nev);
}

Modes sparse_modes(const Assembled& s, const ModalOptions& o) {
  SparseModalStats stats;
  ShiftInvert op(s, o, stats);
  if (o.max_frequency_hz <= 0.0) return sparse_modes_count(s, o, op, stats, o.num_modes);
  // Every mode below f_max: grow the count until the highest mode found lies above f_max.
  // The factorisation is reused; only the Lanczos iteration is repeated.
  int nev = std::max(o.num_modes, 8);
  const int last = massive_dofs(s) - 1; // the most modes the engine can find
  while (true) {
    nev = std::min(nev, last);
    Modes m = sparse_modes_count(s, o, op, stats, nev);
    if (!m.status.ok()) return m;
    const double omega_max = two_pi * o.max_frequency_hz;
    if (m.omega(m.num_modes() - 1) >= omega_max || nev == last) {
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
    return checked(sparse_modes(s, o));
  }
  return checked(dense_modes(s, o));
}

} // namespace jointid::fem
