// Modal analysis against Euler–Bernoulli beam theory, eigen-equation properties and the
// second engine.
#include "fem/modal.hpp"

#include "bench/lattice.hpp"
#include "support/beam_models.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

using namespace jointid;
using fem::ModalEngine;

namespace {

using jointid::test::eps;
using jointid::test::pi;

// Roots βL of the beam characteristic equations, by Newton from a nearby start:
// cantilever 1 + cos x cosh x = 0, free–free 1 − cos x cosh x = 0.
double characteristic_root(double start, double sign) {
  double x = start;
  for (int i = 0; i < 60; ++i)
    x -= (sign + std::cos(x) * std::cosh(x)) /
         (-std::sin(x) * std::cosh(x) + std::cos(x) * std::sinh(x));
  return x;
}
double cantilever_root(double start) {
  return characteristic_root(start, 1.0);
}
double free_free_root(double start) {
  return characteristic_root(start, -1.0);
}

fem::Modes modes_of(const fem::Model& model, int count, ModalEngine engine = ModalEngine::dense) {
  fem::ModalOptions o;
  o.num_modes = count;
  o.engine = engine;
  fem::Modes m = fem::modal_analysis(fem::assemble(model), o);
  EXPECT_TRUE(m.status.ok());
  return m;
}

// Relative error of mode r of an n-element cantilever against the analytic value.
double cantilever_error(int n, int r) {
  const test::BeamProperties p;
  const double beta_L[] = {cantilever_root(1.875104), cantilever_root(4.694091),
                           cantilever_root(7.854757)};
  const fem::Modes m = modes_of(test::cantilever(n, p), r + 1);
  return m.omega(r) / (beta_L[r] * beta_L[r] * p.omega_scale()) - 1.0;
}

} // namespace

TEST(Modal, CharacteristicRootsMatchTheTabulatedValues) {
  // Guards the reference itself: the Newton roots reproduce the published βL to their 7 digits.
  EXPECT_NEAR(cantilever_root(1.9), 1.875104, 5e-7);
  EXPECT_NEAR(cantilever_root(4.7), 4.694091, 5e-7);
  EXPECT_NEAR(cantilever_root(7.85), 7.854757, 5e-7);
  EXPECT_NEAR(cantilever_root(11.0), 10.995541, 5e-7);
  EXPECT_NEAR(free_free_root(4.7), 4.730041, 5e-7);
}

TEST(Modal, CantileverMatchesAnalyticFrequencies) {
  // 40 Hermite elements: the discretisation error of the first four modes is far below 0.1 %
  // (it falls as h⁴, see the next test), so 0.1 % can only fail on a modelling error.
  const test::BeamProperties p;
  const fem::Modes m = modes_of(test::cantilever(40, p), 4);
  const double beta_L[] = {1.875104, 4.694091, 7.854757, 10.995541};
  ASSERT_EQ(m.num_modes(), 4);
  for (int r = 0; r < 4; ++r) {
    const double exact = beta_L[r] * beta_L[r] * p.omega_scale();
    EXPECT_NEAR(m.omega(r), exact, 1e-3 * exact) << "mode " << r + 1;
    // Consistent mass and exact stiffness: Rayleigh–Ritz, so FE frequencies lie above.
    EXPECT_GT(m.omega(r), exact * (1.0 - 1e-6)) << "mode " << r + 1;
  }
  // The METHOD.md beam has its first mode at 3.0 Hz (thickness chosen for the 6-element model).
  EXPECT_NEAR(m.frequency_hz(0), 3.0, 3e-3);
}

TEST(Modal, FrequencyErrorConvergesAsHToTheFourth) {
  // Hermite cubic elements with consistent mass: eigenvalue error O(h^4). Errors at n = 4, 8
  // (mode 1) and 8, 16 (mode 2) are 1e-6 … 1e-3, far above the rounding of the eigensolver
  // (~1e-12 for these small models), so their ratio must be close to 2⁴ = 16.
  const double mode1 = cantilever_error(4, 0) / cantilever_error(8, 0);
  const double mode2 = cantilever_error(8, 1) / cantilever_error(16, 1);
  EXPECT_GT(mode1, 12.0);
  EXPECT_LT(mode1, 20.0);
  EXPECT_GT(mode2, 12.0);
  EXPECT_LT(mode2, 20.0);
}

TEST(Modal, ModesAreMassOrthonormalAndSatisfyTheEigenEquation) {
  const fem::Assembled s = fem::assemble(test::cantilever(12, {}));
  fem::ModalOptions o;
  o.num_modes = 0; // all
  o.engine = ModalEngine::dense;
  const fem::Modes m = fem::modal_analysis(s, o);
  ASSERT_EQ(m.num_modes(), s.dofs.num_equations());
  const Eigen::MatrixXd K(s.K), M(s.M);
  const int n = m.num_modes();
  // Backward-stable dense solver: ΦᵀMΦ = I to a few hundred eps (n = 24).
  EXPECT_LE((m.phi.transpose() * M * m.phi - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff(),
            1e-12);
  // Residual of each mode relative to ‖Kφ‖ + ω²‖Mφ‖: rounding of order eps·‖K‖/‖Kφ‖ for the
  // lowest modes (cond ≈ (ω_max/ω_1)² ≈ 1e6 here), so 1e-8 leaves margin and still catches any
  // wrong pair (relative residual of order 1).
  for (int r = 0; r < n; ++r) {
    const Eigen::VectorXd Kphi = K * m.phi.col(r), Mphi = M * m.phi.col(r);
    const double w2 = m.omega(r) * m.omega(r);
    EXPECT_LE((Kphi - w2 * Mphi).norm(), 1e-8 * (Kphi.norm() + w2 * Mphi.norm())) << "mode " << r;
  }
  for (int r = 1; r < n; ++r) {
    EXPECT_GE(m.omega(r), m.omega(r - 1));
  }
}

TEST(Modal, SparseEngineEqualsDenseEngine) {
  // 10 elements: the dense solver's eigenvalue error is ≈ eps·λ_max, i.e. a relative error
  // eps·(ω_max/ω_1)² ≈ 2e-16 · 3e6 ≈ 6e-10 at worst for mode 1 — below the 1e-9 asked. The
  // shift-invert Lanczos is relative-accurate at the low end. Shapes: eigenvector error
  // ≈ eps·λ_max / gap ≈ 1e-10; compared up to sign with 1e-7.
  const fem::Assembled s = fem::assemble(test::cantilever(10, {}));
  fem::ModalOptions o;
  o.num_modes = 6;
  o.engine = ModalEngine::dense;
  const fem::Modes dense = fem::modal_analysis(s, o);
  o.engine = ModalEngine::sparse;
  const fem::Modes sparse = fem::modal_analysis(s, o);
  ASSERT_TRUE(sparse.status.ok());
  ASSERT_EQ(sparse.num_modes(), 6);
  for (int r = 0; r < 6; ++r) {
    EXPECT_NEAR(sparse.omega(r), dense.omega(r), 1e-9 * dense.omega(r)) << "mode " << r;
    const double sign = dense.phi.col(r).dot(sparse.phi.col(r)) >= 0 ? 1.0 : -1.0;
    EXPECT_LE((dense.phi.col(r) - sign * sparse.phi.col(r)).norm(), 1e-7 * dense.phi.col(r).norm())
        << "mode " << r;
  }
  // The sparse engine reports what it did; the dense one does not.
  EXPECT_FALSE(dense.sparse.has_value());
  ASSERT_TRUE(sparse.sparse.has_value());
  const fem::SparseModalStats& st = *sparse.sparse;
  EXPECT_EQ(st.factor.rows, s.dofs.num_equations());
  EXPECT_GE(st.factor.factor_nonzeros, s.dofs.num_equations()); // at least the diagonal
  EXPECT_NE(st.factor.ordering.find("on groups"), std::string::npos) << st.factor.ordering;
  // Block Lanczos (the default): 20 equations, 6 modes, so blocks of 7 (the block is cut to
  // (20 − 6)/2 for so small a space) and the whole space in 3 solves (7, 7, and 6 columns
  // that remain), exact.
  EXPECT_EQ(st.method, "block Lanczos");
  EXPECT_EQ(st.block_size, 7);
  EXPECT_EQ(st.ncv, 20);
  EXPECT_EQ(st.solves, 3);
  EXPECT_EQ(st.right_hand_sides, 20);
  // Spectra, one right-hand side per solve, still reachable and the same modes.
  o.sparse_method = fem::SparseMethod::spectra;
  const fem::Modes spectra = fem::modal_analysis(s, o);
  ASSERT_TRUE(spectra.status.ok());
  for (int r = 0; r < 6; ++r)
    EXPECT_NEAR(spectra.omega(r), dense.omega(r), 1e-9 * dense.omega(r)) << "mode " << r;
  ASSERT_TRUE(spectra.sparse.has_value());
  EXPECT_EQ(spectra.sparse->method, "Spectra");
  EXPECT_GE(spectra.sparse->solves, 6);
  EXPECT_EQ(spectra.sparse->right_hand_sides, spectra.sparse->solves);
  EXPECT_GE(spectra.sparse->ncv, 13);
}

TEST(Modal, SimplySupportedBeamFrequencies) {
  // Pinned at both ends (uy fixed, rz free): ω_n = (nπ)² sqrt(EI/ρAL⁴). 20 elements: error
  // O(h⁴) ≈ 1e-5 for mode 4, well inside 1e-3.
  const test::BeamProperties p;
  fem::Model model = test::uniform_beam(20, p);
  model.supports.push_back({1, {fem::Dof::uy}});
  model.supports.push_back({21, {fem::Dof::uy}});
  const fem::Modes m = modes_of(model, 4);
  for (int r = 0; r < 4; ++r) {
    const double exact = std::pow((r + 1) * pi, 2) * p.omega_scale();
    EXPECT_NEAR(m.omega(r), exact, 1e-3 * exact) << "mode " << r + 1;
  }
}

TEST(Modal, ClampedClampedBeamFrequenciesWithTheSparseEngine) {
  // Clamped at both ends: cos x cosh x = 1, the same roots as free–free (4.730041, 7.853205,
  // 10.995608, ...). 40 elements, Spectra + CHOLMOD: error O(h⁴) ≈ 1e-5 for mode 4.
  const test::BeamProperties p;
  fem::Model model = test::uniform_beam(40, p);
  model.supports.push_back({1, {fem::Dof::uy, fem::Dof::rz}});
  model.supports.push_back({41, {fem::Dof::uy, fem::Dof::rz}});
  const fem::Modes m = modes_of(model, 4, ModalEngine::sparse);
  const double starts[] = {4.73, 7.85, 11.0, 14.14};
  for (int r = 0; r < 4; ++r) {
    const double root = free_free_root(starts[r]);
    const double exact = root * root * p.omega_scale();
    EXPECT_NEAR(m.omega(r), exact, 1e-3 * exact) << "mode " << r + 1;
    EXPECT_GT(m.omega(r), exact * (1 - 1e-12)) << "Rayleigh–Ritz bounds from above";
  }
}

TEST(Modal, FreeFreeFrameHasThreeRigidModesInBothEngines) {
  // A free planar frame: two translations and a rotation with ω = 0. In floating point the
  // rigid eigenvalues are rounding of K, |λ| ≲ eps·λ_max·(a few tens); the sparse engine works
  // on K − σM with σ < 0 (default shift), whose factorisation has the same rounding. The 4th
  // mode is the first free–free bending mode, (4.730041)² sqrt(EI/ρAL⁴).
  const test::BeamProperties p;
  const fem::Model model = test::uniform_beam(20, p, fem::ElementType::frame2d);
  const fem::Assembled s = fem::assemble(model);
  fem::ModalOptions o;
  o.num_modes = 0;
  o.engine = ModalEngine::dense;
  const fem::Modes all = fem::modal_analysis(s, o);
  ASSERT_TRUE(all.status.ok());
  const double lambda_max = std::pow(all.omega(all.num_modes() - 1), 2);
  const double rigid_bound = std::sqrt(100 * eps * lambda_max);
  const double bending = std::pow(free_free_root(4.73), 2) * p.omega_scale();
  ASSERT_GT(bending, 1e3 * rigid_bound); // the bound separates rigid from elastic modes

  o.num_modes = 5;
  o.engine = ModalEngine::sparse;
  ASSERT_GT(o.shift_hz, 0.0); // σ = −(2π shift_hz)² < 0: K − σM is positive definite
  const fem::Modes sparse = fem::modal_analysis(s, o);
  ASSERT_TRUE(sparse.status.ok());
  for (const fem::Modes* m : {&all, &sparse}) {
    for (int r = 0; r < 3; ++r) {
      EXPECT_LE(m->omega(r), rigid_bound) << "rigid mode " << r;
    }
    EXPECT_NEAR(m->omega(3), bending, 1e-3 * bending);
  }
  EXPECT_NEAR(sparse.omega(4), all.omega(4), 1e-9 * all.omega(4));
  // The three rigid shapes span the rigid motions: their strain energy φᵀKφ = ω² is tiny and
  // they are M-orthonormal.
  const Eigen::MatrixXd R = sparse.phi.leftCols(3);
  EXPECT_LE((R.transpose() * Eigen::MatrixXd(s.M) * R - Eigen::MatrixXd::Identity(3, 3)).norm(),
            1e-8);
}

TEST(Modal, LumpedMassConvergesToTheSameFirstFrequency) {
  // HRZ lumping is only O(h²) accurate (the consistent mass is O(h⁴)): with 40 elements the
  // first frequency is within 1e-3, and halving h divides the error by ≈ 4.
  const test::BeamProperties p;
  const double exact = std::pow(cantilever_root(1.875), 2) * p.omega_scale();
  auto lumped_error = [&](int n) {
    fem::Model model = test::cantilever(n, p);
    model.mass_options.lumped = true;
    return std::abs(modes_of(model, 1).omega(0) / exact - 1.0);
  };
  const double e20 = lumped_error(20), e40 = lumped_error(40);
  EXPECT_LT(e40, 1e-3);
  EXPECT_GT(e20 / e40, 3.0);
  EXPECT_LT(e20 / e40, 5.0);
}

TEST(Modal, FrequencyBandReturnsExactlyTheModesBelowIt) {
  const fem::Assembled s = fem::assemble(test::cantilever(40, {}));
  fem::ModalOptions o;
  o.num_modes = 0;
  o.engine = ModalEngine::dense;
  const fem::Modes all = fem::modal_analysis(s, o);
  // Band edges halfway between modes 5/6 and 12/13 (12 > the sparse engine's first guess of
  // 8 modes, so its growing search is exercised).
  for (int below : {5, 12}) {
    const double f_max = 0.5 * (all.frequency_hz(below - 1) + all.frequency_hz(below));
    for (ModalEngine engine : {ModalEngine::dense, ModalEngine::sparse}) {
      fem::ModalOptions band;
      band.max_frequency_hz = f_max;
      band.engine = engine;
      const fem::Modes m = fem::modal_analysis(s, band);
      ASSERT_TRUE(m.status.ok());
      ASSERT_EQ(m.num_modes(), below) << "engine " << static_cast<int>(engine);
      EXPECT_LT(m.frequency_hz(below - 1), f_max);
      // Same modes as the full solution (dense accuracy: eps·λ_max relative ~1e-7 here).
      for (int r = 0; r < below; ++r) {
        EXPECT_NEAR(m.omega(r), all.omega(r), 1e-7 * all.omega(r));
      }
    }
  }
}

TEST(Modal, BadOptionsThrow) {
  const fem::Assembled s = fem::assemble(test::cantilever(3, {}));
  fem::ModalOptions o;
  o.num_modes = 7; // 6 equations
  EXPECT_THROW(fem::modal_analysis(s, o), std::invalid_argument);
  o.num_modes = -1;
  EXPECT_THROW(fem::modal_analysis(s, o), std::invalid_argument);
  o.num_modes = 0;
  o.engine = ModalEngine::sparse;
  EXPECT_THROW(fem::modal_analysis(s, o), std::invalid_argument);
}

// A lumped mass matrix without rotary inertia: the rotations are massless. Both engines must
// give the modes of the statically condensed model (rotations eliminated from K, exact for a
// massless DOF): ω² from K* = Ktt − Ktr Krr⁻¹ Krt with Mtt, and φr = −Krr⁻¹ Krt φt.
TEST(Modal, MasslessRotationsGiveTheCondensedModelsModes) {
  fem::Assembled s = fem::assemble(test::cantilever(60, {}));
  const int n = s.dofs.num_equations();
  std::vector<int> t, r; // translations (mass), rotations (none)
  Eigen::VectorXd lumped = Eigen::VectorXd::Zero(n);
  const Eigen::MatrixXd M(s.M);
  for (int e = 0; e < n; ++e) {
    if (s.dofs.node_dof(e).dof == fem::Dof::rz) {
      r.push_back(e);
    } else {
      t.push_back(e);
      for (int j = 0; j < n; ++j) // the row sum of the translational part: a lumped mass
        if (s.dofs.node_dof(j).dof != fem::Dof::rz) lumped(e) += M(e, j);
    }
  }
  ASSERT_EQ(r.size(), t.size());
  s.M = fem::SparseMatrix(lumped.asDiagonal());
  const Eigen::MatrixXd K(s.K);
  const auto nt = static_cast<Eigen::Index>(t.size());
  Eigen::MatrixXd Ktt(nt, nt), Ktr(nt, nt), Krr(nt, nt), Mtt = Eigen::MatrixXd::Zero(nt, nt);
  for (Eigen::Index i = 0; i < nt; ++i) {
    Mtt(i, i) = lumped(t[i]);
    for (Eigen::Index j = 0; j < nt; ++j) {
      Ktt(i, j) = K(t[i], t[j]);
      Ktr(i, j) = K(t[i], r[j]);
      Krr(i, j) = K(r[i], r[j]);
    }
  }
  const Eigen::LLT<Eigen::MatrixXd> Krr_llt(Krr);
  const Eigen::MatrixXd condensed = Ktt - Ktr * Krr_llt.solve(Ktr.transpose());
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> reference(condensed, Mtt);
  const int count = 6;
  for (const ModalEngine engine : {ModalEngine::dense, ModalEngine::sparse}) {
    fem::ModalOptions o;
    o.num_modes = count;
    o.engine = engine;
    const fem::Modes m = fem::modal_analysis(s, o);
    ASSERT_TRUE(m.status.ok()) << m.status.reason;
    ASSERT_EQ(m.num_modes(), count);
    // ΦᵀMΦ = I (rounding level: the solvers' accuracy, eps times the spread of the spectrum).
    const Eigen::MatrixXd gram = m.phi.transpose() * (s.M * m.phi);
    EXPECT_LT((gram - Eigen::MatrixXd::Identity(count, count)).cwiseAbs().maxCoeff(), 1e-9);
    for (int k = 0; k < count; ++k) {
      // Backward-stable solvers (and the condensation) err by ~eps·λ_max absolute; the sparse
      // engine's Lanczos tolerance is 1e-10 relative.
      const double lambda = reference.eigenvalues()(k);
      const double lambda_max = reference.eigenvalues()(nt - 1);
      EXPECT_NEAR(m.omega(k) * m.omega(k), lambda, 1e-10 * lambda + 100.0 * eps * lambda_max)
          << "engine " << static_cast<int>(engine) << ", mode " << k + 1;
      Eigen::VectorXd phi_t(nt), phi_r(nt);
      for (Eigen::Index i = 0; i < nt; ++i) {
        phi_t(i) = m.phi(t[i], k);
        phi_r(i) = m.phi(r[i], k);
      }
      const Eigen::VectorXd expected = reference.eigenvectors().col(k);
      const double sign = phi_t.dot(expected) < 0.0 ? -1.0 : 1.0;
      EXPECT_LT((sign * phi_t - expected).norm(), 1e-7 * expected.norm());
      const Eigen::VectorXd condensed_r = -Krr_llt.solve(Ktr.transpose() * phi_t);
      EXPECT_LT((phi_r - condensed_r).norm(), 1e-7 * condensed_r.norm());
    }
  }
  // All modes of the dense engine: only the finite ones, as many as the massive DOFs.
  fem::ModalOptions all;
  all.num_modes = 0;
  all.engine = ModalEngine::dense;
  EXPECT_EQ(fem::modal_analysis(s, all).num_modes(), nt);
}

TEST(Modal, BothEnginesNameTheDofThatIsNeitherStiffNorHeavy) {
  // A spring of zero stiffness to a massless node: K − σM has a zero row at 99:uy.
  fem::Model m = test::cantilever(10, {});
  m.nodes.push_back({99, Eigen::Vector3d(5.0, 5.0, 0.0)});
  m.springs.push_back({99, 0, fem::Dof::uy, 0.0});
  for (const ModalEngine engine : {ModalEngine::dense, ModalEngine::sparse}) {
    fem::ModalOptions o;
    o.num_modes = 3;
    o.engine = engine;
    try {
      fem::modal_analysis(fem::assemble(m), o);
      FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("99:uy"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
    }
  }
  // A spring without a mass and nothing else: no finite mode at all, an empty result.
  fem::Model massless = test::oscillator(1.0, 100.0);
  massless.masses.clear();
  fem::ModalOptions dense;
  dense.num_modes = 0;
  dense.engine = ModalEngine::dense;
  const fem::Modes none = fem::modal_analysis(fem::assemble(massless), dense);
  EXPECT_TRUE(none.status.ok());
  EXPECT_EQ(none.num_modes(), 0);
}

TEST(Modal, BandNeedingASecondPassFindsEveryMode) {
  // A band that needs more than the first guess of 8 modes: the count is doubled and the
  // Lanczos run again (on the factor of the first pass). Reference: the same engine asked
  // for 12 modes (the dense solver is only eps·λ_max/λ_1 ≈ 1e-7 accurate at mode 1 with 40
  // elements; it serves to place the band edge between modes 12 and 13).
  const fem::Assembled s = fem::assemble(test::cantilever(40, {}));
  fem::ModalOptions o;
  o.engine = ModalEngine::dense;
  o.num_modes = 0;
  const fem::Modes dense = fem::modal_analysis(s, o);
  o.engine = ModalEngine::sparse;
  o.num_modes = 12;
  const fem::Modes all = fem::modal_analysis(s, o);
  o.num_modes = 0;
  o.max_frequency_hz = 0.5 * (dense.frequency_hz(11) + dense.frequency_hz(12));
  const fem::Modes band = fem::modal_analysis(s, o);
  ASSERT_TRUE(band.status.ok());
  ASSERT_EQ(band.num_modes(), 12);
  for (int r = 0; r < 12; ++r)
    EXPECT_NEAR(band.omega(r), all.omega(r), 1e-9 * all.omega(r));
  ASSERT_TRUE(band.sparse.has_value());
  EXPECT_GE(band.sparse->ncv, 2 * 16 + 1); // the second pass, 16 modes
}

TEST(Modal, OscillatorFrequency) {
  // Single DOF: ω = sqrt(k/m) to rounding.
  const fem::Modes m = modes_of(test::oscillator(2.5, 1000.0), 1);
  EXPECT_NEAR(m.omega(0), 20.0, 1e-13 * 20.0);
  EXPECT_NEAR(std::abs(m.phi(0, 0)), 1.0 / std::sqrt(2.5), 1e-14);
}

namespace {

// Modes of `s` by the sparse engine with the given iteration and block size.
fem::Modes sparse_modes(const fem::Assembled& s, int count, fem::SparseMethod method,
                        int block_size = 8) {
  fem::ModalOptions o;
  o.num_modes = count;
  o.engine = ModalEngine::sparse;
  o.sparse_method = method;
  o.block_size = block_size;
  return fem::modal_analysis(s, o);
}

// Indices r with ω_r² and ω_{r+1}² equal to `relative` (a multiple eigenvalue).
std::vector<int> multiple_pairs(const fem::Modes& m, double relative) {
  std::vector<int> pairs;
  for (int r = 0; r + 1 < m.num_modes(); ++r)
    if (std::abs(std::pow(m.omega(r + 1), 2) / std::pow(m.omega(r), 2) - 1.0) < relative)
      pairs.push_back(r);
  return pairs;
}

} // namespace

TEST(Modal, BlockLanczosFindsEveryCopyOfTheDoubleModesOfASymmetricLattice) {
  // The 7 × 7 × 5 frame lattice of the benchmarks (1176 equations, base fixed) is symmetric
  // under x ↔ y, so many of its modes are double (the two sways, ...). Reference: the dense
  // engine, whose eigenvalues err by ~eps·λ_max absolutely (λ_max/λ_1 ≈ 10⁸ here; measured
  // 4e-12 relative at worst); the shift-invert ones relatively, to the convergence test.
  // A copy missed shifts the rest of the list by one mode, an error of several % — as
  // Spectra's single-vector Lanczos does here: it returns one copy of the double mode 16–17,
  // so its modes 17–20 are 1.5–4 % off in frequency.
  const fem::Assembled s = fem::assemble(bench::frame_lattice(7, 7, 5, 1.0));
  ASSERT_EQ(s.dofs.num_equations(), 1176);
  fem::ModalOptions o;
  o.num_modes = 0;
  o.engine = ModalEngine::dense;
  const fem::Modes dense = fem::modal_analysis(s, o);
  const double lambda_max = std::pow(dense.omega(dense.num_modes() - 1), 2);
  const std::vector<int> doubles = multiple_pairs(dense, 1e-8);
  ASSERT_GE(std::count_if(doubles.begin(), doubles.end(), [](int r) { return r < 19; }), 5);
  for (int block : {2, 3, 8}) {
    const fem::Modes m = sparse_modes(s, 20, fem::SparseMethod::block_lanczos, block);
    ASSERT_TRUE(m.status.ok()) << m.status.reason;
    ASSERT_EQ(m.num_modes(), 20);
    for (int r = 0; r < 20; ++r) {
      const double lambda = dense.omega(r) * dense.omega(r);
      EXPECT_NEAR(m.omega(r) * m.omega(r), lambda, 1e-10 * lambda + 100.0 * eps * lambda_max)
          << "block " << block << ", mode " << r + 1;
    }
    // ΦᵀMΦ = I and the eigen-equation, ‖KΦ − MΦΛ‖_F / ‖KΦ‖_F: the convergence test bounds
    // ‖(K − σM)⁻¹(Kφ − λMφ)‖_M by 1e-10, which leaves ‖Kφ − λMφ‖/‖Kφ‖ at 1e-13 … 1e-9
    // (measured on such lattices); 1e-8 fails for any wrong pair by orders of magnitude.
    const Eigen::MatrixXd gram = m.phi.transpose() * (s.M * m.phi);
    EXPECT_LE((gram - Eigen::MatrixXd::Identity(20, 20)).cwiseAbs().maxCoeff(), 1e-12);
    const Eigen::MatrixXd KPhi = s.K * m.phi;
    const Eigen::VectorXd lambda = m.omega.array().square();
    EXPECT_LE((KPhi - (s.M * m.phi) * lambda.asDiagonal()).norm(), 1e-8 * KPhi.norm());
    ASSERT_TRUE(m.sparse.has_value());
    EXPECT_EQ(m.sparse->block_size, block);
    // Blocks of `block` columns (no direction lost on the way).
    EXPECT_EQ(m.sparse->right_hand_sides, static_cast<long long>(block) * m.sparse->solves);
  }
}

TEST(Modal, BlockLanczosEqualsSpectraToRoundingWithFewerSolves) {
  // 8 × 8 × 6 lattice (1920 equations), 20 modes: both iterations are shift-invert on the
  // same factor with the same convergence test (1e-10), so their eigenvalues agree far below
  // it (θ errs by about the residual squared). Compared: the 16 lowest (Spectra returns one
  // copy of the double mode 16–17, as in the test above, and differs from mode 17 on).
  const fem::Assembled s = fem::assemble(bench::frame_lattice(8, 8, 6, 1.0));
  ASSERT_EQ(s.dofs.num_equations(), 1920);
  const fem::Modes spectra = sparse_modes(s, 20, fem::SparseMethod::spectra);
  const fem::Modes block = sparse_modes(s, 20, fem::SparseMethod::block_lanczos);
  ASSERT_TRUE(spectra.status.ok()) << spectra.status.reason;
  ASSERT_TRUE(block.status.ok()) << block.status.reason;
  for (int r = 0; r < 16; ++r)
    EXPECT_NEAR(block.omega(r) * block.omega(r), spectra.omega(r) * spectra.omega(r),
                1e-10 * spectra.omega(r) * spectra.omega(r))
        << "mode " << r + 1;
  ASSERT_TRUE(block.sparse.has_value() && spectra.sparse.has_value());
  EXPECT_LT(block.sparse->solves, spectra.sparse->solves);
}

TEST(Modal, FreeSpaceFrameHasSixRigidModesWithTheBlockEngine) {
  // A 4 × 4 × 3 lattice with no support: 6 rigid-body modes (3 translations, 3 rotations),
  // numerically ω² at rounding level, a sextuple eigenvalue that a block of 8 spans from the
  // start (σ < 0 keeps K − σM positive definite). Mode 7 on is elastic, as the dense engine.
  fem::Model model = bench::frame_lattice(4, 4, 3, 1.0);
  model.supports.clear();
  const fem::Assembled s = fem::assemble(model);
  ASSERT_EQ(s.dofs.num_equations(), 288);
  fem::ModalOptions o;
  o.num_modes = 0;
  o.engine = ModalEngine::dense;
  const fem::Modes all = fem::modal_analysis(s, o);
  const double lambda_max = std::pow(all.omega(all.num_modes() - 1), 2);
  const double rigid_bound = std::sqrt(100 * eps * lambda_max);
  ASSERT_GT(all.omega(6), 1e3 * rigid_bound); // the bound separates rigid from elastic
  const fem::Modes m = sparse_modes(s, 10, fem::SparseMethod::block_lanczos);
  ASSERT_TRUE(m.status.ok()) << m.status.reason;
  for (int r = 0; r < 6; ++r)
    EXPECT_LE(m.omega(r), rigid_bound) << "rigid mode " << r + 1;
  for (int r = 6; r < 10; ++r)
    EXPECT_NEAR(m.omega(r), all.omega(r), 1e-8 * all.omega(r)) << "mode " << r + 1;
  // The rigid shapes: M-orthonormal, no strain energy to rounding, and spanning the 6 rigid
  // motions (a translation along x is in their span).
  const Eigen::MatrixXd R = m.phi.leftCols(6);
  const Eigen::MatrixXd M(s.M);
  EXPECT_LE((R.transpose() * M * R - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-10);
  Eigen::VectorXd ux = Eigen::VectorXd::Zero(s.dofs.num_equations());
  for (int e = 0; e < s.dofs.num_equations(); ++e)
    if (s.dofs.node_dof(e).dof == fem::Dof::ux) ux(e) = 1.0;
  const Eigen::VectorXd in_span = R * (R.transpose() * (M * ux));
  EXPECT_LE((in_span - ux).norm(), 1e-6 * ux.norm());
}

TEST(Modal, BothSparseIterationsReportNonConvergenceNamingThemselves) {
  // One restart at tolerance 0 (met only by an exact residual): 10 modes of a 400-equation
  // cantilever do not converge; the reason names the iteration, the count and the limits.
  const fem::Assembled s = fem::assemble(test::cantilever(200, {}));
  fem::ModalOptions o;
  o.num_modes = 10;
  o.engine = ModalEngine::sparse;
  o.max_iterations = 1;
  o.tolerance = 0.0;
  const fem::Modes block = fem::modal_analysis(s, o);
  EXPECT_EQ(block.status.code, fem::Status::Code::not_converging);
  EXPECT_EQ(
      block.status.reason.rfind("block shift-invert Lanczos did not converge to 10 modes in 1 "
                                "restarts (tolerance 0; ",
                                0),
      0u)
      << block.status.reason;
  EXPECT_EQ(block.num_modes(), 0);
  ASSERT_TRUE(block.sparse.has_value());
  EXPECT_EQ(block.sparse->restarts, 1);
  o.sparse_method = fem::SparseMethod::spectra;
  const fem::Modes spectra = fem::modal_analysis(s, o);
  EXPECT_EQ(spectra.status.code, fem::Status::Code::not_converging);
  EXPECT_NE(spectra.status.reason.find("(Spectra)"), std::string::npos) << spectra.status.reason;
  // The defaults converge: the failure is the limits'.
  o.max_iterations = fem::ModalOptions{}.max_iterations;
  o.tolerance = fem::ModalOptions{}.tolerance;
  o.sparse_method = fem::SparseMethod::block_lanczos;
  EXPECT_TRUE(fem::modal_analysis(s, o).status.ok());
}
