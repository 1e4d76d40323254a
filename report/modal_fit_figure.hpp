#pragma once
/// The pictures of `jointid modal-fit`: the stabilisation diagram and the measured FRFs against
/// the fitted ones.
#include "identify/modal_fit.hpp"
#include "report/chart.hpp"

namespace jointid::report {

/// The poles of every order over frequency (new, stable in frequency, stable in frequency and
/// damping), the modes chosen as vertical lines, and behind them the mean of |H| over the
/// responses on a logarithmic scale mapped onto the order axis (its shape, not its values).
Figure stabilisation_figure(const identify::ModalFit& fit, const identify::MeasuredFrfs& data);

/// Per response: |H| (log scale) and its phase (degrees) over frequency, measured as points and
/// fitted (the modes and both residuals) as a line; the model as written (without the lower
/// residual) dashed where it differs visibly. Up to 4 responses side by side, magnitudes above
/// phases.
Figure modal_fit_figure(const identify::ModalFit& fit, const identify::MeasuredFrfs& data);

} // namespace jointid::report
