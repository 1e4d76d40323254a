// The modal fit against known modal parameters: FRFs of the finite element cantilever (every
// mode, so the modes above the band are really there) and of a modal model with two modes 1 %
// apart, each with 1 % noise on every line; and the refusals.
#include "identify/modal_fit.hpp"

#include "frf/receptance.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"
#include "support/synthesised_cantilever.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace jointid::identify {
namespace {

using jointid::test::two_pi;
using test::error_of;

// Lines f0, f0 + df, … up to f1 (Hz).
Eigen::VectorXd lines(double f0, double f1, double df) {
  const auto n = static_cast<Eigen::Index>(std::floor((f1 - f0) / df + 1e-9)) + 1;
  return Eigen::VectorXd::LinSpaced(n, f0, f0 + static_cast<double>(n - 1) * df);
}

// Relative complex Gaussian noise of RMS `level` on every value (seeded): H (1 + level·ε),
// E|ε|² = 1.
void add_noise(Eigen::MatrixXcd& H, double level, unsigned seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, level / std::sqrt(2.0));
  for (Eigen::Index c = 0; c < H.cols(); ++c)
    for (Eigen::Index j = 0; j < H.rows(); ++j)
      H(j, c) *= std::complex<double>(1.0 + normal(random), normal(random));
}

// FRFs from `drive` to `responses` (DOFs of `dofs`) by a modal synthesis.
MeasuredFrfs frfs(const frf::ModalSynthesis& synthesis, const std::vector<fem::NodeDof>& dofs,
                  const std::vector<int>& equations, int drive, const Eigen::VectorXd& f) {
  MeasuredFrfs d;
  d.drive = dofs[static_cast<std::size_t>(drive)];
  d.drive_name = "f@" + fem::to_string(d.drive);
  d.frequency_hz = f;
  d.H.resize(f.size(), static_cast<Eigen::Index>(equations.size()));
  for (std::size_t c = 0; c < equations.size(); ++c) {
    d.responses.push_back(dofs[c]);
    d.response_names.push_back("x@" + fem::to_string(dofs[c]));
    d.measured_as.push_back(Quantity::displacement);
  }
  const std::vector<int> col{equations[static_cast<std::size_t>(drive)]};
  for (Eigen::Index j = 0; j < f.size(); ++j)
    d.H.row(j) = synthesis.receptance(two_pi * f(j), equations, col).transpose();
  d.coherence = Eigen::MatrixXd::Constant(d.H.rows(), d.H.cols(), 1.0);
  d.resolution_hz = f(1) - f(0);
  return d;
}

TEST(ModalFit, RecoversTheCantileversModesFromFrfsWithOnePercentNoise) {
  // The 6-element cantilever, 1 % modal damping, every mode: in the band 0.5–60 Hz its modes at
  // 3.0, 18.8 and 52.6 Hz; the modes at 103 Hz and above make the upper residual. Responses uy at
  // nodes 3, 5 and 7, the force at 7 (the driving point); lines 0.01 Hz apart: 6 in the first
  // mode's half-power band 2ζf = 0.06 Hz, 38 and 105 in the others'.
  const test::SynthesisedCantilever beam;
  const std::vector<int> nodes{3, 5, 7};
  std::vector<int> equations;
  std::vector<fem::NodeDof> dofs;
  for (int n : nodes) {
    equations.push_back(beam.eq(n));
    dofs.push_back({n, fem::Dof::uy});
  }
  MeasuredFrfs data = frfs(beam.H, dofs, equations, 2, lines(0.5, 60.0, 0.01));
  const MeasuredFrfs exact = data;
  add_noise(data.H, 0.01, 7);

  const ModalFit fit = modal_fit(data, {.modes = 3});
  ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
  ASSERT_EQ(fit.modes.size(), 3u);
  const Eigen::MatrixXd phi = beam.H.shapes(equations); // 3 × n_modes, mass-normalised
  for (int r = 0; r < 3; ++r) {
    const FittedMode& m = fit.modes[static_cast<std::size_t>(r)];
    const double f_true = beam.modes.frequency_hz(r);
    // Noise ε = 1 % on each line, n lines in the half-power band (n >= 6): the standard errors
    // are about ε ζ f/√n in frequency and ε ζ/√n in damping (relative: 4e-5 and 0.4 % for the
    // first mode). Tolerances: 5e-4 and 3 %, ten times that or more.
    EXPECT_NEAR(m.frequency_hz / f_true, 1.0, 5e-4) << "mode " << r + 1 << ": " << m.frequency_hz;
    EXPECT_NEAR(m.damping / 0.01, 1.0, 0.03) << "mode " << r + 1;
    ASSERT_TRUE(m.in_model());
    Eigen::VectorXd truth = phi.col(r);
    if (truth(2) < 0.0) truth = -truth; // the fit's shape is positive at the driving point
    EXPECT_GT(modal_assurance(m.shape, truth), 0.99) << "mode " << r + 1;
    // Scale: the driving point's residue φ_d² has a relative error of about ε/√n (0.4 %): the
    // shape's scale within 2 %.
    EXPECT_NEAR(m.shape(2) / truth(2), 1.0, 0.02) << "mode " << r + 1;
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(m.shape(i), truth(i), 0.02 * truth.cwiseAbs().maxCoeff())
          << "mode " << r + 1 << ", node " << nodes[static_cast<std::size_t>(i)];
  }
  // The misfit is of the noise's size (1 % of |H| on every line; weighted by |H|², so ruled by
  // the few lines at the peaks) for the fit and for the model as written (no lower residual;
  // nothing below the band here). Line by line it is not at the noise everywhere: the modes
  // above the band are one constant (the upper residual), while the 103 Hz mode's term grows by
  // (60/103)² = 34 % over the band; that shows near the antiresonances, where |H| is small.
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(fit.fit_error(c), 0.02) << c;
    EXPECT_LT(fit.model_error(c), 0.02) << c;
  }
  // Against the exact FRFs the model is closer than the noise.
  for (int c = 0; c < 3; ++c)
    EXPECT_LT((fit.model_frf.col(c) - exact.H.col(c)).norm() / exact.H.col(c).norm(), 0.005) << c;

  // Without --modes: the same three modes.
  const ModalFit automatic = modal_fit(data);
  ASSERT_TRUE(automatic.status.ok()) << automatic.status.reason;
  ASSERT_EQ(automatic.modes.size(), 3u);
  for (int r = 0; r < 3; ++r)
    EXPECT_NEAR(automatic.modes[static_cast<std::size_t>(r)].frequency_hz /
                    beam.modes.frequency_hz(r),
                1.0, 5e-4);
}

TEST(ModalFit, TheModelIsTheModalSynthesisOfItsModalModel) {
  // The FRFs the fit reports for its [modal] model are what frf::ModalSynthesis (the route every
  // analysis takes) computes from that model: the conventions of [modal] (mass-normalised shapes
  // as rows, ζ as a ratio of the undamped ω_r, the residual flexibility) are the fit's.
  const test::SynthesisedCantilever beam;
  std::vector<int> equations{beam.eq(4), beam.eq(7)};
  const std::vector<fem::NodeDof> dofs{{4, fem::Dof::uy}, {7, fem::Dof::uy}};
  MeasuredFrfs data = frfs(beam.H, dofs, equations, 1, lines(10.0, 70.0, 0.02));
  add_noise(data.H, 0.01, 3);
  const ModalFit fit = modal_fit(data, {.modes = 2});
  ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
  ASSERT_EQ(fit.substructure.num_modes(), 2);
  ASSERT_EQ(fit.substructure.residual_flexibility.rows(), 2);
  const frf::ModalSynthesis synthesis(fit.substructure, {0, 1});
  const std::vector<int> rows{0, 1}, drive{1};
  for (Eigen::Index j = 0; j < data.num_lines(); j += 97) {
    const Eigen::MatrixXcd h = synthesis.receptance(two_pi * data.frequency_hz(j), rows, drive);
    for (int c = 0; c < 2; ++c)
      EXPECT_LT(std::abs(h(c, 0) - fit.model_frf(j, c)), 1e-12 * std::abs(h(c, 0))) << j;
  }
  // The residual flexibility: the upper residual in the driving point's column (measured), of
  // rank one elsewhere.
  const Eigen::MatrixXd& R = fit.substructure.residual_flexibility;
  EXPECT_DOUBLE_EQ(R(1, 1), fit.upper_residual(1));
  EXPECT_DOUBLE_EQ(R(0, 1), fit.upper_residual(0));
  EXPECT_DOUBLE_EQ(R(1, 0), R(0, 1));
  EXPECT_NEAR(R(0, 0), R(0, 1) * R(0, 1) / R(1, 1), 1e-15 * std::abs(R(0, 0)));
  // The modes below the band (3 Hz) are the lower residual, reported and left out of the model.
  bool warned = false;
  for (const auto& w : fit.warnings)
    warned = warned || w.find("lower residual") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_GT(fit.lower_residual(1), 0.0); // mass-like at the driving point: −L/ω², L > 0
}

// Three DOFs, modes at 10.0, 10.1 (1 % apart) and 25 Hz.
struct CloseModes {
  frf::ModalModel model;
  CloseModes() {
    model.dofs = {{1, fem::Dof::uy}, {2, fem::Dof::uy}, {3, fem::Dof::uy}};
    model.frequencies_hz = Eigen::Vector3d(10.0, 10.1, 25.0);
    model.damping = Eigen::Vector3d(0.005, 0.005, 0.01);
    model.shapes.resize(3, 3);
    model.shapes << 1.0, 0.5, -0.8, //
        0.7, -1.0, 0.4,             //
        0.5, 0.9, 0.6;
    model.shapes *= 0.3; // 1/sqrt(kg)
  }
};

TEST(ModalFit, FindsTwoModesOnePercentApart) {
  // Modes at 10.0 and 10.1 Hz with ζ = 0.5 %: their half-power bands (0.1 Hz wide) touch, the
  // magnitude shows one broad peak. Lines 0.005 Hz apart, 1 % noise, the force at DOF 1.
  const CloseModes close;
  const frf::ModalSynthesis synthesis(close.model, {0, 1, 2});
  MeasuredFrfs data = frfs(synthesis, close.model.dofs, {0, 1, 2}, 0, lines(5.0, 30.0, 0.005));
  const MeasuredFrfs exact = data;
  add_noise(data.H, 0.01, 11);
  for (int wanted : {3, 0}) {
    const ModalFit fit = modal_fit(data, {.modes = wanted});
    ASSERT_TRUE(fit.status.ok()) << fit.status.reason;
    ASSERT_EQ(fit.modes.size(), 3u) << "modes asked: " << wanted;
    // The fit is of the noise's size against the data and well inside it against the truth.
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(fit.fit_error(c), 0.02) << c;
      EXPECT_LT((fit.fitted.col(c) - exact.H.col(c)).norm() / exact.H.col(c).norm(), 0.005) << c;
    }
    for (int r = 0; r < 3; ++r) {
      const FittedMode& m = fit.modes[static_cast<std::size_t>(r)];
      // A tenth of the modes' separation (0.1 Hz) in frequency; the damping within 10 %.
      EXPECT_NEAR(m.frequency_hz, close.model.frequencies_hz(r), 0.01) << "mode " << r + 1;
      EXPECT_NEAR(m.damping / close.model.damping(r), 1.0, 0.1) << "mode " << r + 1;
      ASSERT_TRUE(m.in_model());
      EXPECT_GT(modal_assurance(m.shape, close.model.shapes.row(r).transpose()), 0.99)
          << "mode " << r + 1;
      EXPECT_NEAR(m.shape(0), close.model.shapes(r, 0), 0.03 * close.model.shapes(r, 0));
    }
  }
}

TEST(ModalFit, AskingMoreModesThanTheDiagramShowsIsAStatus) {
  const CloseModes close;
  const frf::ModalSynthesis synthesis(close.model, {0, 1, 2});
  MeasuredFrfs data = frfs(synthesis, close.model.dofs, {0, 1, 2}, 0, lines(20.0, 30.0, 0.01));
  add_noise(data.H, 0.01, 5);
  const ModalFit fit = modal_fit(data, {.modes = 2}); // only the 25 Hz mode is in the band
  EXPECT_EQ(fit.status.code, fem::Status::Code::not_separable);
  EXPECT_NE(fit.status.reason.find("shows 1 mode in the band"), std::string::npos)
      << fit.status.reason;
  ASSERT_EQ(fit.modes.size(), 1u);
  EXPECT_NEAR(fit.modes[0].frequency_hz, 25.0, 0.01);
}

TEST(ModalFit, RefusesWhatItCannotFit) {
  const CloseModes close;
  const frf::ModalSynthesis synthesis(close.model, {0, 1, 2});
  const MeasuredFrfs data = frfs(synthesis, close.model.dofs, {0, 1, 2}, 0, lines(5.0, 30.0, 0.05));
  // The driving point not measured: no mass normalisation.
  MeasuredFrfs no_drive = data;
  no_drive.drive = {9, fem::Dof::uy};
  no_drive.drive_name = "f@9:uy";
  EXPECT_EQ(error_of([&] { modal_fit(no_drive); }),
            "the driving point f@9:uy is not among the responses (x@1:uy, x@2:uy, x@3:uy): "
            "mass-normalised shapes need the response at the driving point (measure x, v or a at "
            "9:uy too)");
  // Too few lines for the modes asked: 2 N + 6.
  MeasuredFrfs few = data;
  few.frequency_hz = data.frequency_hz.head(13);
  few.H = data.H.topRows(13);
  few.coherence = data.coherence.topRows(13);
  EXPECT_EQ(error_of([&] { modal_fit(few, {.modes = 4}); }),
            "the band holds 13 lines (5 to 5.6 Hz): fitting 4 modes needs at least 14 (2 N + 6): "
            "widen the band, refine the resolution or ask fewer modes");
  EXPECT_NO_THROW(modal_fit(few, {.modes = 3}));
  few.frequency_hz = data.frequency_hz.head(9);
  few.H = data.H.topRows(9);
  few.coherence = data.coherence.topRows(9);
  EXPECT_NE(error_of([&] { modal_fit(few); }).find("a stabilisation diagram needs at least 10"),
            std::string::npos);
  EXPECT_NE(error_of([&] { modal_fit(data, {.max_order = 2}); }).find("at least 4, got 2"),
            std::string::npos);
}

TEST(ModalFit, WarnsAboutWhatTheModelCannotHold) {
  // Two DOFs, the drive at the first; FRFs made term by term: mode 1 (12 Hz) as a passive
  // structure's, "mode" 2 (20 Hz) with a negative residue at the driving point (no mode of a
  // passive structure has one), a negative constant (an upper residual ≤ 0).
  MeasuredFrfs d;
  d.drive = {1, fem::Dof::uy};
  d.drive_name = "f@1:uy";
  d.responses = {{1, fem::Dof::uy}, {2, fem::Dof::uy}};
  d.response_names = {"a@1:uy", "a@2:uy"};
  d.measured_as = {Quantity::acceleration, Quantity::acceleration};
  d.frequency_hz = lines(5.0, 30.0, 0.02);
  d.H.resize(d.frequency_hz.size(), 2);
  const double a1[] = {0.09, 0.06}, a2[] = {-0.04, 0.05};
  for (Eigen::Index j = 0; j < d.frequency_hz.size(); ++j) {
    const double w = two_pi * d.frequency_hz(j), w1 = two_pi * 12.0, w2 = two_pi * 20.0;
    for (int c = 0; c < 2; ++c)
      d.H(j, c) = a1[c] / std::complex<double>(w1 * w1 - w * w, 2.0 * 0.01 * w1 * w) +
                  a2[c] / std::complex<double>(w2 * w2 - w * w, 2.0 * 0.01 * w2 * w) - 1e-6;
  }
  d.coherence = Eigen::MatrixXd::Constant(d.H.rows(), 2, 0.95);
  d.coherence.col(1).setConstant(0.5);
  // As if from Welch's method with lines 0.1 Hz apart: mode 1's half-power band (0.24 Hz)
  // spans fewer than 4 of them.
  d.method = SpectraMethod::welch;
  d.resolution_hz = 0.1;
  auto has = [](const ModalFit& fit, const std::string& part) {
    for (const auto& w : fit.warnings)
      if (w.find(part) != std::string::npos) return true;
    return false;
  };
  // Asked for two modes: the second kept in the fit, left out of the model.
  const ModalFit two = modal_fit(d, {.modes = 2});
  ASSERT_TRUE(two.status.ok()) << two.status.reason;
  ASSERT_EQ(two.modes.size(), 2u);
  EXPECT_NEAR(two.modes[1].residues(0), -0.04, 1e-6);
  EXPECT_FALSE(two.modes[1].in_model());
  EXPECT_EQ(two.substructure.num_modes(), 1);
  EXPECT_TRUE(
      has(two, "mode 2 (20 Hz): its residue at the driving point f@1:uy is -0.04, not > 0"));
  EXPECT_TRUE(has(two, "the upper residual at the driving point f@1:uy is -1e-06 m/N, not > 0"));
  EXPECT_EQ(two.substructure.residual_flexibility.size(), 0);
  EXPECT_TRUE(has(two, "mode 1 (12 Hz): its half-power bandwidth, 0.24 Hz, spans fewer than 4"));
  EXPECT_TRUE(has(two, "a@2:uy: mean coherence 0.500 in the band"));
  EXPECT_FALSE(has(two, "a@1:uy: mean coherence"));
  // Chosen by the diagram: the 20 Hz pole is no mode.
  const ModalFit automatic = modal_fit(d);
  ASSERT_TRUE(automatic.status.ok()) << automatic.status.reason;
  ASSERT_EQ(automatic.modes.size(), 1u);
  EXPECT_NEAR(automatic.modes[0].frequency_hz, 12.0, 1e-6);
  EXPECT_TRUE(has(automatic, "a pole at 20 Hz (ζ = 0.01), stable at"));
}

TEST(ModalFit, ModalAssurance) {
  EXPECT_DOUBLE_EQ(modal_assurance(Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(-2.0, -4.0)), 1.0);
  EXPECT_DOUBLE_EQ(modal_assurance(Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(0.0, 3.0)), 0.0);
  EXPECT_DOUBLE_EQ(modal_assurance(Eigen::Vector2d(1.0, 1.0), Eigen::Vector2d(1.0, 0.0)), 0.5);
}

} // namespace
} // namespace jointid::identify
