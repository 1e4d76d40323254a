#pragma once
/// Receptance FRFs H(ω) = X/F (m/N, complex, x(t) = Re(X e^{iωt})) of the linear substructure,
/// by modal synthesis (with a static residual-flexibility correction for the modes not kept)
/// and by a direct sparse solve of (K − ω²M + iωC), the cross-check.
#include "fem/damping.hpp"
#include "fem/modal.hpp"
#include "fem/status.hpp"
#include "frf/measured_frf.hpp"
#include "frf/modal_model.hpp"

#include <Eigen/Core>
#include <complex>
#include <memory>
#include <span>
#include <vector>

namespace jointid::frf {

using Complex = std::complex<double>;
using CMatrix = Eigen::MatrixXcd;
using CVector = Eigen::VectorXcd;

/// DOF sets by equation number: set 2 = DOFs a joint touches, set 1 = the others of interest
/// (drive points, measured points).
struct Partition {
  std::vector<int> set1;
  std::vector<int> set2;
};

/// H11 (n1×n1), H12 (n1×n2), H21 (n2×n1), H22 (n2×n2) at one frequency.
struct Blocks {
  CMatrix H11, H12, H21, H22;
};

struct ModalSynthesisOptions {
  /// Add K⁻¹ − Σ_kept φφᵀ/ω² (the static flexibility of the modes not kept). Needs a
  /// non-singular K (no rigid-body modes); ignored otherwise.
  bool residual_flexibility = true;
};

/// H(ω)_ij = Σ_r φ_ir φ_jr / (ω_r² − ω² + 2iζ_r ω_r ω) [+ R_ij], for DOFs among `dofs`.
/// ζ_r comes from the model's damping (modal ratio, or Rayleigh's α/2ω_r + βω_r/2), or from a
/// modal model's ratios.
///
/// A synthesis from modes whose analysis failed has that status (status(), with its reason)
/// and nothing to synthesise from: check status() first; using it otherwise (receptance(),
/// shapes(), …) throws std::logic_error with the reason, never returns a number.
class ModalSynthesis {
public:
  /// Throws std::invalid_argument for an equation out of range or a row the modes lack; modes
  /// whose status is not ok give a synthesis with that status.
  ModalSynthesis(const fem::Assembled& system, const fem::Modes& modes, const fem::Damping& damping,
                 std::vector<int> dofs, const ModalSynthesisOptions& options = {});
  /// From a substructure given by its modes: equation e is modal.dofs[e] (the numbering of
  /// fem::DofMap::from_dofs), `dofs` the equations served; ω_r = 2π f_r, 2ζ_rω_r from the given
  /// ratios, and the residual flexibility (if given) restricted to `dofs`. Validates `modal`;
  /// throws std::invalid_argument for it or for an equation out of range.
  ModalSynthesis(const ModalModel& modal, std::vector<int> dofs);
  /// From a substructure given by measured FRFs (equation e is measured->data().dofs[e]):
  /// receptance() reads and interpolates them (frf/measured_frf.hpp); there are no modes
  /// (num_modes() 0, no residual). Throws std::invalid_argument for an equation out of range.
  ModalSynthesis(std::shared_ptr<const MeasuredReceptance> measured, std::vector<int> dofs);
  /// Several substructures side by side (frf::Substructure of [[substructures]]): H is block
  /// diagonal, part p serving the equations equations[p] (its own dofs() in the same order:
  /// entry i of parts[p].dofs() is equation equations[p][i] here). The modes of every part
  /// together (each shape zero outside its part), their residuals block by block, and the
  /// measured FRFs of each part in its block. Throws std::invalid_argument when the sizes
  /// differ or an equation is served twice. A part whose status is not ok makes the whole
  /// synthesis fail with that status.
  static ModalSynthesis block_diagonal(const std::vector<ModalSynthesis>& parts,
                                       const std::vector<std::vector<int>>& equations);
  /// A synthesis over `dofs` that could not be made, with the status that says why (not ok).
  static ModalSynthesis failed(fem::Status status, std::vector<int> dofs);
  /// ok, or why there are no modes to synthesise from (the modal analysis' status).
  const fem::Status& status() const { return status_; }
  /// A copy with every mode's damping 2ζ_rω_r multiplied by `factor` (> 0; else
  /// std::invalid_argument): "the substructure's damping is off by a factor".
  /// Measured FRFs have no modal damping to scale: std::logic_error (check measured()).
  ModalSynthesis with_damping_scale(double factor) const;
  /// A copy with ξ (1/s) taken from every mode's damping, 2ζ_rω_r − ξ: the structure with the
  /// self-excitation −ξ M ẋ of the extended periodic motion concept (frf/backbone.hpp; ΦᵀMΦ = I,
  /// so in modal coordinates it is −ξ q̇). The residual flexibility (quasi-static) is kept.
  /// Measured FRFs have no modal damping: std::logic_error (check measured()); a ξ not finite:
  /// std::invalid_argument.
  ModalSynthesis with_self_excitation(double xi) const;
  /// The (first) measured FRFs behind the synthesis, or nullptr when it comes from modes only.
  const MeasuredReceptance* measured() const {
    return measured_.empty() ? nullptr : measured_.front().frf.get();
  }
  /// Rows and columns are equation numbers, each one of `dofs`.
  CMatrix receptance(double omega, std::span<const int> rows, std::span<const int> cols) const;
  /// The receptances at several frequencies side by side: rows × (|cols| · |omegas|), block k
  /// (columns k |cols| …) the receptance at omegas[k]. One allocation, the modal products
  /// φ_ir φ_jr formed once (the harmonic balance's K + 1 harmonics).
  CMatrix receptances(std::span<const double> omegas, std::span<const int> rows,
                      std::span<const int> cols) const;
  Blocks blocks(double omega, const Partition& partition) const;
  bool has_residual() const { return has_residual_; }
  int num_modes() const { return static_cast<int>(omega_.size()); }
  const std::vector<int>& dofs() const { return dofs_; }
  /// The modes behind the synthesis: ω_r (rad/s), 2ζ_rω_r (1/s), and the mass-normalised shapes
  /// at the given equations (|equations| × n_modes; each one of `dofs`).
  const Eigen::VectorXd& natural_frequencies() const {
    require_ok();
    return omega_;
  }
  const Eigen::VectorXd& modal_damping() const {
    require_ok();
    return modal_damping_;
  }
  Eigen::MatrixXd shapes(std::span<const int> equations) const;
  /// The static residual flexibility (m/N) of the modes not computed, rows × cols (zero when
  /// the synthesis has none).
  Eigen::MatrixXd residual_flexibility(std::span<const int> rows, std::span<const int> cols) const;

private:
  ModalSynthesis() = default; // for block_diagonal and failed
  int position(int equation) const;
  /// Throws std::logic_error with the status' reason when it is not ok (a caller that did not
  /// check status()).
  void require_ok() const;
  fem::Status status_;
  std::vector<int> dofs_;
  Eigen::MatrixXd phi_; ///< |dofs| × n_modes
  Eigen::VectorXd omega_;
  Eigen::VectorXd modal_damping_; ///< 2 ζ_r ω_r, 1/s (finite for rigid modes under αM damping)
  Eigen::MatrixXd residual_;      ///< |dofs| × |dofs|
  bool has_residual_ = false;
  /// Measured FRFs serving some of dofs_: local[i] is the equation of the FRFs for dofs_[i], or
  /// -1 when dofs_[i] is not theirs (H between them and it is 0).
  struct MeasuredBlock {
    std::shared_ptr<const MeasuredReceptance> frf;
    std::vector<int> local;
  };
  std::vector<MeasuredBlock> measured_;
};

/// Direct receptance (K − ω²M + iωC)⁻¹ restricted to rows × cols, by a complex sparse LU
/// (UMFPACK). Cost: one factorisation per frequency. A singular K − ω²M + iωC (an undamped
/// natural frequency, a DOF with neither stiffness nor mass) is numerical_issue, with no value.
fem::Outcome<CMatrix> direct_receptance(const fem::Assembled& system, const fem::SparseMatrix& C,
                                        double omega, std::span<const int> rows,
                                        std::span<const int> cols);

} // namespace jointid::frf
