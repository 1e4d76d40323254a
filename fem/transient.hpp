#pragma once
/// Time simulation of the substructure with its non-linear local forces (the joints) under any
/// force history, by the Newmark integrator of `fem/time_integration.hpp` (exact stick–slip):
///  - on the full finite element model (the reference), or
///  - in modal coordinates: the retained modes q (q̈ + 2ζ_rω_r q̇ + ω_r² q = φ_rᵀ f) plus a
///    static correction for the modes left out — their residual flexibility
///    R = K⁻¹ − Σ_kept φ_r φ_rᵀ/ω_r² at the DOFs S where forces act (the applied forces' and the
///    joints'), as extra Ritz vectors: the columns of R_{:,S} (directions of R_SS below
///    `tolerance`·max K⁻¹_SS dropped), made K- and M-orthonormal. They are K- and M-orthogonal
///    to the retained modes, so the reduced system is diagonal: the retained modes and a few
///    pseudo-modes above them whose static deflection at S is exactly that of the left-out
///    modes (the static correction) and whose mass is the Rayleigh–Ritz estimate. Accurate while
///    the left-out modes lie well above the excitation (their dynamic amplification
///    1/(1 − (ω/ω_r)²) ≈ 1). A massless static correction was tried first and dropped: the
///    trapezoidal rule's velocity and acceleration of a massless coordinate carry an undamped
///    alternating error (amplification −1), which ruined the accelerations.
/// The force between samples is the linear interpolant of the samples; the motion starts at rest.
/// SI units: s, N, m.
#include "fem/assembly.hpp"
#include "fem/modal.hpp"
#include "fem/model.hpp"
#include "fem/time_integration.hpp"

#include <Eigen/Core>
#include <functional>
#include <span>
#include <vector>

namespace jointid::fem {

/// Forces at a few equations, sampled uniformly from t = 0.
struct ForceHistory {
  double dt = 0.0;            ///< s, sample spacing (> 0)
  std::vector<int> equations; ///< where each column acts
  Eigen::MatrixXd samples;    ///< n_samples × |equations|, N or N·m
};

struct TransientOptions {
  int substeps = 1; ///< time steps per sample interval (h = dt / substeps)
  /// Seconds over which the force is faded in (a half-cosine from 0 to 1) so that the start
  /// from rest is smooth; 0: the force acts from the first sample.
  double fade_in_s = 0.0;
  NewmarkOptions newmark;
  /// Called with the fraction done (0 … 1), about every 1 % of the samples; empty: not called.
  std::function<void(double)> progress;
};

struct TransientResponse {
  /// not_converging: the joints' Newton iteration failed at a step (the reason says when; the
  /// samples before it are kept); numerical_issue: the effective stiffness is singular.
  Status status;
  int samples_done = 0; ///< samples computed (all unless the joints' iteration failed)
  Eigen::VectorXd t;    ///< s, the samples' times
  Eigen::MatrixXd u;    ///< n_samples × n_outputs displacement (m or rad)
  Eigen::MatrixXd v;    ///< velocity
  Eigen::MatrixXd a;    ///< acceleration (Newmark's)
};

/// The full model: M ü + C u̇ + K u = f(t) − B g at the samples. Throws std::invalid_argument for
/// a bad history (dt <= 0, equation out of range, non-finite samples) or output.
TransientResponse transient_response(const Assembled& system, const SparseMatrix& C,
                                     const LocalForces* forces, const ForceHistory& history,
                                     std::span<const int> outputs,
                                     const TransientOptions& options = {});

/// The reduced system in modal coordinates w = [q; z] (see the header comment), as an
/// Assembled system integrated by the same Newmark scheme: K = diag(ω_r², ω_z²), M = I,
/// C = diag(2ζ(ω)ω) (the model's damping at each frequency); physical u = basis · w.
struct ModalReduction {
  Assembled system;       ///< its DofMap numbers the reduced coordinates (no physical meaning)
  SparseMatrix C;         ///< diagonal
  Eigen::MatrixXd basis;  ///< n_eq × (n_modes + n_static): [Φ Ψ]
  int kept_modes = 0;     ///< columns of Φ
  int static_columns = 0; ///< columns of Ψ (0: no static correction)
};

/// `modes` are the retained modes (every row of φ; mass-normalised), `damping` gives ζ_r,
/// `static_dofs` the equations that receive forces (applied and joints). Empty static_dofs: no
/// correction. Throws std::invalid_argument when the modes lack rows, or a correction is asked
/// of a model with a singular K (rigid-body modes: no static flexibility).
ModalReduction modal_reduction(const Assembled& system, const Modes& modes, const Damping& damping,
                               std::span<const int> static_dofs, double tolerance = 1e-9);

/// The same simulation on a modal reduction; `forces` act on the full model's equations (its
/// coordinates B are projected, Bᵀu = (basisᵀB)ᵀw) and the history and outputs are full-model
/// equations.
TransientResponse transient_response(const ModalReduction& reduction, const LocalForces* forces,
                                     const ForceHistory& history, std::span<const int> outputs,
                                     const TransientOptions& options = {});

} // namespace jointid::fem
