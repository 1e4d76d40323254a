// The linear substructure as the analyses see it: FE (dense or band of modes) or given by its
// modes; receptance and the damping matrix for time integration.
#include "frf/substructure.hpp"

#include "fem/damping.hpp"
#include "support/beam_models.hpp"
#include "support/cantilever.hpp"
#include "support/failing_substructure.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

using namespace jointid;
using fem::Dof;

namespace {

using jointid::test::all_modes;

using jointid::test::relative_difference;

using jointid::test::two_pi;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A cantilever of 800 beam elements: 1600 equations, above the dense limit (1500).
fem::Model long_cantilever() {
  fem::Model m = test::cantilever(800);
  m.damping.kind = fem::Damping::Kind::modal;
  m.damping.modal_ratio = 0.01;
  return m;
}

} // namespace

TEST(Substructure, SmallFEModelUsesEveryMode) {
  // The paper cantilever (12 equations): every mode, as a ModalSynthesis built by hand from
  // the dense eigensolver with the model's damping.
  const fem::Model model = test::paper_cantilever();
  const frf::Substructure sub(model);
  ASSERT_NE(sub.model(), nullptr);
  ASSERT_NE(sub.system(), nullptr);
  EXPECT_EQ(sub.modal(), nullptr);
  EXPECT_EQ(sub.dofs().num_equations(), 12);
  const std::vector<int> dofs{sub.dofs().equation({4, Dof::uy}), sub.dofs().equation({7, Dof::uy})};
  std::vector<std::string> notes;
  const frf::ModalSynthesis H = sub.synthesis(dofs, 0.0, &notes);
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(H.num_modes(), 12);

  const fem::Assembled system = fem::assemble(model);
  const frf::ModalSynthesis by_hand(system, all_modes(system), model.damping, dofs);
  for (double f : {0.0, 1.0, 3.0, 18.8, 40.0}) {
    const double w = two_pi * f;
    EXPECT_LE(relative_difference(H.receptance(w, dofs, dofs), by_hand.receptance(w, dofs, dofs)),
              1e-12)
        << f << " Hz";
  }
  // The exact receptance: the direct solve with the modal damping matrix.
  const fem::SparseMatrix C = sub.damping_matrix().value;
  for (double f : {1.0, 3.0, 18.8}) {
    const double w = two_pi * f;
    EXPECT_LE(relative_difference(H.receptance(w, dofs, dofs),
                                  frf::direct_receptance(system, C, w, dofs, dofs).value),
              1e-9)
        << f << " Hz";
  }
}

TEST(Substructure, MasslessRotationsGetTheirStaticFlexibility) {
  // A cantilever whose mass matrix is lumped on the translations only: the rotations have no
  // mass, so no finite mode. The synthesis from the finite modes plus the residual flexibility
  // K⁻¹ − Σ φφᵀ/ω² must equal the direct solve at a translation and at a massless rotation
  // (exactly so with mass-proportional damping: the missing "infinite" modes are undamped).
  fem::Assembled system = fem::assemble(test::cantilever(12, {}));
  const int n = system.dofs.num_equations();
  Eigen::VectorXd lumped = Eigen::VectorXd::Zero(n);
  const Eigen::MatrixXd M(system.M);
  for (int e = 0; e < n; ++e)
    if (system.dofs.node_dof(e).dof != Dof::rz)
      for (int j = 0; j < n; ++j)
        if (system.dofs.node_dof(j).dof != Dof::rz) lumped(e) += M(e, j);
  system.M = fem::SparseMatrix(lumped.asDiagonal());
  fem::Damping damping;
  damping.kind = fem::Damping::Kind::rayleigh;
  damping.alpha = 0.5;
  const frf::Substructure sub(system, damping);
  const std::vector<int> dofs{system.dofs.equation({13, Dof::uy}),
                              system.dofs.equation({13, Dof::rz}),
                              system.dofs.equation({7, Dof::rz})};
  const frf::ModalSynthesis H = sub.synthesis(dofs, 0.0);
  EXPECT_EQ(H.num_modes(), n / 2);
  EXPECT_TRUE(H.has_residual());
  const fem::SparseMatrix C = sub.damping_matrix().value;
  for (double f : {0.0, 2.0, 18.0, 150.0}) {
    const double w = two_pi * f;
    EXPECT_LE(relative_difference(H.receptance(w, dofs, dofs),
                                  frf::direct_receptance(system, C, w, dofs, dofs).value),
              1e-9)
        << f << " Hz";
  }
}

TEST(Substructure, LargeFEModelUsesTheModesBelowFmaxWithResidual) {
  // 1600 equations: the sparse engine's modes below 30 Hz (the cantilever's first three,
  // 3.0, 18.8 and 52.7 Hz for 2 m: two of them) plus residual flexibility.
  const fem::Model model = long_cantilever();
  const frf::Substructure sub(model);
  ASSERT_EQ(sub.dofs().num_equations(), 1600);
  const std::vector<int> dofs{sub.dofs().equation({401, Dof::uy}),
                              sub.dofs().equation({801, Dof::uy})};
  std::vector<std::string> notes;
  const frf::ModalSynthesis H = sub.synthesis(dofs, 30.0, &notes);
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(H.num_modes(), 2);
  EXPECT_TRUE(H.has_residual());

  fem::ModalOptions o;
  o.max_frequency_hz = 30.0;
  o.engine = fem::ModalEngine::sparse;
  const frf::ModalSynthesis by_hand(*sub.system(), fem::modal_analysis(*sub.system(), o),
                                    model.damping, dofs);
  for (double f : {0.0, 2.0, 3.0, 10.0, 25.0}) {
    const double w = two_pi * f;
    EXPECT_LE(relative_difference(H.receptance(w, dofs, dofs), by_hand.receptance(w, dofs, dofs)),
              1e-9)
        << f << " Hz";
  }
  // The static limit is the flexibility: the tip's L³/3EI (2 m, paper section). The residual
  // comes from a Cholesky solve with K, whose condition number grows as (800 elements)⁴: about
  // 2e-6 relative is rounding here, while the modes left out without the residual would be
  // missing 0.46 % (modes 3 and up of a cantilever: 1 − 0.9707 − 0.0247).
  const test::BeamProperties p;
  const std::vector<int> tip{dofs[1]};
  const double tip_flexibility = std::pow(p.length, 3) / (3 * p.E * p.I());
  EXPECT_NEAR(H.receptance(0.0, tip, tip)(0, 0).real(), tip_flexibility, 1e-5 * tip_flexibility);
  // The band needs an upper frequency.
  EXPECT_THROW(sub.synthesis(dofs, 0.0), std::invalid_argument);
}

TEST(Substructure, LargeFreeModelNotesTheModesLeftOut) {
  // A free beam has rigid-body modes: K is singular, no residual flexibility; the note says so.
  fem::Model model = test::uniform_beam(800);
  const frf::Substructure sub(model);
  const std::vector<int> dofs{sub.dofs().equation({801, Dof::uy})};
  std::vector<std::string> notes;
  const frf::ModalSynthesis H = sub.synthesis(dofs, 30.0, &notes);
  EXPECT_FALSE(H.has_residual());
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_TRUE(contains(notes[0], "receptance from " + std::to_string(H.num_modes()) +
                                     " of 1602 modes without residual flexibility"))
      << notes[0];
  EXPECT_TRUE(contains(notes[0], "rigid-body modes")) << notes[0];
}

TEST(Substructure, EquationsOutsideTheModelAreRefused) {
  const frf::Substructure sub(test::paper_cantilever());
  EXPECT_THROW(sub.synthesis({12}, 10.0), std::invalid_argument);
  EXPECT_THROW(sub.synthesis({-1}, 10.0), std::invalid_argument);
  fem::Model broken = test::paper_cantilever();
  broken.materials[0].E = -1.0;
  EXPECT_THROW(frf::Substructure{broken}, std::invalid_argument);
}

TEST(Substructure, RayleighDampingMatrixIsAlphaMPlusBetaK) {
  fem::Model model = test::paper_cantilever();
  model.damping.kind = fem::Damping::Kind::rayleigh;
  model.damping.alpha = 0.4;
  model.damping.beta = 2e-5;
  const frf::Substructure sub(model);
  const Eigen::MatrixXd C(sub.damping_matrix().value);
  const fem::Assembled s = fem::assemble(model);
  const Eigen::MatrixXd expected = 0.4 * Eigen::MatrixXd(s.M) + 2e-5 * Eigen::MatrixXd(s.K);
  EXPECT_LE((C - expected).norm(), 1e-14 * expected.norm());
  // No damping: a zero matrix of the right size.
  model.damping = {};
  const fem::SparseMatrix none = frf::Substructure(model).damping_matrix().value;
  EXPECT_EQ(none.rows(), 12);
  EXPECT_EQ(none.cols(), 12);
  EXPECT_EQ(none.nonZeros(), 0);
}

TEST(Substructure, ModalDampingMatrixIsDiagonalisedByTheModes) {
  // Φᵀ C Φ = diag(2ζω_r) with ζ = 1 %, every mode (Φ mass-normalised from an independent
  // dense solve).
  const frf::Substructure sub(test::paper_cantilever());
  const Eigen::MatrixXd C(sub.damping_matrix().value);
  const fem::Modes modes = all_modes(*sub.system());
  const Eigen::MatrixXd modal = modes.phi.transpose() * C * modes.phi;
  const Eigen::MatrixXd expected = (2.0 * 0.01 * modes.omega).asDiagonal();
  EXPECT_LE((modal - expected).norm(), 1e-9 * expected.norm());
}

TEST(Substructure, ModalDampingAboveTheDenseLimitIsRefused) {
  const frf::Substructure sub(long_cantilever());
  try {
    (void)sub.damping_matrix();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, "needs every mode")) << message;
    EXPECT_TRUE(contains(message, "1600 equations (more than 1500)")) << message;
    EXPECT_TRUE(contains(message, "rayleigh = [alpha, beta]")) << message;
  }
  // Rayleigh damping is fine at any size.
  fem::Model model = long_cantilever();
  model.damping.kind = fem::Damping::Kind::rayleigh;
  model.damping.beta = 1e-5;
  EXPECT_EQ(frf::Substructure(model).damping_matrix().value.rows(), 1600);
}

TEST(Substructure, ModalModelUsesItsModes) {
  frf::ModalModel modal;
  modal.dofs = {{7, Dof::uy}, {4, Dof::uy}};
  modal.frequencies_hz = Eigen::Vector2d(3.0, 18.8);
  modal.damping = Eigen::Vector2d(0.01, 0.02);
  modal.shapes.resize(2, 2);
  modal.shapes << 0.5, 0.2, -0.4, 0.3;
  modal.residual_flexibility = Eigen::Matrix2d::Identity() * 1e-8;
  const frf::Substructure sub(modal);
  EXPECT_EQ(sub.model(), nullptr);
  EXPECT_EQ(sub.system(), nullptr);
  ASSERT_NE(sub.modal(), nullptr);
  EXPECT_EQ(sub.dofs().num_equations(), 2);
  EXPECT_EQ(sub.dofs().equation({4, Dof::uy}), 1);
  std::vector<std::string> notes;
  const std::vector<int> dofs{1, 0};
  const frf::ModalSynthesis H = sub.synthesis(dofs, 0.0, &notes);
  EXPECT_TRUE(notes.empty());
  EXPECT_TRUE(H.has_residual());
  // H_{7:uy, 4:uy} at 10 Hz by hand: Σ φ_7 φ_4 / (ω_r² − ω² + 2iζ_rω_rω) + 0.
  const double w = two_pi * 10.0;
  frf::Complex expected = 0.0;
  for (int r = 0; r < 2; ++r) {
    const double wr = two_pi * modal.frequencies_hz(r);
    expected += modal.shapes(r, 0) * modal.shapes(r, 1) /
                frf::Complex(wr * wr - w * w, 2 * modal.damping(r) * wr * w);
  }
  const std::vector<int> row{0}, col{1};
  EXPECT_LE(std::abs(H.receptance(w, row, col)(0, 0) - expected), 1e-14 * std::abs(expected));
  EXPECT_THROW(sub.synthesis({2}, 10.0), std::invalid_argument);
  // No time integration without K and M.
  try {
    (void)sub.damping_matrix();
    FAIL() << "expected std::logic_error";
  } catch (const std::logic_error& e) {
    EXPECT_TRUE(contains(e.what(), "time integration needs a finite element model")) << e.what();
  }
  modal.damping(0) = -1.0;
  EXPECT_THROW(frf::Substructure{modal}, std::invalid_argument);
}

namespace {

// The sparse engine held to one restart at a tolerance of 0: a band of modes that does not
// converge (a real non-convergence, through the documented band-solver seam).
frf::Substructure::BandSolver unconverging_band() {
  return [](const fem::Model&, const fem::Assembled& system, const fem::ModalOptions& options,
            const std::vector<int>&) {
    fem::ModalOptions o = options;
    o.max_iterations = 1;
    o.tolerance = 0.0;
    return fem::modal_analysis(system, o);
  };
}

} // namespace

TEST(Substructure, AModalAnalysisThatFailsIsTheSynthesisStatus) {
  frf::Substructure sub(long_cantilever());
  sub.set_band_solver(unconverging_band());
  const std::vector<int> tip{sub.dofs().equation({801, Dof::uy})};
  const std::string failed =
      "the modal analysis failed: block shift-invert Lanczos did not converge to ";
  const frf::ModalSynthesis H = sub.synthesis(tip, 30.0);
  EXPECT_EQ(H.status().code, fem::Status::Code::not_converging);
  EXPECT_TRUE(H.status().reason.starts_with(failed)) << H.status().reason;
  EXPECT_THROW((void)H.receptance(1.0, tip, tip), std::logic_error);
  // Bad input still throws.
  EXPECT_THROW(sub.synthesis(tip, 0.0), std::invalid_argument);

  // A composite substructure: the failing part's status, naming the part.
  frf::Substructure composite(
      {frf::Substructure(test::cantilever(4)), frf::Substructure(long_cantilever())}, {1000, 0});
  composite.set_band_solver(unconverging_band());
  const std::vector<int> both{composite.dofs().equation({1005, Dof::uy}),
                              composite.dofs().equation({801, Dof::uy})};
  const frf::ModalSynthesis C = composite.synthesis(both, 30.0);
  EXPECT_EQ(C.status().code, fem::Status::Code::not_converging);
  EXPECT_TRUE(C.status().reason.starts_with("substructure 2: " + failed)) << C.status().reason;
  // Its first part alone is fine.
  const frf::ModalSynthesis first = composite.synthesis({both[0]}, 30.0);
  EXPECT_TRUE(first.status().ok()) << first.status().reason;
}

TEST(Substructure, ADenseModalAnalysisThatFailsIsAStatus) {
  // A mass of 1e-300 kg against springs of 1e10 N/m (tests/support/failing_substructure.hpp):
  // the dense eigensolver's reduction overflows and its eigenvalues are NaN, which the modal
  // analysis reports. The synthesis and the modal damping matrix, which need every mode, pass
  // its status up with the reason.
  const frf::Substructure sub = test::failing_substructure();
  const std::vector<int> dofs{0, 1, 2};
  const frf::ModalSynthesis H = sub.synthesis(dofs, 10.0);
  EXPECT_EQ(H.status().code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(H.status().reason, "the modal analysis failed: " + test::failing_modes_reason);
  const fem::Outcome<fem::SparseMatrix> C = sub.damping_matrix();
  EXPECT_EQ(C.status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(C.status.reason, "modal damping needs every mode, and the modal analysis failed: " +
                                 test::failing_modes_reason);
  EXPECT_EQ(C.value.size(), 0);
}
