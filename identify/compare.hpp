#pragma once
/// Measured vs predicted response spectra (the paper's Figs. 7–8): the model with its joints
/// at their values is driven by a record's measured force channels (identify/random_tests.hpp),
/// and the Welch PSD (identify/spectra.hpp) of every measured response channel is compared
/// with that of the same quantity predicted at the same DOF, over a band, in dB:
///     difference(f) = 10 log10(G_predicted(f) / G_measured(f)).
/// The start of the record (`skip_s`) is left out of both spectra: the simulation starts from
/// rest, while the measured structure may already have been moving; a measured force that does
/// not start at zero is faded in over the first half of that time. The transient this leaves
/// decays with the modes' damping (time constant 1/(ζ_r ω_r)): choose skip_s accordingly.
#include "identify/random_tests.hpp"
#include "identify/spectra.hpp"

#include <string>
#include <vector>

namespace jointid::identify {

struct CompareOptions {
  double f0_hz = 0.0, f1_hz = 0.0; ///< band; both 0: from the first bin above DC to Nyquist
  int segment = 0;                 ///< Welch segment (samples); 0: the largest power of two
                                   ///< giving at least 16 averages (at least 64)
  double skip_s = -1.0;            ///< s left out at the start; < 0: 10 % of the record
  ForcedOptions simulation;        ///< route, cutoff, substeps (quantities are set here)
};

struct ChannelComparison {
  std::string channel;                 ///< "x@7:uy"
  Eigen::VectorXd frequency_hz;        ///< the bins in the band
  Eigen::VectorXd measured, predicted; ///< one-sided PSD, (unit)²/Hz
  Eigen::VectorXd difference_db;       ///< 10 log10(predicted / measured)
  double rms_db = 0.0;                 ///< RMS of difference_db over the band
  double max_db = 0.0;                 ///< largest |difference_db|
};

struct Comparison {
  /// ok, or the prediction's status (its simulation failed; then no channels are compared)
  fem::Status status;
  std::string source;
  double f0_hz = 0.0, f1_hz = 0.0;
  double sample_rate_hz = 0.0;
  int segment = 0, averages = 0;
  double resolution_hz = 0.0;
  double skip_s = 0.0;
  /// Standard deviation of a difference in dB between two independent Welch estimates of the
  /// same spectrum: 10 log10(e) sqrt(2 / averages) (each PSD estimate has a normalised random
  /// error of about 1/sqrt(averages)).
  double statistical_db = 0.0;
  std::vector<ChannelComparison> channels;
  ForcedTest prediction;
  std::vector<std::string> notes;
};

/// Throws std::invalid_argument naming the record for: no force or no response channel, a band
/// outside 0 … Nyquist or holding no bin, a segment longer than what remains after skip_s.
/// A prediction that fails (simulate_forced's status) is the comparison's status.
Comparison compare_spectra(const frf::Substructure& substructure,
                           const std::vector<joints::Joint>& joints, const Record& measured,
                           const CompareOptions& options = {});

} // namespace jointid::identify
