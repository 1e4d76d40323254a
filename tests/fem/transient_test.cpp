// Time simulation under arbitrary force histories: the modal route against the full model on
// the paper's cantilever with a non-linear joint, and the force-history generators against
// their definitions (band, RMS, seed, lines).
#include "fem/transient.hpp"

#include "fem/damping.hpp"
#include "fem/excitation.hpp"
#include "fem/fft.hpp"
#include "joints/joint.hpp"
#include "support/beam_models.hpp"
#include "support/cantilever.hpp"
#include "support/error_of.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

using namespace jointid;

namespace {

joints::Joint tip_joint(std::vector<joints::Term> terms, std::vector<double> values) {
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

struct Cantilever {
  fem::Model model = test::paper_cantilever();
  fem::Assembled system = fem::assemble(model);
  fem::Modes modes =
      fem::modal_analysis(system, {.num_modes = 0, .engine = fem::ModalEngine::dense});
  fem::SparseMatrix C = fem::damping_matrix(system, model.damping, &modes);
  int tip = system.dofs.equation({7, fem::Dof::uy});
  int mid = system.dofs.equation({4, fem::Dof::uy});
};

const Cantilever& cantilever() {
  static const Cantilever c;
  return c;
}

// Band-limited random force at the tip: 1–30 Hz, 20 N RMS, 6 s at 256 Hz.
fem::ForceHistory random_force(int equation, double f1 = 30.0) {
  fem::ForceHistory h;
  h.dt = 1.0 / 256.0;
  h.equations = {equation};
  h.samples = fem::band_limited_random({1.0, f1, 20.0, 7}, {6.0, 256.0});
  return h;
}

fem::Modes lowest(const fem::Modes& all, int count) {
  fem::Modes m = all;
  m.omega.conservativeResize(count);
  m.phi.conservativeResize(Eigen::NoChange, count);
  return m;
}

fem::TransientOptions options(int substeps, double fade_in_s) {
  fem::TransientOptions o;
  o.substeps = substeps;
  o.fade_in_s = fade_in_s;
  return o;
}

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

} // namespace

TEST(Transient, ModalRouteWithEveryModeIsTheFullModel) {
  // With every mode kept the modal coordinates are an exact change of basis of the same
  // Newmark scheme (C = MΦ diag(2ζω) ΦᵀM is diagonal in them): the two routes agree to
  // rounding, whatever the joint (here model I's, with its cubic and quadratic terms).
  const Cantilever& c = cantilever();
  const joints::JointForces joint(
      {tip_joint({joints::Term::k, joints::Term::c, joints::Term::c2, joints::Term::k3},
                 {4800.0, 20.0, 500.0, 1.6e8})},
      c.system.dofs);
  const fem::ForceHistory force = random_force(c.tip);
  const std::vector<int> outputs{c.tip, c.mid};
  const fem::TransientOptions o = options(4, 0.0);
  const fem::TransientResponse full =
      fem::transient_response(c.system, c.C, &joint, force, outputs, o);
  const fem::ModalReduction all = fem::modal_reduction(c.system, c.modes, c.model.damping, {});
  EXPECT_EQ(all.kept_modes, 12);
  EXPECT_EQ(all.static_columns, 0);
  const fem::TransientResponse modal = fem::transient_response(all, &joint, force, outputs, o);
  ASSERT_TRUE(full.status.ok());
  ASSERT_TRUE(modal.status.ok());
  std::printf("every mode vs full model: %.3g (x), %.3g (v), relative to the peak\n",
              relative_difference(modal.u, full.u), relative_difference(modal.v, full.v));
  EXPECT_LT(relative_difference(modal.u, full.u), 1e-9);
  EXPECT_LT(relative_difference(modal.v, full.v), 1e-9);
  // The joint matters: the tip moves far less than without it.
  const fem::TransientResponse free =
      fem::transient_response(c.system, c.C, nullptr, force, outputs, o);
  EXPECT_GT(free.u.col(0).cwiseAbs().maxCoeff(), 2.0 * full.u.col(0).cwiseAbs().maxCoeff());
}

TEST(Transient, TruncatedModesWithStaticCorrectionFollowTheFullModel) {
  // Three modes kept (3.0, 18.8, 52.8 Hz) for a 1–30 Hz force; the nine left out start at
  // 103 Hz. The static correction (their flexibility at the loaded DOF, as one pseudo-mode)
  // leaves only their dynamic amplification beyond the Rayleigh–Ritz estimate: the tip
  // displacement agrees to 1e-4 of its peak (measured 7e-6), the velocity to 1e-2 (measured
  // 1e-3; derivatives weigh the high frequencies). Without the correction the left-out modes'
  // static part is missing: 9e-2 measured, at least 100 times worse.
  const Cantilever& c = cantilever();
  const joints::JointForces joint(
      {tip_joint({joints::Term::k, joints::Term::c, joints::Term::k3}, {4800.0, 20.0, 1.6e8})},
      c.system.dofs);
  const fem::ForceHistory force = random_force(c.tip);
  const std::vector<int> outputs{c.tip, c.mid};
  // Faded in: the massless static coordinates start consistent (at rest, zero force).
  const fem::TransientOptions o = options(4, 0.5);
  const fem::TransientResponse full =
      fem::transient_response(c.system, c.C, &joint, force, outputs, o);
  const std::vector<int> loaded{c.tip};
  const fem::ModalReduction corrected =
      fem::modal_reduction(c.system, lowest(c.modes, 3), c.model.damping, loaded);
  EXPECT_EQ(corrected.static_columns, 1);
  const fem::ModalReduction bare =
      fem::modal_reduction(c.system, lowest(c.modes, 3), c.model.damping, {});
  const fem::TransientResponse with = fem::transient_response(corrected, &joint, force, outputs, o);
  const fem::TransientResponse without = fem::transient_response(bare, &joint, force, outputs, o);
  const double error_with = relative_difference(with.u.col(0), full.u.col(0));
  const double error_without = relative_difference(without.u.col(0), full.u.col(0));
  RecordProperty("tip_error_static_correction", std::to_string(error_with));
  RecordProperty("tip_error_no_correction", std::to_string(error_without));
  std::printf("modal (3 modes) vs full, tip x: %.3g with static correction, %.3g without; "
              "v: %.3g\n",
              error_with, error_without, relative_difference(with.v.col(0), full.v.col(0)));
  EXPECT_LT(error_with, 1e-4);
  EXPECT_GT(error_without, 100.0 * error_with);
  EXPECT_LT(relative_difference(with.v.col(0), full.v.col(0)), 1e-2);
  EXPECT_LT(relative_difference(with.u.col(1), full.u.col(1)), 1e-3);
}

TEST(Transient, ModalRouteHandlesDryFrictionLikeTheFullModel) {
  // Model II's joint (Coulomb friction 3 N, exact stick–slip) with every mode kept: the same
  // scheme in other coordinates, so the same sticking and slipping, to the Newton tolerance.
  const Cantilever& c = cantilever();
  const joints::JointForces joint({tip_joint({joints::Term::k, joints::Term::fc}, {4800.0, 3.0})},
                                  c.system.dofs);
  fem::ForceHistory force = random_force(c.tip);
  force.samples *= 0.2; // 4 N RMS: it sticks and slips
  const std::vector<int> outputs{c.tip};
  const fem::TransientOptions o = options(4, 0.5);
  const fem::TransientResponse full =
      fem::transient_response(c.system, c.C, &joint, force, outputs, o);
  const fem::TransientResponse modal = fem::transient_response(
      fem::modal_reduction(c.system, c.modes, c.model.damping, {}), &joint, force, outputs, o);
  ASSERT_TRUE(full.status.ok());
  ASSERT_TRUE(modal.status.ok());
  std::printf("dry friction, every mode vs full model: %.3g (x)\n",
              relative_difference(modal.u, full.u));
  EXPECT_LT(relative_difference(modal.u, full.u), 1e-6);
  int stuck = 0;
  for (Eigen::Index i = 0; i < full.v.rows(); ++i)
    stuck += std::abs(full.v(i, 0)) < 1e-9;
  EXPECT_GT(stuck, 10); // it does stick
}

TEST(Transient, ModalReductionIsStaticallyExactAtTheLoadedDofs) {
  // Properties of the reduction with 2 of 12 modes and the static correction at the tip and
  // mid-span: the basis is M-orthonormal and K-orthogonal (so the reduced system is diagonal),
  // and a static load at the loaded DOFs deflects them exactly as the full model does
  // (K_red⁻¹ in reduced coordinates equals K⁻¹ there), which without the correction it does not.
  const Cantilever& c = cantilever();
  const std::vector<int> loaded{c.tip, c.mid};
  const fem::ModalReduction r =
      fem::modal_reduction(c.system, lowest(c.modes, 2), c.model.damping, loaded);
  ASSERT_EQ(r.kept_modes, 2);
  ASSERT_EQ(r.static_columns, 2);
  const Eigen::MatrixXd& T = r.basis;
  const Eigen::MatrixXd mass = T.transpose() * (c.system.M * T);
  const Eigen::MatrixXd stiffness = T.transpose() * (c.system.K * T);
  // To rounding (1e-12): the residual flexibility is computed with the kept modes projected
  // out (P K⁻¹ Pᵀ, P = I − ΦΦᵀM); as the difference K⁻¹ − ΦΛ⁻¹Φᵀ it was 1e-9 here.
  EXPECT_LT((mass - Eigen::MatrixXd::Identity(4, 4)).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::MatrixXd K_red(r.system.K);
  EXPECT_LT((stiffness - K_red).cwiseAbs().maxCoeff(), 1e-9 * K_red.cwiseAbs().maxCoeff());
  // The pseudo-modes lie above the kept modes (Rayleigh–Ritz: at or above the 3rd mode, 52.8 Hz).
  for (int z = 2; z < 4; ++z)
    EXPECT_GE(std::sqrt(K_red(z, z)), c.modes.omega(2) * (1.0 - 1e-9));
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(c.system.dofs.num_equations(), 2);
  E(c.tip, 0) = 1.0;
  E(c.mid, 1) = 1.0;
  const Eigen::MatrixXd exact = Eigen::MatrixXd(c.system.K).ldlt().solve(E);
  const Eigen::MatrixXd reduced =
      T * K_red.diagonal().cwiseInverse().asDiagonal() * T.transpose() * E;
  const Eigen::MatrixXd bare = T.leftCols(2) *
                               K_red.diagonal().head(2).cwiseInverse().asDiagonal() *
                               T.leftCols(2).transpose() * E;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(reduced(loaded[i], j), exact(loaded[i], j), 1e-10 * exact(c.tip, 0));
      EXPECT_GT(std::abs(bare(loaded[i], j) - exact(loaded[i], j)), 1e-4 * exact(c.tip, 0));
    }
  // A supported structure is required for a static correction; a free beam is refused.
  fem::Model free = c.model;
  free.supports.clear();
  const fem::Assembled loose = fem::assemble(free);
  const fem::Modes modes = fem::modal_analysis(loose, {.num_modes = 5});
  const std::vector<int> one{0};
  try {
    fem::modal_reduction(loose, modes, free.damping, one);
    FAIL() << "a static correction of a free beam accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "modal reduction: K is singular (rigid-body modes or a mechanism), so "
                           "the left-out modes have no static flexibility; keep every mode or "
                           "support the structure");
  }
}

TEST(Transient, ASampledForceIsAppliedAsTheBandLimitedOne) {
  // A sampled force stands for a band-limited one: the response's lines must be the receptance
  // times the samples' lines. The cantilever with a linear joint (k, c at the tip: exact
  // receptance by a dense solve) under a multisine of 1–8 Hz, period 4 s, sampled at 256 Hz,
  // 16 steps a sample; the last four of eight periods. The linear interpolant of the samples
  // applied each line f scaled by sinc²(f/fs) ≈ 1 − (π f/fs)²/3: 3.2e-3 at 8 Hz. The cubic's
  // error falls as (f/fs)⁴ (≈ 2e-6 at 8 Hz); Newmark's period error (ωh)²/12 ≈ 1.3e-5 at 8 Hz,
  // amplified near the resonance by 1/(2ζ) ≈ 10: the bound is 2e-4.
  const Cantilever& c = cantilever();
  const double k = 4800.0, damper = 20.0;
  const joints::JointForces joint({tip_joint({joints::Term::k, joints::Term::c}, {k, damper})},
                                  c.system.dofs);
  fem::ForceHistory force;
  force.dt = 1.0 / 256.0;
  force.equations = {c.tip};
  force.samples = fem::multisine({1.0, 8.0, 20.0, 4.0}, {32.0, 256.0});
  const std::vector<int> outputs{c.tip};
  const fem::TransientResponse r =
      fem::transient_response(c.system, c.C, &joint, force, outputs, options(16, 1.0));
  ASSERT_TRUE(r.status.ok()) << r.status.reason;
  const int N = 1024, first = 4 * N;
  fem::RealFft fft(4 * N);
  const Eigen::VectorXcd X = fft.forward(r.u.col(0).segment(first, 4 * N));
  const Eigen::VectorXcd F = fft.forward(force.samples.col(0).segment(first, 4 * N));
  Eigen::MatrixXd K = Eigen::MatrixXd(c.system.K), M = Eigen::MatrixXd(c.system.M),
                  C = Eigen::MatrixXd(c.C);
  K(c.tip, c.tip) += k;
  C(c.tip, c.tip) += damper;
  double worst = 0.0;
  for (int line = 4; line <= 32; ++line) { // 1 … 8 Hz, every 0.25 Hz: bins 4 · line
    const double omega = 2.0 * std::numbers::pi * line / 4.0;
    const Eigen::MatrixXcd D = K.cast<std::complex<double>>() -
                               omega * omega * M.cast<std::complex<double>>() +
                               std::complex<double>(0.0, omega) * C.cast<std::complex<double>>();
    const std::complex<double> H = D.partialPivLu().inverse()(c.tip, c.tip);
    worst = std::max(worst, std::abs(X(4 * line) / F(4 * line) - H) / std::abs(H));
  }
  std::printf("largest relative error of a response line: %.3g\n", worst);
  EXPECT_LT(worst, 2e-4);
}

TEST(Transient, BadInputsAreRefused) {
  const Cantilever& c = cantilever();
  fem::ForceHistory h = random_force(c.tip);
  const std::vector<int> outputs{c.tip};
  h.dt = 0.0;
  EXPECT_THROW(fem::transient_response(c.system, c.C, nullptr, h, outputs), std::invalid_argument);
  h = random_force(99);
  EXPECT_THROW(fem::transient_response(c.system, c.C, nullptr, h, outputs), std::invalid_argument);
  h = random_force(c.tip);
  const std::vector<int> bad{-1};
  EXPECT_THROW(fem::transient_response(c.system, c.C, nullptr, h, bad), std::invalid_argument);
  EXPECT_THROW(fem::transient_response(c.system, c.C, nullptr, h, outputs, options(0, 0.0)),
               std::invalid_argument);
  // A sample that is not a number is named by its row and column.
  h.samples(100, 0) = std::numeric_limits<double>::infinity();
  try {
    fem::transient_response(c.system, c.C, nullptr, h, outputs);
    FAIL() << "an infinite force accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "force history: sample 101 of column 1 (equation " +
                                         std::to_string(c.tip) + ") is inf, not a finite number");
  }
}

TEST(Excitation, BandLimitedRandomHasItsBandRmsAndSeed) {
  const fem::Sampling s{8.0, 512.0};
  const Eigen::VectorXd x = fem::band_limited_random({10.0, 40.0, 3.0, 5}, s);
  ASSERT_EQ(x.size(), 4096);
  EXPECT_NEAR(std::sqrt(x.squaredNorm() / x.size()), 3.0, 1e-12);
  EXPECT_NEAR(x.mean(), 0.0, 1e-12);
  fem::RealFft fft(4096);
  const Eigen::VectorXcd X = fft.forward(x);
  double inside = 0.0, outside = 0.0;
  for (Eigen::Index k = 0; k < X.size(); ++k) {
    const double f = k / 8.0;
    (f >= 10.0 && f <= 40.0 ? inside : outside) += std::norm(X(k));
  }
  EXPECT_LT(outside, 1e-20 * inside);
  // Gaussian: kurtosis 3 (standard error sqrt(24/n) ≈ 0.08 for n = 4096, but the 241 lines of
  // the band give fewer independent values: 0.5 allowed).
  const double m4 = x.array().pow(4).mean() / std::pow(9.0, 2);
  EXPECT_NEAR(m4, 3.0, 0.5);
  EXPECT_EQ(x, fem::band_limited_random({10.0, 40.0, 3.0, 5}, s));
  EXPECT_GT((x - fem::band_limited_random({10.0, 40.0, 3.0, 6}, s)).norm(), 1.0);
  EXPECT_THROW(fem::band_limited_random({10.0, 300.0, 3.0, 5}, s), std::invalid_argument);
  EXPECT_THROW(fem::band_limited_random({10.0, 40.0, -1.0, 5}, s), std::invalid_argument);
  EXPECT_THROW(fem::band_limited_random({10.0, 40.0, 1.0, 5}, {0.0, 512.0}), std::invalid_argument);
}

TEST(Excitation, SweepAndMultisine) {
  const fem::Sampling s{4.0, 1024.0};
  // Linear sweep 5 → 45 Hz: the phase advances by 2π (f0 + f1)/2 T, i.e. 100 cycles.
  const Eigen::VectorXd sweep = fem::sine_sweep({5.0, 45.0, 2.0, false}, s);
  EXPECT_LE(sweep.cwiseAbs().maxCoeff(), 2.0);
  int crossings = 0;
  for (Eigen::Index i = 1; i < sweep.size(); ++i)
    crossings += (sweep(i - 1) < 0.0) != (sweep(i) < 0.0);
  EXPECT_NEAR(crossings, 200, 2);
  // Multisine over 10–20 Hz: lines k/4 s, so 41 lines of equal amplitude and none outside.
  const Eigen::VectorXd ms = fem::multisine({10.0, 20.0, 1.5}, s);
  EXPECT_NEAR(std::sqrt(ms.squaredNorm() / ms.size()), 1.5, 1e-12);
  fem::RealFft fft(static_cast<int>(ms.size()));
  const Eigen::VectorXd mag = fft.forward(ms).cwiseAbs();
  int lines = 0;
  for (Eigen::Index k = 0; k < mag.size(); ++k)
    if (mag(k) > 1e-6 * mag.maxCoeff()) {
      ++lines;
      EXPECT_NEAR(mag(k), mag(40), 1e-9 * mag(40)) << k;
      EXPECT_TRUE(k >= 40 && k <= 80) << k;
    }
  EXPECT_EQ(lines, 41);
  // With a period of 1 s: that period four times, lines every 1 Hz (11 in 10–20 Hz).
  const Eigen::VectorXd repeated = fem::multisine({10.0, 20.0, 1.5, 1.0}, s);
  ASSERT_EQ(repeated.size(), 4096);
  for (int p = 1; p < 4; ++p)
    EXPECT_EQ(repeated.segment(1024 * p, 1024), repeated.head(1024)) << p;
  EXPECT_NEAR(std::sqrt(repeated.squaredNorm() / 4096.0), 1.5, 1e-12);
  const Eigen::VectorXd rmag = fft.forward(repeated).cwiseAbs();
  int repeated_lines = 0;
  for (Eigen::Index k = 0; k < rmag.size(); ++k)
    if (rmag(k) > 1e-6 * rmag.maxCoeff()) {
      ++repeated_lines;
      EXPECT_EQ(k % 4, 0) << k;
    }
  EXPECT_EQ(repeated_lines, 11);
  // A period that is not a whole number of samples, or does not divide the duration: refused.
  EXPECT_THROW(fem::multisine({10.0, 20.0, 1.5, 0.0012}, s), std::invalid_argument);
  EXPECT_THROW(fem::multisine({10.0, 20.0, 1.5, 1.5}, s), std::invalid_argument);
}

TEST(Transient, NumericalFailuresAreStatusesSayingWhen) {
  // One Newton iteration cannot solve a step with a joint (the first only measures the
  // residual): the step from sample 0 (t = 0) to its first substep (t = 0.005 s) fails.
  const fem::Assembled s = fem::assemble(test::oscillator(1.0, 100.0));
  joints::Joint j{"cubic", 1, 0, fem::Dof::ux, {joints::Term::k3}, {1e6}, {true}, {}};
  const joints::JointForces cubic({j}, s.dofs);
  const fem::ForceHistory history{0.01, {0}, Eigen::MatrixXd::Ones(4, 1)};
  fem::TransientOptions o;
  o.substeps = 2;
  o.newmark.max_newton = 1;
  const std::vector<int> out{0};
  const fem::SparseMatrix C(1, 1);
  const fem::TransientResponse r = fem::transient_response(s, C, &cubic, history, out, o);
  EXPECT_EQ(r.status.code, fem::Status::Code::not_converging);
  EXPECT_EQ(r.status.reason, "the joints' Newton iteration failed after t = 0 s (no convergence "
                             "in 1 iterations on the way to t = 0.005 s)");
  EXPECT_EQ(r.samples_done, 1);
  // With the default iterations every sample is computed.
  o.newmark.max_newton = fem::NewmarkOptions{}.max_newton;
  const fem::TransientResponse ok = fem::transient_response(s, C, &cubic, history, out, o);
  EXPECT_TRUE(ok.status.ok()) << ok.status.reason;
  EXPECT_EQ(ok.samples_done, 4);
  // A DOF with neither mass nor stiffness: the effective stiffness is singular.
  const fem::Assembled nothing = fem::assemble(test::oscillator(0.0, 0.0));
  const fem::TransientResponse none = fem::transient_response(nothing, C, nullptr, history, out);
  EXPECT_EQ(none.status.code, fem::Status::Code::numerical_issue);
  EXPECT_NE(none.status.reason.find("effective stiffness K + a1 C + a0 M is singular"),
            std::string::npos)
      << none.status.reason;
  EXPECT_EQ(none.samples_done, 0);
}

namespace {

// Two modes (3 and 19 Hz, 1 % damping) at two DOFs (nodes 1 and 2, uy) and the static
// flexibility R of modes left out there, as a TimeModel: x = Φ q + R F.
fem::TimeModel two_modes_with_residual() {
  fem::TimeModel m;
  const double w1 = 2 * std::numbers::pi * 3.0, w2 = 2 * std::numbers::pi * 19.0;
  Eigen::MatrixXd K = Eigen::Vector2d(w1 * w1, w2 * w2).asDiagonal();
  Eigen::MatrixXd C = Eigen::Vector2d(0.02 * w1, 0.02 * w2).asDiagonal();
  m.system.dofs = fem::DofMap::from_dofs({{1, fem::Dof::ux}, {2, fem::Dof::ux}});
  m.system.K = K.sparseView();
  m.system.M = Eigen::MatrixXd::Identity(2, 2).sparseView();
  m.C = C.sparseView();
  Eigen::MatrixXd phi(2, 2), R(2, 2);
  phi << 0.5, -0.4, 0.2, 0.3;  // 1/sqrt(kg)
  R << 1e-4, 2e-5, 2e-5, 5e-5; // m/N
  m.T = phi.sparseView();
  m.R = R.sparseView();
  return m;
}

} // namespace

// The model above with a dry-friction joint (k = 500 N/m, c = 20 N s/m, fc = 2 N) at node 1,
// driven at node 2 by 6 N at 2 Hz with `steps` time steps a period, over 8 periods.
struct StickSlipRun {
  int steps = 0;
  double h = 0.0;
  fem::TransientResponse r;
  std::vector<char> stuck; // per sample of the last 2 periods: held since the last (to rounding)
  int first = 0;           // the first sample of the last 2 periods
};

StickSlipRun stick_slip_run(int steps) {
  const fem::TimeModel m = two_modes_with_residual();
  joints::Joint j{"a",
                  1,
                  0,
                  fem::Dof::ux,
                  {joints::Term::k, joints::Term::c, joints::Term::fc},
                  {500.0, 20.0, 2.0},
                  {},
                  {}};
  j.fixed.assign(3, true);
  const joints::JointForces forces({j}, m.system.dofs);
  StickSlipRun run;
  run.steps = steps;
  const double f = 2.0, w = 2 * std::numbers::pi * f;
  run.h = 1.0 / (steps * f);
  fem::ForceHistory history;
  history.dt = run.h;
  history.equations = {1};
  const int n = 8 * steps;
  history.samples.resize(n, 1);
  for (int i = 0; i < n; ++i)
    history.samples(i, 0) = 6.0 * std::sin(w * i * run.h);
  const std::vector<int> outputs{0, 1};
  run.r = fem::transient_response(m, &forces, history, outputs);
  run.first = 6 * steps;
  const Eigen::VectorXd& x = run.r.u.col(0);
  for (int i = run.first; i < n; ++i)
    run.stuck.push_back(std::abs(x(i) - x(i - 1)) <= 1e-12 * std::abs(x(i)));
  return run;
}

// Whether sample i (of the last 2 periods, leaving a margin) lies away from the stick–slip
// transitions: from 3 steps before to 20 ms after one. The joint's damper on the static part's
// spring is a first-order lag of time constant R c / (1 + R k) = 1.9 ms (R = 1e-4 m/N at its
// DOF): at slip onset its velocity settles over that time, resolved by the steps or not.
bool away_from_transitions(const StickSlipRun& run, int i) {
  const int after = static_cast<int>(std::ceil(0.02 / run.h));
  if (i < run.first + after || i + 4 >= static_cast<int>(run.r.t.size())) return false;
  for (int k = i - after; k <= i + 3; ++k)
    if (run.stuck[static_cast<std::size_t>(k - run.first)] !=
        run.stuck[static_cast<std::size_t>(k + 1 - run.first)])
      return false;
  return true;
}

// Away from the transitions at DOF j: the largest |central difference of x − v|, the largest
// second difference |x_{i+1} − 2x_i + x_{i−1}| and the largest |ẍ|.
struct Smoothness {
  double velocity = 0.0, second_difference = 0.0, acceleration = 0.0;
};

Smoothness smoothness(const StickSlipRun& run, int j) {
  const Eigen::VectorXd &x = run.r.u.col(j), &v = run.r.v.col(j), &a = run.r.a.col(j);
  Smoothness s;
  for (int i = run.first; i < static_cast<int>(x.size()); ++i) {
    if (!away_from_transitions(run, i)) continue;
    s.velocity = std::max(s.velocity, std::abs((x(i + 1) - x(i - 1)) / (2 * run.h) - v(i)));
    s.second_difference = std::max(s.second_difference, std::abs(x(i + 1) - 2 * x(i) + x(i - 1)));
    s.acceleration = std::max(s.acceleration, std::abs(a(i)));
  }
  return s;
}

TEST(Transient, StaticCorrectionThroughStickSlipHasNoStepToStepMemory) {
  // The joint sticks and slips every half period, and the static part R F of the response has
  // a kink at each transition (F, with the joint's force, changes its rate there). The static
  // part has no mass: the trapezoidal rule's own velocity of it would keep an undamped
  // alternating error (+e, −e, …) after each kink, of the size of the kink's jump in rate
  // whatever the step, and the joint's force, fed with that velocity, would alternate with it.
  // The integrator uses backward differences of the static part's history instead, which
  // forget a kink within a few steps (the error halving at each). So, away from the transitions
  // (3 steps before to 20 ms after each; the joint does stick and slip, its displacement held
  // to rounding while it sticks): (1) the displacements have no step-to-step sawtooth,
  // |Δ²x| ≤ 4 max|ẍ| h²; (2) the velocity is the derivative of the displacement to second order
  // in h: halving h divides the largest difference from the central difference by about 4
  // (> 3 asserted), where an alternating error would not shrink.
  const StickSlipRun a = stick_slip_run(1024), b = stick_slip_run(2048);
  for (const StickSlipRun* run : {&a, &b}) {
    ASSERT_TRUE(run->r.status.ok()) << run->r.status.reason;
    const auto held = std::count(run->stuck.begin(), run->stuck.end(), 1);
    const auto checked = static_cast<long>(run->stuck.size());
    EXPECT_GT(held, checked / 10);           // it sticks
    EXPECT_LT(held, checked - checked / 10); // and slips
    for (int j = 0; j < 2; ++j) {
      const Smoothness s = smoothness(*run, j);
      EXPECT_LE(s.second_difference, 4 * s.acceleration * run->h * run->h)
          << "DOF " << j << ", " << run->steps << " steps a period";
    }
  }
  for (int j = 0; j < 2; ++j) {
    const double ea = smoothness(a, j).velocity, eb = smoothness(b, j).velocity;
    std::printf("DOF %d: velocity against the central difference %.3g, halving h %.3g\n", j, ea,
                eb);
    EXPECT_GT(ea, 3.0 * eb) << "DOF " << j;
  }
}

TEST(Transient, AStuckJointWithStaticFlexibilityHoldsItsDofAndTheRestFollows) {
  // The model above with a dry-friction joint at node 1 whose limit (1 kN) the 5 N sine at node
  // 2 never reaches: the joint sticks from rest, x_1 ≡ 0 to rounding (the static correction moves
  // with the friction force, the loop closed in the joint's Newton solve), and node 2 moves as
  // the structure held at node 1: X_2 = (H_22 − H_21 H_12 / H_11) F with H = Φ diag(1/(ω_r² − ω²
  // + 2iζ_rω_rω)) Φᵀ + R, the model's receptance, by hand. Newmark's period error (ωh)²/12 =
  // 3e-6 at 1024 steps a period, magnified near resonance by 1/(2ζ) = 50: 2e-4 asserted.
  const fem::TimeModel m = two_modes_with_residual();
  joints::Joint j{"a", 1, 0, fem::Dof::ux, {joints::Term::fc}, {1000.0}, {true}, {}};
  const joints::JointForces forces({j}, m.system.dofs);
  const Eigen::MatrixXd phi(m.T), R(m.R);
  for (double f : {1.0, 4.0}) {
    const double w = 2 * std::numbers::pi * f;
    fem::SteadyStateOptions o;
    o.steps_per_period = 1024;
    o.output_periods = 1;
    const std::vector<int> outputs{0, 1};
    const fem::SteadyState s = fem::steady_state(m, &forces, {1, 5.0, f}, outputs, o);
    ASSERT_TRUE(s.status.ok()) << s.status.reason;
    EXPECT_LE(s.u.col(0).cwiseAbs().maxCoeff(), 1e-12 * s.u.col(1).cwiseAbs().maxCoeff());
    Eigen::MatrixXcd H = R.cast<std::complex<double>>();
    for (int r = 0; r < 2; ++r) {
      const double wr = std::sqrt(m.system.K.coeff(r, r)), c = m.C.coeff(r, r);
      H += phi.col(r) * phi.col(r).transpose() / std::complex<double>(wr * wr - w * w, c * w);
    }
    const std::complex<double> X2 =
        (H(1, 1) - H(1, 0) * H(0, 1) / H(0, 0)) * std::complex<double>(0.0, -5.0);
    std::complex<double> A2 = 0.0;
    for (Eigen::Index i = 0; i < s.t.size(); ++i)
      A2 += s.u(i, 1) * std::polar(1.0, -w * s.t(i));
    A2 *= 2.0 / static_cast<double>(s.t.size());
    EXPECT_LE(std::abs(A2 - X2), 2e-4 * std::abs(X2)) << f;
  }
}

TEST(Transient, ATimeModelOfInconsistentSizesIsRefused) {
  fem::ForceHistory h;
  h.dt = 0.01;
  h.equations = {1};
  h.samples = Eigen::MatrixXd::Ones(4, 1);
  const std::vector<int> outputs{0};
  fem::TimeModel m = two_modes_with_residual();
  m.R = Eigen::MatrixXd::Identity(3, 3).sparseView();
  EXPECT_EQ(test::error_of([&] { fem::transient_response(m, nullptr, h, outputs); }),
            "time model: R is 3 x 3, expected 2 x 2");
  m = two_modes_with_residual();
  m.T = Eigen::MatrixXd::Ones(2, 3).sparseView();
  EXPECT_EQ(test::error_of([&] { fem::transient_response(m, nullptr, h, outputs); }),
            "time model: T has 3 columns for 2 coordinates");
  // Newmark's static flexibility: one row and column per local coordinate.
  m = two_modes_with_residual();
  joints::Joint j{"a", 1, 0, fem::Dof::ux, {joints::Term::k}, {1.0}, {true}, {}};
  const joints::JointForces forces({j}, m.system.dofs);
  EXPECT_EQ(test::error_of(
                [&] { fem::Newmark(m.system, m.C, forces, Eigen::MatrixXd::Zero(2, 2), 0.01); }),
            "Newmark: the static flexibility is 2 x 2, expected 1 x 1 (one row and column per "
            "local coordinate)");
}
