#include "fem/block_lanczos.hpp"

#include "fem/assert.hpp"

#include <Eigen/Eigenvalues>
#include <cblas.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace jointid::fem {

namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double eps = std::numeric_limits<double>::epsilon();

using detail::Projection;

// Y = Z S for an n × q block Z and a small q × k matrix S, on the system BLAS (every core),
// into Y's storage when it already has the size: at 10⁶ DOFs a new n × 8 block costs more in
// page faults than the product.
void times_small(const MatrixXd& Z, const MatrixXd& S, MatrixXd& Y) {
  Y.resize(Z.rows(), S.cols());
  if (Y.size() == 0) return;
  if (Z.cols() == 0) {
    Y.setZero();
    return;
  }
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, static_cast<int>(Z.rows()),
              static_cast<int>(S.cols()), static_cast<int>(Z.cols()), 1.0, Z.data(),
              static_cast<int>(Z.rows()), S.data(), static_cast<int>(S.rows()), 0.0, Y.data(),
              static_cast<int>(Y.rows()));
}

// Z ← Z Δ^{-1/2} U D^{-1/2} from the scaled Gram matrix Δ^{-1/2} ZᵀMZ Δ^{-1/2} = U D Uᵀ,
// Δ = diag(ZᵀMZ) (SVQB, Stathopoulos & Wu 2002): the scaling lets columns of very different
// M-norms (a block after its projection, some columns nearly converged) be orthonormalised
// to rounding. A column of M-norm at most `floor`, and a direction the scaled Gram matrix
// cannot tell from the others (D below q ε), is dropped. MZ ← M Z of the result; returns R
// with Z_in = Z_out R. A second pass when the first was ill-conditioned (its orthonormality
// error is about ε κ).
MatrixXd svqb(const ShiftInvertPencil& P, MatrixXd& Z, MatrixXd& MZ, double floor,
              MatrixXd& scratch) {
  const Index q0 = Z.cols();
  MatrixXd R = MatrixXd::Identity(q0, q0);
  for (int pass = 0; pass < 2 && Z.cols() > 0; ++pass) {
    P.mass(Z, MZ);
    MatrixXd G = Z.transpose() * MZ;
    G = 0.5 * (G + G.transpose()).eval();
    const Index q = Z.cols();
    VectorXd scale(q);
    for (Index i = 0; i < q; ++i)
      scale(i) = G(i, i) > floor * floor && G(i, i) > 0.0 ? 1.0 / std::sqrt(G(i, i)) : 0.0;
    const MatrixXd Gs = scale.asDiagonal() * G * scale.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(Gs);
    const VectorXd& d = eig.eigenvalues(); // ascending, ≤ q
    Index first = 0;
    while (first < q && !(d(first) > q * eps))
      ++first;
    const Index kept = q - first;
    const MatrixXd U = eig.eigenvectors().rightCols(kept);
    const VectorXd root = d.tail(kept).cwiseSqrt();
    const MatrixXd to_new = scale.asDiagonal() * U * root.cwiseInverse().asDiagonal();
    times_small(Z, to_new, scratch);
    Z.swap(scratch);
    times_small(MZ, to_new, scratch);
    MZ.swap(scratch);
    // Z_in = Z_out D^{1/2} Uᵀ Δ^{1/2}; Δ^{1/2} is 1/scale (0 for a dropped column).
    const VectorXd unscale = scale.unaryExpr([](double v) { return v > 0.0 ? 1.0 / v : 0.0; });
    R = (root.asDiagonal() * U.transpose() * unscale.asDiagonal() * R).eval();
    if (kept == 0 || d(first) > 1e-4 * d(q - 1)) break; // well conditioned: one pass is enough
    floor = 0.0;
  }
  return R;
}

// Whether ZᵀMZ = I to well within rounding's reach (1e-8): an orthonormalised block, checked
// by debug asserts (n q² flops, a fraction of the orthonormalisation's own).
[[maybe_unused]] bool m_orthonormal(const MatrixXd& Z, const MatrixXd& MZ) {
  if (Z.cols() == 0) return true;
  const MatrixXd G = Z.transpose() * MZ;
  return (G - MatrixXd::Identity(G.rows(), G.cols())).cwiseAbs().maxCoeff() <= 1e-8;
}

// The products with the basis, n × m by m × b for n up to 10⁶, are the largest dense work
// outside the solves: they go to the system BLAS (the one CHOLMOD uses; OpenBLAS here, on
// every core with the machine's kernels), where Eigen's own product would use one core.

// C = V(:, 0:m)ᵀ Z.
MatrixXd basis_transpose_times(const MatrixXd& V, Index m, const MatrixXd& Z) {
  MatrixXd C(m, Z.cols());
  if (m == 0 || Z.cols() == 0) return C.setZero();
  cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, static_cast<int>(m),
              static_cast<int>(Z.cols()), static_cast<int>(V.rows()), 1.0, V.data(),
              static_cast<int>(V.rows()), Z.data(), static_cast<int>(Z.rows()), 0.0, C.data(),
              static_cast<int>(m));
  return C;
}

// Z ← Z + alpha V(:, first:first + m) C.
void add_basis_times(MatrixXd& Z, double alpha, const MatrixXd& V, Index m, const MatrixXd& C,
                     Index first = 0) {
  if (m == 0 || Z.cols() == 0) return;
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, static_cast<int>(Z.rows()),
              static_cast<int>(Z.cols()), static_cast<int>(m), alpha, V.data() + first * V.rows(),
              static_cast<int>(V.rows()), C.data(), static_cast<int>(C.rows()), 1.0, Z.data(),
              static_cast<int>(Z.rows()));
}

// V(:, 0:m) S for an m × k matrix S.
MatrixXd basis_times(const MatrixXd& V, Index m, const MatrixXd& S) {
  MatrixXd Y = MatrixXd::Zero(V.rows(), S.cols());
  add_basis_times(Y, 1.0, V, m, S);
  return Y;
}

} // namespace

// Makes Z M-orthonormal and M-orthogonal to the first m columns of V: `passes` passes of
// block classical Gram–Schmidt (two for a block never projected before; one after a first
// projection the caller made, the Lanczos step against the last blocks), then SVQB, repeated
// while the result is not orthogonal to V to rounding (a block that nearly lies in span(V)
// loses digits in the first round). Directions that do lie in span(V) (M-norm below
// `relative_floor` times the largest column's before any projection) are dropped; `removed`
// holds, per column, the M-norm² a caller's first projection took away (empty: none). MZ holds
// M Z of the result.
Projection detail::orthonormalise(const ShiftInvertPencil& P, const MatrixXd& V, Index m,
                                  MatrixXd& Z, MatrixXd& MZ, double relative_floor,
                                  MatrixXd& scratch, int passes,
                                  const Eigen::RowVectorXd& removed) {
  Projection p;
  p.C = MatrixXd::Zero(m, Z.cols());
  P.mass(Z, MZ);
  Eigen::RowVectorXd norms2 = Z.cwiseProduct(MZ).colwise().sum();
  if (removed.size() == norms2.size()) norms2 += removed; // Pythagoras
  const double scale = std::sqrt(std::max(0.0, norms2.maxCoeff()));
  const double floor = relative_floor * scale;
  // Whether the last pass still removed much (more than half of a column's M-norm², by
  // Pythagoras): only then can the result be off orthogonal by more than rounding ("twice is
  // enough", Kahan–Parlett) and is checked.
  bool check = false;
  if (m > 0) {
    for (int pass = 0; pass < passes; ++pass) {
      if (pass > 0) P.mass(Z, MZ);
      const MatrixXd c = basis_transpose_times(V, m, MZ);
      if (pass == passes - 1) {
        const Eigen::RowVectorXd before = Z.cwiseProduct(MZ).colwise().sum();
        check = (c.colwise().squaredNorm().array() > 0.5 * before.array()).any();
      }
      add_basis_times(Z, -1.0, V, m, c);
      p.C += c;
    }
  }
  p.R = svqb(P, Z, MZ, floor, scratch);
  for (int round = 0; round < 2 && check && Z.cols() > 0; ++round) {
    const MatrixXd e = basis_transpose_times(V, m, MZ); // cosines: Z, V are M-orthonormal
    if (e.cwiseAbs().maxCoeff() <= 8.0 * eps * std::sqrt(static_cast<double>(m))) break;
    add_basis_times(Z, -1.0, V, m, e); // Z_in = V (C + e R) + Z' R
    p.C += e * p.R;
    p.R = svqb(P, Z, MZ, 0.0, scratch) * p.R;
    ++p.rounds;
  }
  return p;
}

namespace {
using detail::orthonormalise;

// V.leftCols(k) ← V.leftCols(m) S (S is m × k, k ≤ m) in place, a slab of rows at a time, so
// no second n × k matrix is needed.
void multiply_in_place(MatrixXd& V, Index m, const MatrixXd& S) {
  const Index n = V.rows(), k = S.cols();
  constexpr Index slab = 16384;
  MatrixXd rows(std::min(slab, n), k);
  for (Index r = 0; r < n; r += slab) {
    const Index h = std::min(slab, n - r);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, static_cast<int>(h), static_cast<int>(k),
                static_cast<int>(m), 1.0, V.data() + r, static_cast<int>(n), S.data(),
                static_cast<int>(S.rows()), 0.0, rows.data(), static_cast<int>(rows.rows()));
    V.block(r, 0, h, k) = rows.topRows(h);
  }
}

class Iteration {
public:
  Iteration(ShiftInvertPencil& pencil, const BlockLanczosOptions& o) : P_(pencil), o_(o) {
    n_ = P_.rows();
    if (o.nev < 1 || o.block_size < 1 || o.max_basis < 0 || o.max_dimension < 0 ||
        !(o.tolerance >= 0.0) || o.max_restarts < 0)
      throw std::invalid_argument(
          "block Lanczos: need nev >= 1, block_size >= 1, max_basis >= 0, max_dimension >= 0, "
          "tolerance >= 0 and max_restarts >= 0 (got nev " +
          std::to_string(o.nev) + ", block_size " + std::to_string(o.block_size) + ", max_basis " +
          std::to_string(o.max_basis) + ", max_dimension " + std::to_string(o.max_dimension) +
          ", tolerance " + std::to_string(o.tolerance) + ", max_restarts " +
          std::to_string(o.max_restarts) + ")");
    rank_ = o.max_dimension > 0 ? std::min<Index>(o.max_dimension, n_) : n_;
    if (o.nev >= rank_)
      throw std::invalid_argument("block Lanczos: asked for " + std::to_string(o.nev) +
                                  " eigenpairs in a space of dimension " + std::to_string(rank_) +
                                  "; ask for fewer");
    nev_ = o.nev;
    // A space too small for the block (a small model): smaller blocks, so that the basis can
    // hold the wanted vectors and a block beside them.
    b_ = std::min<Index>(o.block_size, std::max<Index>(1, (rank_ - nev_) / 2));
    // The default cap: room for the wanted vectors, as many others, and 6 blocks (nev 20, b 8:
    // 88 vectors, 96 with the next block, 768 MB at 10⁶ DOFs). Measured on the frame lattices
    // of 10⁴, 10⁵ and 10⁶ DOFs (20 modes, blocks of 8): a cap of 56 took 21–23 passes over the
    // factor, 72 took 19, 88 and more 18 (docs/benchmarks.md); the work outside the solves
    // hardly changed.
    cap_ = o.max_basis > 0 ? o.max_basis : 2 * nev_ + 6 * b_;
    cap_ = std::min(std::max(cap_, nev_ + b_), rank_);
    b_ = std::min(b_, cap_ - nev_);
  }

  BlockLanczosResult run() {
    BlockLanczosResult out;
    out.block_size = static_cast<int>(b_);
    out.max_basis = static_cast<int>(cap_);
    V_.resize(n_, cap_ + b_);
    H_ = MatrixXd::Zero(cap_, cap_);
    start();
    // A block at a time, with Rayleigh–Ritz and the convergence test after each (they cost
    // O(cap³), nothing next to a solve): no solve is spent once the wanted pairs converged.
    bool converged = false;
    for (int restarts = 0;; ++restarts) {
      out.restarts = restarts;
      do {
        absorb();
        converged = m_ >= nev_ && ritz(out);
        if (converged) break;
      } while (q_ > 0 && m_ + q_ <= cap_);
      if (converged || restarts == o_.max_restarts) break;
      restart();
    }
    out.theta = theta_.head(nev_);
    if (converged) {
      refine(out);
    } else {
      out.status = Status::failure(
          Status::Code::not_converging,
          "block Lanczos: " + std::to_string(out.converged_count) + " of " + std::to_string(nev_) +
              " wanted eigenpairs met the tolerance " + std::to_string(o_.tolerance) + " in " +
              std::to_string(o_.max_restarts) + " restarts (largest relative residual " +
              std::to_string(out.max_residual) + ")");
    }
    out.solves = solves_;
    out.right_hand_sides = rhs_;
    return out;
  }

private:
  void solve(const MatrixXd& B, MatrixXd& X) {
    P_.solve(B, X);
    ++solves_;
    rhs_ += B.cols();
  }

  // Random columns (a fixed seed: runs are reproducible); with massless DOFs mapped by Op so
  // that they have no component in M's null space.
  MatrixXd fresh(Index columns) {
    std::normal_distribution<double> normal;
    MatrixXd Z(n_, columns);
    for (Index j = 0; j < columns; ++j)
      for (Index i = 0; i < n_; ++i)
        Z(i, j) = normal(random_);
    if (o_.purify) {
      MatrixXd MZ;
      P_.mass(Z, MZ);
      solve(MZ, Z);
    }
    return Z;
  }

  void start() {
    MatrixXd Z = fresh(b_), MZ;
    orthonormalise(P_, V_, 0, Z, MZ, deflation, scratch_);
    m_ = 0;
    c0_ = 0;
    q_ = Z.cols();
    V_.middleCols(0, q_) = Z;
    MQ_ = std::move(MZ);
    R_.resize(q_, 0);
  }

  // Absorbs the next block into the basis (the caller checks that it fits under the cap):
  // Op V = V H + Q R E_last, with Q the next block (columns m..m+q of V) and R coupling it to
  // columns c0..m.
  void absorb() {
    if (m_ > c0_) {
      H_.block(m_, c0_, q_, m_ - c0_) = R_;
      H_.block(c0_, m_, m_ - c0_, q_) = R_.transpose();
    }
    const Index j = m_, q = q_;
    m_ += q;
    MatrixXd& W = W_;
    MatrixXd& MW = MW_;
    W.resize(n_, q);
    solve(MQ_, W); // W = Op Q
    // The Lanczos step first, against the columns Q couples to: their coefficients are known,
    // V(c0..j)ᵀ M Op Q = Rᵀ (Op is M-self-adjoint and Op V(c0..j) = V H + Q R), and Qᵀ M Op Q
    // = (M Q)ᵀ W needs no product with M. In exact arithmetic that leaves W M-orthogonal to
    // the whole basis; one pass of Gram–Schmidt against the whole basis then takes away what
    // rounding and the solve's error left (the second pass of CGS2, the first being this one),
    // with one product with M and two reads of the basis fewer than two full passes.
    MatrixXd local(m_ - c0_, q);
    local.topRows(j - c0_) = R_.transpose();
    local.bottomRows(q) = basis_transpose_times(MQ_, q, W);
    add_basis_times(W, -1.0, V_, m_ - c0_, local, c0_);
    const Projection p =
        orthonormalise(P_, V_, m_, W, MW, deflation, scratch_, 1, local.colwise().squaredNorm());
    const MatrixXd D = local.bottomRows(q) + p.C.bottomRows(q); // Q_jᵀ M Op Q_j
    H_.block(j, j, q, q) = 0.5 * (D + D.transpose());
    Index kept = W.cols();
    JOINTID_ASSERT(m_ + kept <= V_.cols(), "the next block fits in the basis storage");
    JOINTID_ASSERT(m_orthonormal(W, MW), "the next Lanczos block is M-orthonormal");
    MatrixXd R = MatrixXd::Zero(q, q);
    R.topRows(kept) = p.R;
    V_.middleCols(m_, kept) = W;
    if (kept == q) {
      MQ_.swap(MW); // MW's storage is the next block's
    } else {
      MQ_.resize(n_, q);
      MQ_.leftCols(kept) = MW;
    }
    // A direction lost (Op Q nearly in span(V)): refill the block with fresh directions
    // while the space has room, so the block keeps its size; they enter with R = 0.
    if (kept < q && m_ + q < rank_) {
      MatrixXd Z = fresh(q - kept), MZ;
      orthonormalise(P_, V_, m_ + kept, Z, MZ, deflation, scratch_);
      V_.middleCols(m_ + kept, Z.cols()) = Z;
      MQ_.middleCols(kept, Z.cols()) = MZ;
      kept += Z.cols();
    }
    R_ = R.topRows(kept);
    MQ_.conservativeResize(n_, kept);
    c0_ = j;
    q_ = kept;
  }

  // Rayleigh–Ritz on the symmetric projection (θ descending) and the convergence test of
  // the nev wanted pairs; true when all passed.
  bool ritz(BlockLanczosResult& out) {
    MatrixXd T = H_.topLeftCorner(m_, m_);
    T = 0.5 * (T + T.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(T);
    theta_ = eig.eigenvalues().reverse();
    S_ = eig.eigenvectors().rowwise().reverse();
    // ‖Op y_i − θ_i y_i‖_M = ‖R s_i(c0..m)‖: only the last block couples to the next one.
    out.converged_count = 0;
    out.max_residual = 0.0;
    const double eps23 = std::pow(eps, 2.0 / 3.0);
    for (Index i = 0; i < nev_; ++i) {
      const double residual = q_ > 0 ? (R_ * S_.block(c0_, i, m_ - c0_, 1)).norm() : 0.0;
      const double scale = std::max(eps23, std::abs(theta_(i)));
      if (residual <= o_.tolerance * scale) ++out.converged_count;
      out.max_residual = std::max(out.max_residual, residual / std::abs(theta_(i)));
    }
    return out.converged_count == nev_;
  }

  // Keeps the k leading Ritz vectors and the next block: V ← [V S_k, Q], H ← diag(θ_k), and Q
  // now couples to all k kept columns through R s(c0..m).
  void restart() {
    const VectorXd& theta = theta_;
    const MatrixXd& S = S_;
    // The wanted vectors and half of the others (Wu & Simon): measured on the 10⁴-DOF
    // lattice, keeping none of the others took twice the solves, keeping all 10–20 % more.
    const Index k = nev_ + (cap_ - q_ - nev_) / 2;
    multiply_in_place(V_, m_, S.leftCols(k));
    if (k != m_) { // k < m: the block moves left, through a copy (the ranges may overlap)
      W_ = V_.middleCols(m_, q_);
      V_.middleCols(k, q_) = W_;
    }
    R_ = (R_ * S.block(c0_, 0, m_ - c0_, k)).eval();
    H_.setZero();
    H_.diagonal().head(k) = theta.head(k);
    m_ = k;
    c0_ = 0;
  }

  // The converged Ritz vectors, refined by one more application of Op: φ ← Op φ / θ. Why:
  // the test bounds the residual in the (K − σM)⁻¹ norm, which leaves the error of φ along
  // the high modes (small θ) as it is, and K magnifies exactly those in ‖Kφ − λMφ‖ (1e-8
  // relative measured on the 10⁴-DOF lattice at tolerance 1e-10); a power step divides each
  // by θ_i/θ_j (1e-11). No solve is needed: Op V S = V S Θ + Q R S(c0..m), the Krylov relation
  // (Ericsson & Ruhe's purification). With a singular M the step is a real solve instead
  // (one, of nev columns), so that the vectors lose the components in M's null space that
  // rounding put there (the M-inner product cannot see them, nor the relation, whose vectors
  // carry them). Then M-orthonormalised again (Löwdin: the smallest change); the eigenvalues
  // stay the Ritz values, accurate to the residual squared.
  void refine(BlockLanczosResult& out) {
    const VectorXd inverse = out.theta.cwiseInverse();
    if (o_.purify) {
      MatrixXd phi = basis_times(V_, m_, S_.leftCols(nev_)), MPhi;
      V_.resize(0, 0); // the basis is no longer needed: free it before the solve
      P_.mass(phi, MPhi);
      out.vectors.resize(n_, nev_);
      solve(MPhi, out.vectors);
      out.vectors = (out.vectors * inverse.asDiagonal()).eval();
    } else {
      out.vectors = basis_times(V_, m_, S_.leftCols(nev_));
      if (q_ > 0)
        out.vectors.noalias() +=
            V_.middleCols(m_, q_) * (R_ * S_.block(c0_, 0, m_ - c0_, nev_) * inverse.asDiagonal());
      V_.resize(0, 0);
    }
    MatrixXd MY;
    P_.mass(out.vectors, MY);
    MatrixXd G = out.vectors.transpose() * MY;
    G = 0.5 * (G + G.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(G);
    out.vectors = (out.vectors * eig.operatorInverseSqrt()).eval();
  }

  // A direction whose M-norm fell below this fraction of the block's is taken as lying in the
  // basis already (the Krylov space is invariant there).
  static constexpr double deflation = 1e-12;

  ShiftInvertPencil& P_;
  const BlockLanczosOptions& o_;
  Index n_ = 0, rank_ = 0, nev_ = 0, b_ = 0, cap_ = 0;
  MatrixXd V_, H_, R_, MQ_;
  // Work blocks kept from block to block (n × b each; new ones would cost page faults).
  MatrixXd W_, MW_, scratch_;
  VectorXd theta_; // Ritz values of the last Rayleigh–Ritz, descending
  MatrixXd S_;     // their eigenvectors in the basis
  Index m_ = 0, c0_ = 0, q_ = 0;
  long long solves_ = 0, rhs_ = 0;
  std::mt19937_64 random_{o_.seed};
};

} // namespace

BlockLanczosResult block_lanczos(ShiftInvertPencil& pencil, const BlockLanczosOptions& options) {
  return Iteration(pencil, options).run();
}

} // namespace jointid::fem
