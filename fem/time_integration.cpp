#include "fem/time_integration.hpp"

#include "fem/assert.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace jointid::fem {

Newmark::Newmark(const Assembled& system, const SparseMatrix& C, const LocalForces* forces,
                 double h, const NewmarkOptions& options)
    : system_(system), C_(C), forces_(forces), h_(h), o_(options) {
  factorise();
}

Newmark::Newmark(const Assembled& system, const SparseMatrix& C, const LocalForces& forces,
                 const Eigen::MatrixXd& static_flexibility, double h, const NewmarkOptions& options)
    : system_(system), C_(C), forces_(&forces), h_(h), o_(options) {
  const auto nc = forces.coordinates().cols();
  if (static_flexibility.rows() != nc || static_flexibility.cols() != nc)
    throw std::invalid_argument(
        "Newmark: the static flexibility is " + std::to_string(static_flexibility.rows()) + " x " +
        std::to_string(static_flexibility.cols()) + ", expected " + std::to_string(nc) + " x " +
        std::to_string(nc) + " (one row and column per local coordinate)");
  if (!static_flexibility.allFinite())
    throw std::invalid_argument("Newmark: the static flexibility has a non-finite entry");
  static_correction_ = true;
  static_flexibility_ = 0.5 * (static_flexibility + static_flexibility.transpose());
  factorise();
  if (!status_.ok()) return;
  W_ += static_flexibility_;
  // A coordinate whose static flexibility is nil (to rounding of the largest) has none: its row
  // of the positive semi-definite W_s is zero, and it is held while it sticks as in a model
  // with mass everywhere.
  const double largest = nc > 0 ? static_flexibility_.cwiseAbs().maxCoeff() : 0.0;
  no_static_.assign(static_cast<std::size_t>(nc), 0);
  for (Eigen::Index i = 0; i < nc; ++i)
    no_static_[static_cast<std::size_t>(i)] =
        static_flexibility_.row(i).cwiseAbs().maxCoeff() <=
        64.0 * std::numeric_limits<double>::epsilon() * largest;
  static_history_ = Eigen::MatrixXd::Zero(nc, 4);
  ydot_ = yddot_ = Eigen::VectorXd::Zero(nc);
}

void Newmark::factorise() {
  if (!(h_ > 0.0)) throw std::invalid_argument("time step must be > 0");
  const double b = o_.beta, g = o_.gamma, h = h_;
  a0_ = 1.0 / (b * h * h);
  a1_ = g / (b * h);
  a2_ = 1.0 / (b * h);
  a3_ = 1.0 / (2.0 * b) - 1.0;
  a4_ = g / b - 1.0;
  a5_ = h * (g / (2.0 * b) - 1.0);
  const int n = system_.dofs.num_equations();
  SparseMatrix keff = system_.K + a0_ * system_.M;
  if (C_.nonZeros() > 0) keff += a1_ * C_;
  keff_.compute(keff);
  if (keff_.info() != Eigen::Success) {
    status_ = Status::failure(Status::Code::numerical_issue,
                              "Newmark: the effective stiffness K + a1 C + a0 M is singular (a "
                              "DOF with neither stiffness nor mass?)");
    return;
  }
  const int nc = forces_ ? static_cast<int>(forces_->coordinates().cols()) : 0;
  if (forces_) {
    const Eigen::MatrixXd B(forces_->coordinates());
    S_ = keff_.solve(B);
    W_ = B.transpose() * S_;
    friction_ = forces_->friction_limits();
  }
  u_ = v_ = a_ = Eigen::VectorXd::Zero(n);
  y_ = lambda_ = g_total_ = Eigen::VectorXd::Zero(nc);
  stuck_.assign(nc, 0);
  stuck_before_.assign(nc, 0);
  history_.assign(forces_ ? static_cast<std::size_t>(forces_->state_size()) : 0, 0.0);
}

// The coordinates stuck after this step and the last one have ẏ = 0 over the step, so their
// true acceleration is ÿ = 0. The step's acceleration satisfies the equation of motion with the
// step's friction forces λ; with λ_S − δ on the stuck set S instead, ü changes by M⁻¹B_S δ, and
// B_Sᵀü = 0 gives (B_SᵀM⁻¹B_S) δ = −B_Sᵀü.
void Newmark::hold_stuck(Eigen::VectorXd& a_next) {
  std::vector<int> S;
  for (std::size_t i = 0; i < stuck_.size(); ++i)
    if (stuck_[i] && stuck_before_[i] && (!static_correction_ || no_static_[i]))
      S.push_back(static_cast<int>(i));
  if (S.empty() || mass_singular_) return;
  const SparseMatrix& B = forces_->coordinates();
  if (mass_b_.size() == 0) {
    Eigen::SimplicialLDLT<SparseMatrix> mass(system_.M);
    const Eigen::MatrixXd Bd(B);
    if (mass.info() == Eigen::Success) mass_b_ = mass.solve(Bd);
    if (mass.info() != Eigen::Success || !mass_b_.allFinite() ||
        (mass.vectorD().array() <= 0.0).any()) {
      mass_singular_ = true;
      return;
    }
  }
  const int m = static_cast<int>(S.size());
  Eigen::MatrixXd MB(a_next.size(), m), A(m, m);
  Eigen::VectorXd ya(m);
  for (int p = 0; p < m; ++p) {
    MB.col(p) = mass_b_.col(S[p]);
    ya(p) = B.col(S[p]).dot(a_next);
  }
  for (int p = 0; p < m; ++p)
    for (int q = 0; q < m; ++q)
      A(p, q) = B.col(S[p]).dot(MB.col(q));
  const Eigen::VectorXd delta = A.ldlt().solve(-ya);
  for (int p = 0; p < m; ++p)
    if (!(std::abs(lambda_(S[p]) - delta(p)) <= friction_(S[p]))) return; // it slips
  a_next += MB * delta;
  for (int p = 0; p < m; ++p) {
    lambda_(S[p]) -= delta(p);
    g_total_(S[p]) -= delta(p);
  }
}

void Newmark::set_state(const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& f) {
  JOINTID_ASSERT(status_.ok(), "Newmark::set_state after a failed factorisation");
  JOINTID_ASSERT(u.size() == u_.size() && v.size() == u_.size() && f.size() == u_.size(),
                 "Newmark::set_state: one entry per equation");
  u_ = u;
  v_ = v;
  Eigen::VectorXd rhs = f - system_.K * u;
  if (C_.nonZeros() > 0) rhs -= C_ * v;
  lambda_.setZero();
  g_total_.setZero();
  if (forces_) {
    const SparseMatrix& B = forces_->coordinates();
    y_ = B.transpose() * u;
    Eigen::VectorXd g, gy, gv;
    forces_->advance(history_, y_);
    forces_->evaluate_from(history_, y_, B.transpose() * v, g, gy, gv);
    g_total_ = g;
    rhs -= B * g;
  }
  Eigen::SimplicialLDLT<SparseMatrix> mass(system_.M);
  a_ = mass.info() == Eigen::Success ? Eigen::VectorXd(mass.solve(rhs))
                                     : Eigen::VectorXd::Zero(u.size());
}

void Newmark::set_state(const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& f, const Eigen::VectorXd& z) {
  JOINTID_ASSERT(static_correction_, "Newmark::set_state with z needs a static correction");
  JOINTID_ASSERT(status_.ok(), "Newmark::set_state after a failed factorisation");
  JOINTID_ASSERT(u.size() == u_.size() && v.size() == u_.size() && f.size() == u_.size() &&
                     z.size() == y_.size(),
                 "Newmark::set_state: one entry per equation, z one per coordinate");
  const SparseMatrix& B = forces_->coordinates();
  const Eigen::VectorXd y_modal = B.transpose() * u, ydot = B.transpose() * v;
  // y = Bᵀu + z − W_s g(y, ẏ) by Newton (the smooth part; friction taken as 0 at the start).
  Eigen::VectorXd y = y_modal + z, g, gy, gv;
  const auto nc = y.size();
  for (int it = 0; it < o_.max_newton && nc > 0; ++it) {
    forces_->evaluate(y, ydot, g, gy, gv);
    const Eigen::VectorXd r = y - y_modal - z + static_flexibility_ * g;
    const double scale = std::max({y.cwiseAbs().maxCoeff(), z.cwiseAbs().maxCoeff(), 1e-300});
    if (r.cwiseAbs().maxCoeff() <= o_.newton_tolerance * scale) break;
    const Eigen::MatrixXd J =
        Eigen::MatrixXd::Identity(nc, nc) + static_flexibility_ * gy.asDiagonal();
    y -= J.partialPivLu().solve(r);
  }
  forces_->evaluate(y, ydot, g, gy, gv);
  u_ = u;
  v_ = v;
  y_ = y;
  lambda_.setZero();
  g_total_ = g;
  Eigen::VectorXd rhs = f - system_.K * u - B * g;
  if (C_.nonZeros() > 0) rhs -= C_ * v;
  Eigen::SimplicialLDLT<SparseMatrix> mass(system_.M);
  a_ = mass.info() == Eigen::Success ? Eigen::VectorXd(mass.solve(rhs))
                                     : Eigen::VectorXd::Zero(u.size());
  // The static part at rest before t = 0: its history constant.
  const Eigen::VectorXd y_static = z - static_flexibility_ * g;
  for (Eigen::Index k = 0; k < static_history_.cols(); ++k)
    static_history_.col(k) = y_static;
  stuck_.assign(stuck_.size(), 0);
  ydot_ = ydot;
  yddot_ = B.transpose() * a_;
}

// Solves  R1 = y − y_pred + W (g(y, a1 y + e) + λ) = 0  and, for each dry-friction coordinate,
// R2_i = λ_i − proj_[−F_i, F_i](λ_i + r_i ẏ_i) = 0 (stick: ẏ_i = 0 with |λ_i| ≤ F_i; slip:
// λ_i = F_i sign(ẏ_i)) by semi-smooth Newton on (y, λ).
bool Newmark::solve_local(const Eigen::VectorXd& y_pred, const Eigen::VectorXd& e) {
  const int nc = static_cast<int>(y_pred.size());
  Eigen::VectorXd y = y_, lambda = lambda_, g, gy, gv;
  Eigen::VectorXd r(nc);
  for (int i = 0; i < nc; ++i)
    r(i) = 1.0 / (a1_ * W_(i, i));
  Eigen::MatrixXd J(2 * nc, 2 * nc);
  Eigen::VectorXd R(2 * nc);
  const double scale = std::max({y_pred.cwiseAbs().maxCoeff(), y_.cwiseAbs().maxCoeff(), 1e-300});
  // Forces with a history are piecewise smooth in y (a slider sticks or slides, a gap opens or
  // closes): their steps are halved until the smooth residual decreases.
  const bool damped = forces_->piecewise_smooth();
  Eigen::VectorXd d, y_trial, g_trial, gy_trial, gv_trial;
  double r_norm = 0.0;
  if (damped) {
    forces_->evaluate_from(history_, y, a1_ * y + e, g, gy, gv);
    r_norm = (y - y_pred + W_ * (g + lambda)).norm();
  }
  for (int it = 0; it < o_.max_newton; ++it) {
    const Eigen::VectorXd ydot = a1_ * y + e;
    if (!damped) forces_->evaluate_from(history_, y, ydot, g, gy, gv);
    R.head(nc) = y - y_pred + W_ * (g + lambda);
    J.setZero();
    J.topLeftCorner(nc, nc) = Eigen::MatrixXd::Identity(nc, nc) + W_ * (gy + a1_ * gv).asDiagonal();
    J.topRightCorner(nc, nc) = W_;
    bool friction_ok = true;
    for (int i = 0; i < nc; ++i) {
      const double F = friction_(i);
      if (F <= 0.0) {
        R(nc + i) = lambda(i);
        J(nc + i, nc + i) = 1.0;
        continue;
      }
      const double trial = lambda(i) + r(i) * ydot(i);
      stuck_[i] = std::abs(trial) <= F;
      if (std::abs(trial) <= F) { // stick
        R(nc + i) = -r(i) * ydot(i);
        J(nc + i, i) = -r(i) * a1_;
        // ẏ = a1 y + e is a difference of large numbers: zero to within its rounding.
        const double rounding =
            64.0 * std::numeric_limits<double>::epsilon() * (std::abs(a1_ * y(i)) + std::abs(e(i)));
        friction_ok = friction_ok && std::abs(ydot(i)) <= rounding;
      } else { // slip
        R(nc + i) = lambda(i) - F * (trial > 0 ? 1.0 : -1.0);
        J(nc + i, nc + i) = 1.0;
        friction_ok = friction_ok && std::abs(R(nc + i)) <= 1e-12 * F;
      }
    }
    if (R.head(nc).cwiseAbs().maxCoeff() <= o_.newton_tolerance * scale && friction_ok) {
      y_ = y;
      lambda_ = lambda;
      g_total_ = g + lambda;
      return true;
    }
    d = J.partialPivLu().solve(-R);
    if (!damped) {
      y += d.head(nc);
      lambda += d.tail(nc);
      continue;
    }
    // Damped: the smooth rows' residual (friction rows are piecewise linear in λ, exact in one
    // step) must decrease; the full step is taken when nothing decreases (a corner).
    double t = 1.0;
    bool decreased = false;
    for (int halving = 0; halving < 30 && !decreased; ++halving) {
      if (halving > 0) t *= 0.5;
      y_trial = y + t * d.head(nc);
      forces_->evaluate_from(history_, y_trial, a1_ * y_trial + e, g_trial, gy_trial, gv_trial);
      decreased = (y_trial - y_pred + W_ * (g_trial + lambda + t * d.tail(nc))).norm() < r_norm;
    }
    if (!decreased) t = 1.0; // nothing decreases (a corner, or rounding): the full step
    y += t * d.head(nc);
    lambda += t * d.tail(nc);
    forces_->evaluate_from(history_, y, a1_ * y + e, g, gy, gv);
    r_norm = (y - y_pred + W_ * (g + lambda)).norm();
  }
  return false;
}

Status Newmark::step(const Eigen::VectorXd& f_next) {
  JOINTID_ASSERT(!static_correction_, "Newmark::step: a static correction needs z");
  return advance(f_next, nullptr);
}

Status Newmark::step(const Eigen::VectorXd& f_next, const Eigen::VectorXd& z_next) {
  JOINTID_ASSERT(static_correction_, "Newmark::step with z needs a static correction");
  JOINTID_ASSERT(z_next.size() == y_.size(), "Newmark::step: z has one entry per coordinate");
  return advance(f_next, &z_next);
}

Status Newmark::advance(const Eigen::VectorXd& f_next, const Eigen::VectorXd* z_next) {
  JOINTID_ASSERT(status_.ok(), "Newmark::step after a failed factorisation");
  JOINTID_ASSERT(f_next.size() == u_.size(), "Newmark::step: one load per equation");
  Eigen::VectorXd rhs = f_next + system_.M * (a0_ * u_ + a2_ * v_ + a3_ * a_);
  if (C_.nonZeros() > 0) rhs += C_ * (a1_ * u_ + a4_ * v_ + a5_ * a_);
  Eigen::VectorXd u_next = keff_.solve(rhs);
  Status status;
  if (forces_ && forces_->coordinates().cols() > 0) {
    const SparseMatrix& B = forces_->coordinates();
    Eigen::VectorXd y_pred = B.transpose() * u_next;
    Eigen::VectorXd e;
    if (z_next) {
      // ẏ_{n+1} = a1 (y − y_n) − a4 ẏ_n − a5 ÿ_n from the estimates (see the header)
      y_pred += *z_next;
      e = -a1_ * y_ - a4_ * ydot_ - a5_ * yddot_;
    } else {
      // ẏ_{n+1} = a1 (y − y_n) − Bᵀ(a4 v_n + a5 a_n) = a1 y + e
      e = -a1_ * y_ - B.transpose() * (a4_ * v_ + a5_ * a_);
    }
    stuck_before_ = stuck_;
    if (!solve_local(y_pred, e))
      status = Status::failure(Status::Code::not_converging,
                               "the joints' Newton iteration did not converge in " +
                                   std::to_string(o_.max_newton) + " iterations");
    if (status.ok()) forces_->advance(history_, y_);
    u_next -= S_ * g_total_;
  }
  Eigen::VectorXd a_next = a0_ * (u_next - u_) - a2_ * v_ - a3_ * a_;
  v_ += h_ * ((1.0 - o_.gamma) * a_ + o_.gamma * a_next); // the scheme's (keeps ẏ = 0)
  if (forces_ && status.ok()) hold_stuck(a_next);         // the true ü, and λ, kept
  a_ = a_next;
  u_ = u_next;
  if (z_next && status.ok()) update_static_estimates(*z_next);
  return status;
}

void Newmark::update_static_estimates(const Eigen::VectorXd& z) {
  // y_s = z − W_s (g + λ): the coordinates' share of the static correction, newest first.
  for (Eigen::Index k = static_history_.cols() - 1; k > 0; --k)
    static_history_.col(k) = static_history_.col(k - 1);
  static_history_.col(0) = z - static_flexibility_ * g_total_;
  const Eigen::MatrixXd& s = static_history_;
  const SparseMatrix& B = forces_->coordinates();
  // Second-order backward differences: BDF2's ẏ_s = (3 s_n − 4 s_{n−1} + s_{n−2}) / 2h (error
  // −h²/3 times the third derivative), ÿ_s = (2 s_n − 5 s_{n−1} + 4 s_{n−2} − s_{n−3}) / h².
  ydot_ = B.transpose() * v_ + (3.0 * s.col(0) - 4.0 * s.col(1) + s.col(2)) / (2.0 * h_);
  yddot_ = B.transpose() * a_ +
           (2.0 * s.col(0) - 5.0 * s.col(1) + 4.0 * s.col(2) - s.col(3)) / (h_ * h_);
  for (std::size_t i = 0; i < stuck_.size(); ++i)
    if (stuck_[i]) { // the stick condition itself: y holds still
      ydot_(static_cast<Eigen::Index>(i)) = 0.0;
      yddot_(static_cast<Eigen::Index>(i)) = 0.0;
    }
}

SteadyState steady_state(const Assembled& system, const SparseMatrix& C, const LocalForces* forces,
                         const SineLoad& load, std::span<const int> outputs,
                         const SteadyStateOptions& o) {
  const int n = system.dofs.num_equations();
  if (load.equation < 0 || load.equation >= n)
    throw std::invalid_argument("sine load: bad equation");
  if (!(load.frequency_hz > 0.0))
    throw std::invalid_argument("sine load: frequency must be > 0 Hz");
  if (o.steps_per_period < 8 || o.output_periods < 1 || o.max_periods < o.output_periods + 2)
    throw std::invalid_argument(
        "steady state: need >= 8 steps per period and max_periods > output_periods + 1");
  const double h = 1.0 / load.frequency_hz / o.steps_per_period; // as the driver's
  Newmark integrator(system, C, forces, h, o.newmark);
  if (!integrator.status().ok()) {
    SteadyState out;
    out.status = integrator.status();
    return out;
  }
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  integrator.set_state(Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n), f);
  const auto nout = static_cast<Eigen::Index>(outputs.size());
  return periodic_steady_state(
      load.amplitude, load.frequency_hz, static_cast<int>(nout), o,
      [&](double force) {
        f(load.equation) = force;
        return integrator.step(f);
      },
      [&](Eigen::VectorXd& u, Eigen::VectorXd& v) {
        for (Eigen::Index j = 0; j < nout; ++j) {
          u(j) = integrator.u()(outputs[static_cast<std::size_t>(j)]);
          v(j) = integrator.v()(outputs[static_cast<std::size_t>(j)]);
        }
      });
}

SteadyState
periodic_steady_state(double amplitude, double frequency_hz, int nout, const SteadyStateOptions& o,
                      const std::function<Status(double force)>& step,
                      const std::function<void(Eigen::VectorXd& u, Eigen::VectorXd& v)>& sample) {
  if (!(frequency_hz > 0.0)) throw std::invalid_argument("sine load: frequency must be > 0 Hz");
  if (o.steps_per_period < 8 || o.output_periods < 1 || o.max_periods < o.output_periods + 2)
    throw std::invalid_argument(
        "steady state: need >= 8 steps per period and max_periods > output_periods + 1");
  const int N = o.steps_per_period;
  const double T = 1.0 / frequency_hz, h = T / N, omega = 2.0 * std::numbers::pi * frequency_hz;
  SteadyState out;

  // Ring of the last output_periods + 1 periods: samples at the start of each step.
  const int keep = o.output_periods + 1;
  Eigen::MatrixXd u_hist(keep * N, nout), v_hist(keep * N, nout);
  Eigen::VectorXd u_now(nout), v_now(nout);
  int calm = 0;
  const int needed = std::max(2, o.output_periods);
  for (int p = 0; p < o.max_periods; ++p) {
    const int slot = p % keep;
    for (int k = 0; k < N; ++k) {
      sample(u_now, v_now);
      u_hist.row(slot * N + k) = u_now.transpose();
      v_hist.row(slot * N + k) = v_now.transpose();
      if (Status status = step(amplitude * std::sin(omega * (k + 1) * h)); !status.ok()) {
        std::ostringstream reason;
        reason << "the joints' Newton iteration failed in period " << p + 1
               << " (t = " << (p * N + k + 1) * h << " s; no convergence in "
               << o.newmark.max_newton << " iterations)";
        out.status = Status::failure(status.code, reason.str());
        out.periods_run = p + 1;
        return out;
      }
    }
    out.periods_run = p + 1;
    if (p == 0) continue;
    const int prev = (p - 1) % keep;
    const auto now_u = u_hist.middleRows(slot * N, N), before_u = u_hist.middleRows(prev * N, N);
    const double size = std::max(now_u.cwiseAbs().maxCoeff(), 1e-300);
    out.period_change = (now_u - before_u).cwiseAbs().maxCoeff() / size;
    calm = out.period_change < o.tolerance ? calm + 1 : 0;
    // Every period given out must agree with the one before it (not only the last two: the
    // first of a record of many periods would still hold the transient).
    if (calm >= needed && p + 1 >= keep) break;
  }
  if (calm < needed) {
    std::ostringstream reason;
    reason << "not a periodic steady state after " << out.periods_run
           << " periods (last period-to-period change " << out.period_change << ", tolerance "
           << o.tolerance << ")";
    out.status = Status::failure(Status::Code::not_periodic, reason.str());
  }
  // Assemble the last output_periods periods in time order.
  const int last = (out.periods_run - 1) % keep;
  const int total = o.output_periods * N;
  out.t.resize(total);
  out.force.resize(total);
  out.u.resize(total, nout);
  out.v.resize(total, nout);
  for (int q = 0; q < o.output_periods; ++q) {
    const int slot = ((last - (o.output_periods - 1) + q) % keep + keep) % keep;
    out.u.middleRows(q * N, N) = u_hist.middleRows(slot * N, N);
    out.v.middleRows(q * N, N) = v_hist.middleRows(slot * N, N);
  }
  for (int i = 0; i < total; ++i) {
    out.t(i) = i * h;
    out.force(i) = amplitude * std::sin(omega * i * h);
  }
  return out;
}

} // namespace jointid::fem
