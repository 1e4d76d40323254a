#pragma once
/// Force histories for time simulation: band-limited Gaussian random, sine sweep and
/// multisine, uniformly sampled (sample i at t = i / sample_rate_hz). N or N·m, s, Hz.
#include <Eigen/Core>
#include <cstdint>

namespace jointid::fem {

/// Samples of a signal of `duration_s` at `sample_rate_hz`: round(duration · rate) samples.
struct Sampling {
  double duration_s = 0.0;     ///< s (> 0)
  double sample_rate_hz = 0.0; ///< Hz (> 0); the band must lie below half of it
};

/// Gaussian random force with a flat (one-sided) power spectrum between f0 and f1 Hz and none
/// outside: white Gaussian samples (seeded), transformed, every bin outside [f0, f1] zeroed,
/// transformed back (a linear filter of Gaussian noise: Gaussian), scaled to the given RMS
/// about a zero mean. The signal is periodic over its duration (no leakage at its ends).
struct BandLimitedRandom {
  double f0_hz = 0.0, f1_hz = 0.0; ///< band, 0 <= f0 < f1 < sample_rate / 2
  double rms = 1.0;                ///< N or N·m (> 0)
  std::uint64_t seed = 1;
};
Eigen::VectorXd band_limited_random(const BandLimitedRandom& spec, const Sampling& sampling);

/// F0 sin(φ(t)) with the instantaneous frequency going from f0 to f1 over the duration,
/// linearly (φ = 2π(f0 t + (f1 − f0) t²/2T)) or exponentially (logarithmic sweep).
struct SineSweep {
  double f0_hz = 0.0, f1_hz = 0.0; ///< > 0, below sample_rate / 2
  double amplitude = 1.0;          ///< N or N·m (peak)
  bool logarithmic = false;
};
Eigen::VectorXd sine_sweep(const SineSweep& spec, const Sampling& sampling);

/// Σ_k cos(2π k t / T + φ_k) over the lines k/T in [f0, f1] (T the period: the duration unless
/// given, so periodic over the record), equal amplitudes, Schroeder phases
/// φ_k = −π k'(k'+1)/K (k' = 0 … K−1; a low crest factor), scaled to the given RMS; a period
/// shorter than the duration is repeated.
struct Multisine {
  double f0_hz = 0.0, f1_hz = 0.0; ///< band, at least one line k/T in it
  double rms = 1.0;                ///< N or N·m
  /// s; 0: the duration. Must hold a whole number of samples and divide the duration into a
  /// whole number of periods.
  double period_s = 0.0;
};
Eigen::VectorXd multisine(const Multisine& spec, const Sampling& sampling);

} // namespace jointid::fem
