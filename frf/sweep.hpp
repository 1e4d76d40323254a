#pragma once
/// The substructure's frequency response functions over a band, as a test engineer measures
/// them with one force: receptance (displacement per force), mobility (velocity per force) or
/// accelerance (acceleration per force). Conventions: a force f(t) = Re(F e^{iωt}) gives the
/// response x(t) = Re(H F e^{iωt}), so mobility is iω H and accelerance −ω² H, with H the
/// receptance (K − ω²M + iωC)⁻¹ by modal synthesis (frf::Substructure::synthesis). SI units:
/// m/N, (m/s)/N, (m/s²)/N; rad for rotations and N m for moments.
#include "fem/status.hpp"
#include "frf/substructure.hpp"

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

namespace jointid::frf {

enum class FrfKind { receptance, mobility, accelerance };

/// "receptance", "mobility", "accelerance".
std::string_view frf_kind_name(FrfKind kind);
/// Parses those names; throws std::invalid_argument listing them.
FrfKind parse_frf_kind(std::string_view name);

struct FrfSweep {
  /// ok, or the synthesis' status (its modal analysis failed; then no values)
  fem::Status status;
  FrfKind kind = FrfKind::receptance;
  int drive = 0;                  ///< equation of the force
  std::vector<int> responses;     ///< equations of the responses (columns of `values`)
  std::vector<double> freq_hz;    ///< rows of `values`
  Eigen::MatrixXcd values;        ///< |freq_hz| × |responses|
  std::vector<std::string> notes; ///< what the synthesis says the user should know
};

/// The FRFs from `drive` to each of `responses` (equations of sub.dofs()) at `freq_hz` (each
/// finite and >= 0). The synthesis covers the band up to the highest frequency (its modes
/// below twice that, with residual flexibility, for a model above the dense limit). Throws
/// std::invalid_argument for an equation outside the model, no response, a response listed
/// twice, no frequency or a frequency that is negative or not finite. A modal analysis that
/// fails is the sweep's status.
FrfSweep frf_sweep(const Substructure& sub, int drive, std::vector<int> responses,
                   std::vector<double> freq_hz, FrfKind kind = FrfKind::receptance);

/// `points` frequencies from f0_hz to f1_hz (Hz) evenly spaced, as a universal file's dataset 58
/// stores them (a start and a step), with both ends exact: f0 + (f1 − f0) i / (points − 1), the
/// last f1 itself. Throws std::invalid_argument for fewer than 2 points or ends not finite.
std::vector<double> evenly_spaced_hz(double f0_hz, double f1_hz, int points);

} // namespace jointid::frf
