#pragma once
/// Backbones: the natural frequency and damping ratio of one mode of the substructure with its
/// joints against amplitude, by the extended periodic motion concept (EPMC; M. Krack, Computers
/// & Structures 154 (2015) 59–71). The damped structure is given the self-excitation −ξ M ẋ,
///     M ẍ + (C − ξ M) ẋ + K x + B g(Bᵀx, Bᵀẋ) = 0,
/// which makes its free motion periodic: ξ puts back, per cycle, the energy the damping and the
/// joints take. The unknowns are the harmonics of the joints' deformations (the harmonic
/// balance's, frf/harmonic_balance.hpp, whose residual and Jacobian serve as they are: the
/// self-excitation is the modal damping 2ζ_rω_r − ξ, ModalSynthesis::with_self_excitation),
/// ω and ξ; a phase (the reference joint's fundamental real) and the amplitude (its fundamental's
/// modulus) close the system. The damping ratio is D = ξ / (2ω), the frequency ω / 2π. At small
/// amplitude this is the linear mode of the structure with the joints' linear terms; ∂R/∂ω and
/// ∂R/∂ξ are central differences (as the frequency continuation's ∂R/∂ω). Where no joint has a
/// linear term the linear mode is the substructure's own (a pole of the receptance, taken in
/// modal coordinates), the first point starts from the joints' describing functions, and the
/// amplitudes where no joint exerts a force (a gap's clearance open) are that mode exactly.
/// Exact dry friction is refused: it sticks at small amplitude, so the joint does not deform.
/// SI units.
#include "fem/dof.hpp"
#include "fem/status.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"

#include <string>
#include <vector>

namespace jointid::frf {

struct BackboneOptions {
  HarmonicBalanceOptions hb{.harmonics = 5}; ///< harmonics, AFT samples, friction, tolerance
  int points = 40;                           ///< amplitudes, spaced evenly on a log scale
  int max_refinements = 8; ///< times a failed step is halved (in log amplitude) before it stops
};

struct BackbonePoint {
  double amplitude = 0.0;       ///< |X_1| at the amplitude DOF (peak, m or rad)
  double joint_amplitude = 0.0; ///< |Y_1| of the reference joint's deformation (m or rad)
  double frequency_hz = 0.0;    ///< ω / 2π
  double damping_ratio = 0.0;   ///< ξ / (2ω)
  double self_excitation = 0.0; ///< ξ, 1/s
  Eigen::MatrixXcd Y;           ///< (K+1) × n_joints: harmonics of the joints' deformations
};

/// The linear mode of the structure with its joints' linear terms (frf::detail::linear_joint).
struct LinearMode {
  double frequency_hz = 0.0;
  double damping_ratio = 0.0;
  double self_excitation = 0.0; ///< ξ, 1/s
  Eigen::VectorXd joint_shape;  ///< the joints' deformations, the reference joint's 1
  double amplitude_ratio = 0.0; ///< |X_1 at the amplitude DOF| / |Y_1 of the reference joint|
};

struct Backbone {
  /// ok, or why it stopped (the points up to there are kept), e.g. "no convergence at amplitude
  /// …" or the synthesis' status.
  fem::Status status;
  int mode = 0;               ///< 1-based, of the structure with its joints' linear terms
  fem::NodeDof amplitude_dof; ///< where `amplitude` is taken
  int reference_joint = 0;    ///< the joint whose fundamental fixes amplitude and phase
  int harmonics = 0;
  LinearMode linear;
  std::vector<BackbonePoint> points; ///< by increasing joint amplitude
  std::vector<std::string> notes;
};

/// The backbone of `mode` over the reference joint's deformation amplitudes a0 … a1 (> 0, the
/// joint deformed most by the linear mode), on a synthesis covering the joints' DOFs and
/// `amplitude_equation`. Throws std::invalid_argument for no joints, a mode out of range (1 …
/// the synthesis' modes), a mode that no joint deforms (every joint at a node of it: 1e-6 of
/// the largest joint deformation of any mode), bad amplitudes or options; a synthesis from
/// measured FRFs is refused (they have no modal damping to self-excite).
Backbone trace_backbone(const ModalSynthesis& synthesis, const std::vector<joints::Joint>& joints,
                        const fem::DofMap& dofs, int mode, int amplitude_equation, double a0,
                        double a1, const BackboneOptions& options = {});

/// The backbone of `mode` of the substructure with its joints for amplitudes |X_1| at
/// `amplitude_dof` from about `from` to `to` (> 0; converted to the reference joint's
/// deformation by the linear mode's ratio, so the ends are met as far as the mode keeps its
/// shape). The synthesis covers the mode's harmonics (synthesis_band_hz). Throws as
/// trace_backbone, and for a DOF not in the model; a modal analysis that fails is the status.
Backbone backbone(const Substructure& substructure, const std::vector<joints::Joint>& joints,
                  int mode, const fem::NodeDof& amplitude_dof, double from, double to,
                  const BackboneOptions& options = {});

} // namespace jointid::frf
