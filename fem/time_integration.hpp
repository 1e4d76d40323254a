#pragma once
/// Implicit time integration (Newmark, average acceleration by default) of
///     M ü + C u̇ + K u = f(t) − B g(Bᵀu, Bᵀu̇) − B λ,
/// where B (n_eq × n_c) maps the structure to a few local coordinates y = Bᵀu (the joints'
/// deformations), g is their smooth force law and λ their dry-friction force, set-valued:
/// λ_i ∈ F_i·Sign(ẏ_i), i.e. |λ_i| ≤ F_i while the coordinate sticks (ẏ_i = 0). Each step is
/// solved in the n_c local coordinates only (the linear part is condensed once), by a
/// semi-smooth Newton method on y and λ — exact stick–slip, no regularisation. While a
/// coordinate sticks (this step and the last), its acceleration is held at its true value,
/// ÿ_i = 0: the trapezoidal rule alone would make ÿ_i alternate ±a* from step to step (and λ_i
/// with it) after the jump at the onset of stick; the step's λ on the stuck coordinates is
/// replaced by the one for which Bᵀü = 0 there (from M⁻¹B, factorised at the first stick; not
/// done when M is singular or when that force would exceed a limit, i.e. the joint slips).
///
/// With a static correction (a model integrated in modal coordinates whose left-out modes enter
/// by their residual flexibility, fem/transient.hpp's TimeModel) the local coordinates also move
/// with the current forces, y = Bᵀu + z − W_s (g + λ): z is the applied forces' static
/// deflection at the coordinates, W_s their static flexibility to their own forces. The joints'
/// force depends on y and y on it: the loop is closed inside the same local Newton solve, whose
/// flexibility becomes Bᵀ K_eff⁻¹ B + W_s (see docs/method.md, "Time simulation of a modal
/// model"). ẏ_{n+1} is still the trapezoidal rule's a1 (y_{n+1} − y_n) − a4 ẏ_n − a5 ÿ_n (stick
/// keeps y exactly), but from estimates of ẏ_n, ÿ_n that carry no memory of their own: Bᵀu̇_n
/// plus a backward difference of the static part's history (BDF2), 0 where the coordinate
/// sticks. The static part has no mass: the trapezoidal rule's own velocity of it would keep an
/// undamped alternating error (amplification −1) after every kink of the force, e.g. at each
/// stick–slip transition. A coordinate with static flexibility is not held as above: its
/// friction force follows from the positions (the static part is a spring), and Bᵀü = 0 would
/// be the wrong condition; one without (W_s's row zero) is held as in the finite element model.
///
/// Forces with a history (hysteresis: the positions of a joint's sliders) carry a state from
/// step to step (LocalForces::state_size()): within a step the force is evaluated from the last
/// step's state at the trial y (for sliders the return map, exact for a deformation linear over
/// the step — no regularisation), and the state is advanced once the step has converged. Their
/// Newton steps are damped (halved until the residual decreases): such forces are only
/// piecewise smooth in y.
#include "fem/assembly.hpp"
#include "fem/status.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace jointid::fem {

/// Forces of a few local coordinates (the joints), as the integrator needs them. The force g
/// resists the deformation: the structure receives −B g. `fem` knows nothing of joint models.
class LocalForces {
public:
  virtual ~LocalForces() = default;
  /// B: n_eq × n_c, the coordinates y = Bᵀu.
  virtual const SparseMatrix& coordinates() const = 0;
  /// Smooth part: g_i(y_i, ẏ_i) and its derivatives (each coordinate's force depends on that
  /// coordinate only).
  virtual void evaluate(const Eigen::VectorXd& y, const Eigen::VectorXd& ydot, Eigen::VectorXd& g,
                        Eigen::VectorXd& dg_dy, Eigen::VectorXd& dg_dydot) const = 0;
  /// Dry-friction force limits F_i >= 0 (0 where a coordinate has no dry friction).
  virtual Eigen::VectorXd friction_limits() const = 0;
  /// History variables carried from step to step (e.g. slider positions), 0 for memoryless
  /// forces. They start at 0.
  virtual int state_size() const { return 0; }
  /// The smooth part at (y, ẏ) reached from `state` (the end of the last step), without
  /// changing it; by default evaluate().
  virtual void evaluate_from(std::span<const double> /*state*/, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& ydot, Eigen::VectorXd& g,
                             Eigen::VectorXd& dg_dy, Eigen::VectorXd& dg_dydot) const {
    evaluate(y, ydot, g, dg_dy, dg_dydot);
  }
  /// Moves `state` to the end of a converged step at y.
  virtual void advance(std::span<double> /*state*/, const Eigen::VectorXd& /*y*/) const {}
  /// The smooth part is only piecewise smooth in y (sliders, a contact): Newton's steps are
  /// damped.
  virtual bool piecewise_smooth() const { return state_size() > 0; }
};

struct NewmarkOptions {
  double beta = 0.25; ///< 1/4, gamma 1/2: average acceleration, unconditionally stable, no
  double gamma = 0.5; ///< numerical damping; period error ≈ (ωh)²/12
  int max_newton = 60;
  double newton_tolerance = 1e-13; ///< on the local equations, relative to |y|
};

/// State-holding integrator: construct, check status(), then step(). Time step h fixed (s).
class Newmark {
public:
  /// Throws std::invalid_argument for h <= 0. An effective stiffness K + a1 C + a0 M that cannot
  /// be factorised (singular: a DOF with neither stiffness nor mass, nor damping) is a status.
  Newmark(const Assembled& system, const SparseMatrix& C, const LocalForces* forces, double h,
          const NewmarkOptions& options = {});
  /// With a static correction: `static_flexibility` is W_s (n_c × n_c, symmetric, positive
  /// semi-definite; m/N), and every set_state() and step() gives z. Throws
  /// std::invalid_argument for W_s of the wrong size or not finite, or no forces.
  Newmark(const Assembled& system, const SparseMatrix& C, const LocalForces& forces,
          const Eigen::MatrixXd& static_flexibility, double h, const NewmarkOptions& options = {});
  /// numerical_issue when the effective stiffness could not be factorised: then neither
  /// set_state() nor step() may be called.
  const Status& status() const { return status_; }
  /// Sets u, u̇ and computes ü from the equation of motion with force f (friction taken as 0);
  /// a history (sliders) is moved from its state to u, as if the joints were deformed to it.
  void set_state(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const Eigen::VectorXd& f);
  /// The same with a static correction: z is the applied force's static deflection at the
  /// coordinates (n_c); y = Bᵀu + z − W_s g(y, Bᵀv) is solved for y (the static part at rest).
  void set_state(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const Eigen::VectorXd& f,
                 const Eigen::VectorXd& z);
  /// Advances one step to the load f_{n+1} (one entry per equation). not_converging when the
  /// joints' Newton iteration did not converge within NewmarkOptions::max_newton iterations
  /// (the state is then the last iterate's).
  Status step(const Eigen::VectorXd& f_next);
  /// The same with a static correction: z_next is the applied force's static deflection at the
  /// coordinates at the end of the step.
  Status step(const Eigen::VectorXd& f_next, const Eigen::VectorXd& z_next);
  bool has_static_correction() const { return static_correction_; }

  const Eigen::VectorXd& u() const { return u_; }
  const Eigen::VectorXd& v() const { return v_; }
  const Eigen::VectorXd& a() const { return a_; }
  /// Local coordinates and their total force (g + λ) after the last step.
  const Eigen::VectorXd& y() const { return y_; }
  const Eigen::VectorXd& local_force() const { return g_total_; }
  /// The local forces' history variables (LocalForces::state_size()) after the last step.
  const std::vector<double>& history() const { return history_; }
  double h() const { return h_; }

private:
  void factorise();
  Status advance(const Eigen::VectorXd& f_next, const Eigen::VectorXd* z_next);
  bool solve_local(const Eigen::VectorXd& y_pred, const Eigen::VectorXd& e);
  void hold_stuck(Eigen::VectorXd& a_next);
  /// Static correction: the static part y_s = z − W_s (g + λ) of the coordinates after a step,
  /// and the estimates of ẏ, ÿ the next step starts from.
  void update_static_estimates(const Eigen::VectorXd& z);
  const Assembled& system_;
  const SparseMatrix& C_;
  const LocalForces* forces_;
  double h_;
  NewmarkOptions o_;
  Status status_;
  double a0_, a1_, a2_, a3_, a4_, a5_;
  Eigen::SimplicialLDLT<SparseMatrix> keff_;
  Eigen::MatrixXd S_; ///< K_eff⁻¹ B
  Eigen::MatrixXd W_; ///< Bᵀ K_eff⁻¹ B
  Eigen::VectorXd friction_;
  Eigen::VectorXd u_, v_, a_, y_, lambda_, g_total_;
  std::vector<char> stuck_, stuck_before_; ///< per coordinate: sticking after this / last step
  std::vector<double> history_;            ///< the local forces' state (sliders)
  Eigen::MatrixXd mass_b_;     ///< M⁻¹ B, computed at the first stick (empty: not yet)
  bool mass_singular_ = false; ///< M has no inverse (massless DOFs): no projection
  // Static correction (none unless the second constructor).
  bool static_correction_ = false;
  Eigen::MatrixXd static_flexibility_; ///< W_s
  std::vector<char> no_static_;        ///< per coordinate: W_s's row is zero (held as in FE)
  Eigen::MatrixXd static_history_;     ///< n_c × 4: y_s at steps n, n−1, n−2, n−3
  Eigen::VectorXd ydot_, yddot_;       ///< estimates of ẏ_n, ÿ_n the next step starts from
};

/// A sinusoidal force F0·sin(2π f t) at one equation.
struct SineLoad {
  int equation = 0;
  double amplitude = 0.0;    ///< N or N·m (peak)
  double frequency_hz = 0.0; ///< Hz
};

struct SteadyStateOptions {
  int steps_per_period = 2048;
  int output_periods = 4;
  int max_periods = 4000;
  /// Converged when two consecutive periods differ by less than this, relative to the
  /// largest output amplitude, twice in a row and for every period given out (each of the
  /// output_periods agrees with the one before it).
  double tolerance = 1e-10;
  NewmarkOptions newmark;
};

struct SteadyState {
  /// not_periodic: max_periods ran without two consecutive periods within the tolerance (the
  /// last periods are returned all the same); not_converging: the joints' Newton iteration
  /// failed at a step (no samples); numerical_issue: the effective stiffness is singular.
  Status status;
  int periods_run = 0;
  double period_change = 0.0; ///< last relative period-to-period change
  Eigen::VectorXd t;          ///< uniformly sampled whole periods, s (starting at 0)
  Eigen::VectorXd force;      ///< applied force at the samples
  Eigen::MatrixXd u;          ///< n_samples × n_outputs displacements
  Eigen::MatrixXd v;          ///< n_samples × n_outputs velocities
};

/// Runs from rest until a periodic steady state; returns the last `output_periods` periods
/// sampled at the time steps (steps_per_period samples per period, the endpoint excluded).
SteadyState steady_state(const Assembled& system, const SparseMatrix& C, const LocalForces* forces,
                         const SineLoad& load, std::span<const int> output_equations,
                         const SteadyStateOptions& options = {});

/// steady_state's periodic driver for any integrator (fem/transient.hpp's TimeModel uses it):
/// from a state at rest, `step(force)` advances one time step (a period / steps_per_period) to
/// the load amplitude·sin(2π f t) at the step's end, and `sample(u, v)` gives the n_outputs
/// displacements and velocities at the current step. A step's failure is the result's status
/// (its code; the reason says in which period and when). Throws std::invalid_argument as
/// steady_state does for a frequency <= 0 or bad options.
SteadyState
periodic_steady_state(double amplitude, double frequency_hz, int n_outputs,
                      const SteadyStateOptions& options,
                      const std::function<Status(double force)>& step,
                      const std::function<void(Eigen::VectorXd& u, Eigen::VectorXd& v)>& sample);

} // namespace jointid::fem
