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

// The forces expressed on the reduced coordinates: B_w = basisᵀ B.
class ProjectedForces final : public LocalForces {
public:
  ProjectedForces(const LocalForces& inner, const Eigen::MatrixXd& basis) : inner_(inner) {
    const Eigen::MatrixXd B = basis.transpose() * Eigen::MatrixXd(inner.coordinates());
    B_ = B.sparseView(0.0, 0.0);
  }
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

// Steps the integrator through the history. load(i, s) is the force vector on the integrated
// system at sample i scaled by s; record(r, i) stores the outputs of sample i.
TransientResponse
integrate(const Assembled& system, const SparseMatrix& C, const LocalForces* forces,
          const ForceHistory& history,
          const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& load,
          const std::function<void(const Newmark&, TransientResponse&, Eigen::Index)>& record,
          int n_outputs, const TransientOptions& o) {
  if (o.substeps < 1)
    throw std::invalid_argument("transient response: expected at least 1 substep, got " +
                                std::to_string(o.substeps));
  if (!(std::isfinite(o.fade_in_s) && o.fade_in_s >= 0.0))
    throw std::invalid_argument("transient response: expected a fade-in >= 0 s, got " +
                                std::to_string(o.fade_in_s));
  const Eigen::Index n = history.samples.rows();
  const int n_sys = system.dofs.num_equations();
  const double h = history.dt / o.substeps;
  auto fade = [&](double t) {
    return t >= o.fade_in_s ? 1.0 : 0.5 * (1.0 - std::cos(std::numbers::pi * t / o.fade_in_s));
  };
  // The linear interpolant, at a fractional sample index, of the samples (faded in).
  auto applied = [&](double sample) {
    const auto i = std::min(static_cast<Eigen::Index>(sample), n - 2);
    const double tau = sample - static_cast<double>(i);
    const double t = static_cast<double>(i) * history.dt;
    const Eigen::VectorXd f = (1.0 - tau) * fade(t) * history.samples.row(i).transpose() +
                              tau * fade(t + history.dt) * history.samples.row(i + 1).transpose();
    return Eigen::VectorXd(load(f));
  };

  TransientResponse out;
  out.t = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1) * history.dt);
  out.u = out.v = out.a = Eigen::MatrixXd::Zero(n, n_outputs);
  Newmark integrator(system, C, forces, h, o.newmark);
  if (!integrator.status().ok()) {
    out.status = integrator.status();
    out.samples_done = 0;
    return out;
  }
  integrator.set_state(Eigen::VectorXd::Zero(n_sys), Eigen::VectorXd::Zero(n_sys), applied(0.0));
  record(integrator, out, 0);
  out.samples_done = 1;
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    for (int s = 1; s <= o.substeps; ++s) {
      const double sample = static_cast<double>(i) + static_cast<double>(s) / o.substeps;
      if (Status step = integrator.step(applied(sample)); !step.ok()) {
        std::ostringstream reason;
        reason << "the joints' Newton iteration failed after t = "
               << static_cast<double>(i) * history.dt << " s (no convergence in "
               << o.newmark.max_newton << " iterations on the way to t = " << sample * history.dt
               << " s)";
        out.status = Status::failure(step.code, reason.str());
        return out;
      }
    }
    record(integrator, out, i + 1);
    out.samples_done = static_cast<int>(i + 2);
    if (o.progress && (i + 2) % std::max<Eigen::Index>(1, n / 100) == 0)
      o.progress(static_cast<double>(i + 2) / static_cast<double>(n));
  }
  return out;
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
  return integrate(system, C, forces, history, load, record, static_cast<int>(out_eq.size()), o);
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
  std::optional<ProjectedForces> projected;
  if (forces) projected.emplace(*forces, red.basis);
  auto load = [&](const Eigen::VectorXd& f) { return Eigen::VectorXd(to_w * f); };
  auto record = [&](const Newmark& m, TransientResponse& r, Eigen::Index i) {
    r.u.row(i) = (at_outputs * m.u()).transpose();
    r.v.row(i) = (at_outputs * m.v()).transpose();
    r.a.row(i) = (at_outputs * m.a()).transpose();
  };
  return integrate(red.system, red.C, projected ? &*projected : nullptr, history, load, record,
                   static_cast<int>(outputs.size()), o);
}

} // namespace jointid::fem
