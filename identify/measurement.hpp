#pragma once
/// Tests as measured, and their reduction to harmonics (nothing here depends on the joints).
///
/// A test is either a time record (Record: DESIGN.md's measurement CSV) or one row of a
/// stepped-sine table (Phasors: the complex fundamental of every channel, x(t) = Re(X e^{iωt}),
/// peak, SI). A record is a sine test, a periodic broadband test or a sweep
/// (identify/record_kind.hpp): a periodic test is reduced to its lines, the harmonics of its
/// period (identify/periodic.hpp); a sweep to stepped-sine rows, one per window
/// (identify/sweep.hpp). measure() turns a sine test into a Measurement:
///  - the excitation frequency;
///  - harmonics 0 … K of every force channel and of the *displacement* at every response DOF,
///    whichever quantity was measured there (X = V/(ikω) from velocity, X = −A/(kω)² from
///    acceleration; the mean of a displacement derived that way is unknown and set to 0);
///  - the noise variance of those harmonics, estimated from the record itself (the scatter of
///    its periods about their synchronous average, or else the residual of a many-harmonic fit);
///  - one period of displacement and velocity at every response DOF, on which the joints' basis
///    functions are evaluated: the synchronous average of the record's periods (it divides the
///    noise variance by the number of periods before the non-linear basis functions see it), or
///    for a table the sinusoid of the fundamental.
#include "fem/dof.hpp"
#include "identify/record.hpp"
#include "identify/record_kind.hpp"

#include <Eigen/Core>
#include <complex>
#include <limits>
#include <string>
#include <variant>
#include <vector>

namespace jointid::identify {

/// One channel of a stepped-sine row: its complex amplitude at the excitation frequency.
struct PhasorChannel {
  Quantity quantity = Quantity::displacement;
  fem::NodeDof at;
  std::complex<double> value; ///< peak, SI, x(t) = Re(value · e^{iωt})
  std::string name() const;   ///< "x@7:uy"
};

/// One sine test of a stepped-sine table: the fundamental of every channel.
struct Phasors {
  std::string source; ///< "table.csv:12" (file and line), for messages
  double frequency_hz = 0.0;
  std::vector<PhasorChannel> channels;
};

/// A sine test as measured: a time record or a stepped-sine row.
using SineTest = std::variant<Record, Phasors>;
const std::string& source_of(const SineTest& test);

struct MeasureOptions {
  int harmonics = 3; ///< K: harmonics 0 … K are extracted from records (tables give 1)
  /// Warn when the fundamental of the first and last half of a record differ by more than
  /// this (relative), beyond what the record's noise explains.
  double steady_tolerance = 1e-3;
  /// Average a record's periods before the basis functions see it (where a period holds a whole
  /// number of samples): the noise variance the non-linear basis functions turn into bias is
  /// divided by the number of periods.
  bool average_periods = true;
  /// A record's periods (where they hold a whole number of samples) are steady when they differ
  /// by no more than their noise allows, or by this fraction (RMS) of the period: the floor for
  /// noise-free (simulated) records, whose transient must have died away far below the accuracy
  /// asked of them (identify/periodic.hpp).
  double period_tolerance = 1e-6;
  /// Periodic tests: the excited lines used lie in this band (Hz); the lines where only the
  /// response stands out of its noise (the joints' harmonics and combinations) lie above its
  /// lower end and up to `harmonics` times the highest excited line. Default: every line.
  double band_from_hz = 0.0;
  double band_to_hz = std::numeric_limits<double>::infinity();
  /// Sweeps: windows of at most this many periods of the instantaneous frequency (fewer where
  /// the sweep is fast: see identify/sweep.hpp).
  int sweep_window_periods = 10;
};

struct Measurement {
  std::string source;
  /// sine: a sine test (a record or a stepped-sine row); periodic: a periodic broadband test,
  /// whose harmonics k of frequency_hz = 1/T are its lines; sweep: a stepped-sine row reduced
  /// from a window of a sweep.
  RecordKind kind = RecordKind::sine;
  /// Not empty: why the test is left out (a record with fewer than two steady periods); the
  /// other fields are then not set, and fit() and discover() pass over it with this warning.
  std::string left_out;
  double frequency_hz = 0.0;
  int harmonics = 0; ///< K: rows 0 … K of F, X and X_variance
  /// From a stepped-sine table: only harmonic 1 was measured (rows 0 and 2 … K are 0).
  bool fundamental_only = false;

  std::vector<fem::NodeDof> force_at;
  Eigen::MatrixXcd F; ///< (K+1) × forces, N or N·m
  /// E|δF|² of every entry of F from the record's noise (N²); NaN where unknown (tables).
  Eigen::MatrixXd F_variance;

  std::vector<fem::NodeDof> response_at; ///< every DOF with a x, v or a channel, in file order
  std::vector<Quantity> measured_as;     ///< per response DOF: x if measured, else v, else a
  Eigen::MatrixXcd X;                    ///< (K+1) × responses: displacement, m or rad
  /// E|δX|² of every entry of X from the record's noise (m²); NaN where unknown (tables).
  Eigen::MatrixXd X_variance;
  /// Per response DOF: false when its mean displacement is unknown (derived from v or a).
  std::vector<bool> has_mean;

  /// Uniform samples over whole periods starting at t[0] (one period when the record's periods
  /// were averaged): displacement and velocity at every response DOF, for the basis functions.
  Eigen::VectorXd t;
  Eigen::MatrixXd x, v;
  int periods_averaged = 1;
  /// A raw sample's noise variance divided by this is that of an analysed sample (t, x, v): the
  /// periods averaged, or for a sweep's row the record's samples behind each synthesised one.
  double averaging = 1.0;
  /// Per response DOF: noise standard deviation of its measured channel's samples (its own
  /// unit), NaN where unknown.
  std::vector<double> channel_noise;
  /// Per response DOF: that of a separately measured velocity channel used for `v`; NaN where
  /// `v` is derived from the response's own channel (or unknown).
  std::vector<double> velocity_noise;
  /// Per force channel: the noise standard deviation of its samples (N or N·m), NaN if unknown.
  std::vector<double> force_noise;
  /// Harmonics 1 … this of a channel make the signals derived from it (x from v or a, v from x
  /// or a): derived(t) = Σ_k Re((ikω)^p Q_k e^{ikωt}).
  int derived_harmonics = 0;

  /// Periodic test: the lines (harmonics of frequency_hz) whose equations are used — every
  /// excited line in the band, and every other line up to MeasureOptions::harmonics times the
  /// highest excited one where a response stands out of its noise (five standard deviations)
  /// — ascending; and of them the excited ones. Empty for sine tests.
  std::vector<int> lines, excited_lines;
  /// Periodic test: every period averaged, as measured — F and X at `lines` (rows in the order
  /// of `lines`), x and v samples as `x`, `v` — whose scatter is the noise of each line.
  struct Period {
    Eigen::MatrixXcd F, X;
    Eigen::MatrixXd x, v;
  };
  std::vector<Period> periods;
  /// Periods of the record dropped as a transient (1-based, for messages); empty: none.
  std::vector<int> dropped_periods;
  /// Sweep row: the sweep rate at the window (Hz/s), and the relative error of its response
  /// harmonics the sweep rate makes (the quasi-steady bias, estimated from the measured FRF's
  /// curvature: identify/sweep.hpp).
  double sweep_rate_hz_per_s = 0.0;
  double sweep_bias = 0.0;

  std::vector<std::string> warnings;

  int response_index(const fem::NodeDof& at) const; ///< -1 when not measured
  int force_index(const fem::NodeDof& at) const;    ///< -1 when there is no force there
  bool has_harmonic(int k) const { return fundamental_only ? k == 1 : k >= 0 && k <= harmonics; }
};

/// Reduces one test: a sine test or a periodic test (a sweep gives many rows: the vector
/// overload). Throws std::invalid_argument naming the test's source: no force channel, no
/// response channel, shorter than a period, harmonic K above the record's Nyquist frequency, a
/// record that is no sine test, periodic test nor sweep (record_kind.hpp), a sweep. Warnings
/// (not steady, transient periods dropped, clipped, only one period, derived velocity) go to
/// Measurement::warnings. A sine record whose periods hold a whole number of samples, and every
/// periodic record, has its periods checked: a transient at its start (leading periods that
/// differ from the next beyond the noise and the steady tolerance) is dropped, and a record
/// with fewer than two steady periods left is left out (Measurement::left_out).
Measurement measure(const SineTest& test, const MeasureOptions& options = {});
/// Every test reduced; a sweep record becomes its stepped-sine rows, in order.
std::vector<Measurement> measure(const std::vector<SineTest>& tests,
                                 const MeasureOptions& options = {});
/// The response DOFs of a record, in order of first appearance, appended to m.response_at with
/// m.measured_as: each DOF's best channel (x, then v, then a), returned in that order.
std::vector<const Channel*> best_response_channels(const Record& r, Measurement& m);

/// The tests not left out, and the left-out ones' reasons appended to `notes`.
std::vector<Measurement> usable(const std::vector<Measurement>& measurements,
                                std::vector<std::string>& notes);

/// The force amplitude of a measurement: the largest |F_1| of its force channels (N or N·m).
double force_level(const Measurement& m);

} // namespace jointid::identify
