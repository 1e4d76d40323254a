#pragma once
/// A sine sweep reduced to stepped-sine rows: one Measurement (kind sweep) per window, with its
/// harmonics and their noise, as a sine test at the window's frequency.
///
/// 1. **Phase.** The force's instantaneous phase φ(t): the argument of its analytic signal
///    (Hilbert transform by FFT), unwrapped.
/// 2. **Windows.** Consecutive, not overlapping: each holds at most
///    MeasureOptions::sweep_window_periods periods of its frequency, at most √(1.2/|ω̇|) seconds
///    (so that averaging a response that changes with frequency over the window stays below a
///    tenth of the sweep rate's own bias, see 4), and at least two periods. Windows where the
///    force is below a tenth of its median amplitude (a fade-in, a pause) are passed over.
/// 3. **Harmonics.** In each window the phase is fitted by φ ≈ a + ω_c τ + ½ ω̇ τ² about its
///    centre — ω_c/2π is the row's frequency, ω̇ the sweep rate there — and every channel by
///    least squares to harmonics of that phase, x ≈ X_0 + Σ Re(X_k e^{ikφ}): locked to the
///    force, a fit that a frequency changing within the window does not blur. The noise of each
///    channel is the residual of a fit with more harmonics; displacement from velocity or
///    acceleration is derived harmonic by harmonic, as for sine records.
/// 4. **The sweep rate's bias.** A linear system driven by e^{iφ(t)} with a slowly changing
///    frequency responds, to first order in ω̇, with
///        X = [H(ω) − (i/2) ω̇ H''(ω)] F
///    (expand φ(t − τ) to second order in the convolution): the quasi-steady response H(ω) F is
///    off by ½ |ω̇| |H''/H| relative — large where the response changes fast with frequency,
///    at a lightly damped resonance. Each row states this bias (Measurement::sweep_bias) with
///    H = X_1/F_1 of the largest response channel, its second derivative by a least-squares
///    parabola through the neighbouring rows; the window's averaging adds (ω̇ L)²/24 |H''/H|.
///    The rows are not corrected (a second derivative of noisy data would add its noise): sweep
///    slower where the bias matters. One warning per sweep gives its largest value.
#include "identify/measurement.hpp"
#include "identify/record.hpp"
#include "identify/record_kind.hpp"

#include <vector>

namespace jointid::identify {

/// The stepped-sine rows of a sweep record, by frequency as swept. Each row's source is
/// "<record> at <f> Hz". Throws std::invalid_argument naming the record: no force or response
/// channel, too short for a window of two periods, no window below the Nyquist frequency for
/// MeasureOptions::harmonics.
std::vector<Measurement> reduce_sweep(const Record& record, const RecordClass& kind,
                                      const MeasureOptions& options);

} // namespace jointid::identify
