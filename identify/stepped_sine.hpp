#pragma once
/// Stepped-sine tables: many sine tests reduced to the complex amplitudes of their fundamentals
/// (peak, SI, x(t) = Re(X e^{iωt})), one test a row. io/record_csv.hpp reads and writes them.
#include "identify/record.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace jointid::identify {

struct SteppedSineTable {
  std::vector<double> freq_hz;       ///< one per test, Hz
  std::vector<std::string> channels; ///< "x@7:uy", ...
  Eigen::MatrixXcd values;           ///< tests × channels, complex peak amplitudes (SI)
  std::vector<int> lines;            ///< line of each test in its file (0: not from a file)
};

/// The fundamentals of sine-test records as a stepped-sine table: each channel's complex
/// amplitude at its record's excitation frequency (a least-squares fit over the record's whole
/// periods), one row per record; the frequency is the record's excitation_hz, else estimated
/// from its force (or first) channel. The records must have the same channels in the same
/// order; throws std::invalid_argument naming the first that differs, one shorter than a
/// period, one whose frequency is not below the Nyquist frequency of its sampling, or one whose
/// whole periods hold fewer than 3 samples.
SteppedSineTable stepped_sine_table(const std::vector<Record>& records);

} // namespace jointid::identify
