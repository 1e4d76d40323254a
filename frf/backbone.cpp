#include "frf/backbone.hpp"

#include "fem/text.hpp"
#include "frf/hb_equations.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace jointid::frf {

using detail::two_pi;

namespace {

// The harmonic balance of the self-excited structure at (ω, ξ): its receptances and equations.
struct ModeFrame {
  std::unique_ptr<HarmonicBalance> hb;
  std::unique_ptr<detail::Equations> eq;
};

// A point of the backbone: the packed harmonics z, ω and ξ at the reference amplitude a.
struct ModeState {
  Eigen::VectorXd z;
  double omega = 0.0, xi = 0.0, a = 0.0;
};

// The EPMC equations of some joints: R(z; ω, ξ) = 0 with the phase and amplitude conditions.
class Epmc {
public:
  Epmc(const ModalSynthesis& H, const std::vector<joints::Joint>& joints, const fem::DofMap& dofs,
       int amplitude_equation, int reference, const HarmonicBalanceOptions& o)
      : H_(H), joints_(joints), dofs_(dofs), outputs_{amplitude_equation}, reference_(reference),
        o_(o), no_force_(Eigen::MatrixXcd::Zero(2, 0)) {}

  ModeFrame frame(double omega, double xi) const {
    ModeFrame f;
    f.hb = std::make_unique<HarmonicBalance>(H_.with_self_excitation(xi), joints_, dofs_,
                                             std::vector<int>{}, outputs_, omega / two_pi, o_);
    f.eq = f.hb->equations(joints_, no_force_);
    return f;
  }

  // The packed unknowns for the joints' deformation harmonics Y (K+1 × n_joints) at (ω, ξ).
  Eigen::VectorXd pack(const Eigen::MatrixXcd& Y, double omega, double xi) const {
    const ModeFrame f = frame(omega, xi);
    return f.hb->first_guess(*f.eq, &Y);
  }
  Eigen::MatrixXcd unpack(const ModeState& s) const {
    return frame(s.omega, s.xi).eq->unpack(s.z, static_cast<int>(joints_.size()));
  }

  // Newton on [R(z; ω, ξ); Im Y_1,ref; Re Y_1,ref − a] = 0 from s, in coordinates scaled by the
  // amplitude (z; friction forces through their compliance) and by ω (ω, ξ). True when the
  // residual is within the tolerance relative to |z| and the conditions hold.
  bool solve(ModeState& s, double a, std::string& why) const {
    const double tol = std::max(o_.tolerance, 1e-10);
    s.a = a;
    for (int it = 0; it < 40; ++it) {
      const ModeFrame f = frame(s.omega, s.xi);
      const detail::Equations& P = *f.eq;
      const int n = P.size(), o = reference_ * P.m() + P.at(P.symmetric() ? 0 : 1);
      Eigen::MatrixXd J;
      const Eigen::VectorXd R = P.residual(s.z, 1.0, &J);
      const double phase = s.z(o + 1), amp = s.z(o) - a;
      const double relative = R.norm() / std::max(P.norm(s.z), 1e-300);
      if (relative < tol && std::abs(phase) <= 1e-12 * a && std::abs(amp) <= 1e-12 * a) return true;
      Eigen::VectorXd unit = Eigen::VectorXd::Constant(n, a);
      for (std::size_t k = 0; k < P.friction.size(); ++k)
        unit.segment((P.nj + static_cast<int>(k)) * P.m(), P.m()).setConstant(a / P.friction[k].c);
      const double dw = 1e-6 * s.omega;
      const Eigen::VectorXd dR_dw = (frame(s.omega + dw, s.xi).eq->residual(s.z, 1.0, nullptr) -
                                     frame(s.omega - dw, s.xi).eq->residual(s.z, 1.0, nullptr)) /
                                    (2.0 * dw);
      const Eigen::VectorXd dR_dxi = (frame(s.omega, s.xi + dw).eq->residual(s.z, 1.0, nullptr) -
                                      frame(s.omega, s.xi - dw).eq->residual(s.z, 1.0, nullptr)) /
                                     (2.0 * dw);
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n + 2, n + 2);
      A.topLeftCorner(n, n) = J * unit.asDiagonal();
      A.block(0, n, n, 1) = dR_dw * s.omega;
      A.block(0, n + 1, n, 1) = dR_dxi * s.omega;
      A(n, o + 1) = unit(o + 1);
      A(n + 1, o) = unit(o);
      Eigen::VectorXd b(n + 2);
      b << -R, -phase, -amp;
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
      Eigen::VectorXd du;
      if (lu.isInvertible()) {
        du = lu.solve(b);
      } else {
        Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A);
        cod.setThreshold(1e-13);
        du = cod.solve(b);
      }
      if (!du.allFinite()) {
        why = "the Newton step is not finite";
        return false;
      }
      // Backtracking on |[R; conditions]|.
      const double merit = std::sqrt(R.squaredNorm() + phase * phase + amp * amp);
      bool improved = false;
      for (double t = 1.0; t > 1e-3; t *= 0.5) {
        ModeState trial = s;
        trial.z += t * unit.cwiseProduct(du.head(n));
        trial.omega += t * s.omega * du(n);
        trial.xi += t * s.omega * du(n + 1);
        if (!(trial.omega > 0.0) || !trial.z.allFinite() || !std::isfinite(trial.xi)) continue;
        const Eigen::VectorXd Rt = frame(trial.omega, trial.xi).eq->residual(trial.z, 1.0, nullptr);
        const double pt = trial.z(o + 1), at = trial.z(o) - a;
        if (Rt.allFinite() && std::sqrt(Rt.squaredNorm() + pt * pt + at * at) < merit) {
          s = std::move(trial);
          improved = true;
          break;
        }
      }
      if (!improved) {
        why = "Newton stalled at relative residual " + significant(relative, 4);
        return false;
      }
    }
    why = "no convergence in 40 Newton iterations";
    return false;
  }

  // The point's numbers: |X_1| at the amplitude DOF, |Y_1| of the reference joint, f, D.
  BackbonePoint point(const ModeState& s) const {
    const ModeFrame f = frame(s.omega, s.xi);
    const HarmonicBalanceResult r = f.hb->result(*f.eq, s.z);
    BackbonePoint p;
    p.amplitude = std::abs(r.X(1, 0));
    p.joint_amplitude = std::abs(r.Y(1, reference_));
    p.frequency_hz = s.omega / two_pi;
    p.self_excitation = s.xi;
    p.damping_ratio = s.xi / (2.0 * s.omega);
    p.Y = r.Y;
    return p;
  }

private:
  const ModalSynthesis& H_;
  const std::vector<joints::Joint>& joints_;
  const fem::DofMap& dofs_;
  std::vector<int> outputs_;
  int reference_;
  HarmonicBalanceOptions o_;
  Eigen::MatrixXcd no_force_; // free motion: no force columns
};

// The joints with their linear terms only (k, c: frf::detail::linear_joint).
std::vector<joints::Joint> linearised(const std::vector<joints::Joint>& joints) {
  std::vector<joints::Joint> out;
  for (const joints::Joint& j : joints) {
    const detail::LinearJoint l = detail::linear_joint(j);
    joints::Joint lin;
    lin.name = j.name, lin.node = j.node, lin.node_b = j.node_b, lin.dof = j.dof;
    lin.terms = {joints::Term::k, joints::Term::c};
    lin.values = {l.stiffness, l.damping};
    lin.fixed = {true, true};
    out.push_back(std::move(lin));
  }
  return out;
}

class ModeTracer {
public:
  ModeTracer(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
             const fem::DofMap& dofs, int mode, int amplitude_equation, const BackboneOptions& o)
      : H_(H), joints_(joints), dofs_(dofs), mode_(mode), amplitude_equation_(amplitude_equation),
        o_(o), linear_joints_(linearised(joints)) {
    if (joints.empty())
      throw std::invalid_argument("backbone: no joints: the structure is linear, its modes are "
                                  "those of `jointid modes`");
    if (H.measured())
      throw std::invalid_argument("backbone: the substructure is given by measured FRFs, which "
                                  "have no modes to self-excite; give it by a model or [modal]");
    if (o.points < 2) throw std::invalid_argument("backbone: expected at least 2 points");
    if (o.hb.exact_friction)
      for (const joints::Joint& j : joints) {
        const int t = j.term_index(joints::Term::fc);
        if (t >= 0 && j.values[static_cast<std::size_t>(t)] != 0.0)
          throw std::invalid_argument(
              "backbone: joint '" + j.name +
              "' has dry friction (fc): at small amplitudes it sticks and does not deform, so "
              "its deformation cannot carry the backbone from the linear mode (that of the "
              "joint held rigid); give the joint a stiffness in stick instead, a jenkins (kt, "
              "fs) or iwan term");
      }
    const int m = H.num_modes();
    if (mode < 1 || mode > m)
      throw std::invalid_argument("backbone: mode " + std::to_string(mode) +
                                  " is out of range: expected 1 to " + std::to_string(m) +
                                  " (the modes of the substructure's synthesis)");
    // The linear mode in modal coordinates q (ΦᵀMΦ = I): K = Ω² + Pᵀ k P, C = diag(2ζω) +
    // Pᵀ c P, P = Bᵀ Φ_J the joints' deformations per mode; mode N the N-th lowest of K. Its
    // frequency and damping are a start only: the residual flexibility and the damping's
    // coupling enter through the EPMC solve.
    const std::vector<int> jdofs = joints::joint_dof_set(joints, dofs);
    const Eigen::MatrixXd P =
        joints::joint_coordinates_on(joints, dofs, jdofs).transpose() * H.shapes(jdofs);
    Eigen::VectorXd k(joints.size()), c(joints.size());
    for (std::size_t j = 0; j < joints.size(); ++j)
      k(static_cast<Eigen::Index>(j)) = linear_joints_[j].values[0],
      c(static_cast<Eigen::Index>(j)) = linear_joints_[j].values[1];
    const Eigen::MatrixXd Km =
        Eigen::MatrixXd(H.natural_frequencies().array().square().matrix().asDiagonal()) +
        P.transpose() * k.asDiagonal() * P;
    const Eigen::MatrixXd Cm =
        Eigen::MatrixXd(H.modal_damping().asDiagonal()) + P.transpose() * c.asDiagonal() * P;
    P_ = P;
    for (const joints::Joint& j : linear_joints_)
      free_ = free_ && j.values[0] == 0.0 && j.values[1] == 0.0;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Km);
    const Eigen::VectorXd v = eig.eigenvectors().col(mode - 1);
    mode_vector_ = v;
    const Eigen::VectorXd y = P * v;
    Eigen::Index ref = 0;
    const double largest = y.cwiseAbs().maxCoeff(&ref);
    if (!(largest > 1e-6 * P.cwiseAbs().maxCoeff()))
      throw std::invalid_argument(
          "backbone: mode " + std::to_string(mode) + " (" +
          significant(std::sqrt(std::max(eig.eigenvalues()(mode - 1), 0.0)) / two_pi, 4) +
          " Hz) does not deform any joint (each is at a node of the mode), so its joints cannot "
          "change it with amplitude; choose another mode");
    reference_ = static_cast<int>(ref);
    omega0_ = std::sqrt(std::max(eig.eigenvalues()(mode - 1), 0.0));
    xi0_ = v.dot(Cm * v);
    shape0_ = y / y(ref);
    if (!(omega0_ > 0.0))
      throw std::invalid_argument("backbone: mode " + std::to_string(mode) +
                                  " is a rigid-body motion (0 Hz): it has no natural frequency");
  }

  int reference() const { return reference_; }

  // The linear mode (the linear joints' EPMC at unit amplitude), and its state.
  LinearMode linear(std::string& why) {
    const Epmc lin(H_, linear_joints_, dofs_, amplitude_equation_, reference_, o_.hb);
    const int K = o_.hb.harmonics, nj = static_cast<int>(joints_.size());
    Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K + 1, nj);
    Y.row(1) = shape0_.cast<Complex>().transpose();
    ModeState s;
    s.omega = omega0_, s.xi = xi0_;
    LinearMode out;
    if (free_) {
      // No joint has a linear term (a cubic spring alone, a gap with clearance, friction): the
      // linear mode is the substructure's own, exactly (no joint force, so neither the
      // residual flexibility nor the damping's coupling enters), and its (ω, ξ) is a pole of
      // the receptance, where the EPMC's equations cannot be evaluated.
      const std::array<int, 1> at{amplitude_equation_};
      const double x = (H_.shapes(at) * mode_vector_)(0);
      const double y = (P_ * mode_vector_)(reference_);
      s.a = 1.0;
      linear_state_ = s;
      linear_Y_ = Y;
      out.frequency_hz = omega0_ / two_pi;
      out.damping_ratio = xi0_ / (2.0 * omega0_);
      out.self_excitation = xi0_;
      out.joint_shape = shape0_;
      out.amplitude_ratio = amplitude_ratio_ = std::abs(x / y);
      return out;
    }
    s.z = lin.pack(Y, s.omega, s.xi);
    if (!lin.solve(s, 1.0, why)) return out;
    linear_state_ = s;
    const BackbonePoint p = lin.point(s);
    out.frequency_hz = p.frequency_hz;
    out.damping_ratio = p.damping_ratio;
    out.self_excitation = p.self_excitation;
    out.joint_shape = p.Y.row(1).real().transpose();
    out.amplitude_ratio = p.amplitude / p.joint_amplitude;
    linear_Y_ = p.Y;
    return out;
  }

  // The backbone over joint amplitudes a0 … a1 (linear() first).
  void trace(double a0, double a1, Backbone& out) const {
    const Epmc epmc(H_, joints_, dofs_, amplitude_equation_, reference_, o_.hb);
    const int n = o_.points;
    auto amplitude = [&](int i) {
      return a0 * std::pow(a1 / a0, static_cast<double>(i) / (n - 1));
    };
    ModeState s = *linear_state_;
    int i = 0;
    if (free_) {
      // From the pole: the describing functions' estimate (the joints' equivalent stiffness and
      // damping in the linear mode's shape), in modal coordinates. Where the joints exert no
      // force at all (a clearance not yet closed) the point is the linear mode itself.
      std::optional<ModeState> start;
      for (; i < n && !(start = equivalent_linear(epmc, amplitude(i))); ++i)
        out.points.push_back(linear_point(amplitude(i)));
      if (!start) return;
      s = *start;
    }
    const double first = amplitude(i);
    s.z = epmc.pack(linear_Y_ * first, s.omega, s.xi);
    std::string why;
    if (!epmc.solve(s, first, why)) {
      out.status = fem::Status::failure(fem::Status::Code::not_converging,
                                        "backbone: no solution at " +
                                            std::string(i == 0 ? "the first amplitude, " : "") +
                                            significant(first, 4) + " (joint deformation): " + why);
      return;
    }
    out.points.push_back(epmc.point(s));
    std::optional<ModeState> before;
    for (++i; i < n; ++i) {
      const double a = amplitude(i);
      if (!advance(epmc, s, before, a, 0, why)) {
        out.status = fem::Status::failure(
            fem::Status::Code::not_converging,
            "backbone: stopped at joint deformation " + significant(a, 4) + " after " +
                std::to_string(out.points.size()) + " points: " + why);
        return;
      }
      out.points.push_back(epmc.point(s));
    }
  }

private:
  // The joints' describing functions N_j = G_1,j / Y_1,j at the linear mode's shape times a (the
  // first harmonic of their forces, from the EPMC's equations slightly off the pole), taken as
  // springs Re N and dampers Im N / ω in the modal coordinates of the linear mode: that mode's
  // (ω, ξ). Empty when no joint exerts a force there.
  std::optional<ModeState> equivalent_linear(const Epmc& epmc, double a) const {
    const double w = omega0_ * (1.0 + 1e-3);
    const ModeFrame f = epmc.frame(w, xi0_);
    const Eigen::MatrixXcd Y = linear_Y_ * a;
    const Eigen::VectorXd z = f.hb->first_guess(*f.eq, &Y);
    const Eigen::MatrixXcd G = f.eq->forces(z);
    const auto nj = static_cast<Eigen::Index>(joints_.size());
    Eigen::VectorXd k = Eigen::VectorXd::Zero(nj), c = Eigen::VectorXd::Zero(nj);
    for (Eigen::Index j = 0; j < nj; ++j)
      if (std::abs(Y(1, j)) > 0.0) {
        const Complex N = G(1, j) / Y(1, j);
        k(j) = N.real(), c(j) = N.imag() / w;
      }
    if (k.isZero(0.0) && c.isZero(0.0)) return std::nullopt;
    const Eigen::MatrixXd Km =
        Eigen::MatrixXd(H_.natural_frequencies().array().square().matrix().asDiagonal()) +
        P_.transpose() * k.asDiagonal() * P_;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Km);
    const Eigen::VectorXd v = eig.eigenvectors().col(mode_ - 1);
    const Eigen::MatrixXd Cm =
        Eigen::MatrixXd(H_.modal_damping().asDiagonal()) + P_.transpose() * c.asDiagonal() * P_;
    ModeState s;
    s.omega = std::sqrt(std::max(eig.eigenvalues()(mode_ - 1), 0.0));
    s.xi = v.dot(Cm * v);
    s.a = a;
    if (!(s.omega > 0.0)) return std::nullopt;
    return s;
  }

  // The linear mode at joint amplitude a (no joint has a linear term and none exerts a force).
  BackbonePoint linear_point(double a) const {
    BackbonePoint p;
    p.amplitude = a * amplitude_ratio_;
    p.joint_amplitude = a;
    p.frequency_hz = omega0_ / two_pi;
    p.self_excitation = xi0_;
    p.damping_ratio = xi0_ / (2.0 * omega0_);
    p.Y = linear_Y_ * a;
    return p;
  }

  // From s (and the point before it, for a secant prediction of ω and ξ in log amplitude) to
  // amplitude a; a failed step is halved (in log amplitude) up to max_refinements times.
  bool advance(const Epmc& epmc, ModeState& s, std::optional<ModeState>& before, double a,
               int depth, std::string& why) const {
    ModeState next = s;
    const double r = a / s.a;
    next.z *= r;
    if (before) {
      const double x = std::log(r) / std::log(s.a / before->a);
      next.omega = s.omega + x * (s.omega - before->omega);
      next.xi = s.xi + x * (s.xi - before->xi);
    }
    if (epmc.solve(next, a, why)) {
      before = s;
      s = std::move(next);
      return true;
    }
    if (depth >= o_.max_refinements) return false;
    const double mid = std::sqrt(s.a * a);
    return advance(epmc, s, before, mid, depth + 1, why) &&
           advance(epmc, s, before, a, depth + 1, why);
  }

  const ModalSynthesis& H_;
  const std::vector<joints::Joint>& joints_;
  const fem::DofMap& dofs_;
  int mode_, amplitude_equation_;
  BackboneOptions o_;
  std::vector<joints::Joint> linear_joints_;
  int reference_ = 0;
  double omega0_ = 0.0, xi0_ = 0.0;
  Eigen::VectorXd shape0_;
  Eigen::MatrixXd P_;            // the joints' deformations per mode
  Eigen::VectorXd mode_vector_;  // the linear mode in the synthesis' modal coordinates
  bool free_ = true;             // no joint has a linear term: the linear mode is a pole
  double amplitude_ratio_ = 0.0; // the linear mode's, when free_
  std::optional<ModeState> linear_state_;
  Eigen::MatrixXcd linear_Y_;
};

void check_range(double a0, double a1) {
  if (!(a0 > 0.0) || !(a1 > a0) || !std::isfinite(a1))
    throw std::invalid_argument("backbone: the amplitudes must be finite with 0 < from < to, got " +
                                significant(a0, 4) + " and " + significant(a1, 4));
}

Backbone run(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
             const fem::DofMap& dofs, int mode, int amplitude_equation, double from, double to,
             bool at_dof, const BackboneOptions& o) {
  check_range(from, to);
  ModeTracer tracer(H, joints, dofs, mode, amplitude_equation, o);
  Backbone out;
  out.mode = mode;
  out.amplitude_dof = dofs.node_dof(amplitude_equation);
  out.reference_joint = tracer.reference();
  out.harmonics = o.hb.harmonics;
  std::string why;
  out.linear = tracer.linear(why);
  if (!(out.linear.frequency_hz > 0.0)) {
    out.status = fem::Status::failure(fem::Status::Code::not_converging,
                                      "backbone: the linear mode " + std::to_string(mode) +
                                          " was not found: " + why);
    return out;
  }
  double a0 = from, a1 = to;
  if (at_dof) {
    if (!(out.linear.amplitude_ratio > 1e-9))
      throw std::invalid_argument("backbone: " + fem::to_string(out.amplitude_dof) +
                                  " does not move in mode " + std::to_string(mode) +
                                  " (a node of the mode): choose another amplitude DOF");
    a0 /= out.linear.amplitude_ratio, a1 /= out.linear.amplitude_ratio;
  }
  tracer.trace(a0, a1, out);
  return out;
}

} // namespace

Backbone trace_backbone(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                        const fem::DofMap& dofs, int mode, int amplitude_equation, double a0,
                        double a1, const BackboneOptions& o) {
  return run(H, joints, dofs, mode, amplitude_equation, a0, a1, false, o);
}

Backbone backbone(const Substructure& sub, const std::vector<joints::Joint>& joints, int mode,
                  const fem::NodeDof& amplitude_dof, double from, double to,
                  const BackboneOptions& o) {
  check_range(from, to);
  if (joints.empty())
    throw std::invalid_argument("backbone: no joints: the structure is linear, its modes are "
                                "those of `jointid modes`");
  if (mode < 1) throw std::invalid_argument("backbone: mode numbers start at 1");
  const fem::DofMap& dofs = sub.dofs();
  const int amplitude_equation = dofs.equation(amplitude_dof);
  std::vector<int> outputs = joints::joint_dof_set(joints, dofs);
  if (std::find(outputs.begin(), outputs.end(), amplitude_equation) == outputs.end())
    outputs.push_back(amplitude_equation);
  // The band: modes up to 2K times the mode's frequency (synthesis_band_hz), found by widening
  // it until it holds the mode with room (a model within the dense limit, or a modal model,
  // gives all its modes at once).
  std::vector<std::string> notes;
  double f_max = 10.0;
  for (int pass = 0; pass < 40; ++pass) {
    notes.clear();
    const ModalSynthesis H =
        sub.synthesis(outputs, synthesis_band_hz(f_max, o.hb.harmonics), &notes);
    if (!H.status().ok()) {
      Backbone out;
      out.status = H.status();
      out.mode = mode;
      out.amplitude_dof = amplitude_dof;
      return out;
    }
    const Eigen::VectorXd& w = H.natural_frequencies();
    const bool holds = w.size() >= mode && 1.5 * w(mode - 1) / two_pi <= f_max;
    const bool all = w.size() == 0 || w(w.size() - 1) / two_pi < 0.25 * f_max;
    if (holds || all || pass == 39) {
      Backbone out = run(H, joints, dofs, mode, amplitude_equation, from, to, true, o);
      out.notes.insert(out.notes.begin(), notes.begin(), notes.end());
      return out;
    }
    f_max = w.size() >= mode ? 1.5 * w(mode - 1) / two_pi : 4.0 * f_max;
  }
  return {}; // not reached
}

} // namespace jointid::frf
