#pragma once
/// A substructure in the coordinates its time simulation uses (fem::TimeModel, integrated by
/// fem::transient_response and fem::steady_state with the joints' exact stick–slip):
///  - a finite element model or [matrices]: in full (K, M and its damping matrix), or in modal
///    coordinates (the modes below a cutoff and static pseudo-modes, fem::modal_reduction);
///  - a [modal] model: its modal coordinates, q̈_r + 2ζ_rω_r q̇_r + ω_r² q_r = φ_rᵀ F, and its
///    residual flexibility R as the static correction x = Φ q + R F, F the total force at its
///    DOFs (applied and the joints');
///  - several substructures ([[substructures]]): each part so, side by side; the joints alone
///    couple them.
/// Measured FRFs ([frf]) have no time-domain model and are refused. SI units.
#include "fem/status.hpp"
#include "fem/transient.hpp"
#include "frf/substructure.hpp"

#include <string>
#include <vector>

namespace jointid::frf {

struct TimeModelOptions {
  /// Finite element models and [matrices]: false, in full; true, the modes below
  /// modal_cutoff_hz (> 0) plus static pseudo-modes at the loaded equations. Models of up to
  /// 200 equations get every mode from the dense eigensolver, larger ones only the band below
  /// the cutoff (sparse engine). A [modal] model always keeps every mode it gives.
  bool modal_coordinates = false;
  double modal_cutoff_hz = 0.0; ///< Hz
  /// Modal coordinates of a finite element part: the static pseudo-modes (false: none).
  bool static_correction = true;
  /// The substructure's equations where forces act (applied and the joints'): the static
  /// pseudo-modes of finite element parts in modal coordinates are made there.
  std::vector<int> loaded;
  /// The frequency below which the force's power lies (Hz; 0: unknown). A finite element
  /// part's mode left out between the cutoff and it is driven near its resonance, which the
  /// static correction does not hold: each such part gets a warning naming them.
  double force_band_hz = 0.0;
};

struct TimeDomainModel {
  /// ok, or why there is no model: a modal analysis or a modal damping matrix that failed (a
  /// part's reason after "substructure p: ").
  fem::Status status;
  fem::TimeModel model;
  int modes_kept = 0;     ///< modal coordinates: finite element parts' kept modes, [modal] modes
  int static_columns = 0; ///< static pseudo-modes of finite element parts
  int residual_dofs = 0;  ///< DOFs of [modal] parts whose residual flexibility is applied
  /// A finite element model in modal coordinates that kept every mode (no correction needed).
  bool every_mode = false;
  /// How each substructure is integrated, e.g. "5 modes of its [modal] model, its residual
  /// flexibility at 3 DOFs as a static correction" (one entry; one per part of a composite).
  std::vector<std::string> parts;
  /// What costs accuracy: modes left out below the force's band (TimeModelOptions).
  std::vector<std::string> warnings;
};

/// The substructure's time model. Throws std::invalid_argument for measured FRFs ([frf]; a
/// part's named "substructure p"), saying that they have no time-domain model and to fit them
/// first (jointid modal-fit); for modal coordinates without a cutoff > 0; for an equation of
/// `loaded` outside the substructure. A numerical failure is the result's status.
TimeDomainModel time_domain_model(const Substructure& substructure,
                                  const TimeModelOptions& options = {});

/// The reason measured FRFs cannot be simulated in time, after `what` ("substructure 2 is given
/// by measured FRFs ([frf])"): the text of time_domain_model's refusal.
std::string no_time_domain_model(const std::string& what);

} // namespace jointid::frf
