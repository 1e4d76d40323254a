#pragma once
/// The FRFs of a low-level test from one driving point to several responses, as receptance:
/// estimated by H1 from time records (random, periodic multisine, sweep or impact), or taken
/// from measured FRF files. The input of a modal fit (identify/modal_fit.hpp).
///
/// SI units: receptance in m/N (rad/N, m/(N m), rad/(N m)), frequencies in Hz, with the
/// convention x(t) = Re(X e^{iωt}), X = H F. A response measured as velocity or acceleration is
/// converted to receptance line by line before anything is fitted: X = V/(iω), X = A/(iω)² =
/// −A/ω² (its cross and auto spectra with it, so H1 and the coherence are the receptance's).
#include "fem/dof.hpp"
#include "frf/measured_frf.hpp"
#include "identify/record.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace jointid::identify {

/// How the spectra of time records are estimated.
enum class SpectraMethod {
  automatic, ///< `periods` for a record that states its period (`# period_s`), else `welch`
  welch,     ///< Hann-windowed segments, 50 % overlap (identify/spectra.hpp): random excitation
  periods,   ///< each whole period, rectangular window (no leakage): periodic excitation
  whole,     ///< each record as one block, rectangular window: impacts, or sweeps from rest to rest
  measured   ///< not estimated: FRF files (frfs_from_measured)
};
const char* spectra_method_name(SpectraMethod method); ///< "welch", "periods", …

struct FrfEstimateOptions {
  double f0_hz = 0.0, f1_hz = 0.0; ///< the band kept, 0 <= f0 < f1 (Hz); lines at 0 Hz never
  SpectraMethod method = SpectraMethod::automatic;
  /// Welch: samples per segment; 0: the largest power of two giving at least 8 averages in the
  /// shortest record (the resolution is fs / segment).
  int segment = 0;
  /// periods: the period (s) of every record; 0: each record's own Record::period_s.
  double period_s = 0.0;
};

/// FRFs H(f) from the driving point to every response, on common lines.
struct MeasuredFrfs {
  fem::NodeDof drive;     ///< the driving point (the force's DOF)
  std::string drive_name; ///< the force channel "f@7:uy", or "7:uy" from FRF files
  std::vector<fem::NodeDof> responses;
  std::vector<std::string> response_names; ///< the channel used, "a@3:uy", or "3:uy" (files)
  std::vector<Quantity> measured_as;       ///< per response: x, v or a (x for FRF files)
  Eigen::VectorXd frequency_hz;            ///< the lines used, increasing, > 0
  Eigen::MatrixXcd H;                      ///< lines × responses: receptance
  /// lines × responses: the ordinary coherence γ² of the H1 estimate; NaN where it is not
  /// estimated (FRF files, or a single block: one block always gives γ² = 1).
  Eigen::MatrixXd coherence;
  SpectraMethod method = SpectraMethod::measured; ///< as used (never `automatic`)
  std::vector<int> blocks;     ///< per response: blocks averaged (segments, periods or records)
  double resolution_hz = 0.0;  ///< spacing of the lines before any were left out
  double sample_rate_hz = 0.0; ///< 0 for FRF files
  int block_samples = 0;       ///< samples per block (segment, period, record); 0 for files
  std::vector<std::string> sources;
  std::vector<std::string> notes; ///< what the user should know (lines left out, channels ignored)

  int num_responses() const { return static_cast<int>(responses.size()); }
  int num_lines() const { return static_cast<int>(frequency_hz.size()); }
  /// The column of the driving point among the responses, or -1 when it was not measured.
  int drive_column() const;
};

/// H1 = Σ G_fx / Σ G_ff over every block of every record, and γ² = |Σ G_fx|² / (Σ G_ff Σ G_xx),
/// on the lines inside [f0, f1] where the force has power (G_ff at least 1e-4 of its largest
/// value in the band; the others are left out with a note). Each record holds exactly one force
/// channel, the same DOF in every record, and any x, v or a channels (one per DOF: x before v
/// before a, the others noted as ignored); a response may be in some records only (a roving
/// sensor). Blocks: `welch` segments, `periods` the whole periods at the end of the record
/// (the first samples, where a transient would be, are the ones left over), `whole` the record
/// zero-padded to the longest. A period that does not hold a whole number of samples (to 1e-6)
/// falls back to Welch with a note. Throws std::invalid_argument naming the record for: no
/// records, no force channel or several, forces at different DOFs in different records, no
/// response channel, sample rates that differ, a band reaching above the Nyquist frequency,
/// `periods` without a period or a record shorter than one period or one segment.
MeasuredFrfs frfs_from_records(const std::vector<Record>& records,
                               const FrfEstimateOptions& options);

/// The measured FRFs (frf::MeasuredFrf, receptance as read: io/measured_frf_file.hpp) on their
/// lines inside [f0, f1]. Throws std::invalid_argument naming the function's source for: FRFs
/// from several drives (one reference only), functions on different lines, a band outside the
/// lines measured.
MeasuredFrfs frfs_from_measured(const frf::MeasuredFrf& frf, double f0_hz, double f1_hz);

} // namespace jointid::identify
