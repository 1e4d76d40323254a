#pragma once
/// A linear substructure given by measured FRFs at a few DOFs (from a modal test: an impact
/// hammer or a shaker at the drive points and at the joints' DOFs) instead of a finite element
/// model: the receptance H(ω) is read from the measurement at the frequencies the analyses need.
/// SI units: m/N (rad/(N m), m/(N m), rad/N for rotations and moments); frequencies in Hz.
///
/// **Which entries.** H_ij (response i, drive j) is the measured function from j to i, or, by
/// Maxwell–Betti reciprocity (a linear, passive substructure: H = Hᵀ), the one from i to j.
/// Where both were measured, the function with response i and drive j is used. An analysis that
/// needs an entry neither measured gets std::invalid_argument naming both directions.
///
/// **Between lines.** Each function is known at its lines f_0 < f_1 < … (spacing need not be
/// even). At a line (to 1e-9 of the spacing) the value is the measurement; between lines it is
/// interpolated, real and imaginary parts alike, by the cubic through the two lines either side
/// (the quadratic or linear one when the function has 3 or 2 lines; the cubic is shifted
/// inwards in the first and last interval). The error of a cubic falls with the fourth power of
/// the spacing: around a resonance of half-power bandwidth 2ζf_r, lines ζf_r/4 apart give about
/// 1.8e-3 of the peak, ζf_r/8 1.3e-4 (measured in tests/frf/measured_frf_test.cpp; the bound is
/// (9/16)(h/ζf_r)⁴ for spacing h). interpolation_error() estimates it from the data.
///
/// **Outside the band.** A frequency above the last line, or between 0 and the first line, is
/// refused (std::invalid_argument naming the function, the frequency and the band: measure a
/// wider band or ask fewer harmonics). ω = 0 (harmonic 0: a static load or the mean of an even
/// joint force) takes the value at the first line when the band does not start at 0 Hz: the
/// quasi-static flexibility, good when the first line lies well below the first resonance.
#include "fem/dof.hpp"

#include <Eigen/Core>
#include <complex>
#include <span>
#include <string>
#include <vector>

namespace jointid::frf {

/// One measured FRF: receptance from a force (moment) at `drive` to the response at `response`.
struct MeasuredFunction {
  fem::NodeDof response;
  fem::NodeDof drive;
  std::vector<double> frequencies_hz;           ///< strictly increasing, finite, >= 0
  std::vector<std::complex<double>> receptance; ///< one per line, SI (converted when read)
  std::string source;                           ///< where it was read, for messages
};

struct MeasuredFrf {
  /// The substructure's DOFs (equation e is dofs[e], fem::DofMap::from_dofs): every response and
  /// drive of the functions, and any other DOF a joint or test uses.
  std::vector<fem::NodeDof> dofs;
  std::vector<MeasuredFunction> functions;

  /// Throws std::invalid_argument naming the function (its source) and what is wrong: no DOFs or
  /// no functions, a DOF listed twice or with a node id <= 0, a response or drive not among
  /// `dofs`, fewer than 2 lines, sizes that differ, a frequency that is negative, not finite or
  /// not above the previous one, a value that is not finite, the same response and drive twice.
  void validate() const;
};

/// Interpolation of the measured functions (see the file comment). Equations are numbered as
/// frf.dofs.
class MeasuredReceptance {
public:
  /// Validates `frf` (std::invalid_argument).
  explicit MeasuredReceptance(MeasuredFrf frf);

  /// H(ω) restricted to rows × cols (equation numbers). Throws std::invalid_argument for an
  /// equation out of range, an entry not measured in either direction, a frequency outside a
  /// function's band.
  Eigen::MatrixXcd receptance(double omega, std::span<const int> rows,
                              std::span<const int> cols) const;

  /// An estimate of the interpolation error of the functions among `equations` (both ends
  /// among them), relative to each function's peak |H|: each line is predicted by the cubic
  /// through the two lines either side of it (without it), and the largest difference scaled
  /// by 9/64, the ratio of the cubic's error terms mid-interval ((9/16) h⁴ H⁗/24) and at the
  /// left-out line (4 h⁴ H⁗/24). Within a factor 2 of the true error around a resonance
  /// (tests/frf/measured_frf_test.cpp). `where` (if not null) receives the function and the
  /// frequency of the largest. 0 for functions of fewer than 5 lines.
  double interpolation_error(std::span<const int> equations, std::string* where = nullptr) const;

  /// The highest frequency (Hz) at which every function among `equations` (both ends among
  /// them) is measured: the lowest of their last lines (infinity if none is among them).
  double band_top_hz(std::span<const int> equations) const;

  const MeasuredFrf& data() const { return frf_; }

private:
  /// The function serving entry (row, col): measured so, else the reciprocal one; -1 if none.
  int function_for(int row, int col) const;
  std::complex<double> value(const MeasuredFunction& f, double freq_hz) const;

  MeasuredFrf frf_;
  std::vector<int> index_; ///< n × n: function of (response i, drive j), or -1
};

} // namespace jointid::frf
