#pragma once
/// The linear substructure as the analyses see it: a finite element model (assembled K, M and
/// its damping), K and M given by another program, a modal model given by its modes at a few
/// DOFs, or FRFs measured at a few DOFs. SI units; frequencies in Hz.
#include "fem/assembly.hpp"
#include "fem/modal.hpp"
#include "fem/model.hpp"
#include "fem/status.hpp"
#include "frf/modal_model.hpp"
#include "frf/receptance.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace jointid::frf {

/// The band of modes a synthesis needs for excitation up to f_max_hz with harmonics 0 … K: the
/// modes below twice the highest harmonic's frequency, the residual flexibility standing in for
/// those above (used for finite element models above the dense limit).
inline double synthesis_band_hz(double f_max_hz, int harmonics) {
  return 2.0 * harmonics * f_max_hz;
}

class Substructure {
public:
  /// Validates and assembles (throws std::invalid_argument for an invalid model).
  explicit Substructure(fem::Model model);
  /// Validates (throws std::invalid_argument); equations are numbered as modal.dofs.
  explicit Substructure(ModalModel modal);
  /// K and M given (exported by another finite element program), their rows numbered by
  /// `system.dofs`, with this damping. Throws std::invalid_argument for matrices of the wrong
  /// size, not finite, not symmetric (to 1e-10 of the largest entry) or with a negative mass on
  /// the diagonal, naming the matrix and the entry.
  Substructure(fem::Assembled system, fem::Damping damping);
  /// Measured FRFs (frf/measured_frf.hpp); equations are numbered as frf.dofs. Validates
  /// (std::invalid_argument). No modes: response curves (which need them for stability) and
  /// time integration refuse it; identification and harmonic balance read H from it.
  explicit Substructure(MeasuredFrf frf);
  /// Several substructures side by side, not connected except by the joints between them: H is
  /// block diagonal (frf::ModalSynthesis::block_diagonal). Part p's node n is node
  /// n + node_offsets[p] here. Equations: part 1's in its order, then part 2's, … Throws
  /// std::invalid_argument for no parts, sizes that differ, a negative offset, a part that is
  /// itself composite, or a node of two parts (naming both: "give one a node offset").
  Substructure(std::vector<Substructure> parts, std::vector<int> node_offsets);

  /// The equations: the FE model's free DOFs, or fem::DofMap::from_dofs(modal.dofs).
  const fem::DofMap& dofs() const;
  const fem::Model* model() const { return model_ ? &*model_ : nullptr; } ///< nullptr: modal, K/M
  const fem::Assembled* system() const { return system_ ? &*system_ : nullptr; } ///< ditto
  const ModalModel* modal() const { return modal_ ? &*modal_ : nullptr; }        ///< nullptr: FE
  /// The measured FRFs, or nullptr.
  const MeasuredReceptance* measured() const { return measured_.get(); }
  /// The parts of a composite substructure (empty otherwise).
  const std::vector<Substructure>& parts() const { return parts_; }
  /// The highest frequency (Hz) up to which every measured FRF among `equations` is known
  /// (infinity when none of them comes from measured FRFs).
  double band_top_hz(const std::vector<int>& equations) const;
  /// How it is given, for messages: "a finite element model", "its matrices ([matrices])",
  /// "its modes ([modal])", "measured FRFs ([frf])" or "several substructures
  /// ([[substructures]])".
  const char* given_by() const;
  /// The FE model's (or the given matrices') damping; none for a modal model.
  const fem::Damping& damping() const { return damping_; }

  /// Receptance over `dofs` (equation numbers) for excitation frequencies up to f_max_hz:
  /// an FE model with at most fem::ModalOptions{}.dense_limit equations uses every mode (exact;
  /// the dense engine, f_max_hz unused); a larger one the modes below f_max_hz (> 0; sparse
  /// engine, frequency band) with residual flexibility. A modal model uses its given modes and
  /// residual. `notes` (if not null) receives what the user should know, e.g. "receptance from
  /// 12 of 3000 modes without residual flexibility (the model has rigid-body modes): the modes
  /// left out are ignored". A modal analysis that fails gives a synthesis with its status
  /// (ModalSynthesis::status(), the reason saying why; a part's prefixed "substructure p: ");
  /// throws std::invalid_argument for an equation outside the model or f_max_hz <= 0 where it
  /// is needed. Measured FRFs: notes receive the estimated interpolation error when it exceeds
  /// 1e-3 of a function's peak.
  ModalSynthesis synthesis(std::vector<int> dofs, double f_max_hz,
                           std::vector<std::string>* notes = nullptr) const;

  /// Viscous damping matrix for time integration (FE only; N·s/m): Rayleigh directly (none: an
  /// empty matrix); modal damping needs every mode, so a model above the dense limit is refused
  /// (std::invalid_argument saying to use [damping] rayleigh = [alpha, beta]). Throws
  /// std::logic_error for a modal model ("time integration needs a finite element model").
  /// The modal analysis modal damping needs can fail: its status, and no matrix.
  fem::Outcome<fem::SparseMatrix> damping_matrix() const;

  /// Computes the band of modes a synthesis of an FE model above the dense limit needs:
  /// (model, assembled system, options with max_frequency_hz set, equations whose rows of φ
  /// are needed) → modes, which may hold only those rows (fem::Modes::rows). E.g. the
  /// distributed engine (fem::slepc_modal_analysis), called on every MPI rank alike.
  using BandSolver = std::function<fem::Modes(const fem::Model&, const fem::Assembled&,
                                              const fem::ModalOptions&, const std::vector<int>&)>;
  /// Replaces the default band solver (fem::modal_analysis, sparse engine); empty: default.
  /// Also for every part of a composite substructure.
  void set_band_solver(BandSolver solver) {
    for (Substructure& part : parts_)
      part.set_band_solver(solver);
    band_solver_ = std::move(solver);
  }

private:
  /// Every mode of the FE model (dense engine), computed once and kept.
  const fem::Modes& all_modes() const;

  std::optional<fem::Model> model_;
  std::optional<fem::Assembled> system_;
  std::optional<ModalModel> modal_;
  std::shared_ptr<const MeasuredReceptance> measured_;
  std::vector<Substructure> parts_;
  std::vector<int> node_offsets_;
  std::vector<int> part_of_, local_of_; // a composite's equation → its part and equation there
  fem::Damping damping_;                // of the FE model, or of the given matrices
  fem::DofMap modal_dofs_;
  mutable std::optional<fem::Modes> all_modes_; // a cache: not safe for concurrent first use
  BandSolver band_solver_;
};

} // namespace jointid::frf
