// Receptance by modal synthesis against the direct sparse solve, the static flexibility and
// the symmetry of a reciprocal structure.
#include "frf/receptance.hpp"

#include "support/beam_models.hpp"
#include "support/cantilever.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

using namespace jointid;
using fem::Dof;

namespace {

using jointid::test::all_modes;

using jointid::test::relative_difference;

using jointid::test::two_pi;

// A cantilever with a few DOFs of interest: tip uy and rz, mid-span uy, node 3 uy.
struct Cantilever {
  explicit Cantilever(int elements, fem::Damping damping) : model(test::cantilever(elements, {})) {
    model.damping = damping;
    system = fem::assemble(model);
    const int tip = elements + 1, mid = elements / 2 + 1;
    dofs = {system.dofs.equation({tip, Dof::uy}), system.dofs.equation({tip, Dof::rz}),
            system.dofs.equation({mid, Dof::uy}), system.dofs.equation({3, Dof::uy})};
  }
  fem::Model model;
  fem::Assembled system;
  std::vector<int> dofs;
};

fem::Damping rayleigh(double alpha, double beta) {
  fem::Damping d;
  d.kind = fem::Damping::Kind::rayleigh;
  d.alpha = alpha;
  d.beta = beta;
  return d;
}

fem::Damping modal(double ratio) {
  fem::Damping d;
  d.kind = fem::Damping::Kind::modal;
  d.modal_ratio = ratio;
  return d;
}

} // namespace

TEST(Receptance, AllModesEqualTheDirectSolve) {
  // With every mode kept, modal synthesis is an exact rewriting of (K − ω²M + iωC)⁻¹ whenever
  // Φ diagonalises C (Rayleigh, or modal C built from all modes). 8 elements: the dense
  // eigensolver's relative error for mode 1 is ≲ eps·λ_max/λ_1 ≈ 2e-16·1e6 ≈ 2e-10 and the LU
  // solve is of the same order, so 1e-9 relative (Frobenius over the block) holds; a wrong ζ_r
  // or a sign would be off by percent. Frequencies: static, between modes, at mode 2, above.
  for (const fem::Damping& d : {rayleigh(0.6, 2e-5), modal(0.02)}) {
    const Cantilever c(8, d);
    const fem::Modes modes = all_modes(c.system);
    const fem::SparseMatrix C = fem::damping_matrix(c.system, d, &modes);
    const frf::ModalSynthesis H(c.system, modes, d, c.dofs);
    for (double w : {0.0, 0.5 * modes.omega(0), 0.5 * (modes.omega(0) + modes.omega(1)),
                     modes.omega(1), 1.3 * modes.omega(4)}) {
      const frf::CMatrix direct = frf::direct_receptance(c.system, C, w, c.dofs, c.dofs).value;
      EXPECT_LE(relative_difference(H.receptance(w, c.dofs, c.dofs), direct), 1e-9)
          << "ω = " << w << ", damping kind " << static_cast<int>(d.kind);
    }
  }
}

TEST(Receptance, AtManyFrequenciesWithRepeatedDofsEqualsTheDirectSolveEntryByEntry) {
  // receptances(ω₁ … ω_n, rows, cols): the frequencies side by side, entries repeated where a
  // DOF is (computed once, copied). Against the direct solve at each frequency, every entry,
  // with rows and columns that repeat DOFs in several places and orders (1e-9 as above), and
  // exactly equal to the single-frequency call.
  const fem::Damping d = rayleigh(0.6, 2e-5);
  const Cantilever c(8, d);
  const fem::Modes modes = all_modes(c.system);
  const fem::SparseMatrix C = fem::damping_matrix(c.system, d, &modes);
  const frf::ModalSynthesis H(c.system, modes, d, c.dofs);
  const std::vector<int> rows{c.dofs[2], c.dofs[0], c.dofs[2], c.dofs[3], c.dofs[0]};
  const std::vector<int> cols{c.dofs[0], c.dofs[0], c.dofs[1], c.dofs[2]};
  const std::vector<double> omegas{0.0, 0.5 * modes.omega(0),
                                   0.5 * (modes.omega(0) + modes.omega(1)),
                                   0.5 * (modes.omega(2) + modes.omega(3))};
  const frf::CMatrix all = H.receptances(omegas, rows, cols);
  ASSERT_EQ(all.rows(), 5);
  ASSERT_EQ(all.cols(), 4 * 4);
  for (std::size_t k = 0; k < omegas.size(); ++k) {
    const auto block = all.middleCols(static_cast<Eigen::Index>(4 * k), 4);
    const frf::CMatrix direct = frf::direct_receptance(c.system, C, omegas[k], rows, cols).value;
    EXPECT_LE(relative_difference(block, direct), 1e-9) << "ω = " << omegas[k];
    EXPECT_EQ((block - H.receptance(omegas[k], rows, cols)).cwiseAbs().maxCoeff(), 0.0);
    for (Eigen::Index i = 0; i < 5; ++i)
      for (Eigen::Index j = 0; j < 4; ++j) {
        const std::vector<int> r{rows[static_cast<std::size_t>(i)]},
            q{cols[static_cast<std::size_t>(j)]};
        EXPECT_EQ(block(i, j), H.receptance(omegas[k], r, q)(0, 0)) << i << ", " << j;
      }
  }
}

TEST(Receptance, ResidualFlexibilityCorrectsTruncation) {
  // 4 of 80 modes (40 elements). Well below mode 5, the modes left out respond
  // quasi-statically, Σ_out φφᵀ/(ω_r² − ω²) ≈ Σ_out φφᵀ/ω_r² (1 + ω²/ω_r² + …): the static
  // correction removes all but the (ω/ω_5)² part. Up to midway between modes 2 and 3,
  // (ω/ω_5)² ≤ ((4.694² + 7.855²)/2 / 14.137²)² ≈ 0.044, so the correction must bring the
  // synthesis more than 10× closer to the direct solution.
  const fem::Damping d = modal(0.01);
  const Cantilever c(40, d);
  const fem::Modes every = all_modes(c.system);
  const fem::SparseMatrix C = fem::damping_matrix(c.system, d, &every);
  fem::ModalOptions o;
  o.num_modes = 4;
  o.engine = fem::ModalEngine::sparse;
  const fem::Modes four = fem::modal_analysis(c.system, o);
  ASSERT_TRUE(four.status.ok());
  const frf::ModalSynthesis with(c.system, four, d, c.dofs);
  const frf::ModalSynthesis without(c.system, four, d, c.dofs, {.residual_flexibility = false});
  EXPECT_TRUE(with.has_residual());
  EXPECT_FALSE(without.has_residual());
  for (double w : {0.3 * four.omega(0), 0.5 * (four.omega(0) + four.omega(1)),
                   0.5 * (four.omega(1) + four.omega(2))}) {
    const frf::CMatrix direct = frf::direct_receptance(c.system, C, w, c.dofs, c.dofs).value;
    const double error_with = relative_difference(with.receptance(w, c.dofs, c.dofs), direct);
    const double error_without = relative_difference(without.receptance(w, c.dofs, c.dofs), direct);
    EXPECT_LT(error_with, error_without / 10) << "ω = " << w;
    EXPECT_GT(error_without, 1e-6) << "truncation must be visible at ω = " << w;
  }
}

TEST(Receptance, StaticLimitIsTheFlexibilityMatrix) {
  // At ω = 0, H = K⁻¹: with every mode and no correction (Σ φφᵀ/ω² = K⁻¹ by the spectral
  // theorem), and with 3 modes plus the residual. K⁻¹ here comes from a dense LU of K; both
  // agree to cond(K)·eps ≈ 1e-10 relative (8 elements).
  const fem::Damping d = modal(0.03);
  const Cantilever c(8, d);
  const Eigen::MatrixXd flex = test::dense_flexibility(c.system);
  Eigen::MatrixXd expected(c.dofs.size(), c.dofs.size());
  for (std::size_t i = 0; i < c.dofs.size(); ++i)
    for (std::size_t j = 0; j < c.dofs.size(); ++j)
      expected(i, j) = flex(c.dofs[i], c.dofs[j]);
  const frf::ModalSynthesis full(c.system, all_modes(c.system), d, c.dofs,
                                 {.residual_flexibility = false});
  fem::ModalOptions o;
  o.num_modes = 3;
  const frf::ModalSynthesis truncated(c.system, fem::modal_analysis(c.system, o), d, c.dofs);
  for (const frf::ModalSynthesis* H : {&full, &truncated}) {
    const frf::CMatrix H0 = H->receptance(0.0, c.dofs, c.dofs);
    EXPECT_LE((H0.real() - expected).norm(), 1e-9 * expected.norm());
    EXPECT_LE(H0.imag().norm(), 1e-15 * expected.norm()); // no damping force at rest
  }
  // Sanity of the reference: the tip's static flexibility is L³/3EI.
  const test::BeamProperties p;
  EXPECT_NEAR(expected(0, 0), std::pow(p.length, 3) / (3 * p.E * p.I()), 1e-9 * expected(0, 0));
}

TEST(Receptance, IsReciprocal) {
  // H_ij = H_ji: symmetric K, M, C. Modal synthesis is symmetric by construction; the direct LU
  // solve is not, so its asymmetry is rounding, ≲ cond(D)·eps ≈ 1e-10 relative here.
  const fem::Damping d = rayleigh(0.4, 1e-5);
  const Cantilever c(10, d);
  const fem::Modes modes = all_modes(c.system);
  const frf::ModalSynthesis H(c.system, modes, d, c.dofs);
  const fem::SparseMatrix C = fem::damping_matrix(c.system, d);
  for (double w : {0.7 * modes.omega(0), 1.01 * modes.omega(2)}) {
    const frf::CMatrix modal = H.receptance(w, c.dofs, c.dofs);
    EXPECT_LE((modal - modal.transpose()).norm(), 1e-14 * modal.norm());
    const frf::CMatrix direct = frf::direct_receptance(c.system, C, w, c.dofs, c.dofs).value;
    EXPECT_LE((direct - direct.transpose()).norm(), 1e-9 * direct.norm());
    // Not Hermitian: a damped receptance has a genuine imaginary part.
    EXPECT_GT(modal.imag().norm(), 1e-3 * modal.norm());
  }
}

TEST(Receptance, BlocksHaveThePartitionShapesAndH21IsH12Transposed) {
  const fem::Damping d = modal(0.01);
  const Cantilever c(6, d);
  const fem::Modes modes = all_modes(c.system);
  const frf::ModalSynthesis H(c.system, modes, d, c.dofs);
  const frf::Partition p{{c.dofs[1], c.dofs[2], c.dofs[3]}, {c.dofs[0]}}; // joint at the tip
  const double w = two_pi * 4.0;
  const frf::Blocks b = H.blocks(w, p);
  EXPECT_EQ(b.H11.rows(), 3);
  EXPECT_EQ(b.H11.cols(), 3);
  EXPECT_EQ(b.H12.rows(), 3);
  EXPECT_EQ(b.H12.cols(), 1);
  EXPECT_EQ(b.H21.rows(), 1);
  EXPECT_EQ(b.H21.cols(), 3);
  EXPECT_EQ(b.H22.rows(), 1);
  EXPECT_EQ(b.H22.cols(), 1);
  EXPECT_LE((b.H21 - b.H12.transpose()).norm(), 1e-14 * b.H12.norm());
  // Blocks are the entries of the full receptance in partition order.
  const frf::CMatrix full = H.receptance(w, c.dofs, c.dofs);
  EXPECT_EQ(b.H22(0, 0), full(0, 0));
  EXPECT_EQ(b.H12(0, 0), full(1, 0));
  EXPECT_EQ(b.H11(2, 1), full(3, 2));
}

TEST(Receptance, FreeStructureMatchesTheDirectSolveWithRigidModes) {
  // Free–free frame: the rigid modes contribute the mass line 1/(ω_r² − ω² + iαω) with ω_r of
  // rounding size (the dense solver returns ≈1e-4 rad/s, or exactly 0 when λ_r comes out
  // negative). The residual correction is skipped (K singular). Mass-proportional damping αM
  // damps the rigid modes too (2ζ_rω_r = α even at ω_r = 0), as in the direct solve. The rigid
  // ω_r² perturb H by ≈ (ω_r/ω)², so the tolerance is 1e-9 + 10 (ω_3/ω)² (≲ 1e-8 here).
  for (const fem::Damping& d : {rayleigh(0.0, 1e-5), rayleigh(0.5, 1e-5)}) {
    fem::Model model = test::uniform_beam(6, {}, fem::ElementType::frame2d);
    model.damping = d;
    const fem::Assembled s = fem::assemble(model);
    const fem::Modes modes = all_modes(s);
    const std::vector<int> dofs{s.dofs.equation({1, Dof::ux}), s.dofs.equation({4, Dof::uy}),
                                s.dofs.equation({7, Dof::rz})};
    const frf::ModalSynthesis H(s, modes, d, dofs);
    EXPECT_FALSE(H.has_residual());
    const fem::SparseMatrix C = fem::damping_matrix(s, d);
    for (double w : {10.0, 0.5 * modes.omega(3), 1.5 * modes.omega(4)}) {
      const frf::CMatrix direct = frf::direct_receptance(s, C, w, dofs, dofs).value;
      const double tol = 1e-9 + 10 * std::pow(modes.omega(2) / w, 2);
      EXPECT_LE(relative_difference(H.receptance(w, dofs, dofs), direct), tol)
          << "ω = " << w << ", α = " << d.alpha;
    }
  }
}

TEST(Receptance, BadInputThrows) {
  const fem::Damping d = modal(0.01);
  const Cantilever c(4, d);
  const fem::Modes modes = all_modes(c.system);
  const frf::ModalSynthesis H(c.system, modes, d, {c.dofs[0]});
  const std::vector<int> other{c.dofs[2]};
  EXPECT_THROW(H.receptance(1.0, other, other), std::invalid_argument);
  EXPECT_THROW(frf::ModalSynthesis(c.system, modes, d, {999}), std::invalid_argument);
  // Bad input throws even with modes that failed.
  fem::Modes failed;
  failed.status = fem::Status::failure(fem::Status::Code::numerical_issue, "a test's failure");
  EXPECT_THROW(frf::ModalSynthesis(c.system, failed, d, {999}), std::invalid_argument);
}

TEST(Receptance, ASingularDynamicStiffnessIsAStatus) {
  // Undamped, at its natural frequency (1 rad/s), a 1 kg, 1 N/m oscillator has no receptance: a
  // numerical outcome, not bad input.
  const fem::Assembled one = fem::assemble(test::oscillator(1.0, 1.0));
  const std::vector<int> dof{0};
  const fem::Outcome<frf::CMatrix> at_resonance =
      frf::direct_receptance(one, fem::SparseMatrix(1, 1), 1.0, dof, dof);
  EXPECT_EQ(at_resonance.status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(at_resonance.status.reason,
            "direct receptance: K - w^2 M + i w C is singular at w = 1.000000 rad/s (0.159155 "
            "Hz): an undamped natural frequency, or a DOF with neither stiffness nor mass");
  EXPECT_EQ(at_resonance.value.size(), 0);
  // Beside it, 1 / (k − ω² m) = 1 / (1 − 0.25) m/N at 0.5 rad/s.
  const fem::Outcome<frf::CMatrix> below =
      frf::direct_receptance(one, fem::SparseMatrix(1, 1), 0.5, dof, dof);
  ASSERT_TRUE(below.status.ok()) << below.status.reason;
  EXPECT_NEAR(std::abs(below.value(0, 0) - 1.0 / 0.75), 0.0, 1e-14);
}

TEST(Receptance, ModesThatDidNotConvergeGiveASynthesisWithTheirStatus) {
  // The sparse engine allowed one Lanczos restart and a tolerance of 0: 10 modes of a
  // 400-equation cantilever do not converge, which the status says; the synthesis carries that
  // status and refuses to be used.
  const fem::Damping d = modal(0.01);
  const Cantilever c(200, d);
  fem::ModalOptions o;
  o.num_modes = 10;
  o.engine = fem::ModalEngine::sparse;
  o.max_iterations = 1;
  o.tolerance = 0.0;
  const fem::Modes modes = fem::modal_analysis(c.system, o);
  ASSERT_EQ(modes.status.code, fem::Status::Code::not_converging);
  const frf::ModalSynthesis H(c.system, modes, d, c.dofs);
  EXPECT_EQ(H.status().code, fem::Status::Code::not_converging);
  const std::string reason = "the modal analysis failed: block shift-invert Lanczos did not "
                             "converge to 10 modes in 1 restarts";
  EXPECT_EQ(H.status().reason.rfind(reason, 0), 0u) << H.status().reason;
  try {
    (void)H.receptance(1.0, c.dofs, c.dofs);
    FAIL() << "a failed synthesis gave a receptance";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("check status() first): " + reason), std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)H.shapes(c.dofs), std::logic_error);
  EXPECT_THROW((void)H.natural_frequencies(), std::logic_error);
}

// A substructure given by its modes (frf::ModalModel): the paper cantilever's FE modes at two
// DOFs, 4:uy (mid-span) and 7:uy (tip), as a modal test would give them.
namespace {

struct PaperModes {
  PaperModes() : model(test::paper_cantilever()), system(fem::assemble(model)) {
    modes = all_modes(system);
    equations = {system.dofs.equation({4, Dof::uy}), system.dofs.equation({7, Dof::uy})};
  }
  // The first `count` modes as a ModalModel on 4:uy, 7:uy with the model's 1 % damping.
  frf::ModalModel modal(int count) const {
    frf::ModalModel m;
    m.dofs = {{4, Dof::uy}, {7, Dof::uy}};
    m.frequencies_hz = modes.omega.head(count) / two_pi;
    m.damping = Eigen::VectorXd::Constant(count, model.damping.modal_ratio);
    m.shapes.resize(count, 2);
    for (int i = 0; i < 2; ++i)
      m.shapes.col(i) = modes.phi.row(equations[i]).head(count).transpose();
    return m;
  }
  fem::Modes first(int count) const {
    fem::Modes m = modes;
    m.omega = modes.omega.head(count).eval();
    m.phi = modes.phi.leftCols(count).eval();
    return m;
  }
  fem::Model model;
  fem::Assembled system;
  fem::Modes modes;
  std::vector<int> equations; // FE equations of 4:uy, 7:uy
};

} // namespace

TEST(ReceptanceOfAModalModel, EqualsTheFESynthesisOfTheSameModes) {
  // The same 5 modes, no residual, through the FE constructor and through a ModalModel (whose
  // equations 0, 1 are 4:uy, 7:uy): only f = ω/2π and back differ, ≈ 1e-16 relative.
  const PaperModes p;
  const std::vector<int> served{0, 1};
  const frf::ModalSynthesis fe(p.system, p.first(5), p.model.damping, p.equations,
                               {.residual_flexibility = false});
  const frf::ModalSynthesis modal(p.modal(5), served);
  EXPECT_FALSE(modal.has_residual());
  EXPECT_EQ(modal.num_modes(), 5);
  for (double w : {0.0, 0.5 * p.modes.omega(0), p.modes.omega(0), p.modes.omega(1),
                   0.5 * (p.modes.omega(2) + p.modes.omega(3)), 2.0 * p.modes.omega(4)}) {
    const frf::CMatrix expected = fe.receptance(w, p.equations, p.equations);
    EXPECT_LE(relative_difference(modal.receptance(w, served, served), expected), 1e-12)
        << "ω = " << w;
  }
}

TEST(ReceptanceOfAModalModel, AllModesEqualTheDirectSolve) {
  // All 12 modes of the 6-element model, no residual: an exact rewriting of
  // (K − ω²M + iωC)⁻¹ with the modal C; the direct sparse LU is the independent reference
  // (agreement ≈ cond·eps, 1e-9 as in AllModesEqualTheDirectSolve above).
  const PaperModes p;
  const int n = p.system.dofs.num_equations();
  ASSERT_EQ(n, 12);
  const frf::ModalSynthesis modal(p.modal(n), {0, 1});
  const fem::SparseMatrix C = fem::damping_matrix(p.system, p.model.damping, &p.modes);
  const std::vector<int> served{0, 1};
  for (double w : {0.0, two_pi * 1.0, p.modes.omega(0), two_pi * 10.0, p.modes.omega(1),
                   1.7 * p.modes.omega(5)}) {
    const frf::CMatrix direct =
        frf::direct_receptance(p.system, C, w, p.equations, p.equations).value;
    EXPECT_LE(relative_difference(modal.receptance(w, served, served), direct), 1e-9)
        << "ω = " << w;
  }
}

TEST(ReceptanceOfAModalModel, TruncatedModesWithTheExactResidualHaveTheStaticFlexibility) {
  // 2 modes plus R = K⁻¹ − Σ_kept φφᵀ/ω_r² on 4:uy, 7:uy: at ω = 0 the synthesis is K⁻¹, whose
  // entries for a tip load are those of Euler–Bernoulli statics (cubic elements are exact at
  // the nodes): δ_tip = L³/3EI, δ_mid = 5L³/48EI per unit tip load, and L³/24EI at mid-span
  // for a mid-span load. K⁻¹ from a dense LU; tolerance cond(K)·eps ≈ 1e-10 relative.
  const PaperModes p;
  const Eigen::MatrixXd flex = test::dense_flexibility(p.system);
  frf::ModalModel m = p.modal(2);
  Eigen::Matrix2d R;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      R(i, j) = flex(p.equations[i], p.equations[j]);
  for (int r = 0; r < 2; ++r)
    R -= m.shapes.row(r).transpose() * m.shapes.row(r) / std::pow(p.modes.omega(r), 2);
  m.residual_flexibility = 0.5 * (R + R.transpose());
  const frf::ModalSynthesis H(m, {0, 1});
  EXPECT_TRUE(H.has_residual());
  const std::vector<int> served{0, 1};
  const frf::CMatrix H0 = H.receptance(0.0, served, served);

  const double L = 2.0, E = 210e9, b = 0.25, t = 0.0143622750907616, I = b * t * t * t / 12.0;
  Eigen::Matrix2d statics;
  statics << std::pow(L, 3) / (24 * E * I), 5 * std::pow(L, 3) / (48 * E * I),
      5 * std::pow(L, 3) / (48 * E * I), std::pow(L, 3) / (3 * E * I);
  EXPECT_LE((H0.real() - statics).norm(), 1e-9 * statics.norm()) << H0.real();
  EXPECT_LE(H0.imag().norm(), 1e-15 * statics.norm());
  // The residual matters: without it the static tip flexibility is short by what modes 3–12
  // carry (a few per mille, far above the tolerance).
  frf::ModalModel bare = m;
  bare.residual_flexibility.resize(0, 0);
  const frf::CMatrix H0_bare = frf::ModalSynthesis(bare, {0, 1}).receptance(0.0, served, served);
  EXPECT_GT((H0_bare.real() - statics).norm(), 1e-4 * statics.norm());
  // Serving one equation restricts the residual to it.
  const std::vector<int> tip{1};
  const frf::ModalSynthesis tip_only(m, tip);
  EXPECT_NEAR(tip_only.receptance(0.0, tip, tip)(0, 0).real(), statics(1, 1), 1e-9 * statics(1, 1));
}

TEST(ReceptanceOfAModalModel, DampingScaleDoublesTheDampingOfASingleMode) {
  // One mode f = 12 Hz, ζ = 0.02, φ = 0.4/sqrt(kg) at one DOF: 1/H = (ω_r² − ω² + 2iζω_rω)/φ².
  // Scaling the damping by 2 doubles Im(1/H) = 2ζω_rω/φ² and leaves Re(1/H) as it is.
  frf::ModalModel m;
  m.dofs = {{3, Dof::ux}};
  m.frequencies_hz = Eigen::VectorXd::Constant(1, 12.0);
  m.damping = Eigen::VectorXd::Constant(1, 0.02);
  m.shapes = Eigen::MatrixXd::Constant(1, 1, 0.4);
  const std::vector<int> e{0};
  const frf::ModalSynthesis H(m, e);
  const frf::ModalSynthesis doubled = H.with_damping_scale(2.0);
  const double wr = two_pi * 12.0, phi2 = 0.16;
  for (double w : {wr, 0.8 * wr}) {
    const frf::Complex inv = 1.0 / H.receptance(w, e, e)(0, 0);
    const frf::Complex inv2 = 1.0 / doubled.receptance(w, e, e)(0, 0);
    const double im = 2 * 0.02 * wr * w / phi2, re = (wr * wr - w * w) / phi2;
    EXPECT_NEAR(inv.imag(), im, 1e-12 * im) << "ω = " << w;
    EXPECT_NEAR(inv2.imag(), 2 * im, 1e-12 * im) << "ω = " << w;
    EXPECT_NEAR(inv.real(), re, 1e-12 * std::abs(im)) << "ω = " << w;
    EXPECT_NEAR(inv2.real(), re, 1e-12 * std::abs(im)) << "ω = " << w;
  }
  // The original is untouched; bad factors are refused.
  EXPECT_NEAR((1.0 / H.receptance(wr, e, e)(0, 0)).imag(), 2 * 0.02 * wr * wr / phi2, 1e-6);
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()})
    EXPECT_THROW(H.with_damping_scale(bad), std::invalid_argument) << bad;
}

TEST(ReceptanceOfAModalModel, BadInputThrows) {
  const PaperModes p;
  EXPECT_THROW(frf::ModalSynthesis(p.modal(3), {0, 2}), std::invalid_argument); // 2 DOFs only
  EXPECT_THROW(frf::ModalSynthesis(p.modal(3), {-1}), std::invalid_argument);
  frf::ModalModel bad = p.modal(3);
  bad.damping(1) = -0.01;
  EXPECT_THROW(frf::ModalSynthesis(bad, {0}), std::invalid_argument); // validated
  const frf::ModalSynthesis H(p.modal(3), {1});
  const std::vector<int> other{0};
  EXPECT_THROW(H.receptance(1.0, other, other), std::invalid_argument);
}
