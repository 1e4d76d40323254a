// Damping matrices: diagonalised by the undamped modes with the ratios the model states.
#include "fem/damping.hpp"

#include "support/beam_models.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

using namespace jointid;

namespace {

struct Beam {
  fem::Assembled system = fem::assemble(test::cantilever(8, {}));
  fem::Modes modes = [this] {
    fem::ModalOptions o;
    o.num_modes = 0;
    o.engine = fem::ModalEngine::dense;
    return fem::modal_analysis(system, o);
  }();
};

// max |D^{-1/2} (ΦᵀCΦ − D) D^{-1/2}|, entry (i, j) relative to sqrt(d_i d_j), so that the low
// modes count as much as the high ones. ΦᵀMΦ = I to ε ≈ 1e-13, so ΦᵀCΦ − D ≈ ε (d_i + d_j)
// and the scaled deviation is ≲ 2ε sqrt(d_max/d_min) ≈ 1e-11 for these spectra: 1e-9 asserted.
double scaled_deviation(const Eigen::MatrixXd& modal, const Eigen::VectorXd& d) {
  const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
  return (s.asDiagonal() * (modal - Eigen::MatrixXd(d.asDiagonal())) * s.asDiagonal())
      .cwiseAbs()
      .maxCoeff();
}

} // namespace

TEST(Damping, RayleighIsAlphaMPlusBetaKAndGivesItsModalRatios) {
  const Beam b;
  fem::Damping d;
  d.kind = fem::Damping::Kind::rayleigh;
  d.alpha = 0.8;
  d.beta = 2e-5;
  const Eigen::MatrixXd C(fem::damping_matrix(b.system, d));
  const Eigen::MatrixXd K(b.system.K), M(b.system.M);
  EXPECT_LE((C - (d.alpha * M + d.beta * K)).norm(), 1e-15 * C.norm());
  // In modal coordinates: ΦᵀCΦ = diag(α + β ω_r²) = diag(2 ζ_r ω_r) with the ratio the model
  // reports, ζ = α/2ω + βω/2.
  const Eigen::MatrixXd modal = b.modes.phi.transpose() * C * b.modes.phi;
  const int n = b.modes.num_modes();
  Eigen::VectorXd expected(n);
  for (int r = 0; r < n; ++r) {
    const double w = b.modes.omega(r);
    expected(r) = d.alpha + d.beta * w * w;
    EXPECT_NEAR(2.0 * d.ratio(w) * w, expected(r), 1e-14 * expected(r));
  }
  EXPECT_LE(scaled_deviation(modal, expected), 1e-9);
}

TEST(Damping, ModalMatrixIsDiagonalisedByTheModes) {
  const Beam b;
  fem::Damping d;
  d.kind = fem::Damping::Kind::modal;
  d.modal_ratio = 0.02;
  const Eigen::MatrixXd C(fem::damping_matrix(b.system, d, &b.modes));
  const int n = b.modes.num_modes();
  Eigen::VectorXd expected(n);
  for (int r = 0; r < n; ++r)
    expected(r) = 2.0 * 0.02 * b.modes.omega(r);
  const Eigen::MatrixXd modal = b.modes.phi.transpose() * C * b.modes.phi;
  EXPECT_LE(scaled_deviation(modal, expected), 1e-9);
  EXPECT_LE((C - C.transpose()).norm(), 1e-14 * C.norm());
}

TEST(Damping, ModalDampingOfAnOscillatorIsTwoZetaSqrtKM) {
  // c = 2 ζ sqrt(k m), the textbook viscous coefficient of a single-DOF oscillator.
  const double m = 3.0, k = 2700.0, zeta = 0.05;
  const fem::Assembled s = fem::assemble(test::oscillator(m, k));
  const fem::Modes modes = fem::modal_analysis(s, {.num_modes = 1});
  fem::Damping d;
  d.kind = fem::Damping::Kind::modal;
  d.modal_ratio = zeta;
  const Eigen::MatrixXd C(fem::damping_matrix(s, d, &modes));
  EXPECT_NEAR(C(0, 0), 2 * zeta * std::sqrt(k * m), 1e-13 * 2 * zeta * std::sqrt(k * m));
}

TEST(Damping, ModalNeedsEveryMode) {
  const Beam b;
  fem::Damping d;
  d.kind = fem::Damping::Kind::modal;
  d.modal_ratio = 0.01;
  EXPECT_THROW(fem::damping_matrix(b.system, d), std::invalid_argument);
  const fem::Modes some =
      fem::modal_analysis(b.system, {.num_modes = 4, .engine = fem::ModalEngine::dense});
  EXPECT_THROW(fem::damping_matrix(b.system, d, &some), std::invalid_argument);
}

TEST(Damping, NoneIsAnEmptyMatrixOfTheRightSize) {
  const Beam b;
  const fem::SparseMatrix C = fem::damping_matrix(b.system, fem::Damping{});
  EXPECT_EQ(C.rows(), b.system.dofs.num_equations());
  EXPECT_EQ(C.cols(), b.system.dofs.num_equations());
  EXPECT_EQ(C.nonZeros(), 0);
}
