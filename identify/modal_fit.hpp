#pragma once
/// The linear substructure from a low-level test: modal parameters fitted to measured FRFs
/// (identify/measured_frfs.hpp) from one driving point, as a `[modal]` model (frf/modal_model.hpp).
///
/// 1. Poles: the least-squares complex-frequency estimator (LSCF, Guillaume, Verboven and
///    Peeters; with one reference it is the poly-reference p-LSCF, "PolyMAX"). Every response
///    shares one denominator: H_o(ω) ≈ B_o(z)/A(z), z = e^{iωT}, T = 1/(2 f_top) (the band's
///    top line at z = −1), real coefficients. The equation error W_o (B_o − H_o A) is linear in
///    the coefficients; the numerators are eliminated from the normal equations (Toeplitz
///    blocks, built once from sums over the lines), leaving (n+1) × (n+1) equations for A at
///    each order n with its last coefficient fixed to 1. The roots z_r of A give the poles
///    λ_r = ln(z_r)/T; f_r = |λ_r|/2π, ζ_r = −Re λ_r / |λ_r| (so ω_r = 2π f_r is the undamped
///    natural frequency of the `[modal]` term 1/(ω_r² − ω² + 2iζ_r ω_r ω)). W_o = 1/RMS|H_o|
///    in the band, so that every response counts alike.
/// 2. Stabilisation diagram: the poles at orders 2, 4, …, max_order inside the band. A pole is
///    stable in frequency when a pole of the previous order lies within frequency_tolerance
///    (relative), stable when its damping ratio is also within damping_tolerance (relative).
/// 3. Selection: stable poles with 0 < ζ <= max_damping are grouped; the group with poles at the
///    most orders (each order giving at most its pole nearest the group's centre, within
///    frequency_tolerance of it) is a mode, its frequency and damping the medians of its poles;
///    then the next group among the poles left. With `modes` = N the N best-supported groups;
///    without, every group with poles at 40 % of the orders or more (at least 3) whose residue
///    at the driving point (step 4) is > 0, as a mode of a passive structure has (φ_d² > 0).
/// 4. Residues (least-squares frequency domain, LSFD) with the selected poles fixed, per
///    response o, real normal modes:
///        H_o(ω) ≈ Σ_r a_or / (ω_r² − ω² + 2iζ_r ω_r ω) − L_o/ω² + U_o
///    a_or = φ_or φ_dr (1/kg), L_o the lower residual (the modes below the band, mass-like,
///    1/kg), U_o the upper residual (the modes above, flexibility, m/N); real unknowns, the
///    real and imaginary parts of every line as equations.
/// 5. Mass-normalised shapes from the driving point d: φ_dr = sqrt(a_dr), φ_or = a_or / φ_dr.
///    A mode whose driving-point residue is not > 0 cannot be scaled: it is left out of the
///    model with a warning.
/// 6. The model: those modes at the responses' DOFs, and as residual flexibility the upper
///    residual. A test from one driving point measures only the column d of the flexibility;
///    the rest is taken as of rank one, R_ij = U_i U_j / U_d (as if the modes above the band
///    acted as one), which reproduces the column d exactly and is symmetric. The lower residual
///    has no place in a `[modal]` model: it is reported, and left out.
#include "fem/status.hpp"
#include "frf/modal_model.hpp"
#include "identify/measured_frfs.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace jointid::identify {

struct ModalFitOptions {
  int modes = 0;     ///< N modes; 0: as many as the stabilisation diagram shows
  int max_order = 0; ///< highest LSCF order (even, >= 4); 0: max(40, 4 N + 20), at most lines − 2
  double frequency_tolerance = 0.01; ///< stable in frequency: |Δf|/f within this, order to order
  double damping_tolerance = 0.05;   ///< stable in damping: |Δζ|/ζ within this
  double max_damping = 0.3;          ///< poles more damped than this are not taken as modes
  bool lower_residual = true;        ///< fit L_o
  bool upper_residual = true;        ///< fit U_o
};

enum class PoleStability {
  new_pole,  ///< no pole of the previous order near it
  frequency, ///< stable in frequency only
  stable     ///< stable in frequency and damping
};

/// One pole of the stabilisation diagram.
struct DiagramPole {
  int order = 0;
  double frequency_hz = 0.0, damping = 0.0;
  PoleStability stability = PoleStability::new_pole;
};

struct FittedMode {
  double frequency_hz = 0.0; ///< undamped natural frequency f_r = |λ_r|/2π
  double damping = 0.0;      ///< ζ_r
  int stable_orders = 0;     ///< orders of the diagram with a stable pole of this mode
  Eigen::VectorXd residues;  ///< per response: a_or = φ_or φ_dr (1/kg)
  Eigen::VectorXd shape;     ///< per response: mass-normalised φ_or (1/sqrt(kg)); empty if not
  bool in_model() const { return shape.size() > 0; }
};

struct ModalFit {
  /// not_separable (with its reason) when the data do not determine the modes asked: the
  /// diagram shows fewer than asked, or none (the modes found are kept), or no mode could be
  /// mass-normalised.
  fem::Status status;
  ModalFitOptions options; ///< as used (max_order as chosen)

  int max_order = 0;
  double sampling_time_s = 0.0; ///< T of the z-domain model, 1/(2 f_top)
  std::vector<DiagramPole> diagram;
  std::vector<FittedMode> modes; ///< by frequency

  Eigen::VectorXd lower_residual; ///< per response: L_o (1/kg): the term −L_o/ω²
  Eigen::VectorXd upper_residual; ///< per response: U_o (m/N)
  Eigen::MatrixXcd fitted;        ///< lines × responses: the modes and both residuals
  Eigen::MatrixXcd model_frf;     ///< lines × responses: `substructure` at the drive (as written)
  /// Per response: sqrt(Σ|H − H_fit|² / Σ|H|²) over the band's lines, for `fitted` and for
  /// `model_frf`.
  Eigen::VectorXd fit_error, model_error;
  frf::ModalModel substructure; ///< the `[modal]` model: dofs = the responses
  std::vector<std::string> warnings;
};

/// Fits the modal model to the FRFs (see the file comment). Throws std::invalid_argument for
/// bad input: the driving point not among the responses (its mass normalisation needs it;
/// naming the force and the responses), too few lines for the modes asked or for a diagram
/// (at least 2 N + 6 lines, or 10), max_order < 4, tolerances not > 0. A diagram without the
/// modes asked is a status (not_separable), the modes it shows kept.
ModalFit modal_fit(const MeasuredFrfs& data, const ModalFitOptions& options = {});

/// The MAC of two real shapes: (aᵀb)² / (aᵀa · bᵀb), 1 for shapes that are multiples.
double modal_assurance(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

} // namespace jointid::identify
