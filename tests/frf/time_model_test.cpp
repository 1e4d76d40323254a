// Time simulation of a substructure given by its modes ([modal]) and of several substructures
// side by side, in their own coordinates (frf/time_model.hpp): checked against the finite
// element model the modes come from (its own time simulation, with every mode), against the
// harmonic balance of the same [modal] model, and a composite of two [modal] beams against the
// one finite element model holding both.
#include "frf/time_model.hpp"

#include "fem/modal.hpp"
#include "fem/time_integration.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/receptance.hpp"
#include "support/beam_models.hpp"
#include "support/cantilever.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

using namespace jointid;
using fem::Dof;
using fem::NodeDof;
using joints::Term;
using Complex = std::complex<double>;

namespace {

using jointid::test::harmonic;

using jointid::test::two_pi;

joints::Joint joint(std::string name, int node, int node_b, std::vector<Term> terms,
                    std::vector<double> values) {
  joints::Joint j{std::move(name),   node, node_b, Dof::uy, std::move(terms),
                  std::move(values), {},   {}};
  j.fixed.assign(j.terms.size(), true);
  return j;
}

// The [modal] model an engineer would export from a finite element model: the modes below
// `below_hz` at `dofs`, their damping ratios, and the exact static flexibility of the modes
// left out there (K⁻¹ − Σ_kept φφᵀ/ω², frf::ModalSynthesis).
frf::ModalModel modal_model_of(const fem::Model& model, double below_hz,
                               const std::vector<NodeDof>& dofs) {
  const fem::Assembled system = fem::assemble(model);
  fem::Modes modes =
      fem::modal_analysis(system, {.num_modes = 0, .engine = fem::ModalEngine::dense});
  int kept = 0;
  while (kept < modes.num_modes() && modes.frequency_hz(kept) < below_hz)
    ++kept;
  modes.omega.conservativeResize(kept);
  modes.phi.conservativeResize(Eigen::NoChange, kept);
  std::vector<int> eq;
  for (const NodeDof& nd : dofs)
    eq.push_back(system.dofs.equation(nd));
  const frf::ModalSynthesis synthesis(system, modes, model.damping, eq);
  frf::ModalModel m;
  m.dofs = dofs;
  m.frequencies_hz = modes.omega / two_pi;
  m.damping.resize(kept);
  for (int r = 0; r < kept; ++r)
    m.damping(r) = model.damping.ratio(modes.omega(r));
  m.shapes.resize(kept, static_cast<Eigen::Index>(dofs.size()));
  for (std::size_t i = 0; i < dofs.size(); ++i)
    m.shapes.col(static_cast<Eigen::Index>(i)) = modes.phi.row(eq[i]).transpose();
  m.residual_flexibility = synthesis.residual_flexibility(eq, eq);
  return m;
}

// The periodic steady state of a substructure with its joints under F0 sin(2π f t) at `force`.
fem::SteadyState steady(const frf::Substructure& sub, const std::vector<joints::Joint>& js,
                        const NodeDof& force, double amplitude, double frequency_hz,
                        const std::vector<NodeDof>& outputs, int steps = 1024) {
  const frf::TimeDomainModel m = frf::time_domain_model(sub);
  EXPECT_TRUE(m.status.ok()) << m.status.reason;
  const joints::JointForces forces(js, sub.dofs());
  std::vector<int> out;
  for (const NodeDof& nd : outputs)
    out.push_back(sub.dofs().equation(nd));
  fem::SteadyStateOptions o;
  o.steps_per_period = steps;
  o.output_periods = 1;
  const fem::SteadyState s = fem::steady_state(
      m.model, &forces, {sub.dofs().equation(force), amplitude, frequency_hz}, out, o);
  EXPECT_TRUE(s.status.ok()) << s.status.reason;
  return s;
}

const NodeDof tip{7, Dof::uy}, mid{4, Dof::uy};

} // namespace

TEST(TimeModel, ModalModelIsItsModalCoordinatesAndItsResidualFlexibility) {
  frf::ModalModel modal;
  modal.dofs = {{7, Dof::uy}, {4, Dof::uy}};
  modal.frequencies_hz = Eigen::Vector2d(3.0, 18.8);
  modal.damping = Eigen::Vector2d(0.01, 0.02);
  modal.shapes.resize(2, 2);
  modal.shapes << 0.5, 0.2, -0.4, 0.3;
  modal.residual_flexibility.resize(2, 2);
  modal.residual_flexibility << 2e-8, 1e-9, 1e-9, 3e-8;
  const frf::TimeDomainModel t = frf::time_domain_model(frf::Substructure(modal));
  ASSERT_TRUE(t.status.ok());
  EXPECT_EQ(t.modes_kept, 2);
  EXPECT_EQ(t.residual_dofs, 2);
  const fem::TimeModel& m = t.model;
  for (int r = 0; r < 2; ++r) {
    const double w = two_pi * modal.frequencies_hz(r);
    EXPECT_DOUBLE_EQ(m.system.K.coeff(r, r), w * w);
    EXPECT_DOUBLE_EQ(m.system.M.coeff(r, r), 1.0);
    EXPECT_DOUBLE_EQ(m.C.coeff(r, r), 2.0 * modal.damping(r) * w);
  }
  ASSERT_EQ(m.T.rows(), 2);
  ASSERT_EQ(m.T.cols(), 2);
  ASSERT_EQ(m.R.rows(), 2) << "the residual flexibility is kept";
  ASSERT_EQ(m.R.cols(), 2);
  EXPECT_EQ(Eigen::MatrixXd(m.T), modal.shapes.transpose()); // x = Φ q + R F
  EXPECT_EQ(Eigen::MatrixXd(m.R), modal.residual_flexibility);
  EXPECT_EQ(t.parts.size(), 1u);
  EXPECT_EQ(t.parts[0], "2 modes of its [modal] model, its residual flexibility at 2 DOFs as a "
                        "static correction");
}

TEST(TimeModel, LinearSteadyStateIsTheModalModelsReceptance) {
  // A [modal] model (3 modes and R at the tip and the middle) with a linear joint k, c at the
  // tip: the steady state is X = H_tt F / (1 + H_tt (k + iωc)) with H the model's receptance,
  // static term R included. Newmark's period error (ωh)²/12 = 3.1e-6 at 1024 steps, magnified
  // near resonance by at most 1/(2ζ) ≈ 50, and the backward differences' error in the joint's
  // velocity on the static part (ωh)²/3 = 1.3e-5 of a small share: 2e-4 |X| asserted.
  const frf::ModalModel modal = modal_model_of(test::paper_cantilever(), 60.0, {tip, mid});
  ASSERT_EQ(modal.num_modes(), 3);
  const frf::Substructure sub(modal);
  const double k = 4800.0, c = 20.0, F0 = 40.0;
  const frf::ModalSynthesis H(modal, {0, 1});
  for (double f : {2.0, 4.4, 30.0}) {
    const fem::SteadyState s =
        steady(sub, {joint("tip", 7, 0, {Term::k, Term::c}, {k, c})}, tip, F0, f, {tip, mid});
    const double w = two_pi * f;
    const std::vector<int> t{0}, m{1};
    const Complex Htt = H.receptance(w, t, t)(0, 0), Hmt = H.receptance(w, m, t)(0, 0);
    const Complex denominator = 1.0 + Htt * Complex(k, w * c);
    const Complex X_tip = Htt * Complex(0.0, -F0) / denominator;
    const Complex X_mid = Hmt * Complex(0.0, -F0) / denominator;
    const Complex A_tip = harmonic(s.u.col(0), s.t, w, 1), A_mid = harmonic(s.u.col(1), s.t, w, 1);
    std::printf("%g Hz: tip %.3g, mid %.3g of |X|\n", f, std::abs(A_tip - X_tip) / std::abs(X_tip),
                std::abs(A_mid - X_mid) / std::abs(X_tip));
    EXPECT_LE(std::abs(A_tip - X_tip), 2e-4 * std::abs(X_tip)) << f;
    EXPECT_LE(std::abs(A_mid - X_mid), 2e-4 * std::abs(X_tip)) << f;
    const Complex V_tip = harmonic(s.v.col(0), s.t, w, 1);
    EXPECT_LE(std::abs(V_tip - Complex(0.0, w) * X_tip), 2e-4 * w * std::abs(X_tip)) << f;
  }
}

TEST(TimeModel, ModalModelAgreesWithTheFiniteElementModelItComesFrom) {
  // The cantilever's lowest modes at the tip, with the exact residual flexibility of the others,
  // against the finite element model's own time simulation. What differs is the truncation: the
  // left-out modes respond statically, so the tip receptance differs by
  // ΔH(Ω) = Σ_left-out φ² (1/(ω_r² − Ω² + 2iζω_rΩ) − 1/ω_r²) at every harmonic Ω = hω. Every
  // force acts at the tip (the sine and the joint), so the finite element model's total force
  // there is F_h = X_h / H_tt(hω), and the [modal] model driven by that force would differ by
  // Σ_h |ΔH(hω)| |F_h| (in x; hω times it in v). The joint feeds the difference back (measured
  // up to 1.3 times that here): 3 times it is asserted, plus what the two integrations do
  // differently: for the smooth joint, the left-out modes' period error in the finite element
  // model, (ωh)²/12 of the response (the kept modes are integrated alike); with dry friction,
  // each stick–slip transition located to within a time step h, a phase error up to ωh.
  // Measured (x, v relative to the amplitude and ω times it): cubic, 3 modes below 60 Hz at
  // 1024 steps: 2.6e-6, 7.3e-6; dry friction, 7 modes below 500 Hz at 4096 steps: 2.6e-5,
  // 6.0e-3 (the estimates 2.1e-5, 6.3e-3).
  const fem::Model fe = test::paper_cantilever();
  const frf::Substructure a(fe);
  const fem::Assembled system = fem::assemble(fe);
  const std::vector<int> tip_eq{system.dofs.equation(tip)}, first{0};
  const frf::ModalSynthesis all = a.synthesis(tip_eq, 0.0);
  struct Case {
    std::string name;
    joints::Joint joint;
    double below_hz;
    int steps;
    double own_error; // the integrators'
  };
  const double f = 3.0, F0 = 40.0, w = two_pi * f;
  for (const Case& c :
       {Case{"cubic", joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8}), 60.0,
             1024, std::pow(w / (f * 1024), 2) / 12.0},
        Case{"dry friction", joint("tip", 7, 0, {Term::k, Term::c, Term::fc}, {4800.0, 5.0, 6.0}),
             500.0, 4096, w / (f * 4096)}}) {
    SCOPED_TRACE(c.name);
    const frf::Substructure b(modal_model_of(fe, c.below_hz, {tip, mid}));
    const frf::ModalSynthesis kept(*b.modal(), {0});
    const fem::SteadyState sa = steady(a, {c.joint}, tip, F0, f, {tip, mid}, c.steps);
    const fem::SteadyState sb = steady(b, {c.joint}, tip, F0, f, {tip, mid}, c.steps);
    const double scale = sa.u.col(0).cwiseAbs().maxCoeff();
    double estimate_x = 0.0, estimate_v = 0.0;
    for (int h = 1; h < c.steps / 2; ++h) {
      const Complex H = all.receptance(h * w, tip_eq, tip_eq)(0, 0);
      const double dH = std::abs(H - kept.receptance(h * w, first, first)(0, 0));
      const double F = std::abs(harmonic(sa.u.col(0), sa.t, w, h) / H);
      estimate_x += dH * F / scale;
      estimate_v += h * dH * F / scale;
    }
    const double dx = (sa.u - sb.u).cwiseAbs().maxCoeff() / scale;
    const double dv = (sa.v - sb.v).cwiseAbs().maxCoeff() / (w * scale);
    std::printf("%s, %d modes: x %.3g (estimate %.3g), v %.3g (estimate %.3g)\n", c.name.c_str(),
                b.modal()->num_modes(), dx, estimate_x, dv, estimate_v);
    EXPECT_LE(dx, 3.0 * estimate_x + c.own_error);
    EXPECT_LE(dv, 3.0 * estimate_v + c.own_error);
  }
}

namespace {

// Two steel cantilevers in one model: A (2 m, nodes 1–7, clamped at 1: the paper's cantilever)
// and B (1.5 m, nodes 101–107 one metre above, clamped at 101), not connected; 1 % modal damping.
fem::Model two_beams() {
  fem::Model m = test::paper_cantilever();
  for (int i = 0; i <= 6; ++i)
    m.nodes.push_back({101 + i, Eigen::Vector3d(1.5 * i / 6.0, 1.0, 0.0)});
  for (int i = 0; i < 6; ++i)
    m.elements.push_back({101 + i, 101 + i, 102 + i, fem::ElementType::beam, 0, 0});
  m.supports.push_back({101, {Dof::ux, Dof::uy, Dof::rz}});
  return m;
}

// Beam B alone, numbered 1–7.
fem::Model beam_b() {
  fem::Model m = test::paper_cantilever();
  for (int i = 0; i <= 6; ++i)
    m.nodes[static_cast<std::size_t>(i)].x = Eigen::Vector3d(1.5 * i / 6.0, 1.0, 0.0);
  return m;
}

} // namespace

TEST(TimeModel, TwoModalSubstructuresJoinedAgreeWithTheOneFiniteElementModel) {
  // A and B each given by their modes ([modal]: A's 3 below 60 Hz at its tip and middle, B's 3
  // below 100 Hz at its tip) with the residual flexibility of the others, joined by a joint
  // between A's middle and B's tip (k, c, k3), A's tip joined to ground (k, c, k3): against
  // the finite element model holding both beams. The bound as in the test above, the
  // truncation now a matrix: F_h = H(hω)⁻¹ X_h over the three joint DOFs (every force acts
  // there), the difference Σ_h |ΔH(hω) F_h| at each output.
  const fem::Model both = two_beams();
  const frf::Substructure one(both);
  const frf::Substructure parts(
      {frf::Substructure(modal_model_of(test::paper_cantilever(), 60.0, {tip, mid})),
       frf::Substructure(modal_model_of(beam_b(), 100.0, {tip}))},
      {0, 100});
  const NodeDof b_tip{107, Dof::uy};
  const std::vector<joints::Joint> js{
      joint("tip", 7, 0, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8}),
      joint("link", 4, 107, {Term::k, Term::c, Term::k3}, {3000.0, 10.0, 5e7})};
  const double f = 3.0, F0 = 40.0, w = two_pi * f;
  const int steps = 1024;
  const std::vector<NodeDof> dofs{tip, mid, b_tip};
  const fem::SteadyState sa = steady(one, js, tip, F0, f, dofs, steps);
  const fem::SteadyState sb = steady(parts, js, tip, F0, f, dofs, steps);
  const frf::TimeDomainModel m = frf::time_domain_model(parts);
  ASSERT_EQ(m.parts.size(), 2u);
  EXPECT_EQ(m.modes_kept, 6);
  EXPECT_EQ(m.residual_dofs, 3);
  std::vector<int> ea, eb;
  for (const NodeDof& nd : dofs)
    ea.push_back(one.dofs().equation(nd)), eb.push_back(parts.dofs().equation(nd));
  const frf::ModalSynthesis Ha = one.synthesis(ea, 0.0), Hb = parts.synthesis(eb, 0.0);
  Eigen::VectorXd estimate = Eigen::VectorXd::Zero(3);
  Eigen::Vector3d scale;
  for (int j = 0; j < 3; ++j)
    scale(j) = sa.u.col(j).cwiseAbs().maxCoeff();
  for (int h = 1; h < steps / 2; ++h) {
    Eigen::VectorXcd X(3);
    for (int j = 0; j < 3; ++j)
      X(j) = harmonic(sa.u.col(j), sa.t, w, h);
    const Eigen::MatrixXcd H = Ha.receptance(h * w, ea, ea);
    const Eigen::VectorXcd F = H.partialPivLu().solve(X);
    estimate += ((H - Hb.receptance(h * w, eb, eb)) * F).cwiseAbs();
  }
  const double own = std::pow(w / (f * steps), 2) / 12.0;
  for (int j = 0; j < 3; ++j) {
    const double dx = (sa.u.col(j) - sb.u.col(j)).cwiseAbs().maxCoeff() / scale(j);
    std::printf("%s: x %.3g (estimate %.3g)\n",
                fem::to_string(dofs[static_cast<std::size_t>(j)]).c_str(), dx,
                estimate(j) / scale(j));
    EXPECT_LE(dx, 3.0 * estimate(j) / scale(j) + own)
        << fem::to_string(dofs[static_cast<std::size_t>(j)]);
  }
}

TEST(TimeModel, MeasuredFrfsHaveNoTimeDomainModel) {
  frf::MeasuredFrf measured;
  measured.dofs = {{7, Dof::uy}};
  measured.functions.push_back(
      {{7, Dof::uy}, {7, Dof::uy}, {1.0, 2.0, 3.0}, {1e-6, 2e-6, 1e-6}, "tip.csv"});
  const std::string why =
      ", which have no time-domain model: a measured FRF is known only at its lines, with no "
      "modes or matrices to integrate. Fit a modal model to them first (jointid modal-fit) and "
      "use the [modal] model it writes";
  EXPECT_EQ(test::error_of([&] { (void)frf::time_domain_model(frf::Substructure(measured)); }),
            "the substructure is given by measured FRFs ([frf])" + why);
  const frf::Substructure parts(
      {frf::Substructure(test::paper_cantilever()), frf::Substructure(measured)}, {0, 100});
  EXPECT_EQ(test::error_of([&] { (void)frf::time_domain_model(parts); }),
            "substructure 2 is given by measured FRFs ([frf])" + why);
}
