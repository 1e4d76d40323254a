#include "frf/harmonic_balance.hpp"

#include "frf/hb_equations.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

// The AFT tables that do not depend on ω, for K harmonics and Nt samples θ_n = 2πn / Nt:
// cos pθ_n and sin pθ_n for p ≤ 2K (Nt × (2K+1), the Jacobian's products), ∂y_n/∂z (Nt × (2K+1)),
// ∂ẏ_n/∂z / ω, and the forward transform from samples to packed harmonics ((2K+1) × Nt). Kept
// in a cache: the continuation builds a HarmonicBalance at every frequency it visits, and
// computing (and allocating) these each time was most of its cost.
struct detail::Tables {
  Eigen::MatrixXd cos, sin, dy, dv_unit, forward, forward_t, trig;
};

namespace {

const detail::Tables& aft_tables(int Nt, int K) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::unique_ptr<const detail::Tables>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{Nt, K}];
  if (!slot) {
    auto t = std::make_unique<detail::Tables>();
    const int P = 2 * K, m = 2 * K + 1;
    t->cos.resize(Nt, P + 1), t->sin.resize(Nt, P + 1);
    for (int n = 0; n < Nt; ++n)
      for (int p = 0; p <= P; ++p) { // the angle reduced exactly, p n mod Nt
        const double a = 2.0 * std::numbers::pi * (static_cast<long long>(p) * n % Nt) / Nt;
        t->cos(n, p) = std::cos(a), t->sin(n, p) = std::sin(a);
      }
    t->dy.resize(Nt, m), t->dv_unit.resize(Nt, m), t->forward.resize(m, Nt);
    for (int n = 0; n < Nt; ++n) {
      t->dy(n, 0) = 1.0;
      t->dv_unit(n, 0) = 0.0;
      t->forward(0, n) = 1.0 / Nt;
      for (int k = 1; k <= K; ++k) {
        const double c = t->cos(n, k), s = t->sin(n, k);
        t->dy(n, 2 * k - 1) = c, t->dy(n, 2 * k) = -s;
        t->dv_unit(n, 2 * k - 1) = -k * s, t->dv_unit(n, 2 * k) = -k * c;
        t->forward(2 * k - 1, n) = 2.0 * c / Nt, t->forward(2 * k, n) = -2.0 * s / Nt;
      }
    }
    t->forward_t = t->forward.transpose();
    t->trig.resize(Nt, 2 * m);
    t->trig << t->cos, t->sin;
    slot = std::move(t);
  }
  return *slot;
}

} // namespace

using detail::Equations;
using detail::Friction;
using detail::two_pi;

bool detail::newton(const Equations& P, Eigen::VectorXd& z, double load,
                    const HarmonicBalanceOptions& o, int& iterations, double& res_norm) {
  const int n = P.size();
  // Work arrays kept per thread (newton does not call itself): sizing them is free from the
  // second call on, and a sweep solves thousands of points of the same size.
  struct Work {
    Eigen::MatrixXd J;
    Eigen::VectorXd r, step, zt, rt;
    SmallLU<double> lu;
  };
  thread_local Work work;
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
    double t = 1.0;
    bool improved = false;
    const double r_norm = r.norm();
    for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
      zt.noalias() = z + t * step;
      P.residual(zt, load, rt, nullptr);
      if (rt.allFinite() && rt.norm() < r_norm) {
        z.swap(zt), r.swap(rt), improved = true;
        break;
      }
    }
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
  tables_ = &aft_tables(Nt_, K_);
  dv_ = omega_ * tables_->dv_unit;
  dyv_.resize(2 * Nt_, 2 * K_ + 1);
  dyv_ << tables_->dy, dv_;
  if (K_ > 1) { // the first guess's fundamental-only problem
    coarse_tables_ = &aft_tables(coarse_samples, 1);
    dv1_ = omega_ * coarse_tables_->dv_unit;
    dyv1_.resize(2 * coarse_samples, 3);
    dyv1_ << coarse_tables_->dy, dv1_;
  }
  // Joint DOFs (node and node_b) and the B matrix restricted to them.
  const std::vector<int> jdofs = joints::joint_dof_set(joints, dofs);
  const Eigen::MatrixXd B_real = joints::joint_coordinates_on(joints, dofs, jdofs);
  const Eigen::MatrixXcd B = B_real.cast<Complex>();
  // Grounded joints, each on a DOF of its own, in order (the common case): B = I and the
  // blocks are the receptance's own.
  const bool identity = B_real.rows() == B_real.cols() && B_real.isIdentity(0.0);
  // One receptance per harmonic, rows (joint DOFs, outputs) × columns (joint DOFs, forces),
  // cut into the four blocks.
  std::vector<int> rows = jdofs, cols = jdofs;
  rows.insert(rows.end(), outputs.begin(), outputs.end());
  cols.insert(cols.end(), force_equations.begin(), force_equations.end());
  const auto nd = static_cast<Eigen::Index>(jdofs.size());
  const auto no = static_cast<Eigen::Index>(outputs.size()), nf = static_cast<Eigen::Index>(nf_);
  for (auto* blocks : {&Hyy_, &HyF_, &HoB_, &HoF_})
    blocks->reserve(static_cast<std::size_t>(K_ + 1));
  for (int k = 0; k <= K_; ++k) {
    const CMatrix R = H.receptance(k * omega_, rows, cols);
    if (identity) {
      Hyy_.emplace_back(R.topLeftCorner(nd, nd));
      HyF_.emplace_back(R.topRightCorner(nd, nf));
      HoB_.emplace_back(R.bottomLeftCorner(no, nd));
    } else {
      Hyy_.emplace_back(B.transpose() * R.topLeftCorner(nd, nd) * B);
      HyF_.emplace_back(B.transpose() * R.topRightCorner(nd, nf));
      HoB_.emplace_back(R.bottomLeftCorner(no, nd) * B);
    }
    HoF_.emplace_back(R.bottomRightCorner(no, nf));
  }
}

std::unique_ptr<detail::Equations>
HarmonicBalance::equations(const std::vector<joints::Joint>& joints,
                           const Eigen::MatrixXcd& F) const {
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
  return std::make_unique<Equations>(
      Equations{K_, nj_, Nt_, Hyy_, std::move(HyF_F), std::move(Fk), joints,
                exact ? 0.0 : options_.friction_width, std::move(friction), tables_->dy, dv_, dyv_,
                tables_->forward, tables_->forward_t, tables_->trig, omega_});
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
    CMatrix D(nj, nj);
    CVector y(nj);
    detail::SmallLU<Complex> lu;
    for (int k = 0; k <= K; ++k) {
      D.setIdentity();
      for (int j = 0; j < nj; ++j) {
        Complex lin = 0.0;
        for (std::size_t t = 0; t < joints[j].terms.size(); ++t) {
          const joints::TermInfo& info = joints::term_info(joints[j].terms[t]);
          if (info.degree != 1) continue;
          lin += info.nature == joints::Nature::conservative
                     ? Complex(joints[j].values[t])
                     : Complex(0.0, k * P.omega) * joints[j].values[t];
        }
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
    for (int k = 0; k <= K && start; ++k) {
      const CVector need = P.Hyy[k].fullPivLu().solve((P.HyF_F.row(k) - Y.row(k)).transpose()) -
                           G.row(k).transpose();
      for (std::size_t f = 0; f < friction.size(); ++f) {
        Eigen::MatrixXcd L = P.unpack(z, 1, nj + static_cast<int>(f));
        L(k, 0) = k == 0 ? Complex(need(friction[f].joint).real()) : need(friction[f].joint);
        P.pack(L, z, nj + static_cast<int>(f));
      }
    }
    for (std::size_t f = 0; f < friction.size() && !start; ++f) {
      const Eigen::VectorXd v = P.dv * z.segment(friction[f].joint * m, m);
      Eigen::VectorXd slip(P.Nt);
      for (int n = 0; n < P.Nt; ++n)
        slip(n) = v(n) > 0.0 ? friction[f].limit : v(n) < 0.0 ? -friction[f].limit : 0.0;
      z.segment((nj + static_cast<int>(f)) * m, m) = P.forward * slip;
    }
  }
  return z;
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
  // cheap (3 unknowns a joint, 16 samples; to 1e-6). If it fails, the linear response is the
  // guess.
  // (Hyy_ serves as is: the equations read its harmonics 0 and 1 only.)
  const detail::Tables& t1 = *coarse_tables_;
  const Equations P1{1,
                     nj_,
                     coarse_samples,
                     Hyy_,
                     P.HyF_F.topRows(2),
                     P.Fk.topRows(2),
                     P.joints,
                     P.width,
                     P.friction,
                     t1.dy,
                     dv1_,
                     dyv1_,
                     t1.forward,
                     t1.forward_t,
                     t1.trig,
                     omega_};
  Eigen::VectorXd z1 = start_from(P1, nullptr);
  // The linear response can be far off in amplitude (a stiffening joint near resonance: 9×);
  // Newton then creeps (by 2/3 a step for a cubic; by 1/2 with friction, 10 steps on the
  // paper's cantilever). Scale the displacements first by the power of 2 that leaves the least
  // residual: a few cheap evaluations instead of those steps. The friction forces of the slip
  // law, fc sign(ẏ), do not change with the scale.
  {
    const int nd = nj_ * P1.m();
    Eigen::VectorXd r(P1.size()), zs = z1;
    P1.residual(z1, 1.0, r, nullptr);
    double best = r.norm(), scale = 1.0;
    for (const double step : {0.5, 2.0}) {
      for (double s = step; s >= 1.0 / 1024 && s <= 8.0; s *= step) {
        zs.head(nd) = s * z1.head(nd);
        P1.residual(zs, 1.0, r, nullptr);
        if (!(r.norm() < best)) break;
        best = r.norm(), scale = s;
      }
      if (scale != 1.0) break;
    }
    z1.head(nd) *= scale;
  }
  int iterations = 0;
  double residual = 0.0;
  HarmonicBalanceOptions coarse = options_;
  coarse.tolerance = std::max(options_.tolerance, 1e-6); // a start: the full Newton refines it
  if (!detail::newton(P1, z1, 1.0, coarse, iterations, residual)) return start_from(P, nullptr);
  Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K_ + 1, nj_);
  Y.topRows(2) = P1.unpack(z1, nj_);
  return start_from(P, &Y);
}

HarmonicBalanceResult HarmonicBalance::result(const detail::Equations& P,
                                              const Eigen::VectorXd& z) const {
  HarmonicBalanceResult out;
  out.frequency_hz = frequency_hz_;
  out.Y = P.unpack(z, nj_);
  out.G = P.forces(z);
  const Eigen::Index no = HoB_.empty() ? 0 : HoB_[0].rows();
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
  const std::unique_ptr<Equations> P = equations(joints, F);
  Eigen::VectorXd z = first_guess(*P, start);
  const Eigen::VectorXd z_start = z;
  int iterations = 0;
  double residual = 0.0;
  bool converged = detail::newton(*P, z, 1.0, options_, iterations, residual);
  std::string reason;
  if (!converged) { // load continuation from a small, nearly linear level
    const double direct = residual;
    const int direct_iterations = iterations;
    const int steps = std::max(1, options_.continuation_steps);
    z = z_start / steps;
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
  out.converged = converged;
  out.reason = std::move(reason);
  out.iterations = iterations;
  out.residual = residual;
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
