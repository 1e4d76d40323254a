// fem::SparseCholesky (CHOLMOD, 64-bit indices): solves checked against the residual and
// against Eigen's own LDLᵀ, orderings on groups, and the errors a caller can meet.
#include "fem/sparse_cholesky.hpp"

#include <Eigen/SparseCholesky>
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using jointid::fem::CholeskyOptions;
using jointid::fem::CholeskyOrdering;
using jointid::fem::SparseCholesky;
using Sparse = Eigen::SparseMatrix<double>;

// A 3D grid of nx·ny·nz "nodes" with `d` unknowns each, coupled like a stiffness matrix: every
// unknown of a node to every unknown of itself and its grid neighbours, with random values
// made symmetric and diagonally dominant (so SPD). Grouped node by node, like fem::DofMap.
struct GridMatrix {
  Sparse A;
  std::vector<int> groups;
};

GridMatrix grid_matrix(int nx, int ny, int nz, int d, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int nodes = nx * ny * nz;
  const int n = nodes * d;
  auto id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  std::vector<Eigen::Triplet<double>> t;
  auto couple = [&](int a, int b) {
    for (int p = 0; p < d; ++p)
      for (int q = 0; q < d; ++q) {
        const double v = u(rng);
        t.emplace_back(a * d + p, b * d + q, v);
        t.emplace_back(b * d + q, a * d + p, v);
      }
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (i + 1 < nx) couple(id(i, j, k), id(i + 1, j, k));
        if (j + 1 < ny) couple(id(i, j, k), id(i, j + 1, k));
        if (k + 1 < nz) couple(id(i, j, k), id(i, j, k + 1));
      }
  GridMatrix g;
  g.A.resize(n, n);
  g.A.setFromTriplets(t.begin(), t.end());
  // Strict diagonal dominance: diag = 1 + Σ|off-diagonal| of the row.
  Eigen::VectorXd row_sum = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j)
    for (Sparse::InnerIterator it(g.A, j); it; ++it)
      row_sum(it.row()) += std::abs(it.value());
  Sparse D(n, n);
  D.setIdentity();
  for (int i = 0; i < n; ++i)
    D.coeffRef(i, i) = 1.0 + row_sum(i);
  g.A += D;
  g.groups.resize(n);
  for (int i = 0; i < n; ++i)
    g.groups[i] = i / d;
  return g;
}

// n × columns standard normal values, reproducible from the seed.
Eigen::MatrixXd random_block(Eigen::Index n, Eigen::Index columns, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd B(n, columns);
  for (Eigen::Index j = 0; j < B.cols(); ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      B(i, j) = normal(rng);
  return B;
}

double relative_residual(const Sparse& A, const Eigen::VectorXd& x, const Eigen::VectorXd& b) {
  return (A * x - b).norm() / b.norm();
}

TEST(SparseCholesky, SolvesLikeEigensLdltForEveryOrderingWithAndWithoutGroups) {
  const GridMatrix g = grid_matrix(7, 6, 5, 6, 1);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(g.A.rows(), -1.0, 2.0);
  const Eigen::VectorXd reference = Eigen::SimplicialLDLT<Sparse>(g.A).solve(b);
  for (CholeskyOrdering ordering : {CholeskyOrdering::automatic, CholeskyOrdering::amd,
                                    CholeskyOrdering::metis, CholeskyOrdering::nesdis})
    for (bool grouped : {false, true}) {
      CholeskyOptions o;
      o.ordering = ordering;
      SparseCholesky llt(o);
      const auto& a = grouped ? llt.analyze(g.A, g.groups) : llt.analyze(g.A);
      EXPECT_EQ(a.rows, g.A.rows());
      EXPECT_GE(a.factor_entries, a.factor_nonzeros);
      EXPECT_GT(a.flops, 0.0);
      EXPECT_EQ(a.ordering.find("on groups") != std::string::npos, grouped) << a.ordering;
      llt.factorize(g.A);
      Eigen::VectorXd x(g.A.rows());
      llt.solve(b.data(), x.data());
      // A is diagonally dominant (condition number ≲ 10²): backward stable Cholesky gives a
      // residual of a few ulps times the size of the problem.
      EXPECT_LT(relative_residual(g.A, x, b), 1e-13)
          << "ordering " << static_cast<int>(ordering) << " grouped " << grouped;
      EXPECT_LT((x - reference).norm() / reference.norm(), 1e-12);
      EXPECT_GT(llt.peak_memory_bytes(), 0.0);
    }
}

TEST(SparseCholesky, ABlockSolveEqualsColumnByColumnSolves) {
  // Seven right-hand sides in one CHOLMOD call (the supernodal solve then works on the block
  // with BLAS-3) against seven single solves: the same solutions to rounding, each with its
  // own residual; then widths 1 and 7 again, in either order, on the workspace kept between
  // calls. A block solve that mixed up columns, solved only the first or read the leading
  // dimension wrongly fails by O(1).
  const GridMatrix g = grid_matrix(6, 5, 5, 6, 4);
  const Eigen::Index n = g.A.rows();
  const Eigen::MatrixXd B = random_block(n, 7, 9);
  SparseCholesky llt;
  llt.analyze(g.A, g.groups);
  llt.factorize(g.A);
  Eigen::MatrixXd single(n, 7);
  for (Eigen::Index j = 0; j < 7; ++j)
    llt.solve(B.col(j).data(), single.col(j).data());
  Eigen::MatrixXd block(n, 7);
  llt.solve(B.data(), block.data(), 7);
  for (Eigen::Index j = 0; j < 7; ++j) {
    EXPECT_LT((block.col(j) - single.col(j)).norm(), 1e-13 * single.col(j).norm()) << j;
    EXPECT_LT(relative_residual(g.A, block.col(j), B.col(j)), 1e-13) << j;
  }
  EXPECT_LT((llt.solve(B) - single).norm(), 1e-13 * single.norm()); // the Eigen overload
  Eigen::VectorXd x(n);
  llt.solve(B.col(3).data(), x.data());
  EXPECT_LT((x - single.col(3)).norm(), 1e-13 * x.norm());
  EXPECT_LT((llt.solve(B.rightCols(2)) - single.rightCols(2)).norm(), 1e-13 * single.norm());
  EXPECT_EQ(llt.solve(Eigen::MatrixXd(n, 0)).cols(), 0);
  EXPECT_THROW(llt.solve(Eigen::MatrixXd::Ones(n + 1, 2)), std::invalid_argument);
  EXPECT_THROW(llt.solve(B.data(), block.data(), -1), std::invalid_argument);
  SparseCholesky unfactorized;
  EXPECT_THROW(unfactorized.solve(B.data(), block.data(), 7), std::logic_error);
}

TEST(SparseCholesky, OwnBlockSolveEqualsCholmodsForEveryWidth) {
  // Our supernodal substitution (fem/supernodal_solve.hpp, every core) against CHOLMOD's solve
  // of the same factor, column by column. The 12 × 12 × 12 grid of 6 unknowns (10 368) has a
  // top separator of 864 columns, so its panels of 256, the share of rows and columns among
  // the cores, the subtrees below the cut, the kernels' groups of 8, 4, 2 and 1 columns and the
  // padding of the right-hand sides to a multiple of 8 are all run. Widths 2-17 (all
  // remainders by 4 and 8), two orderings, 1-5 cores, a zero column; then a small grid.
  const GridMatrix g = grid_matrix(12, 12, 12, 6, 11);
  const Eigen::Index n = g.A.rows();
  Eigen::MatrixXd B = random_block(n, 17, 5);
  B.col(5).setZero();
  for (CholeskyOrdering ordering : {CholeskyOrdering::automatic, CholeskyOrdering::amd}) {
    CholeskyOptions cholmod_only, own;
    cholmod_only.ordering = own.ordering = ordering;
    cholmod_only.own_solve_columns = 0;
    own.own_solve_columns = 2;
    SparseCholesky reference(cholmod_only);
    reference.analyze(g.A, g.groups);
    reference.factorize(g.A);
    Eigen::MatrixXd single(n, B.cols());
    for (Eigen::Index j = 0; j < B.cols(); ++j)
      reference.solve(B.col(j).data(), single.col(j).data());
    // Every core of this machine (0), and 1, 3 and 5 cores: the elimination tree cut and its
    // subtrees dealt differently, the top's rows and columns shared in other proportions.
    for (int threads : {0, 1, 3, 5}) {
      own.own_solve_threads = threads;
      SparseCholesky llt(own);
      llt.analyze(g.A, g.groups);
      llt.factorize(g.A);
      for (Eigen::Index width = 2; width <= B.cols(); ++width) {
        if (threads != 0 && width != 2 && width != 8 && width != 13) continue;
        const Eigen::MatrixXd X = llt.solve(B.leftCols(width));
        for (Eigen::Index j = 0; j < width; ++j) {
          // The same factor and arithmetic up to the order of the sums: rounding only. The
          // solution of a zero column is exactly zero.
          EXPECT_LE((X.col(j) - single.col(j)).norm(), 1e-13 * single.col(j).norm())
              << "threads " << threads << " width " << width << " column " << j;
          if (j != 5) {
            EXPECT_LT(relative_residual(g.A, X.col(j), B.col(j)), 1e-13) << width << " " << j;
          }
        }
      }
      // A second solve with the plan and work space of the first (the top's update buffers
      // must have been emptied).
      const Eigen::MatrixXd again = llt.solve(B.leftCols(8));
      EXPECT_LE((again.col(7) - single.col(7)).norm(), 1e-13 * single.col(7).norm()) << threads;
    }
  }
  const GridMatrix small = grid_matrix(5, 4, 4, 3, 12);
  CholeskyOptions own;
  own.own_solve_columns = 2;
  SparseCholesky llt(own);
  llt.analyze(small.A);
  llt.factorize(small.A);
  const Eigen::MatrixXd Bs = Eigen::MatrixXd::Random(small.A.rows(), 3);
  const Eigen::MatrixXd Xs = llt.solve(Bs);
  EXPECT_LT((small.A * Xs - Bs).norm() / Bs.norm(), 1e-13);
}

TEST(SparseCholesky, AutomaticKeepsTheCandidateNeedingLeastMemory) {
  // `automatic` with groups: METIS and NESDIS on the groups, CHOLMOD's default on the
  // equations; the smallest predicted factor is kept.
  const GridMatrix g = grid_matrix(9, 9, 9, 6, 2);
  auto bytes = [&](CholeskyOrdering ordering, bool grouped) {
    CholeskyOptions o;
    o.ordering = ordering;
    SparseCholesky llt(o);
    return (grouped ? llt.analyze(g.A, g.groups) : llt.analyze(g.A)).factor_bytes;
  };
  const double best =
      std::min({bytes(CholeskyOrdering::metis, true), bytes(CholeskyOrdering::nesdis, true),
                bytes(CholeskyOrdering::automatic, false)});
  SparseCholesky llt;
  EXPECT_EQ(llt.analyze(g.A, g.groups).factor_bytes, best);
}

TEST(SparseCholesky, GroupsWorkWithALowerTriangleAndShuffledGroupNumbers) {
  // Only the lower triangle stored, and group numbers that do not grow with the equations:
  // the group graph must still see every coupling (else the ordering is poor, not wrong, so
  // the check is on the fill against the same matrix stored in full).
  const GridMatrix g = grid_matrix(6, 6, 6, 3, 7);
  std::vector<int> shuffled(g.groups.size());
  const int nodes = g.groups.back() + 1;
  for (std::size_t i = 0; i < shuffled.size(); ++i)
    shuffled[i] = nodes - 1 - g.groups[i];
  const Sparse lower = g.A.triangularView<Eigen::Lower>();
  CholeskyOptions o;
  o.ordering = CholeskyOrdering::metis;
  SparseCholesky full(o), low(o);
  EXPECT_EQ(low.analyze(lower, shuffled).factor_nonzeros,
            full.analyze(g.A, shuffled).factor_nonzeros);
  low.factorize(lower);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(g.A.rows());
  Eigen::VectorXd x(g.A.rows());
  low.solve(b.data(), x.data());
  EXPECT_LT(relative_residual(g.A, x, b), 1e-13);
}

TEST(SparseCholesky, GroupNumbersAreLabels) {
  // Gaps and negative numbers (fixed nodes leave gaps in fem::DofMap's node positions) give
  // the same ordering as the dense numbers 0 .. groups-1 in the same order.
  const GridMatrix g = grid_matrix(5, 5, 4, 3, 8);
  std::vector<int> sparse_labels(g.groups.size());
  for (std::size_t i = 0; i < g.groups.size(); ++i)
    sparse_labels[i] = 1000 * g.groups[i] - 7;
  CholeskyOptions o;
  o.ordering = CholeskyOrdering::metis;
  SparseCholesky dense(o), gaps(o);
  EXPECT_EQ(gaps.analyze(g.A, sparse_labels).factor_nonzeros,
            dense.analyze(g.A, g.groups).factor_nonzeros);
  gaps.factorize(g.A);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(g.A.rows());
  Eigen::VectorXd x(g.A.rows());
  gaps.solve(b.data(), x.data());
  EXPECT_LT(relative_residual(g.A, x, b), 1e-13);
}

TEST(SparseCholesky, ReadsOnlyTheLowerTriangle) {
  GridMatrix g = grid_matrix(4, 4, 3, 2, 3);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(g.A.rows());
  SparseCholesky clean;
  clean.factorize(g.A);
  Eigen::VectorXd x_clean(g.A.rows());
  clean.solve(b.data(), x_clean.data());
  // Spoil the strict upper triangle.
  for (int j = 0; j < g.A.outerSize(); ++j)
    for (Sparse::InnerIterator it(g.A, j); it; ++it)
      if (it.row() < j) it.valueRef() = 1e6;
  SparseCholesky spoiled;
  spoiled.factorize(g.A);
  Eigen::VectorXd x(g.A.rows());
  spoiled.solve(b.data(), x.data());
  EXPECT_LT((x - x_clean).norm(), 1e-14 * x_clean.norm());
}

TEST(SparseCholesky, ReportsAMatrixThatIsNotPositiveDefinite) {
  // Every leading block without equation 10 is diagonally dominant, so the factorisation
  // breaks down exactly when it reaches equation 10, whatever the ordering: the error names
  // it in the caller's numbering.
  GridMatrix g = grid_matrix(5, 4, 3, 3, 4);
  g.A.coeffRef(10, 10) = -1.0;
  SparseCholesky llt;
  try {
    llt.factorize(g.A);
    FAIL() << "no error";
  } catch (const jointid::fem::NotPositiveDefinite& e) {
    EXPECT_EQ(e.equation(), 10);
    EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("equation 10"), std::string::npos) << e.what();
  }
  Eigen::VectorXd b = Eigen::VectorXd::Ones(g.A.rows()), x(g.A.rows());
  EXPECT_THROW(llt.solve(b.data(), x.data()), std::logic_error);
}

TEST(SparseCholesky, RefusesAFactorLargerThanTheMemoryAvailable) {
  const GridMatrix g = grid_matrix(5, 5, 5, 6, 5);
  ASSERT_GT(jointid::fem::available_memory_bytes(), 0.0); // Linux /proc/meminfo
  CholeskyOptions o;
  o.max_memory_fraction = 1e-12; // a few bytes allowed
  SparseCholesky llt(o);
  const double need = llt.analyze(g.A, g.groups).factor_bytes;
  EXPECT_GT(need, 8.0 * llt.analysis().factor_entries - 1.0);
  try {
    llt.factorize(g.A);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("GiB"), std::string::npos) << what;
    EXPECT_NE(what.find("available"), std::string::npos) << what;
  }
}

TEST(SparseCholesky, RejectsBadShapesAndGroups) {
  const GridMatrix g = grid_matrix(3, 3, 3, 2, 6);
  SparseCholesky llt;
  EXPECT_THROW(llt.analyze(Sparse(4, 5)), std::invalid_argument);
  EXPECT_THROW(llt.analyze(g.A, std::vector<int>(3, 0)), std::invalid_argument);
  llt.analyze(g.A);
  EXPECT_THROW(llt.factorize(Sparse(g.A.rows() - 1, g.A.rows() - 1)), std::invalid_argument);
  // Same size, another pattern: refused (CHOLMOD would scatter into the wrong places).
  Sparse other = g.A;
  other.coeffRef(g.A.rows() - 1, 0) = 0.5;
  other.coeffRef(0, g.A.rows() - 1) = 0.5;
  EXPECT_THROW(llt.factorize(other), std::invalid_argument);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(g.A.rows()), x(g.A.rows());
  EXPECT_THROW(llt.solve(b.data(), x.data()), std::logic_error); // analysed, not factorised
}

} // namespace
