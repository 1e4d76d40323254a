#pragma once
/// One mode fitted to the receptance X/F of a stepped-sine test at one force level around a
/// resonance: the measured backbone's point of that level (`jointid backbone --tables`).
/// A single-mode rational fit with a complex residue,
///     H(ω) = X/F ≈ A / (ω_n² − ω² + i ω d),        ω_n² − ω² + i ω d ≠ 0,
/// solved as the linear least-squares equation error ω_n² H + d (iω H) − A = ω² H (real and
/// imaginary parts of each row, unknowns ω_n², d and A's two parts), whose rows weigh most near
/// the peak where |H| is largest. A non-linear mode changes its ω_n and d with the amplitude
/// across the rows, which biases such a fit; so the level's point is taken at its row nearest
/// resonance (largest |X/F|) by the single mode's inverse, ω_n² − ω² + iωd = A F / X (A the
/// fit's residue, or one given: share_residue()), at that row's |X|. The standard deviations
/// are the fit's (from its residual's variance through the normal equations, to first order):
/// the misfit of a mode that changes across the rows is in them. SI units.
#include "fem/dof.hpp"
#include "fem/status.hpp"
#include "identify/stepped_sine.hpp"

#include <Eigen/Core>
#include <complex>
#include <span>
#include <string>
#include <vector>

namespace jointid::identify {

struct OneModeFit {
  /// ok; not_separable with fewer than 3 rows (4 unknowns), numerical_issue when the fit finds
  /// no resonance (ω_n² or d not > 0); the reason says which.
  fem::Status status;
  double frequency_hz = 0.0, frequency_std_hz = 0.0;
  double damping_ratio = 0.0, damping_ratio_std = 0.0;
  /// |X| of the row nearest resonance (peak, the unit of X): the level's amplitude.
  double amplitude = 0.0;
  double force_amplitude = 0.0;   ///< mean |F| of the rows
  double relative_residual = 0.0; ///< |equation error| / |ω² H|
  std::complex<double> residue;   ///< the fitted A (1/kg)
};

/// Fits the rows (frequency f_i in Hz, response X_i, force F_i: complex amplitudes of one
/// convention). Throws std::invalid_argument when the sizes differ or a force is 0.
OneModeFit fit_one_mode(std::span<const double> freq_hz, const Eigen::VectorXcd& response,
                        const Eigen::VectorXcd& force,
                        const std::complex<double>* residue = nullptr);

/// The fit of a stepped-sine table of one force level: its force channel (the one `f@…`) and
/// the response at `dof` (`x@<dof>`, else `v@<dof>` or `a@<dof>` turned into displacement, V/iω
/// and A/(−ω²)). Throws std::invalid_argument saying what the table lacks: no force channel or
/// more than one, no channel at `dof`.
OneModeFit fit_one_mode(const SteppedSineTable& table, const fem::NodeDof& dof,
                        const std::complex<double>* residue = nullptr);

/// A point of a measured backbone: one table (one force level) and its fit.
struct MeasuredBackbonePoint {
  std::string table; ///< the table's path as given
  OneModeFit fit;
};

/// The levels' points again with one residue, that of the level of least amplitude (the most
/// nearly linear, where the single-mode fit is sound): the residue is the mode's (φ², 1/kg, at
/// a driving point), which the joints do not change, while each level's own fit takes up the
/// change of frequency and damping across its rows. `tables[i]` is levels[i]'s.
void share_residue(std::vector<MeasuredBackbonePoint>& levels,
                   const std::vector<SteppedSineTable>& tables, const fem::NodeDof& dof);

} // namespace jointid::identify
