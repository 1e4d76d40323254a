// One steady-state point on a 10⁴-DOF frame with three joints, harmonic balance against time
// integration (issue 9's speed comparison beyond the paper's cantilever). Plain main: single
// runs (the time integration takes about a minute). Results: docs/benchmarks.md.
//
// The lattice of bench/lattice.hpp, 10 × 10 × 18 nodes at 0.5 m (10 200 free DOFs), Rayleigh
// damping (≈1 % at the first modes), three joints from top-floor nodes to ground along x:
// k + c + k3 at two corners, k + c + c2 at the middle; a sine force along x at a third corner,
// near the first mode.
//
//   bench_frame_steady_state [steps per period of the time integration (256)]
#include "fem/damping.hpp"
#include "fem/modal.hpp"
#include "fem/time_integration.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"
#include "lattice.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

using namespace jointid;
using joints::Term;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 256;
  const int nx = 10, ny = 10, nz = 18;
  fem::Model model = bench::frame_lattice(nx, ny, nz, 0.5);
  auto t0 = std::chrono::steady_clock::now();
  // The first mode, for the excitation frequency and the damping.
  const fem::Assembled system0 = fem::assemble(model);
  const fem::Modes first = fem::modal_analysis(system0, {.num_modes = 2});
  const double f1 = first.frequency_hz(0), w1 = 2 * std::numbers::pi * f1;
  model.damping.kind = fem::Damping::Kind::rayleigh;
  model.damping.alpha = 0.01 * w1; // ζ = α/2ω + βω/2 = 1 % at ω1
  model.damping.beta = 0.01 / w1;
  const frf::Substructure sub(model);
  const fem::Assembled& system = *sub.system();
  const int top = nz - 1;
  auto node = [&](int i, int j) { return bench::lattice_node_id(nx, ny, i, j, top); };
  auto joint = [](std::string name, int n, std::vector<Term> terms, std::vector<double> values) {
    joints::Joint j{std::move(name),   n,  0, fem::Dof::ux, std::move(terms),
                    std::move(values), {}, {}};
    j.fixed.assign(j.terms.size(), true);
    return j;
  };
  // Joint stiffnesses a tenth of the frame's lateral stiffness at the top (about m ω1² / 10
  // with the modal mass of a 180 t frame's first mode), cubic terms that matter at the response.
  const double kj = 2e5;
  const std::vector<joints::Joint> js{
      joint("a", node(0, 0), {Term::k, Term::c, Term::k3}, {kj, 200.0, 2e9}),
      joint("b", node(nx - 1, ny - 1), {Term::k, Term::c, Term::k3}, {kj, 200.0, 2e9}),
      joint("m", node(nx / 2, ny / 2), {Term::k, Term::c, Term::c2}, {kj, 200.0, 1e4})};
  const int force = system.dofs.equation({node(nx - 1, 0), fem::Dof::ux});
  const double F0 = 2e4, f = 1.05 * f1;
  const int K = 5;
  std::vector<int> outputs = joints::joint_dof_set(js, system.dofs);
  outputs.push_back(force);
  std::printf("frame: %d free DOFs, first mode %.4f Hz; excitation %.4f Hz, %.0f N; set-up "
              "(assembly, first modes) %.2f s\n",
              system.dofs.num_equations(), f1, f, F0, seconds_since(t0));

  t0 = std::chrono::steady_clock::now();
  const frf::ModalSynthesis H = sub.synthesis(outputs, frf::synthesis_band_hz(f, K));
  std::printf("synthesis: %d modes below %.1f Hz with residual flexibility: %.2f s (once per "
              "model)\n",
              H.num_modes(), frf::synthesis_band_hz(f, K), seconds_since(t0));

  frf::HarmonicBalanceOptions o;
  o.harmonics = K;
  frf::HarmonicBalanceResult hb;
  const int reps = 20;
  t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < reps; ++r) {
    const frf::HarmonicBalance problem(H, js, system.dofs, {force}, outputs, f, o);
    hb = problem.solve(js, frf::sine_force(F0));
  }
  const double t_hb = seconds_since(t0) / reps;
  std::printf("harmonic balance (K = %d, from the linear start): %.3f ms a point (mean of %d), "
              "converged %d after %d iterations; |X1| at joint a %.4e m, X3/X1 %.2e\n",
              K, 1e3 * t_hb, reps, hb.status.ok(), hb.iterations, std::abs(hb.X(1, 0)),
              std::abs(hb.X(3, 0)) / std::abs(hb.X(1, 0)));

  t0 = std::chrono::steady_clock::now();
  const fem::Outcome<fem::SparseMatrix> damping = sub.damping_matrix();
  if (!damping.status.ok()) {
    std::fprintf(stderr, "%s\n", damping.status.reason.c_str());
    return 1;
  }
  const fem::SparseMatrix& C = damping.value;
  const joints::JointForces forces(js, system.dofs);
  fem::SteadyStateOptions so;
  so.steps_per_period = steps;
  so.output_periods = 1;
  so.tolerance = 1e-6;
  const fem::SteadyState td = fem::steady_state(system, C, &forces, {force, F0, f}, outputs, so);
  const double t_td = seconds_since(t0);
  const double w = 2 * std::numbers::pi * f;
  std::complex<double> X1 = 0.0;
  for (Eigen::Index i = 0; i < td.t.size(); ++i)
    X1 += td.u(i, 0) * std::polar(1.0, -w * td.t(i));
  X1 *= 2.0 / static_cast<double>(td.t.size());
  std::printf("time integration (%d steps a period, to 1e-6 period-to-period): %.2f s, %d "
              "periods, status %s; |X1| at joint a %.4e m, differs from the harmonic balance by "
              "%.2e relative\n",
              steps, t_td, td.periods_run, std::string(fem::code_name(td.status.code)).c_str(),
              std::abs(X1), std::abs(X1 - hb.X(1, 0)) / std::abs(hb.X(1, 0)));
  std::printf("ratio: %.0f x\n", t_td / t_hb);
}
