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

#include <Eigen/Dense>
#include <gtest/gtest.h>

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
