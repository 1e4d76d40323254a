// The distributed (SLEPc) modal engine against the CHOLMOD engine and against properties.
// Registered twice: as one process and under `mpirun -np 2` (tests/fem/CMakeLists.txt). Every
// rank runs every test (the engine is collective); each checks what it received.
#include "fem/assembly.hpp"
#include "fem/modal.hpp"
#include "fem/slepc_modal.hpp"
#include "frf/substructure.hpp"

#include "bench/lattice.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

namespace jointid {
namespace {

fem::SlepcSession* session = nullptr;

fem::Modes cholmod_modes(const fem::Assembled& system, const fem::ModalOptions& options) {
  fem::ModalOptions o = options;
  o.engine = fem::ModalEngine::sparse;
  return fem::modal_analysis(system, o);
}

// A 12 × 12 × 13 lattice: 10 368 equations, 20 modes, repeated pairs among them (square plan).
TEST(SlepcModal, SameEigenvaluesAsTheCholmodEngine) {
  const fem::Model model = bench::frame_lattice(12, 12, 13, 0.5);
  const fem::Assembled system = fem::assemble(model);
  ASSERT_EQ(system.dofs.num_equations(), 10368);
  const fem::ModalOptions options{.num_modes = 20};
  const fem::Modes reference = cholmod_modes(system, options);
  const fem::Modes modes = fem::slepc_modal_analysis(model, options);
  ASSERT_TRUE(reference.status.ok());
  ASSERT_TRUE(modes.status.ok());
  ASSERT_EQ(modes.num_modes(), 20);
  for (int r = 0; r < 20; ++r) {
    const double lambda = modes.omega(r) * modes.omega(r);
    const double expected = reference.omega(r) * reference.omega(r);
    EXPECT_NEAR(lambda, expected, 1e-10 * expected) << "mode " << r + 1;
  }
  // Modes 19 and 20 are a double pair of the square plan: a single-vector iteration asked for
  // exactly 20 returned one copy and the 21st mode as the 20th (both engines did, until the
  // CHOLMOD engine's block Lanczos found the second copy).
  const double l19 = std::pow(modes.omega(18), 2), l20 = std::pow(modes.omega(19), 2);
  EXPECT_NEAR(l19, l20, 1e-10 * l20);
  ASSERT_TRUE(modes.distributed.has_value());
  EXPECT_EQ(modes.distributed->ranks, session->size());
  EXPECT_GT(modes.distributed->factor_entries, static_cast<double>(system.K.nonZeros()) / 2);
}

// Every row to rank 0: φᵀMφ = I and K φ = λ M φ there; the other ranks receive no rows.
TEST(SlepcModal, ModesAreMassNormalisedAndSolveTheEigenproblem) {
  const fem::Model model = bench::frame_lattice(6, 5, 7, 0.4);
  const fem::Assembled system = fem::assemble(model);
  const fem::Modes modes = fem::slepc_modal_analysis(model, {.num_modes = 12});
  ASSERT_TRUE(modes.status.ok());
  ASSERT_EQ(modes.num_modes(), 12);
  EXPECT_TRUE(modes.rows.empty());
  for (int r = 1; r < 12; ++r)
    EXPECT_LE(modes.omega(r - 1), modes.omega(r));
  if (session->rank() != 0) {
    EXPECT_EQ(modes.phi.rows(), 0);
    return;
  }
  ASSERT_EQ(modes.phi.rows(), system.dofs.num_equations());
  const Eigen::MatrixXd gram = modes.phi.transpose() * system.M * modes.phi;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(12, 12)).cwiseAbs().maxCoeff(), 1e-10);
  const Eigen::MatrixXd KPhi = system.K * modes.phi;
  const Eigen::MatrixXd MPhiL =
      system.M * modes.phi * modes.omega.array().square().matrix().asDiagonal();
  EXPECT_LT((KPhi - MPhiL).norm() / KPhi.norm(), 1e-8);
}

// An unsupported frame: six rigid-body modes at ω ≈ 0, then elastic ones well above.
TEST(SlepcModal, FreeFrameHasSixRigidBodyModes) {
  fem::Model model = bench::frame_lattice(3, 3, 3, 1.0);
  model.supports.clear();
  const fem::Modes modes = fem::slepc_modal_analysis(model, {.num_modes = 8});
  ASSERT_TRUE(modes.status.ok());
  ASSERT_EQ(modes.num_modes(), 8);
  const fem::Assembled system = fem::assemble(model);
  const fem::Modes reference = cholmod_modes(system, {.num_modes = 8});
  const double first_elastic = reference.omega(6);
  ASSERT_GT(first_elastic, 1.0);
  for (int r = 0; r < 6; ++r)
    EXPECT_LT(modes.omega(r), 1e-5 * first_elastic) << "mode " << r + 1;
  EXPECT_NEAR(modes.omega(6), first_elastic, 1e-9 * first_elastic);
  EXPECT_NEAR(modes.omega(7), reference.omega(7), 1e-9 * reference.omega(7));
}

// A band with a few rows sent to every rank: the same modes as the CHOLMOD engine's band, and
// the same flexibility Σ φ_i φ_j / ω² at those rows (independent of the modes' signs and of the
// basis chosen inside a repeated pair).
TEST(SlepcModal, BandWithGatheredRowsMatchesTheCholmodEngine) {
  const fem::Model model = bench::frame_lattice(7, 6, 8, 0.5);
  const fem::Assembled system = fem::assemble(model);
  const fem::ModalOptions options{.num_modes = 0, .max_frequency_hz = 250.0};
  const fem::Modes reference = cholmod_modes(system, options);
  const std::vector<int> rows{5, 100, 1234, system.dofs.num_equations() - 1};
  const fem::Modes modes =
      fem::slepc_modal_analysis(model, options, {.rows = rows, .every_rank = true});
  ASSERT_TRUE(modes.status.ok());
  ASSERT_GT(reference.num_modes(), 8); // the band needs more than the first pass
  ASSERT_EQ(modes.num_modes(), reference.num_modes());
  EXPECT_EQ(modes.rows, rows);
  ASSERT_EQ(modes.phi.rows(), 4);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(4, 4), got = expected;
  for (int r = 0; r < modes.num_modes(); ++r) {
    EXPECT_NEAR(modes.omega(r), reference.omega(r), 1e-9 * reference.omega(r));
    Eigen::Vector4d ref_rows;
    for (int i = 0; i < 4; ++i)
      ref_rows(i) = reference.phi(rows[i], r);
    expected += ref_rows * ref_rows.transpose() / std::pow(reference.omega(r), 2);
    got += modes.phi.col(r) * modes.phi.col(r).transpose() / std::pow(modes.omega(r), 2);
  }
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-8 * expected.cwiseAbs().maxCoeff());
}

// A substructure above the dense limit whose band comes from the SLEPc engine (only the rows
// the synthesis needs, on every rank) gives the receptance of the default (CHOLMOD) band.
TEST(SlepcModal, SubstructureBandGivesTheSameReceptance) {
  const fem::Model model = bench::frame_lattice(7, 6, 8, 0.5);
  const frf::Substructure cholmod(model);
  frf::Substructure slepc(model);
  slepc.set_band_solver([](const fem::Model& m, const fem::Assembled&,
                           const fem::ModalOptions& options, const std::vector<int>& rows) {
    return fem::slepc_modal_analysis(m, options, {.rows = rows, .every_rank = true});
  });
  ASSERT_GT(cholmod.dofs().num_equations(), fem::ModalOptions{}.dense_limit);
  const std::vector<int> dofs{11, 600, 1500};
  const frf::ModalSynthesis a = cholmod.synthesis(dofs, 40.0);
  const frf::ModalSynthesis b = slepc.synthesis(dofs, 40.0);
  ASSERT_EQ(a.num_modes(), b.num_modes());
  EXPECT_TRUE(b.has_residual());
  for (double hz : {3.0, 17.0, 35.0}) {
    const frf::CMatrix Ha = a.receptance(2 * std::numbers::pi * hz, dofs, dofs);
    const frf::CMatrix Hb = b.receptance(2 * std::numbers::pi * hz, dofs, dofs);
    EXPECT_LT((Ha - Hb).norm(), 1e-8 * Ha.norm()) << hz << " Hz";
  }
}

TEST(SlepcModal, CallerMistakesThrow) {
  const fem::Model model = bench::frame_lattice(3, 2, 3, 1.0);
  EXPECT_THROW(fem::slepc_modal_analysis(model, {.num_modes = 0}), std::invalid_argument);
  EXPECT_THROW(fem::slepc_modal_analysis(model, {.num_modes = 10000}), std::invalid_argument);
  EXPECT_THROW(fem::slepc_modal_analysis(model, {.num_modes = 4}, {.rows = {-1}}),
               std::invalid_argument);
}

TEST(SlepcModal, ADofWithNeitherStiffnessNorMassIsRefused) {
  // A node held by a spring of zero stiffness and without mass: K − σM has a zero row, which
  // MUMPS cannot factorise; the error says what to look for (every rank throws it).
  fem::Model model = bench::frame_lattice(3, 2, 3, 1.0);
  model.nodes.push_back({9999, Eigen::Vector3d(50.0, 50.0, 50.0)});
  model.springs.push_back({9999, 0, fem::Dof::uy, 0.0});
  try {
    fem::slepc_modal_analysis(model, {.num_modes = 4});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("could not be factorised"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("neither stiffness nor mass"), std::string::npos)
        << e.what();
  }
}

} // namespace
} // namespace jointid

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  jointid::fem::SlepcSession mpi;
  jointid::session = &mpi;
  // One report: the other ranks run the same tests silently (a failure there still fails the
  // run through their exit status).
  if (mpi.rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
