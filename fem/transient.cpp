#include "fem/transient.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace jointid::fem {

namespace {

void check_history(const ForceHistory& h, int n_eq) {
  if (!(std::isfinite(h.dt) && h.dt > 0.0))
    throw std::invalid_argument("force history: expected a sample spacing dt > 0 s, got " +
                                std::to_string(h.dt));
  if (static_cast<Eigen::Index>(h.equations.size()) != h.samples.cols())
    throw std::invalid_argument("force history: " + std::to_string(h.equations.size()) +
                                " equations but " + std::to_string(h.samples.cols()) + " columns");
  if (h.samples.rows() < 2)
    throw std::invalid_argument("force history: expected at least 2 samples, got " +
                                std::to_string(h.samples.rows()));
  for (int e : h.equations)
    if (e < 0 || e >= n_eq)
      throw std::invalid_argument("force history: equation " + std::to_string(e) +
                                  " is not one of the model's " + std::to_string(n_eq));
  for (Eigen::Index c = 0; c < h.samples.cols(); ++c)
    for (Eigen::Index i = 0; i < h.samples.rows(); ++i)
      if (!std::isfinite(h.samples(i, c)))
        throw std::invalid_argument("force history: sample " + std::to_string(i + 1) +
                                    " of column " + std::to_string(c + 1) + " (equation " +
                                    std::to_string(h.equations[static_cast<std::size_t>(c)]) +
                                    ") is " + std::to_string(h.samples(i, c)) +
                                    ", not a finite number");
}

void check_outputs(std::span<const int> outputs, int n_eq) {
  for (int e : outputs)
    if (e < 0 || e >= n_eq)
      throw std::invalid_argument("transient response: output equation " + std::to_string(e) +
                                  " is not one of the model's " + std::to_string(n_eq));
}

// The same local forces (and their history, for hysteresis) acting through other
// coordinates: B_w = Pᵀ B for the reduced basis or a TimeModel's T as P.
class MappedForces final : public LocalForces {
public:
  MappedForces(const LocalForces& inner, SparseMatrix B) : inner_(inner), B_(std::move(B)) {}
  const SparseMatrix& coordinates() const override { return B_; }
  void evaluate(const Eigen::VectorXd& y, const Eigen::VectorXd& ydot, Eigen::VectorXd& g,
                Eigen::VectorXd& dg_dy, Eigen::VectorXd& dg_dydot) const override {
    inner_.evaluate(y, ydot, g, dg_dy, dg_dydot);
  }
  Eigen::VectorXd friction_limits() const override { return inner_.friction_limits(); }
  int state_size() const override { return inner_.state_size(); }
  void evaluate_from(std::span<const double> state, const Eigen::VectorXd& y,
                     const Eigen::VectorXd& ydot, Eigen::VectorXd& g, Eigen::VectorXd& dg_dy,
                     Eigen::VectorXd& dg_dydot) const override {
    inner_.evaluate_from(state, y, ydot, g, dg_dy, dg_dydot);
  }
  void advance(std::span<double> state, const Eigen::VectorXd& y) const override {
    inner_.advance(state, y);
  }
  bool piecewise_smooth() const override { return inner_.piecewise_smooth(); }

private:
  const LocalForces& inner_;
  SparseMatrix B_;
};

// The forces' coordinates on a reduced basis: basisᵀ B.
SparseMatrix projected_coordinates(const LocalForces& forces, const Eigen::MatrixXd& basis) {
  const Eigen::MatrixXd B = basis.transpose() * Eigen::MatrixXd(forces.coordinates());
  return B.sparseView(0.0, 0.0);
}

// Newmark on a TimeModel's coordinates w with its static correction, and its outputs on x:
// u = T w + s, v = T ẇ + ṡ, a = T ẅ + s̈ with s = R F at the outputs, its derivatives by
// second-order backward differences of its history.
class TimeStepper {
public:
  TimeStepper(const TimeModel& m, const LocalForces* forces, double h, const NewmarkOptions& o,
              std::span<const int> outputs)
      : m_(m), forces_(forces), h_(h) {
    const int n_x = m.num_equations(), n_w = m.system.dofs.num_equations();
    if (m.T.cols() != n_w)
      throw std::invalid_argument("time model: T has " + std::to_string(m.T.cols()) +
                                  " columns for " + std::to_string(n_w) + " coordinates");
    if (m.R.size() != 0 && (m.R.rows() != n_x || m.R.cols() != n_x))
      throw std::invalid_argument("time model: R is " + std::to_string(m.R.rows()) + " x " +
                                  std::to_string(m.R.cols()) + ", expected " + std::to_string(n_x) +
                                  " x " + std::to_string(n_x));
    if (forces && forces->coordinates().rows() != n_x)
      throw std::invalid_argument("time model: the local forces act on " +
                                  std::to_string(forces->coordinates().rows()) +
                                  " equations, the model has " + std::to_string(n_x));
    SparseMatrix pick(static_cast<Eigen::Index>(outputs.size()), n_x); // selects the outputs
    std::vector<Eigen::Triplet<double>> ones;
    for (std::size_t j = 0; j < outputs.size(); ++j)
      ones.emplace_back(static_cast<int>(j), outputs[j], 1.0);
    pick.setFromTriplets(ones.begin(), ones.end());
    T_out_ = pick * m.T;
    static_ = m.has_static_correction();
    if (forces) mapped_.emplace(*forces, SparseMatrix(m.T.transpose()) * forces->coordinates());
    if (static_) {
      R_out_ = pick * m.R;
      if (forces) {
        const SparseMatrix& B = forces->coordinates();
        Z_ = SparseMatrix(B.transpose()) * m.R;
        RB_out_ = Eigen::MatrixXd(R_out_ * B);
        static_flexibility_ = Eigen::MatrixXd(Z_ * B);
      }
      history_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(outputs.size()), 4);
    }
    if (static_ && forces)
      newmark_.emplace(m.system, m.C, *mapped_, static_flexibility_, h, o);
    else
      newmark_.emplace(m.system, m.C, forces ? &*mapped_ : nullptr, h, o);
  }
  const Status& status() const { return newmark_->status(); }

  /// At rest under the applied forces f (one per equation of x).
  void start(const Eigen::VectorXd& f) {
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m_.system.dofs.num_equations());
    const Eigen::VectorXd load = m_.T.transpose() * f;
    if (static_ && forces_)
      newmark_->set_state(zero, zero, load, Z_ * f);
    else
      newmark_->set_state(zero, zero, load);
    if (static_) {
      const Eigen::VectorXd s = static_at_outputs(f);
      for (Eigen::Index k = 0; k < history_.cols(); ++k)
        history_.col(k) = s;
    }
  }
  Status step(const Eigen::VectorXd& f) {
    const Eigen::VectorXd load = m_.T.transpose() * f;
    Status status = static_ && forces_ ? newmark_->step(load, Z_ * f) : newmark_->step(load);
    if (static_ && status.ok()) {
      for (Eigen::Index k = history_.cols() - 1; k > 0; --k)
        history_.col(k) = history_.col(k - 1);
      history_.col(0) = static_at_outputs(f);
    }
    return status;
  }
  /// Displacement, velocity, acceleration at the outputs now.
  void outputs(Eigen::VectorXd& u, Eigen::VectorXd& v, Eigen::VectorXd& a) const {
    u = T_out_ * newmark_->u();
    v = T_out_ * newmark_->v();
    a = T_out_ * newmark_->a();
    if (!static_) return;
    const Eigen::MatrixXd& s = history_;
    u += s.col(0);
    v += (3.0 * s.col(0) - 4.0 * s.col(1) + s.col(2)) / (2.0 * h_);
    a += (2.0 * s.col(0) - 5.0 * s.col(1) + 4.0 * s.col(2) - s.col(3)) / (h_ * h_);
  }

private:
  // R F at the outputs, F = f − B G with the joints' current force G.
  Eigen::VectorXd static_at_outputs(const Eigen::VectorXd& f) const {
    Eigen::VectorXd s = R_out_ * f;
    if (forces_) s -= RB_out_ * newmark_->local_force();
    return s;
  }
  const TimeModel& m_;
  const LocalForces* forces_;
  double h_;
  bool static_ = false;
  std::optional<MappedForces> mapped_;
  std::optional<Newmark> newmark_;
  SparseMatrix T_out_, R_out_, Z_;     ///< T, R at the outputs; Z = Bᵀ R
  Eigen::MatrixXd RB_out_;             ///< R B at the outputs
  Eigen::MatrixXd static_flexibility_; ///< Bᵀ R B
  Eigen::MatrixXd history_;            ///< R F at the outputs, steps n … n−3 (newest first)
};

// Steps an integrator through the history: `ready` is its status before the first step, start(f)
// sets it at rest under the force samples f (one per history column, faded in), step(f)
// advances it to f, record(r, i) stores the outputs of sample i.
TransientResponse integrate(const ForceHistory& history, int n_outputs, const TransientOptions& o,
                            const std::function<Status()>& ready,
                            const std::function<void(const Eigen::VectorXd&)>& start,
                            const std::function<Status(const Eigen::VectorXd&)>& step,
                            const std::function<void(TransientResponse&, Eigen::Index)>& record) {
  if (o.substeps < 1)
    throw std::invalid_argument("transient response: expected at least 1 substep, got " +
                                std::to_string(o.substeps));
  if (!(std::isfinite(o.fade_in_s) && o.fade_in_s >= 0.0))
    throw std::invalid_argument("transient response: expected a fade-in >= 0 s, got " +
                                std::to_string(o.fade_in_s));
  const Eigen::Index n = history.samples.rows();
  auto fade = [&](double t) {
    return t >= o.fade_in_s ? 1.0 : 0.5 * (1.0 - std::cos(std::numbers::pi * t / o.fade_in_s));
  };
  // The force between samples, at a fractional sample index: the cubic through the four
  // nearest samples (faded in; the linear interpolant with fewer than four). A sampled force
  // stands for a band-limited one: the linear interpolant would apply its line at f scaled by
  // sinc²(f/fs), 1 − (π f/fs)²/3 — 4.5e-4 at 3 Hz sampled at 256 Hz, which a resonance turns
  // into a per-cent error of the response; the cubic's error falls as (f/fs)⁴.
  auto applied = [&](double sample) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(history.samples.cols());
    if (n < 4) {
      const auto i = std::min(static_cast<Eigen::Index>(sample), n - 2);
      const double tau = sample - static_cast<double>(i);
      const double t = static_cast<double>(i) * history.dt;
      f = (1.0 - tau) * fade(t) * history.samples.row(i).transpose() +
          tau * fade(t + history.dt) * history.samples.row(i + 1).transpose();
      return f;
    }
    const Eigen::Index first =
        std::clamp<Eigen::Index>(static_cast<Eigen::Index>(sample) - 1, 0, n - 4);
    const double x = sample - static_cast<double>(first); // in [0, 3]
    for (int j = 0; j < 4; ++j) {
      double w = 1.0; // Lagrange weight of node j of the nodes 0, 1, 2, 3
      for (int m = 0; m < 4; ++m)
        if (m != j) w *= (x - m) / static_cast<double>(j - m);
      if (w == 0.0) continue;
      const Eigen::Index node = first + j;
      f += w * fade(static_cast<double>(node) * history.dt) * history.samples.row(node).transpose();
    }
    return f;
  };

  TransientResponse out;
  out.t = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1) * history.dt);
  out.u = out.v = out.a = Eigen::MatrixXd::Zero(n, n_outputs);
  if (Status status = ready(); !status.ok()) {
    out.status = std::move(status);
    out.samples_done = 0;
    return out;
  }
  start(applied(0.0));
  record(out, 0);
  out.samples_done = 1;
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    for (int s = 1; s <= o.substeps; ++s) {
      const double sample = static_cast<double>(i) + static_cast<double>(s) / o.substeps;
      if (Status status = step(applied(sample)); !status.ok()) {
        std::ostringstream reason;
        reason << "the joints' Newton iteration failed after t = "
               << static_cast<double>(i) * history.dt << " s (no convergence in "
               << o.newmark.max_newton << " iterations on the way to t = " << sample * history.dt
               << " s)";
        out.status = Status::failure(status.code, reason.str());
        return out;
      }
    }
    record(out, i + 1);
    out.samples_done = static_cast<int>(i + 2);
    if (o.progress && (i + 2) % std::max<Eigen::Index>(1, n / 100) == 0)
      o.progress(static_cast<double>(i + 2) / static_cast<double>(n));
  }
  return out;
}

// A Newmark integrator of (system, C, forces) through `integrate`: `load` maps the history's
// force samples to the integrated equations, `record` stores the outputs.
TransientResponse integrate_newmark(
    const Assembled& system, const SparseMatrix& C, const LocalForces* forces,
    const ForceHistory& history, const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& load,
    const std::function<void(const Newmark&, TransientResponse&, Eigen::Index)>& record,
    int n_outputs, const TransientOptions& o) {
  if (o.substeps < 1)
    throw std::invalid_argument("transient response: expected at least 1 substep, got " +
                                std::to_string(o.substeps));
  const int n_sys = system.dofs.num_equations();
  Newmark integrator(system, C, forces, history.dt / o.substeps, o.newmark);
  return integrate(
      history, n_outputs, o, [&] { return integrator.status(); },
      [&](const Eigen::VectorXd& f) {
        integrator.set_state(Eigen::VectorXd::Zero(n_sys), Eigen::VectorXd::Zero(n_sys), load(f));
      },
      [&](const Eigen::VectorXd& f) { return integrator.step(load(f)); },
      [&](TransientResponse& r, Eigen::Index i) { record(integrator, r, i); });
}

} // namespace

TransientResponse transient_response(const Assembled& system, const SparseMatrix& C,
                                     const LocalForces* forces, const ForceHistory& history,
                                     std::span<const int> outputs, const TransientOptions& o) {
  const int n_eq = system.dofs.num_equations();
  check_history(history, n_eq);
  check_outputs(outputs, n_eq);
  const std::vector<int> out_eq(outputs.begin(), outputs.end());
  auto load = [&](const Eigen::VectorXd& f) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(n_eq);
    for (std::size_t j = 0; j < history.equations.size(); ++j)
      full(history.equations[j]) += f(static_cast<Eigen::Index>(j));
    return full;
  };
  auto record = [&](const Newmark& m, TransientResponse& r, Eigen::Index i) {
    for (std::size_t j = 0; j < out_eq.size(); ++j) {
      const auto c = static_cast<Eigen::Index>(j);
      r.u(i, c) = m.u()(out_eq[j]);
      r.v(i, c) = m.v()(out_eq[j]);
      r.a(i, c) = m.a()(out_eq[j]);
    }
  };
  return integrate_newmark(system, C, forces, history, load, record,
                           static_cast<int>(out_eq.size()), o);
}

ModalReduction modal_reduction(const Assembled& system, const Modes& modes, const Damping& damping,
                               std::span<const int> static_dofs, double tolerance) {
  const int n_eq = system.dofs.num_equations();
  if (!modes.rows.empty() || modes.phi.rows() != n_eq)
    throw std::invalid_argument("modal reduction: the modes must have every row of the model's " +
                                std::to_string(n_eq) + " equations");
  const int m = modes.num_modes();
  for (int e : static_dofs)
    if (e < 0 || e >= n_eq)
      throw std::invalid_argument("modal reduction: equation " + std::to_string(e) +
                                  " is not one of the model's");
  Eigen::MatrixXd psi(n_eq, 0);
  Eigen::VectorXd static_stiffness; // ω² of the static-correction pseudo-modes
  if (!static_dofs.empty()) {
    const auto s = static_cast<Eigen::Index>(static_dofs.size());
    Eigen::SimplicialLDLT<SparseMatrix> stiffness(system.K);
    if (stiffness.info() != Eigen::Success || !(stiffness.vectorD().array() > 0.0).all())
      throw std::invalid_argument(
          "modal reduction: K is singular (rigid-body modes or a mechanism), so the left-out "
          "modes have no static flexibility; keep every mode or support the structure");
    for (int r = 0; r < m; ++r)
      if (!(modes.omega(r) > 0.0))
        throw std::invalid_argument("modal reduction: a retained mode has zero frequency");
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n_eq, s);
    for (Eigen::Index j = 0; j < s; ++j)
      E(static_dofs[j], j) = 1.0;
    const Eigen::MatrixXd flexibility = stiffness.solve(E); // K⁻¹ E_S
    // R E_S = P K⁻¹ Pᵀ E_S with P = I − ΦΦᵀM (equal to K⁻¹E_S − ΦΛ⁻¹Φ_Sᵀ, since
    // ΦᵀM K⁻¹ = Λ⁻¹Φᵀ): the kept modes' share is taken out of the load before the solve and out
    // of the result after it, instead of subtracting two nearly equal flexibilities — the
    // rounding of an ill-conditioned K lies mostly in the lowest modes, which P removes.
    const Eigen::MatrixXd Mphi = system.M * modes.phi;
    const Eigen::MatrixXd load = E - Mphi * modes.phi.transpose() * E;
    Eigen::MatrixXd R = stiffness.solve(load);
    R -= modes.phi * (Mphi.transpose() * R);
    Eigen::MatrixXd R_ss(s, s), K_inv_ss(s, s);
    for (Eigen::Index j = 0; j < s; ++j) {
      R_ss.row(j) = R.row(static_dofs[j]);
      K_inv_ss.row(j) = flexibility.row(static_dofs[j]);
    }
    R_ss = 0.5 * (R_ss + R_ss.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(R_ss);
    const double floor = tolerance * K_inv_ss.diagonal().cwiseAbs().maxCoeff();
    std::vector<Eigen::Index> keep;
    for (Eigen::Index j = 0; j < s; ++j)
      if (eig.eigenvalues()(j) > floor) keep.push_back(j);
    Eigen::MatrixXd attachment(n_eq, static_cast<Eigen::Index>(keep.size())); // ΨᵀKΨ = I
    for (std::size_t j = 0; j < keep.size(); ++j)
      attachment.col(static_cast<Eigen::Index>(j)) =
          R * eig.eigenvectors().col(keep[j]) / std::sqrt(eig.eigenvalues()(keep[j]));
    // Their mass, ΨᵀMΨ = U diag(μ) Uᵀ: the columns Ψ U diag(μ)^{-1/2} are M-orthonormal with
    // stiffness 1/μ — pseudo-modes above the retained ones (ΦᵀMΨ = ΦᵀKΨ = 0 since
    // ΦᵀM K⁻¹ = Λ⁻¹Φᵀ). Static deflections at S are unchanged; their dynamics is the
    // Rayleigh–Ritz estimate, and no coordinate is massless.
    if (attachment.cols() > 0) {
      const Eigen::MatrixXd mass = attachment.transpose() * (system.M * attachment);
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> m_eig(0.5 * (mass + mass.transpose()));
      if (!(m_eig.eigenvalues().array() > 0.0).all())
        throw std::invalid_argument("modal reduction: the static-correction vectors carry no mass "
                                    "(massless DOFs at the loaded points?)");
      psi = attachment * m_eig.eigenvectors() *
            m_eig.eigenvalues().cwiseSqrt().cwiseInverse().asDiagonal();
      static_stiffness = m_eig.eigenvalues().cwiseInverse();
    }
  }
  ModalReduction red;
  red.kept_modes = m;
  red.static_columns = static_cast<int>(psi.cols());
  const int n = m + red.static_columns;
  red.basis.resize(n_eq, n);
  red.basis << modes.phi, psi;
  std::vector<NodeDof> coordinates;
  for (int i = 0; i < n; ++i)
    coordinates.push_back({i + 1, Dof::ux});
  red.system.dofs = DofMap::from_dofs(coordinates);
  std::vector<Eigen::Triplet<double>> k, mass, c;
  for (int r = 0; r < m; ++r) {
    const double w = modes.omega(r);
    k.emplace_back(r, r, w * w);
    mass.emplace_back(r, r, 1.0);
    c.emplace_back(r, r, 2.0 * damping.ratio(w) * w);
  }
  for (int z = m; z < n; ++z) {
    const double w2 = static_stiffness(z - m), w = std::sqrt(w2);
    k.emplace_back(z, z, w2);
    mass.emplace_back(z, z, 1.0);
    c.emplace_back(z, z, 2.0 * damping.ratio(w) * w);
  }
  red.system.K.resize(n, n);
  red.system.M.resize(n, n);
  red.C.resize(n, n);
  red.system.K.setFromTriplets(k.begin(), k.end());
  red.system.M.setFromTriplets(mass.begin(), mass.end());
  red.C.setFromTriplets(c.begin(), c.end());
  return red;
}

TransientResponse transient_response(const ModalReduction& red, const LocalForces* forces,
                                     const ForceHistory& history, std::span<const int> outputs,
                                     const TransientOptions& o) {
  const auto n_eq = static_cast<int>(red.basis.rows());
  check_history(history, n_eq);
  check_outputs(outputs, n_eq);
  Eigen::MatrixXd to_w(red.basis.cols(), history.equations.size()); // basisᵀ at the forces
  for (std::size_t j = 0; j < history.equations.size(); ++j)
    to_w.col(static_cast<Eigen::Index>(j)) = red.basis.row(history.equations[j]).transpose();
  Eigen::MatrixXd at_outputs(outputs.size(), red.basis.cols());
  for (std::size_t j = 0; j < outputs.size(); ++j)
    at_outputs.row(static_cast<Eigen::Index>(j)) = red.basis.row(outputs[j]);
  std::optional<MappedForces> projected;
  if (forces) projected.emplace(*forces, projected_coordinates(*forces, red.basis));
  auto load = [&](const Eigen::VectorXd& f) { return Eigen::VectorXd(to_w * f); };
  auto record = [&](const Newmark& m, TransientResponse& r, Eigen::Index i) {
    r.u.row(i) = (at_outputs * m.u()).transpose();
    r.v.row(i) = (at_outputs * m.v()).transpose();
    r.a.row(i) = (at_outputs * m.a()).transpose();
  };
  return integrate_newmark(red.system, red.C, projected ? &*projected : nullptr, history, load,
                           record, static_cast<int>(outputs.size()), o);
}

TransientResponse transient_response(const TimeModel& model, const LocalForces* forces,
                                     const ForceHistory& history, std::span<const int> outputs,
                                     const TransientOptions& o) {
  const int n_x = model.num_equations();
  check_history(history, n_x);
  check_outputs(outputs, n_x);
  if (o.substeps < 1)
    throw std::invalid_argument("transient response: expected at least 1 substep, got " +
                                std::to_string(o.substeps));
  TimeStepper stepper(model, forces, history.dt / o.substeps, o.newmark, outputs);
  auto applied = [&](const Eigen::VectorXd& f) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n_x);
    for (std::size_t j = 0; j < history.equations.size(); ++j)
      x(history.equations[j]) += f(static_cast<Eigen::Index>(j));
    return x;
  };
  Eigen::VectorXd u, v, a;
  return integrate(
      history, static_cast<int>(outputs.size()), o, [&] { return stepper.status(); },
      [&](const Eigen::VectorXd& f) { stepper.start(applied(f)); },
      [&](const Eigen::VectorXd& f) { return stepper.step(applied(f)); },
      [&](TransientResponse& r, Eigen::Index i) {
        stepper.outputs(u, v, a);
        r.u.row(i) = u.transpose();
        r.v.row(i) = v.transpose();
        r.a.row(i) = a.transpose();
      });
}

SteadyState steady_state(const TimeModel& model, const LocalForces* forces, const SineLoad& load,
                         std::span<const int> outputs, const SteadyStateOptions& o) {
  const int n_x = model.num_equations();
  if (load.equation < 0 || load.equation >= n_x)
    throw std::invalid_argument("sine load: bad equation");
  if (!(load.frequency_hz > 0.0))
    throw std::invalid_argument("sine load: frequency must be > 0 Hz");
  if (o.steps_per_period < 8)
    throw std::invalid_argument(
        "steady state: need >= 8 steps per period and max_periods > output_periods + 1");
  check_outputs(outputs, n_x);
  const double h = 1.0 / load.frequency_hz / o.steps_per_period;
  TimeStepper stepper(model, forces, h, o.newmark, outputs);
  if (!stepper.status().ok()) {
    SteadyState out;
    out.status = stepper.status();
    return out;
  }
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n_x), a;
  stepper.start(f);
  return periodic_steady_state(
      load.amplitude, load.frequency_hz, static_cast<int>(outputs.size()), o,
      [&](double force) {
        f(load.equation) = force;
        return stepper.step(f);
      },
      [&](Eigen::VectorXd& u, Eigen::VectorXd& v) { stepper.outputs(u, v, a); });
}

} // namespace jointid::fem
