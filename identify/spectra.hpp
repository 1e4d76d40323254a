#pragma once
/// Power and cross spectra of uniformly sampled records by Welch's method (FFTW), and the H1
/// estimate of an FRF.
///
/// Conventions (SI): the record is cut into segments of `segment` samples overlapping by
/// `overlap` (0.5: 50 %); each segment has its mean removed and is multiplied by a periodic
/// Hann window w_n = 0.5 − 0.5 cos(2πn/N), then transformed, X_k = Σ w_n x_n e^{−2πikn/N}.
/// The one-sided cross spectrum at f_k = k·fs/N, k = 0 … N/2, is the average over segments of
///     G_xy(f_k) = c_k · conj(X_k) Y_k / (fs Σ w_n²),   c_k = 2 (1 at DC and, N even, Nyquist),
/// in (unit of x)(unit of y)/Hz; G_xx is the one-sided PSD, real, e.g. N²/Hz for a force, so
/// that ∫ G_xx df over 0 … fs/2 is the variance (Parseval) and a sine of amplitude A gives a
/// peak whose integral is A²/2. Only whole segments are used (samples after the last one are
/// not); records shorter than one segment are refused.
#include <Eigen/Core>
#include <vector>

namespace jointid::identify {

struct WelchOptions {
  int segment = 1024;   ///< samples per segment N (>= 8); the resolution is fs / N
  double overlap = 0.5; ///< fraction of a segment shared by neighbours, 0 <= overlap < 1
};

/// Every auto and cross spectrum of the columns of a record.
struct WelchSpectra {
  Eigen::VectorXd frequency_hz; ///< f_k, k = 0 … N/2
  /// G[i](k, j): column i against column j at f_k (G_ij = average of c·conj(X_i) X_j /(fs Σw²)).
  std::vector<Eigen::MatrixXcd> G;
  int averages = 0; ///< segments averaged
  double resolution_hz = 0.0;
  /// Effective bandwidth of the Hann window, 1.5 fs/N (Hz): a tone's PSD peak is its power
  /// divided by this.
  double noise_bandwidth_hz = 0.0;
  /// One-sided PSD of column i (real part of G_ii).
  Eigen::VectorXd psd(int i) const;
};

/// Throws std::invalid_argument (naming the value) for a sample rate <= 0, bad options, or a
/// record shorter than one segment.
WelchSpectra welch(const Eigen::MatrixXd& signals, double sample_rate_hz,
                   const WelchOptions& options = {});

/// One-sided PSD of one signal (its unit²/Hz), with frequencies.
struct PowerSpectrum {
  Eigen::VectorXd frequency_hz, psd;
  int averages = 0;
};
PowerSpectrum power_spectrum(const Eigen::VectorXd& x, double sample_rate_hz,
                             const WelchOptions& options = {});

/// H1 = G_fx / G_ff, the FRF from a force f to a response x (for a receptance: m/N; complex,
/// x(t) = Re(X e^{iωt}) convention, since G_fx = conj(F)X), and the ordinary coherence
/// γ² = |G_fx|² / (G_ff G_xx). H1 is unbiased by noise on the response. Its normalised random
/// error is about sqrt((1 − γ²) / (2 n γ²)) for n independent averages (Bendat & Piersol).
struct FrfEstimate {
  Eigen::VectorXd frequency_hz;
  Eigen::VectorXcd H;
  Eigen::VectorXd coherence;
  int averages = 0;
};
FrfEstimate h1_estimate(const Eigen::VectorXd& force, const Eigen::VectorXd& response,
                        double sample_rate_hz, const WelchOptions& options = {});

} // namespace jointid::identify
