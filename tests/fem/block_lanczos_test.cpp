// fem::block_lanczos on dense pencils whose eigenpairs are known by construction: K = M Φ Λ ΦᵀM
// with Φ M-orthonormal, so K Φ = M Φ Λ exactly. Checked: the eigenvalues, M-orthonormality,
// multiple eigenvalues (up to the block size), restarts under a small basis cap, a space too
// small for the basis, a singular M, non-convergence and bad options.
#include "fem/block_lanczos.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using jointid::fem::block_lanczos;
using jointid::fem::BlockLanczosOptions;
using jointid::fem::BlockLanczosResult;

// (K − σM)⁻¹ by a dense Cholesky factor, M by a dense product; counts the solves.
class DensePencil final : public jointid::fem::ShiftInvertPencil {
public:
  DensePencil(const MatrixXd& K, const MatrixXd& M, double sigma) : M_(M), llt_(K - sigma * M) {}
  Eigen::Index rows() const override { return M_.rows(); }
  void solve(const MatrixXd& B, MatrixXd& X) override {
    X = llt_.solve(B);
    ++calls;
  }
  void mass(const MatrixXd& X, MatrixXd& Y) const override {
    Y = M_ * X;
    ++mass_calls;
  }
  int calls = 0;
  mutable int mass_calls = 0;

private:
  MatrixXd M_;
  Eigen::LLT<MatrixXd> llt_;
};

MatrixXd random_matrix(int rows, int cols, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  MatrixXd A(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i)
      A(i, j) = normal(rng);
  return A;
}

// A pencil with eigenvalues `lambda` (any order) and a random SPD M.
struct Pencil {
  MatrixXd K, M;
};

Pencil pencil_with(const VectorXd& lambda, unsigned seed) {
  const int n = static_cast<int>(lambda.size());
  std::mt19937 rng(seed);
  const MatrixXd A = random_matrix(n, n, rng);
  Pencil p;
  p.M = MatrixXd::Identity(n, n) + A * A.transpose() / n;
  const Eigen::HouseholderQR<MatrixXd> qr(random_matrix(n, n, rng));
  const MatrixXd Q = qr.householderQ();
  const Eigen::LLT<MatrixXd> L(p.M);
  // Φ = L⁻ᵀ Q: ΦᵀMΦ = Qᵀ L⁻¹ L Lᵀ L⁻ᵀ Q = I.
  const MatrixXd Phi = L.matrixU().solve(Q);
  const MatrixXd MPhi = p.M * Phi;
  p.K = MPhi * lambda.asDiagonal() * MPhi.transpose();
  p.K = 0.5 * (p.K + p.K.transpose()).eval();
  return p;
}

// θ = 1/(λ − σ) of the `count` lowest λ, descending.
VectorXd expected_theta(VectorXd lambda, double sigma, int count) {
  std::sort(lambda.data(), lambda.data() + lambda.size());
  VectorXd theta(count);
  for (int i = 0; i < count; ++i)
    theta(i) = 1.0 / (lambda(i) - sigma);
  return theta;
}

double max_relative_difference(const VectorXd& a, const VectorXd& b) {
  return ((a - b).cwiseAbs().array() / b.cwiseAbs().array()).maxCoeff();
}

// ΦᵀMΦ = I, and each pair's residual r = Kφ − λMφ: what the convergence test bounds,
// ‖(K − σM)⁻¹ r‖_M ≤ tolerance (1e-10; twice that for rounding), and ‖r‖/‖Kφ‖, which that
// bound does not make as small (an error of φ along the high modes is damped by the
// shift-invert, not by K): 1e-7 here still fails for any wrong pair by orders of magnitude.
void expect_eigenpairs(const Pencil& p, const BlockLanczosResult& r, double sigma) {
  const int k = static_cast<int>(r.theta.size());
  ASSERT_EQ(r.vectors.cols(), k);
  const MatrixXd gram = r.vectors.transpose() * p.M * r.vectors;
  EXPECT_LE((gram - MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::LLT<MatrixXd> A(p.K - sigma * p.M);
  for (int i = 0; i < k; ++i) {
    const double lambda = sigma + 1.0 / r.theta(i);
    const VectorXd Kphi = p.K * r.vectors.col(i);
    const VectorXd residual = Kphi - lambda * p.M * r.vectors.col(i);
    const VectorXd pencil_residual = A.solve(residual);
    EXPECT_LE(std::sqrt(pencil_residual.dot(p.M * pencil_residual)), 2e-10) << "pair " << i;
    EXPECT_LE(residual.norm(), 1e-7 * Kphi.norm()) << "pair " << i;
  }
}

} // namespace

TEST(BlockLanczos, FindsTheLowestEigenpairsOfAKnownPencil) {
  // λ = 1, 4, 9, ... (n = 120), σ = −0.5: the 10 lowest, block of 4, automatic basis cap
  // (2·10 + 6·4 = 44 < 120: restarts happen). θ to 1e-12, the pairs to rounding.
  const int n = 120;
  VectorXd lambda(n);
  for (int i = 0; i < n; ++i)
    lambda(i) = (i + 1.0) * (i + 1.0);
  const Pencil p = pencil_with(lambda, 7);
  const double sigma = -0.5;
  DensePencil op(p.K, p.M, sigma);
  BlockLanczosOptions o;
  o.nev = 10;
  o.block_size = 4;
  const BlockLanczosResult r = block_lanczos(op, o);
  ASSERT_TRUE(r.status.ok());
  EXPECT_EQ(r.converged_count, 10);
  EXPECT_EQ(r.block_size, 4);
  EXPECT_EQ(r.max_basis, 44);
  EXPECT_GE(r.restarts, 1);
  EXPECT_LE(max_relative_difference(r.theta, expected_theta(lambda, sigma, 10)), 1e-12);
  expect_eigenpairs(p, r, sigma);
  // Every solve is a block of 4 (no deflation here), and the counts are those of the pencil.
  EXPECT_EQ(r.solves, op.calls);
  EXPECT_EQ(r.right_hand_sides, 4 * r.solves);
  EXPECT_LE(r.max_residual, 1e-10);
}

TEST(BlockLanczos, FindsEveryCopyOfAMultipleEigenvalueUpToTheBlockSize) {
  // λ = 2 three times and λ = 5 twice among simple ones: every copy of both must be among the
  // 8 lowest. A block of 3 spans every direction of the triple eigenspace from the start; with
  // one copy missed the 8 returned values would end with a higher λ than expected.
  const int n = 90;
  VectorXd lambda(n);
  for (int i = 0; i < n; ++i)
    lambda(i) = 10.0 + i;
  lambda.head(8) << 1.0, 2.0, 2.0, 2.0, 3.0, 5.0, 5.0, 7.0;
  const Pencil p = pencil_with(lambda, 11);
  const double sigma = -1.0;
  for (int block : {3, 4, 8}) {
    DensePencil op(p.K, p.M, sigma);
    BlockLanczosOptions o;
    o.nev = 8;
    o.block_size = block;
    const BlockLanczosResult r = block_lanczos(op, o);
    ASSERT_TRUE(r.status.ok()) << "block " << block;
    EXPECT_LE(max_relative_difference(r.theta, expected_theta(lambda, sigma, 8)), 1e-12)
        << "block " << block;
    expect_eigenpairs(p, r, sigma);
    // The three vectors of λ = 2 span its eigenspace: rank 3 (M-orthonormal, so exactly).
    const MatrixXd triple = r.vectors.middleCols(1, 3);
    EXPECT_LE((triple.transpose() * p.M * triple - MatrixXd::Identity(3, 3)).norm(), 1e-12);
    EXPECT_LE((p.K * triple - 2.0 * p.M * triple).norm(), 1e-9 * (p.K * triple).norm());
  }
}

TEST(BlockLanczos, RestartsUnderASmallBasisCapGiveTheSameEigenvalues) {
  // A cap of nev + 2 blocks forces many thick restarts; the result must not change.
  const int n = 200;
  VectorXd lambda(n);
  for (int i = 0; i < n; ++i)
    lambda(i) = 1.0 + 0.3 * i + 0.01 * i * i;
  const Pencil p = pencil_with(lambda, 3);
  const double sigma = -0.25;
  DensePencil op(p.K, p.M, sigma);
  BlockLanczosOptions o;
  o.nev = 12;
  o.block_size = 3;
  o.max_basis = 18;
  const BlockLanczosResult r = block_lanczos(op, o);
  ASSERT_TRUE(r.status.ok());
  EXPECT_EQ(r.max_basis, 18);
  EXPECT_GE(r.restarts, 3); // the cap is what makes it restart
  EXPECT_LE(max_relative_difference(r.theta, expected_theta(lambda, sigma, 12)), 1e-12);
  expect_eigenpairs(p, r, sigma);
}

TEST(BlockLanczos, AWideSpectrumCostsTwoMassProductsPerBlock) {
  // Eigenvalues from 1 to 1e6: the solves' rounding errors (ε κ, κ = λmax/(λmin − σ)) lie
  // along the low modes, which the basis already holds, and the Lanczos step's known
  // coefficients do not remove them; the one pass of Gram–Schmidt against the whole basis
  // must. A block costs a solve and two products with M (the pass and the
  // orthonormalisation); the start three and the refinement one. With three per block (a
  // second full pass) or a basis that lost orthogonality, this fails. The eigenvalues are
  // those of K = MΦΛΦᵀM only to the rounding of building K, ε κ relative (5e-12 measured).
  const int n = 240;
  VectorXd lambda(n);
  for (int i = 0; i < n; ++i)
    lambda(i) = std::pow(10.0, 6.0 * i / (n - 1));
  const Pencil p = pencil_with(lambda, 11);
  const double sigma = -0.5;
  DensePencil op(p.K, p.M, sigma);
  BlockLanczosOptions o;
  o.nev = 10;
  o.block_size = 4;
  o.max_basis = 26;
  const BlockLanczosResult r = block_lanczos(op, o);
  ASSERT_TRUE(r.status.ok());
  EXPECT_GE(r.restarts, 1);
  const double kappa = lambda.maxCoeff() / (lambda.minCoeff() - sigma);
  EXPECT_LE(max_relative_difference(r.theta, expected_theta(lambda, sigma, 10)),
            10 * std::numeric_limits<double>::epsilon() * kappa);
  expect_eigenpairs(p, r, sigma);
  EXPECT_LE(op.mass_calls, 2 * op.calls + 4) << op.calls << " solves";
}

TEST(BlockLanczos, ExhaustsASpaceSmallerThanTheBasisExactly) {
  // n = 14, 11 pairs wanted: the block shrinks to fit and the Krylov space becomes the whole
  // space, where the Ritz pairs are exact (the next block deflates to nothing).
  const int n = 14;
  VectorXd lambda(n);
  for (int i = 0; i < n; ++i)
    lambda(i) = 1.0 + i * i;
  const Pencil p = pencil_with(lambda, 5);
  DensePencil op(p.K, p.M, -1.0);
  BlockLanczosOptions o;
  o.nev = 11;
  o.block_size = 8;
  const BlockLanczosResult r = block_lanczos(op, o);
  ASSERT_TRUE(r.status.ok());
  EXPECT_LE(r.block_size, (n - 11) / 2 + 1);
  EXPECT_EQ(r.restarts, 0);
  EXPECT_LE(max_relative_difference(r.theta, expected_theta(lambda, -1.0, 11)), 1e-12);
  expect_eigenpairs(p, r, -1.0);
}

TEST(BlockLanczos, SingularMassGivesPurifiedVectorsOfTheFiniteModes) {
  // M = diag(m_t, 0): the last 20 of 60 unknowns are massless. The finite modes are those of
  // the statically condensed pencil (K* = Ktt − Ktr Krr⁻¹ Krt, Mtt); a massless unknown follows
  // φr = −Krr⁻¹ Krt φt, which only purified vectors satisfy (M's null space is invisible to
  // the M-inner product the iteration works in).
  const int nt = 40, nr = 20, n = nt + nr;
  std::mt19937 rng(13);
  const MatrixXd A = random_matrix(n, n, rng);
  const MatrixXd K = A * A.transpose() + n * MatrixXd::Identity(n, n);
  MatrixXd M = MatrixXd::Zero(n, n);
  for (int i = 0; i < nt; ++i)
    M(i, i) = 1.0 + 0.5 * i / nt;
  const MatrixXd Ktt = K.topLeftCorner(nt, nt), Ktr = K.topRightCorner(nt, nr);
  const Eigen::LLT<MatrixXd> Krr(K.bottomRightCorner(nr, nr));
  const MatrixXd condensed = Ktt - Ktr * Krr.solve(Ktr.transpose());
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> reference(condensed,
                                                                     M.topLeftCorner(nt, nt));
  const double sigma = -1.0;
  DensePencil op(K, M, sigma);
  BlockLanczosOptions o;
  o.nev = 6;
  o.block_size = 4;
  o.max_dimension = nt;
  o.purify = true;
  const BlockLanczosResult r = block_lanczos(op, o);
  ASSERT_TRUE(r.status.ok());
  for (int i = 0; i < 6; ++i) {
    const double lambda = sigma + 1.0 / r.theta(i);
    EXPECT_NEAR(lambda, reference.eigenvalues()(i), 1e-11 * reference.eigenvalues()(i));
    const VectorXd phi_t = r.vectors.col(i).head(nt), phi_r = r.vectors.col(i).tail(nr);
    const VectorXd condensed_r = -Krr.solve(Ktr.transpose() * phi_t);
    EXPECT_LE((phi_r - condensed_r).norm(), 1e-10 * condensed_r.norm()) << "pair " << i;
  }
  const MatrixXd gram = r.vectors.transpose() * M * r.vectors;
  EXPECT_LE((gram - MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BlockLanczos, ReportsNonConvergenceWithoutVectors) {
  // Tolerance 0 is met only by an exact residual, which a basis smaller than the space never
  // has; no restart allowed.
  const int n = 100;
  VectorXd lambda = VectorXd::LinSpaced(n, 1.0, 100.0);
  const Pencil p = pencil_with(lambda, 2);
  DensePencil op(p.K, p.M, -1.0);
  BlockLanczosOptions o;
  o.nev = 5;
  o.block_size = 2;
  o.tolerance = 0.0;
  o.max_restarts = 0;
  const BlockLanczosResult r = block_lanczos(op, o);
  EXPECT_EQ(r.status.code, jointid::fem::Status::Code::not_converging);
  EXPECT_NE(r.status.reason.find("of 5 wanted eigenpairs met the tolerance 0"), std::string::npos)
      << r.status.reason;
  EXPECT_LT(r.converged_count, 5);
  EXPECT_EQ(r.restarts, 0);
  EXPECT_EQ(r.vectors.size(), 0);
  EXPECT_GT(r.max_residual, 0.0);
  // With the default tolerance and restarts the same problem converges.
  o.tolerance = 1e-10;
  o.max_restarts = 1000;
  EXPECT_TRUE(block_lanczos(op, o).status.ok());
}

TEST(BlockLanczos, BadOptionsThrow) {
  const Pencil p = pencil_with(VectorXd::LinSpaced(10, 1.0, 10.0), 1);
  DensePencil op(p.K, p.M, -1.0);
  auto with = [](auto change) {
    BlockLanczosOptions o;
    o.nev = 3;
    o.block_size = 2;
    change(o);
    return o;
  };
  EXPECT_NO_THROW(block_lanczos(op, with([](BlockLanczosOptions&) {})));
  EXPECT_THROW(block_lanczos(op, with([](BlockLanczosOptions& o) { o.nev = 10; })),
               std::invalid_argument);
  EXPECT_THROW(block_lanczos(op, with([](BlockLanczosOptions& o) { o.nev = 0; })),
               std::invalid_argument);
  EXPECT_THROW(block_lanczos(op, with([](BlockLanczosOptions& o) { o.block_size = 0; })),
               std::invalid_argument);
  EXPECT_THROW(block_lanczos(op, with([](BlockLanczosOptions& o) { o.tolerance = -1.0; })),
               std::invalid_argument);
  EXPECT_THROW(block_lanczos(op, with([](BlockLanczosOptions& o) { o.max_restarts = -1; })),
               std::invalid_argument);
  // nev must be below M's rank when that is given.
  EXPECT_THROW(block_lanczos(op, with([](BlockLanczosOptions& o) { o.max_dimension = 3; })),
               std::invalid_argument);
}

// The orthonormalisation on a block that nearly lies in span(V) (issue 31): Z = V C + δ W with
// δ = 1e-9, so one pass of Gram–Schmidt leaves cosines with V of about ε / δ ≈ 1e-7, far above
// rounding. Two passes bring them to rounding ("twice is enough") without a re-check round; one
// pass (the Lanczos step's, after its own projection) needs the re-check rounds. Either way
// the result is M-orthonormal, M-orthogonal to V to rounding, and Z_in = V C + Z_out R.
// Removing the second pass makes the first case take a round; removing the rounds leaves the
// second case's cosines at ~1e-7.
TEST(BlockLanczos, OrthogonalisationPassesAndRechecksOnANearlyDependentBlock) {
  std::mt19937 rng(5);
  const int n = 120, m = 16, q = 4;
  const MatrixXd A = random_matrix(n, n, rng);
  const MatrixXd M = A * A.transpose() / n + MatrixXd::Identity(n, n);
  DensePencil P(M, M, 0.0);
  // V: M-orthonormal (Cholesky of its Gram matrix).
  MatrixXd V = random_matrix(n, m, rng);
  const MatrixXd G = V.transpose() * M * V;
  V = V * Eigen::LLT<MatrixXd>(G).matrixU().solve(MatrixXd::Identity(m, m));
  const MatrixXd Zin = V * random_matrix(m, q, rng) + 1e-9 * random_matrix(n, q, rng);
  for (const int passes : {2, 1}) {
    MatrixXd Z = Zin, MZ, scratch;
    const jointid::fem::detail::Projection p =
        jointid::fem::detail::orthonormalise(P, V, m, Z, MZ, 0.0, scratch, passes);
    ASSERT_EQ(Z.cols(), q) << passes;
    EXPECT_EQ(p.rounds == 0, passes == 2) << passes << " passes, " << p.rounds << " rounds";
    const double eps = std::numeric_limits<double>::epsilon();
    EXPECT_LT((Z.transpose() * M * Z - MatrixXd::Identity(q, q)).cwiseAbs().maxCoeff(), 100 * eps)
        << passes;
    EXPECT_LT((V.transpose() * M * Z).cwiseAbs().maxCoeff(), 100 * eps) << passes;
    EXPECT_LT((V * p.C + Z * p.R - Zin).cwiseAbs().maxCoeff(),
              100 * eps * Zin.cwiseAbs().maxCoeff())
        << passes;
  }
}
