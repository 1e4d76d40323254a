#include "fem/gmres.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

using namespace jointid;

namespace {

// A non-symmetric matrix, well conditioned but far from the identity: I + a shifted random part,
// scaled down the diagonal so that the preconditioner (its diagonal) has work to do.
Eigen::MatrixXd test_matrix(int n) {
  std::srand(11);
  Eigen::MatrixXd A = 0.3 * Eigen::MatrixXd::Random(n, n) / std::sqrt(static_cast<double>(n));
  for (int i = 0; i < n; ++i)
    A(i, i) += 1.0 + 10.0 * i / n;
  return A;
}

} // namespace

TEST(Gmres, SolvesANonSymmetricSystemAsTheLuDoesWithAndWithoutRestarts) {
  // Against the dense LU: the true relative residual is below the tolerance asked, and the
  // solution agrees within that tolerance times the condition number; restarted every 8
  // products the same (more products). The diagonal as preconditioner takes fewer products.
  const int n = 120;
  const Eigen::MatrixXd A = test_matrix(n);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  const Eigen::VectorXd exact = A.partialPivLu().solve(b);
  const double condition = A.norm() * A.inverse().norm();
  auto apply = [&](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) {
    out = A * v;
  };
  auto none = [](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) { out = v; };
  auto jacobi = [&](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) {
    out = v.cwiseQuotient(A.diagonal());
  };
  std::vector<int> products;
  for (const int restart : {60, 8})
    for (const bool preconditioned : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "restart " << restart << ", " << preconditioned);
      fem::GmresOptions o;
      o.tolerance = 1e-10, o.restart = restart, o.max_iterations = 2000;
      Eigen::VectorXd x;
      const fem::GmresResult r =
          preconditioned ? fem::gmres(apply, jacobi, b, x, o) : fem::gmres(apply, none, b, x, o);
      ASSERT_TRUE(r.converged);
      EXPECT_LE((b - A * x).norm(), 1e-10 * b.norm());
      EXPECT_LE((x - exact).norm(), 1e-10 * condition * exact.norm());
      products.push_back(r.iterations);
    }
  EXPECT_LT(products[1], products[0]); // the preconditioner helps
  EXPECT_GT(products[2], products[0]); // restarts cost products
}

TEST(Gmres, StopsAtItsProductLimitAndSaysSo) {
  // A limit of 5 products cannot reach 1e-12 on this system: not converged, 5 products taken,
  // and the residual reported is the true one and below the start's (1).
  const Eigen::MatrixXd A = test_matrix(80);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(80);
  fem::GmresOptions o;
  o.tolerance = 1e-12, o.restart = 5, o.max_iterations = 5;
  Eigen::VectorXd x;
  const fem::GmresResult r = fem::gmres(
      [&](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) { out = A * v; },
      [](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) { out = v; }, b, x, o);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 5);
  EXPECT_NEAR(r.residual, (b - A * x).norm() / b.norm(), 1e-12);
  EXPECT_LT(r.residual, 1.0);
  // b = 0: x = 0 at once
  Eigen::VectorXd zero = Eigen::VectorXd::Ones(80);
  EXPECT_TRUE(
      fem::gmres(
          [&](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) { out = A * v; },
          [](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) { out = v; },
          Eigen::VectorXd::Zero(80), zero, o)
          .converged);
  EXPECT_EQ(zero.norm(), 0.0);
}
