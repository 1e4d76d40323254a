#pragma once
/// Periodic records: the steadiness of their periods, and the reduction of a periodic broadband
/// test (e.g. a multisine) to its lines.
///
/// **Steady periods.** A record cut into P periods of N samples is steady when each period
/// equals the next up to the noise. The noise is measured where the periodic signal cannot be:
/// the record's spectrum (rectangular window, P N samples) holds every periodic component on
/// the bins k P; the other bins hold only what is not periodic — noise and transients. Their
/// median in 32 bands (a transient fills a few bins near its frequency, the median ignores it),
/// scaled to a mean (÷ ln 2, the median of a χ² of two degrees of freedom), gives the noise
/// variance of a sample σ² whatever the noise's colour. Two periods of steady noise differ by
/// D = ‖x_{p+1} − x_p‖² ≈ 2 N σ² (1 ± √(2/N)); a period is a transient when D exceeds
/// 2 N σ² (1 + 8 √(2/N)) and changes the period by more than the steady tolerance (relative
/// RMS) in some channel. Leading transient periods are dropped; later unsteady periods are
/// named in a warning and kept.
///
/// **Lines.** Each kept period's FFT; their mean is the test's spectrum at the lines k/T, the
/// scatter of the periods about it the noise of each line (E|δX_k|² = the periods' variance / P).
/// Displacement from velocity or acceleration is derived line by line (X_k = Q_k / (ikω)^p)
/// over the lines where the channel stands out of its noise (three standard deviations; with
/// unknown noise, above 1e-4 of its largest line): the derivation would otherwise multiply the
/// noise of the lowest lines by 1/(kω)^p.
#include "identify/measurement.hpp"
#include "identify/record.hpp"
#include "identify/record_kind.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace jointid::identify {

/// The steady periods of a record of `periods` whole periods of `samples` samples each.
struct SteadyPeriods {
  int periods = 0;           ///< whole periods in the record
  int first = 0;             ///< the first steady period (0-based): those before it are dropped
  std::vector<int> unsteady; ///< later periods p (0-based) that differ from p + 1 beyond the
                             ///< noise: kept, named in a warning
  std::string channel;       ///< the channel that changed most, relative to its allowance
  double change = 0.0;       ///< its largest relative change (RMS) from one period to the next
  /// Per channel (in the order given): the noise variance of a sample, off the period's lines.
  std::vector<double> noise_variance;
};

/// `channels`: every channel of the record (its first periods × samples are used). `tolerance`:
/// a relative change (RMS) between periods that is always allowed (MeasureOptions::
/// steady_tolerance), so that a noise-free record is not held to rounding.
SteadyPeriods steady_periods(const std::vector<const Channel*>& channels, int samples, int periods,
                             double tolerance);

/// The per-sample noise variance of x (its first `periods` × N samples, N = x.size() /
/// periods), from its spectrum off the lines k·periods (see above). NaN when periods < 2 or
/// there are too few samples off the lines.
double off_line_noise_variance(const Eigen::Ref<const Eigen::VectorXd>& x, int periods);

/// "periods 1 to 3 of 9", "period 1 of 9".
std::string period_span(int from, int to, int of);

/// What the steady periods mean for a record (its source): the transient periods are dropped
/// (Measurement::dropped_periods, a warning naming them), the record is left out
/// (Measurement::left_out, returns false) when fewer than two steady periods are left or more
/// than half of the pairs kept still differ (a response that does not repeat); later unsteady
/// periods are named in a warning.
bool judge_periods(const SteadyPeriods& steady, const std::string& source, double tolerance,
                   Measurement& m);

/// A periodic test reduced to its lines (Measurement::kind periodic; frequency_hz = 1/T, the
/// lines are its harmonics). Throws std::invalid_argument naming the record: no response
/// channel, no excited line in the band.
Measurement measure_periodic(const Record& record, const RecordClass& kind,
                             const MeasureOptions& options);

/// The warnings for channels that look clipped (more than 1 % of samples at their extremes).
std::vector<std::string> clipping_warnings(const Record& record);

} // namespace jointid::identify
