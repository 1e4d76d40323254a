#pragma once
/// The picture of `jointid response`: response curves (frf::response_curves).
#include "fem/dof.hpp"
#include "frf/continuation.hpp"
#include "report/chart.hpp"

namespace jointid::report {

/// Amplitude of the fundamental |X_1| at `shown` (one of curves.dofs) over frequency, one
/// colour per force amplitude: stable stretches solid, unstable dashed, stability not
/// determined dotted (points), folds marked with black dots.
Figure response_figure(const frf::ResponseCurves& curves, const fem::NodeDof& shown);

/// Whether response_figure can show `dof` on the curves of these joints under a force at
/// `force_at`: the curves hold the joints' DOFs and the force DOF (frf::ResponseCurves::dofs).
bool response_figure_can_show(const std::vector<joints::Joint>& joints,
                              const fem::NodeDof& force_at, const fem::NodeDof& dof);

} // namespace jointid::report
