#pragma once
/// The pictures of `jointid identify`: the time records with their harmonic fits (--fit-png,
/// what the identification sees of each test) and the identified values against the model's
/// (--params-png).
#include "fem/dof.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "report/chart.hpp"

#include <vector>

namespace jointid::report {

/// One chart per test (in order; grid of up to 3 columns): at each of `shown` measured as a
/// displacement channel, the samples of the record's averaged period (points) and the harmonic
/// fit Re Σ_{k=0…K} X_k e^{ikωt} that the identification uses (line; without the mean when it is
/// unknown), over t/T from 0 to 1; the title gives the test, its frequency and the fit's RMS
/// residual relative to the signal's peak. DOFs not measured as displacements (derived from v
/// or a: their samples are the fit itself) are left out. Throws std::invalid_argument when no
/// test has a displacement channel at any of `shown`.
Figure harmonic_fit_figure(const std::vector<identify::Measurement>& tests,
                           const std::vector<fem::NodeDof>& shown);

/// The DOFs harmonic_fit_figure shows for these joints: each joint's DOF at its node and, for a
/// joint between nodes, at its second node; each once, in the joints' order.
std::vector<fem::NodeDof> harmonic_fit_dofs(const std::vector<joints::Joint>& joints);

/// Every identified term whose value the model gives (a simulation's truth, or a prior guess),
/// as identified / model value (points) with its 95 % interval (a vertical line) over the
/// terms ("joint term"), and the line at 1. Throws std::invalid_argument when no identified
/// term has a non-zero value in the model to compare with.
Figure parameter_figure(const identify::FitResult& result,
                        const std::vector<joints::Joint>& model_joints);

} // namespace jointid::report
