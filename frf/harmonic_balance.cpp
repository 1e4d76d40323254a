#include "frf/harmonic_balance.hpp"

#include "frf/hb_equations.hpp"

#include "fem/gmres.hpp"
#include "fem/minimise.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <tuple>

namespace jointid::frf {

// The AFT tables that do not depend on ω, for K harmonics and Nt samples θ_n = 2πn / Nt over
// the period, or, half-wave symmetric, the odd harmonics ≤ K and the Nt / 2 samples of the
// first half: ∂y_n/∂z and ∂ẏ_n/∂z / ω (each Nt × m, and both stacked), the forward transform
// from samples to packed harmonics (transposed: Nt × m), and cos pθ_n beside sin pθ_n for the p
// that the products of two harmonics make (the Jacobian's; p ≤ 2K, the even ones only when
// symmetric). Kept in a cache: the continuation builds a HarmonicBalance at every frequency it
// visits, and computing (and allocating) these each time was most of its cost.
// Past Equations::matrix_free_from unknowns a block only the harmonics and the sample count are
// kept (the transforms run by FFT, and the Jacobian is not formed).
struct detail::Tables {
  std::vector<int> harmonics;
  int samples = 0; // kept: Nt, or Nt / 2 when symmetric
  Eigen::MatrixXd dy, dv_unit, dyv_unit, forward_t, trig;
};

namespace {

const detail::Tables& aft_tables(int Nt, int K, bool symmetric) {
  static std::mutex mutex;
  static std::map<std::tuple<int, int, bool, bool>, std::unique_ptr<const detail::Tables>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  const int count = symmetric ? (K + 1) / 2 : K + 1;
  const int m = 2 * count - (symmetric ? 0 : 1);
  const bool matrix_free =
      m >= detail::Equations::matrix_free_from && m >= detail::Equations::fft_from;
  auto& slot = cache[{Nt, K, symmetric, matrix_free}];
  if (!slot) {
    auto t = std::make_unique<detail::Tables>();
    const int step = symmetric ? 2 : 1;
    for (int k = symmetric ? 1 : 0; k <= K; k += step)
      t->harmonics.push_back(k);
    const int n = symmetric ? Nt / 2 : Nt; // the samples kept (Nt is even when symmetric)
    t->samples = n;
    JOINTID_ASSERT(static_cast<int>(t->harmonics.size()) == count, "the harmonics counted");
    if (matrix_free) {
      slot = std::move(t);
      return *slot;
    }
    // the angle p θ_n reduced exactly, p n mod Nt
    auto angle = [Nt](long long p, int i) { return 2.0 * std::numbers::pi * (p * i % Nt) / Nt; };
    t->dy.resize(n, m), t->dv_unit.resize(n, m), t->forward_t.resize(n, m);
    for (int i = 0; i < n; ++i) {
      int c = 0;
      for (const int k : t->harmonics) {
        if (k == 0) {
          t->dy(i, 0) = 1.0, t->dv_unit(i, 0) = 0.0, t->forward_t(i, 0) = 1.0 / n;
          c = 1;
          continue;
        }
        const double co = std::cos(angle(k, i)), si = std::sin(angle(k, i));
        t->dy(i, c) = co, t->dy(i, c + 1) = -si;
        t->dv_unit(i, c) = -k * si, t->dv_unit(i, c + 1) = -k * co;
        t->forward_t(i, c) = 2.0 * co / n, t->forward_t(i, c + 1) = -2.0 * si / n;
        c += 2;
      }
    }
    t->dyv_unit.resize(2 * n, m);
    t->dyv_unit << t->dy, t->dv_unit;
    const int np = 2 * t->harmonics.back() / step + 1; // p = 0, step, … 2 max(harmonics)
    t->trig.resize(n, 2 * np);
    for (int i = 0; i < n; ++i)
      for (int q = 0; q < np; ++q)
        t->trig(i, q) = std::cos(angle(step * q, i)),
                   t->trig(i, np + q) = std::sin(angle(step * q, i));
    slot = std::move(t);
  }
  return *slot;
}

} // namespace

using detail::Equations;
using detail::Friction;
using detail::two_pi;

namespace {

// The step of an inexact Newton iteration by GMRES, to a relative tolerance that tightens as
// the residual falls (quadratic convergence's: the linear error η|r| at |r| ~ the step's
// second-order error), never tighter than the tolerance needs.
fem::GmresOptions krylov_options(double res_norm, double tolerance) {
  fem::GmresOptions g;
  g.tolerance = std::min(1e-2, std::max(res_norm, 0.1 * tolerance / std::max(res_norm, 1e-300)));
  g.tolerance = std::max(g.tolerance, 1e-13);
  // A step GMRES has not solved in 100 products is taken as it stands (it still lowers the
  // linear model's residual; the backtracking judges it): where the joints' tangent varies most
  // over the period (a cubic joint through resonance) the line preconditioner is weakest, and
  // a few such systems took 600 products, most of a discovery's time.
  g.restart = g.max_iterations = 100;
  return g;
}

// Solves J x = b at the last residual's point by GMRES with the line preconditioner (prepared by
// the caller); x starts at 0.
fem::GmresResult krylov_solve(const Equations& P, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                              const fem::GmresOptions& g) {
  x.setZero(b.size());
  return fem::gmres([&P](const Eigen::Ref<const Eigen::VectorXd>& v,
                         Eigen::VectorXd& out) { P.jacobian_times(v, out); },
                    [&P](const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) {
                      P.precondition(v, out);
                    },
                    b, x, g);
}

// Backtracking along a Newton step: the first of step, step/2, … (30 halvings) that lowers the
// residual's norm is taken (z and r moved there, zt and rt work arrays). False: none did.
bool backtrack(const Equations& P, double load, const Eigen::VectorXd& step, Eigen::VectorXd& z,
               Eigen::VectorXd& r, Eigen::VectorXd& zt, Eigen::VectorXd& rt) {
  const double r_norm = r.norm();
  double t = 1.0;
  for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
    zt.noalias() = z + t * step;
    P.residual(zt, load, rt, nullptr);
    if (rt.allFinite() && rt.norm() < r_norm) {
      z.swap(zt), r.swap(rt);
      return true;
    }
  }
  return false;
}

// newton() without a matrix (Equations::matrix_free()): Newton–Krylov, the same backtracking.
bool newton_krylov(const Equations& P, Eigen::VectorXd& z, double load,
                   const HarmonicBalanceOptions& o, int& iterations, double& res_norm) {
  const int n = P.size();
  Eigen::VectorXd r(n), step(n), zt(n), rt(n);
  P.residual(z, load, r, nullptr);
  // Newton that creeps (a hardening joint driven through resonance from far off: steps cut to
  // 1/500, each taking 0.1 % off the residual) is stopped after a few such steps: the load
  // continuation that follows reaches the solution in a fraction of the products.
  int creeping = 0;
  for (int it = 0; it < o.max_iterations; ++it) {
    ++iterations;
    res_norm = r.norm() / std::max(P.norm(z), 1e-300);
    if (res_norm < o.tolerance) return true;
    P.prepare_preconditioner();
    const fem::GmresResult solved =
        krylov_solve(P, -r, step, krylov_options(res_norm, o.tolerance));
    if (!step.allFinite() || !(solved.residual < 1.0)) return false;
    const double r_norm = r.norm();
    const bool improved = backtrack(P, load, step, z, r, zt, rt);
    if (!improved) return res_norm < o.tolerance;
    creeping = r.norm() > 0.99 * r_norm ? creeping + 1 : 0;
    if (creeping == 4) break;
  }
  res_norm = r.norm() / std::max(P.norm(z), 1e-300);
  return res_norm < o.tolerance;
}

} // namespace

bool detail::newton(const Equations& P, Eigen::VectorXd& z, double load,
                    const HarmonicBalanceOptions& o, int& iterations, double& res_norm) {
  if (P.matrix_free()) return newton_krylov(P, z, load, o, iterations, res_norm);
  const int n = P.size();
  // Work arrays kept per thread and per size (newton does not call itself): sizing them is
  // free from the second call on. A point solves two sizes (the first guess's fundamental-only
  // problem, then the full one) and a sweep thousands of points of the same sizes.
  struct Work {
    int n = -1;
    Eigen::MatrixXd J;
    Eigen::VectorXd r, step, zt, rt;
    SmallLU<double> lu;
  };
  thread_local std::array<Work, 4> works;
  thread_local std::size_t next = 0;
  Work* found = nullptr;
  for (Work& w : works)
    if (w.n == n) found = &w;
  if (!found) found = &works[next], next = (next + 1) % works.size(), found->n = n;
  Work& work = *found;
  Eigen::MatrixXd& J = work.J;
  Eigen::VectorXd &r = work.r, &step = work.step, &zt = work.zt, &rt = work.rt;
  SmallLU<double>& lu = work.lu;
  J.resize(n, n), r.resize(n), step.resize(n), zt.resize(n), rt.resize(n);
  P.residual(z, load, r, &J);
  for (int it = 0; it < o.max_iterations; ++it) {
    ++iterations;
    res_norm = r.norm() / std::max(P.norm(z), 1e-300);
    if (res_norm < o.tolerance) return true;
    // A friction joint stuck for the whole period leaves its mean position and mean force a
    // one-parameter family: J is singular. Take the least-norm step there. Partial pivoting
    // (a fraction of full pivoting's cost at these sizes) shows it in its pivots: J = I + …
    // is of order 1, so a pivot at rounding level is a singular direction.
    lu.compute(J);
    const bool regular = lu.min_pivot > 1e-13 * std::max(1.0, J.lpNorm<Eigen::Infinity>());
    if (regular) {
      step = -r;
      lu.solve_in_place(step);
    }
    if (!regular || !step.allFinite()) {
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(J);
      cod.setThreshold(1e-13);
      step = cod.solve(-r);
    }
    const bool improved = backtrack(P, load, step, z, r, zt, rt);
    if (!improved) return res_norm < o.tolerance;
    // The last residual evaluated is the accepted point's: its Jacobian, unless it converged.
    if (r.norm() / std::max(P.norm(z), 1e-300) >= o.tolerance) P.jacobian(J);
  }
  res_norm = r.norm() / std::max(P.norm(z), 1e-300);
  return res_norm < o.tolerance;
}

Eigen::MatrixXcd sine_force(double amplitude) {
  Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(2, 1);
  F(1, 0) = Complex(0.0, -amplitude); // F0 sin ωt = Re(−i F0 e^{iωt})
  return F;
}

double HarmonicBalanceResult::displacement(int j, double t) const {
  const double omega = two_pi * frequency_hz;
  double x = X(0, j).real();
  for (int k = 1; k < X.rows(); ++k)
    x += (X(k, j) * std::polar(1.0, k * omega * t)).real();
  return x;
}

double HarmonicBalanceResult::velocity(int j, double t) const {
  const double omega = two_pi * frequency_hz;
  double v = 0.0;
  for (int k = 1; k < X.rows(); ++k)
    v += (Complex(0.0, k * omega) * X(k, j) * std::polar(1.0, k * omega * t)).real();
  return v;
}

HarmonicBalance::HarmonicBalance(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                                 const fem::DofMap& dofs, std::vector<int> force_equations,
                                 std::vector<int> outputs, double frequency_hz,
                                 const HarmonicBalanceOptions& o)
    : options_(o) {
  if (o.harmonics < 1) throw std::invalid_argument("harmonic balance: need at least 1 harmonic");
  if (!(frequency_hz > 0.0))
    throw std::invalid_argument("harmonic balance: frequency must be > 0 Hz");
  if (!(o.friction_width > 0.0))
    throw std::invalid_argument("harmonic balance: friction_width must be > 0");
  if (o.time_samples != 0 && o.time_samples < 2 * o.harmonics + 2)
    throw std::invalid_argument("harmonic balance: time_samples must be 0 or > 2 harmonics + 1");
  K_ = o.harmonics;
  nj_ = static_cast<int>(joints.size());
  nf_ = static_cast<int>(force_equations.size());
  Nt_ = o.time_samples > 0 ? o.time_samples : 16 * (K_ + 1);
  frequency_hz_ = frequency_hz;
  omega_ = two_pi * frequency_hz;
  for (const auto& j : joints)
    layout_.push_back({j.node, j.node_b, j.dof});
  tables_[0] = &aft_tables(Nt_, K_, false);
  if (o.half_wave_symmetry) tables_[1] = &aft_tables(Nt_ + Nt_ % 2, K_, true);
  if (K_ > 1) { // the first guess's fundamental-only problem
    coarse_tables_[0] = &aft_tables(coarse_samples, 1, false);
    if (o.half_wave_symmetry) coarse_tables_[1] = &aft_tables(coarse_samples, 1, true);
  }
  // Joint DOFs (node and node_b) and the B matrix restricted to them.
  const std::vector<int> jdofs = joints::joint_dof_set(joints, dofs);
  const Eigen::MatrixXd B_real = joints::joint_coordinates_on(joints, dofs, jdofs);
  // Grounded joints, each on a DOF of its own, in order (the common case): B = I and the
  // blocks are the receptance's own.
  const bool identity = B_real.rows() == B_real.cols() && B_real.isIdentity(0.0);
  const Eigen::MatrixXcd B = identity ? Eigen::MatrixXcd() : B_real.cast<Complex>();
  // The receptances at the harmonics, rows (joint DOFs, outputs) × columns (joint DOFs, forces),
  // cut into the four blocks.
  std::vector<int> rows = jdofs, cols = jdofs;
  rows.insert(rows.end(), outputs.begin(), outputs.end());
  cols.insert(cols.end(), force_equations.begin(), force_equations.end());
  const auto nd = static_cast<Eigen::Index>(jdofs.size());
  const auto no = static_cast<Eigen::Index>(outputs.size()), nf = static_cast<Eigen::Index>(nf_);
  const auto nc = static_cast<Eigen::Index>(cols.size());
  std::vector<double> omegas(static_cast<std::size_t>(K_ + 1));
  for (int k = 0; k <= K_; ++k)
    omegas[static_cast<std::size_t>(k)] = k * omega_;
  const CMatrix R = H.receptances(omegas, rows, cols);
  Hyy_.resize(nj_, nj_, K_), HyF_.resize(nj_, nf, K_), HoB_.resize(no, nj_, K_);
  HoF_.resize(no, nf, K_);
  for (int k = 0; k <= K_; ++k) {
    const auto Rk = R.middleCols(k * nc, nc);
    if (identity) {
      Hyy_[k] = Rk.topLeftCorner(nd, nd);
      HyF_[k] = Rk.topRightCorner(nd, nf);
      HoB_[k] = Rk.bottomLeftCorner(no, nd);
    } else {
      Hyy_[k] = B.transpose() * Rk.topLeftCorner(nd, nd) * B;
      HyF_[k] = B.transpose() * Rk.topRightCorner(nd, nf);
      HoB_[k] = Rk.bottomLeftCorner(no, nd) * B;
    }
    HoF_[k] = Rk.bottomRightCorner(no, nf);
  }
}

std::unique_ptr<detail::Equations>
HarmonicBalance::equations(const std::vector<joints::Joint>& joints, const Eigen::MatrixXcd& F,
                           const Eigen::MatrixXcd* start) const {
  if (static_cast<int>(joints.size()) != nj_)
    throw std::invalid_argument("harmonic balance: the joints differ from the layout");
  for (int j = 0; j < nj_; ++j)
    if (joints[j].node != layout_[j].node || joints[j].node_b != layout_[j].node_b ||
        joints[j].dof != layout_[j].dof || joints[j].values.size() != joints[j].terms.size())
      throw std::invalid_argument("harmonic balance: joint '" + joints[j].name +
                                  "' differs from the layout it was set up for");
  if (F.cols() != nf_)
    throw std::invalid_argument("harmonic balance: " + std::to_string(F.cols()) +
                                " force columns for " + std::to_string(nf_) + " force equations");
  CMatrix Fk = CMatrix::Zero(K_ + 1, nf_);
  Fk.topRows(std::min<Eigen::Index>(F.rows(), K_ + 1)) =
      F.topRows(std::min<Eigen::Index>(F.rows(), K_ + 1));
  Fk.row(0) = Fk.row(0).real().cast<Complex>().eval(); // a mean force is real
  CMatrix HyF_F(K_ + 1, nj_);
  for (int k = 0; k <= K_; ++k)
    for (int j = 0; j < nj_; ++j) {
      Complex h = 0.0;
      for (int f = 0; f < nf_; ++f)
        h += HyF_[k](j, f) * Fk(k, f);
      HyF_F(k, j) = h;
    }
  // Half-wave symmetric (odd harmonics only) when every joint force is odd, the force has no
  // mean or even harmonics, and the start (if any) has none beyond rounding: an asymmetric start
  // may lead to an asymmetric steady state (a symmetry-breaking bifurcation), which the odd
  // harmonics cannot hold.
  bool symmetric = options_.half_wave_symmetry;
  for (int k = 0; k <= K_ && symmetric; k += 2)
    symmetric = Fk.row(k).isZero(0.0);
  if (start && symmetric && start->size() > 0) {
    const double rounding = 1e-12 * start->cwiseAbs().maxCoeff();
    for (Eigen::Index k = 0; k < start->rows() && symmetric; k += 2)
      symmetric = start->row(k).cwiseAbs().maxCoeff() <= rounding;
  }
  for (const joints::Joint& j : joints)
    for (std::size_t t = 0; t < j.terms.size() && symmetric; ++t)
      symmetric = !joints::term_info(j.terms[t]).even || j.values[t] == 0.0;
  const detail::Tables& tables = *tables_[symmetric ? 1 : 0];
  const bool exact = options_.exact_friction;
  std::vector<Friction> friction;
  for (int j = 0; j < nj_; ++j) {
    const int t = joints[j].term_index(joints::Term::fc);
    if (t < 0 || !exact) continue;
    const double limit = joints[j].values[t];
    if (!(limit >= 0.0))
      throw std::invalid_argument("harmonic balance: joint '" + joints[j].name +
                                  "': Coulomb friction fc must be >= 0 N, got " +
                                  std::to_string(limit));
    // Scales: the joint's dynamic compliance at the fundamental, c = |H_yy(ω)_jj|, and r = 1 /
    // (ω c), so that r ẏ is a force of the size the structure's dynamic stiffness gives.
    const double c = std::max(std::abs(Hyy_[1](j, j)), 1e-300);
    friction.push_back({j, limit, 1.0 / (omega_ * c), c});
  }
  // The parametric terms: their parameters checked (a joint without one in range cannot be
  // simulated), the hysteretic ones' elements built once (an iwan's quadrature).
  std::vector<joints::Sliders> sliders(static_cast<std::size_t>(nj_));
  for (int j = 0; j < nj_; ++j)
    if (joints[j].has_parametric_terms())
      sliders[static_cast<std::size_t>(j)] = joints::JointLaw(joints[j]).sliders();
  auto P = std::make_unique<Equations>(
      Equations{K_, nj_, tables.samples, tables.harmonics, Hyy_, std::move(HyF_F), std::move(Fk),
                joints, exact ? 0.0 : options_.friction_width, std::move(friction), tables.dy,
                tables.dv_unit, tables.dyv_unit, tables.forward_t, tables.trig, omega_});
  P->sliders = std::move(sliders);
  return P;
}

namespace {

// The first guess of P's unknowns from `start` (K+1 × nj, of P's K) or, without one, from the
// linear response with the joints' linear terms (degree 1 in the term table).
Eigen::VectorXd start_from(const Equations& P, const Eigen::MatrixXcd* start) {
  const std::vector<joints::Joint>& joints = P.joints;
  const std::vector<Friction>& friction = P.friction;
  const int K = P.K, nj = P.nj, m = P.m();
  Eigen::VectorXd z = Eigen::VectorXd::Zero(P.size());
  if (start) {
    if (start->rows() != K + 1 || start->cols() != nj)
      throw std::invalid_argument("harmonic balance: the start has the wrong shape");
    P.pack(*start, z);
  } else {
    Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K + 1, nj);
    thread_local CMatrix D; // (kept: sized once per thread)
    thread_local CVector y;
    thread_local detail::SmallLU<Complex> lu;
    D.resize(nj, nj), y.resize(nj);
    for (const int k : P.harmonics) {
      D.setIdentity();
      for (int j = 0; j < nj; ++j) {
        const detail::LinearJoint linear = detail::linear_joint(joints[j]);
        const Complex lin(linear.stiffness, k * P.omega * linear.damping);
        D.col(j) += P.Hyy[k].col(j) * lin;
      }
      lu.compute(D);
      y = P.HyF_F.row(k).transpose();
      lu.solve_in_place(y);
      Y.row(k) = y.transpose();
    }
    Y.row(0) = Y.row(0).real().cast<Complex>().eval();
    P.pack(Y, z);
  }
  // Friction forces to start. From a given start: what its motion demands of them, Λ = H_yy⁻¹
  // (H_yf F − Y) − G_smooth, which the projection then brings within ±fc (for a converged start,
  // its own friction forces). From the linear start: the slip law fc sign(ẏ) — that start
  // balances the force without friction, so it would demand Λ ≈ 0, every sample would then
  // stick wherever r|ẏ| < fc, and with every sample stuck the mean friction force is
  // indeterminate (a singular Jacobian: Newton fails at once, e.g. 10 N at 3 Hz on the paper's
  // cantilever with fc = 3 N).
  if (!friction.empty()) {
    const Eigen::MatrixXcd Y = P.unpack(z, nj), G = P.forces(z);
    for (std::size_t i = 0; i < P.harmonics.size() && start; ++i) {
      const int k = P.harmonics[i];
      const CVector need = P.Hyy[k].fullPivLu().solve((P.HyF_F.row(k) - Y.row(k)).transpose()) -
                           G.row(k).transpose();
      for (std::size_t f = 0; f < friction.size(); ++f) {
        Eigen::MatrixXcd L = P.unpack(z, 1, nj + static_cast<int>(f));
        L(k, 0) = k == 0 ? Complex(need(friction[f].joint).real()) : need(friction[f].joint);
        P.pack(L, z, nj + static_cast<int>(f));
      }
    }
    Eigen::VectorXd yv(2 * P.Nt), slip(P.Nt); // y and ẏ, the slip force
    for (std::size_t f = 0; f < friction.size() && !start; ++f) {
      P.samples(z.data() + friction[f].joint * m, yv.data());
      for (int n = 0; n < P.Nt; ++n) {
        const double v = yv(P.Nt + n);
        slip(n) = v > 0.0 ? friction[f].limit : v < 0.0 ? -friction[f].limit : 0.0;
      }
      P.forward(slip.data(), z.data() + (nj + static_cast<int>(f)) * m);
    }
  }
  return z;
}

// The fundamental-only problem's start from the linear response z: its displacements scaled
// by s ∈ [2⁻¹⁰, 8] and shifted in time by φ/ω (harmonic k times e^{ikφ}), s and φ those that
// leave the least residual (see first_guess()); z's friction forces are kept. True if s and φ
// were so found; false if only powers of 2 of s were tried (friction, or not K = 1).
bool scale_and_shift(const Equations& P, Eigen::VectorXd& z) {
  constexpr double s_min = 1.0 / 1024, s_max = 8.0;
  const int nd = P.nj * P.m();
  Eigen::MatrixXd h;
  if (P.K == 1 && P.homogeneous_parts(z, h)) {
    // With u(s) = Σ_p s^p c_p (c0 = h0, c1 = z + h1, c2 = h2, c3 = h3: in h) the residual at s S_φ
    // z is S_φ u(s) − b (S_φ commutes with H_yy and, the joints being time-invariant, with the
    // forces), of norm² |u|² + |b|² − 2 u₀·b₀ − 2 Re(e^{−iφ} W(s)), W = Σ_j conj(u_1j) b_1j:
    // least at φ = arg W, where it is f(s) = |u|² − 2 u₀·b₀ − 2|W| + |b|², polynomials in s
    // but for the modulus.
    // b = pack(H_yf F): its mean (non-symmetric) and fundamental, joint by joint.
    h.col(1) += z.head(nd); // c1
    std::array<double, 7> a{};
    std::array<double, 4> beta{};
    std::array<Complex, 4> W{};
    const int i1 = P.symmetric() ? 0 : 1; // harmonics[i1] = 1
    for (int p = 0; p < 4; ++p) {
      const auto up = static_cast<std::size_t>(p);
      for (int q = p; q < 4; ++q)
        a[up + static_cast<std::size_t>(q)] += (p == q ? 1.0 : 2.0) * h.col(p).dot(h.col(q));
      for (int j = 0; j < P.nj; ++j) {
        const int o = j * P.m(), r = o + P.at(i1);
        if (!P.symmetric()) beta[up] += h(o, p) * P.HyF_F(0, j).real();
        W[up] += std::conj(Complex(h(r, p), h(r + 1, p))) * P.HyF_F(1, j);
      }
    }
    auto polynomial = [](const auto& coefficients, double s) {
      auto v = coefficients.back() * 0.0;
      for (auto it = coefficients.rbegin(); it != coefficients.rend(); ++it)
        v = v * s + *it;
      return v;
    };
    auto f = [&](double s) {
      return polynomial(a, s) - 2.0 * polynomial(beta, s) -
             2.0 * std::sqrt(std::norm(polynomial(W, s))); // (std::abs: a libm call)
    };
    // The least of a grid of ratio 2, then golden-section search between its neighbours to
    // 0.1 % of that bracket (a start needs no more).
    double best = s_min, fbest = f(s_min);
    const double ratio = 2.0;
    for (double s = s_min * ratio; s <= s_max * (1.0 + 1e-12); s *= ratio)
      if (const double v = f(s); v < fbest) best = s, fbest = v;
    const double s = fem::golden_section_minimum(f, std::max(s_min, best / ratio),
                                                 std::min(s_max, best * ratio), 14);
    const Complex shift = std::polar(s, std::arg(polynomial(W, s)));
    for (int j = 0; j < P.nj; ++j) {
      const int o = j * P.m(), r = o + P.at(i1);
      if (!P.symmetric()) z(o) *= s;
      const Complex y = shift * Complex(z(r), z(r + 1));
      z(r) = y.real(), z(r + 1) = y.imag();
    }
    return true;
  }
  Eigen::VectorXd r(P.size()), zs = z;
  P.residual(z, 1.0, r, nullptr);
  double best = r.norm(), scale = 1.0;
  for (const double step : {0.5, 2.0}) {
    for (double s = step; s >= s_min && s <= s_max; s *= step) {
      zs.head(nd) = s * z.head(nd);
      P.residual(zs, 1.0, r, nullptr);
      if (!(r.norm() < best)) break;
      best = r.norm(), scale = s;
    }
    if (scale != 1.0) break;
  }
  z.head(nd) *= scale;
  return false;
}

} // namespace

Eigen::VectorXd HarmonicBalance::first_guess(const detail::Equations& P,
                                             const Eigen::MatrixXcd* start) const {
  if (start || K_ == 1) return start_from(P, start);
  // Without a start: the steady state with the fundamental (and the mean) alone, itself solved
  // from the linear response — the describing-function solution, a few per cent from the full
  // one where the linear response can be off by an order of magnitude (a cubic spring near
  // resonance: 77 mm linear, 8.4 mm at K = 1 and K = 5 on the paper's cantilever at 4 Hz,
  // 80 N), so the full problem needs 3–4 Newton iterations instead of 11. Its iterations are
  // cheap (3 unknowns a joint, 16 samples; to 1e-3). If it fails, the linear response is the
  // guess.
  // (Hyy_ serves as is: the equations read its harmonics 0 and 1 only.)
  const detail::Tables& t1 = *coarse_tables_[P.symmetric() ? 1 : 0];
  const Equations P1{
      1,        nj_,     t1.samples, t1.harmonics, Hyy_,       P.HyF_F.topRows(2), P.Fk.topRows(2),
      P.joints, P.width, P.friction, t1.dy,        t1.dv_unit, t1.dyv_unit,        t1.forward_t,
      t1.trig,  omega_,  P.sliders};
  Eigen::VectorXd z1 = start_from(P1, nullptr);
  // The linear response can be far off in amplitude (a stiffening joint near resonance: 9×)
  // and phase; Newton then creeps (by 2/3 a step for a cubic; by 1/2 with friction, 10 steps on
  // the paper's cantilever). So it is first scaled by s and shifted in time by φ/ω, s and φ
  // those of the least residual. Every term of the library is positively homogeneous,
  // g(s y, s ẏ) = s^d g(y, ẏ), and time-invariant, so without friction unknowns the residual's
  // norm over (s, φ) follows from one transform per degree (scale_and_shift()); with friction
  // (its slip-law forces fc sign(ẏ) do not change with the scale, but the stick–slip rows do)
  // powers of 2 of s are tried instead, a residual each. With one joint and half-wave symmetry
  // the fundamental-only problem has two unknowns, its Y1, which s and φ span: their least
  // residual is its solution (to the search's 0.2 % in s), and its Newton iterations are
  // skipped (4 Hz, 80 N: 3 Newton iterations of the full problem either way).
  const bool solved = scale_and_shift(P1, z1) && nj_ == 1 && P1.symmetric();
  int iterations = 0;
  double residual = 0.0;
  HarmonicBalanceOptions coarse = options_;
  // A start only: it differs from the full solution by the harmonics it omits (per cent), so
  // resolving it beyond 1e-3 buys the full Newton nothing.
  coarse.tolerance = std::max(options_.tolerance, 1e-3);
  if (!solved && !detail::newton(P1, z1, 1.0, coarse, iterations, residual))
    return start_from(P, nullptr);
  Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K_ + 1, nj_);
  Y.topRows(2) = P1.unpack(z1, nj_);
  return start_from(P, &Y);
}

namespace {

// `moved` differs from `joints` in one coefficient alone (a term without parameters and not dry
// friction, whose force is linear in its value): which, and by how much.
struct CoefficientMove {
  int joint;
  joints::Term term;
  double step;
};
std::optional<CoefficientMove> coefficient_move(const std::vector<joints::Joint>& joints,
                                                const std::vector<joints::Joint>& moved) {
  if (moved.size() != joints.size()) return std::nullopt;
  std::optional<CoefficientMove> found;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const joints::Joint &a = joints[j], &b = moved[j];
    if (a.terms != b.terms || a.values.size() != b.values.size() ||
        a.parameters.size() != b.parameters.size() || a.node != b.node || a.node_b != b.node_b ||
        a.dof != b.dof || a.iwan_sliders != b.iwan_sliders)
      return std::nullopt;
    for (std::size_t t = 0; t < a.parameters.size(); ++t) {
      if (a.parameters[t].size() != b.parameters[t].size()) return std::nullopt;
      for (std::size_t q = 0; q < a.parameters[t].size(); ++q)
        if (a.parameters[t][q].value != b.parameters[t][q].value) return std::nullopt;
    }
    for (std::size_t t = 0; t < a.terms.size(); ++t) {
      if (a.values[t] == b.values[t]) continue;
      if (found || joints::has_parameters(a.terms[t]) || joints::is_dry_friction(a.terms[t]))
        return std::nullopt;
      found = CoefficientMove{static_cast<int>(j), a.terms[t], b.values[t] - a.values[t]};
    }
  }
  return found;
}

} // namespace

HarmonicBalanceResult HarmonicBalance::result(const detail::Equations& P,
                                              const Eigen::VectorXd& z) const {
  HarmonicBalanceResult out;
  out.frequency_hz = frequency_hz_;
  out.Y = P.unpack(z, nj_);
  out.G = P.forces(z);
  const Eigen::Index no = HoB_.data.rows();
  out.X.resize(K_ + 1, no);
  for (int k = 0; k <= K_; ++k)
    for (Eigen::Index o = 0; o < no; ++o) { // H_of F − H_oy G, without temporaries
      Complex x = 0.0;
      for (int f = 0; f < nf_; ++f)
        x += HoF_[k](o, f) * P.Fk(k, f);
      for (int j = 0; j < nj_; ++j)
        x -= HoB_[k](o, j) * out.G(k, j);
      out.X(k, o) = x;
    }
  return out;
}

HarmonicBalanceResult HarmonicBalance::solve(const std::vector<joints::Joint>& joints,
                                             const Eigen::MatrixXcd& F,
                                             const Eigen::MatrixXcd* start) const {
  const std::unique_ptr<Equations> P = equations(joints, F, start);
  Eigen::VectorXd z = first_guess(*P, start);
  int iterations = 0;
  double residual = 0.0;
  bool converged = detail::newton(*P, z, 1.0, options_, iterations, residual);
  std::string reason;
  if (!converged) { // load continuation from a small, nearly linear level
    const double direct = residual;
    const int direct_iterations = iterations;
    const int steps = std::max(1, options_.continuation_steps);
    z = first_guess(*P, start) / steps; // (computed again: the direct solve moved z)
    converged = true;
    int s = 1;
    for (; s <= steps && converged; ++s)
      converged =
          detail::newton(*P, z, static_cast<double>(s) / steps, options_, iterations, residual);
    if (!converged) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "no convergence: relative residual %.3g after %d Newton iterations from %s; "
                    "then load steps stalled at step %d of %d (relative residual %.3g; "
                    "tolerance %.3g)",
                    direct, direct_iterations, start ? "the given start" : "the linear response",
                    s - 1, steps, residual, options_.tolerance);
      reason = text;
    }
  }
  HarmonicBalanceResult out = result(*P, z);
  out.status = converged
                   ? fem::Status{}
                   : fem::Status::failure(fem::Status::Code::not_converging, std::move(reason));
  out.iterations = iterations;
  out.residual = residual;
  return out;
}

std::vector<Eigen::MatrixXcd>
HarmonicBalance::output_derivatives(const std::vector<joints::Joint>& joints,
                                    const Eigen::MatrixXcd& F, const Eigen::MatrixXcd& start,
                                    const std::vector<std::vector<joints::Joint>>& moved,
                                    std::span<const double> steps) const {
  JOINTID_ASSERT(moved.size() == steps.size(), "a step per move");
  const std::unique_ptr<Equations> P = equations(joints, F, &start);
  P->scratch().keep_dG = true;
  Eigen::VectorXd z = first_guess(*P, &start);
  const int n = P->size();
  const bool matrix_free = P->matrix_free();
  Eigen::VectorXd r0(n), r(n);
  Eigen::MatrixXd J(matrix_free ? 0 : n, matrix_free ? 0 : n);
  P->residual(z, 1.0, r0, matrix_free ? nullptr : &J);
  // `start` is usually the steady state already solved: solved again only where it is not.
  if (!(r0.norm() / std::max(P->norm(z), 1e-300) < options_.tolerance)) {
    int iterations = 0;
    double residual = 0.0;
    if (!detail::newton(*P, z, 1.0, options_, iterations, residual)) return {};
    P->residual(z, 1.0, r0, matrix_free ? nullptr : &J);
  }
  // dz ← J⁻¹ dz: by the factorisation, or by GMRES (to 1e-10: a derivative, not a step).
  detail::SmallLU<double> lu;
  fem::GmresOptions tight;
  tight.tolerance = 1e-10;
  tight.restart = 100, tight.max_iterations = 300;
  auto solve = [&](Eigen::VectorXd& dz) {
    if (!matrix_free) {
      lu.solve_in_place(dz);
      return true;
    }
    Eigen::VectorXd x;
    const bool ok = krylov_solve(*P, dz, x, tight).converged;
    dz = std::move(x);
    return ok;
  };
  if (matrix_free) {
    P->prepare_preconditioner();
  } else {
    lu.compute(J);
    if (!(lu.min_pivot > 1e-13 * std::max(1.0, J.lpNorm<Eigen::Infinity>()))) return {};
  }
  const Eigen::MatrixXcd G = P->forces(z);
  std::vector<Eigen::MatrixXcd> out(moved.size());
  for (std::size_t p = 0; p < moved.size(); ++p) {
    // The forces' change at z, ΔG, and the residual's, −(R_moved(z) − R(z)): a coefficient's
    // from its own term alone (its force is linear in it), else from the moved equations.
    Eigen::MatrixXcd dG;
    Eigen::VectorXd dz;
    const auto c = coefficient_move(joints, moved[p]);
    // (An even term moved from 0 breaks half-wave symmetry: the equations' unknowns change.)
    if (c && !(P->symmetric() && joints::term_info(c->term).even)) {
      P->coefficient_change(z, c->joint, c->term, c->step, dG, dz);
      dz = -dz;
    } else {
      std::unique_ptr<Equations> Pm;
      try {
        Pm = equations(moved[p], F, &start);
      } catch (const std::invalid_argument&) {
        continue; // out of the joints' range
      }
      if (Pm->size() != n || Pm->symmetric() != P->symmetric() ||
          Pm->friction.size() != P->friction.size())
        continue;
      Pm->residual(z, 1.0, r, nullptr);
      dG = Pm->forces(z) - G;
      dz = r0 - r;
    }
    if (!solve(dz) || !dz.allFinite()) continue;
    // The outputs X = H_of F − H_oy G move with the forces: ΔG + ∂G/∂z dz to first order.
    dG += P->force_change(dz);
    Eigen::MatrixXcd dX(K_ + 1, HoB_.data.rows());
    for (int k = 0; k <= K_; ++k)
      dX.row(k) = -(HoB_[k] * dG.row(k).transpose()).transpose() / steps[p];
    out[p] = std::move(dX);
  }
  return out;
}

HarmonicBalanceResult
harmonic_balance(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                 const fem::DofMap& dofs, int force_equation, double amplitude, double frequency_hz,
                 std::span<const int> outputs, const HarmonicBalanceOptions& o) {
  const HarmonicBalance problem(H, joints, dofs, {force_equation},
                                std::vector<int>(outputs.begin(), outputs.end()), frequency_hz, o);
  return problem.solve(joints, sine_force(amplitude));
}

} // namespace jointid::frf
