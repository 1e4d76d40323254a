#pragma once
/// Harmonic extraction from time records (paper eq. 17, generalised): a least-squares fit of
///     x(t) ≈ X_0 + Σ_{k=1..K} (A_k cos kωt + B_k sin kωt),   X_k = A_k − i B_k,
/// so that x(t) = Re(Σ X_k e^{ikωt}) (peak amplitudes). On a whole number of periods with
/// uniform sampling this equals the DFT (eq. 17); on any other span the fit stays unbiased for
/// signals made of these harmonics.
#include <Eigen/Core>
#include <complex>

namespace jointid::identify {

/// Returns X_0 … X_K (K+1 values; X_0 real). Throws if there are fewer samples than unknowns.
Eigen::VectorXcd fit_harmonics(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double omega,
                               int K);
/// Same fit for several signals sharing t: one column per signal, (K+1) × n_signals.
Eigen::MatrixXcd fit_harmonics(const Eigen::VectorXd& t, const Eigen::MatrixXd& x, double omega,
                               int K);

/// Frequency (Hz) of the dominant sinusoid in x, in O(N log N): the peak of the Hann-windowed
/// spectrum (FFT), interpolated between its bins, then refined by minimising the residual of a
/// least-squares mean + sine fit within one bin of it. Throws if the record is shorter than 4
/// samples.
double estimate_frequency(const Eigen::VectorXd& t, const Eigen::VectorXd& x);

/// Harmonics 0 … K of signals sampled uniformly over exactly one period (rows: the N samples of
/// the period, the first at time t0; columns: signals), by FFT: the same X_k as fit_harmonics
/// (on one whole period the least-squares fit is the DFT), in O(N log N). Throws unless
/// 0 <= K < N/2.
Eigen::MatrixXcd period_harmonics(const Eigen::MatrixXd& x, double t0, double omega, int K);

/// A periodic signal from its harmonics X_0 … X_K at the times t: Re(Σ X_k e^{ikωt}).
Eigen::VectorXd synthesise(const Eigen::VectorXd& t, const Eigen::VectorXcd& X, double omega);

/// Harmonics of the derivative (power > 0) or of the integral (power < 0) of a periodic signal:
/// harmonic k multiplied by (ikω)^power; the mean of an integral is unknown and set to 0.
Eigen::VectorXcd differentiate(const Eigen::VectorXcd& X, double omega, int power);

/// Number of leading samples spanning the largest whole number of periods (at least one
/// period), or 0 if the record is shorter than one period.
int whole_period_samples(const Eigen::VectorXd& t, double frequency_hz);

} // namespace jointid::identify
