#pragma once
/// The discovery report's response figures (their contents: report/chart.hpp draws them), apart
/// from the report so that what they show can be tested without drawing.
///
/// Stepped-sine sweeps — many frequencies at each force level, as a shaker test steps through a
/// resonance — are drawn as FRFs over frequency: per channel the magnitude |X/F| and the phase
/// of X/F in the quantity the channel measured (receptance for x@, mobility for v@, accelerance
/// for a@), one colour per force level from a sequential map (low levels dark, high light), the
/// measured tests as dots and the model's response as lines, before and after each step. Tests
/// at a few frequencies (sine records) keep the receptance |X₁/F₁| over frequency, or over the
/// force level when they have more levels than frequencies.
#include "discover/discover.hpp"
#include "report/chart.hpp"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace jointid::report {

/// True when the tests are stepped-sine sweeps: at their force levels (within 3 %) a median of
/// 8 or more frequencies each.
bool stepped_sine_sweeps(const std::vector<discover::Comparison>& tests);

/// The figure of step `step` (1 …): each channel's response before the step (left) and after
/// it (right); `step` 0: the starting model alone (a run that added nothing). At most four
/// channels.
Figure discovery_response_figure(const discover::Result& result, std::size_t step);

/// What the tests show of a joint against the amplitude of its deformation (discover::
/// JointBehaviour): left, the dissipation per cycle on log axes — each test's as dots, the
/// starting and the final model's as lines (slope 2: viscous, 1: Coulomb sliding, 3 + chi:
/// microslip); right, the equivalent stiffness over the amplitude (a clearance rises from an
/// amplitude on). Dots with D ≤ 0 (noise about none) are left off the log axis. Empty (no charts)
/// when the behaviour has no points.
Figure joint_behaviour_figure(const discover::JointBehaviour& behaviour);

/// The model of a discovery state in words: "'tip': k + c + k3; substructure damping ×1.2".
std::string model_text(const discover::State& s);

/// The colour of level i of n (ascending) on a sequential map (viridis, from its dark violet to
/// its yellow-green, without the last yellow that is hard to see on white).
std::array<int, 3> level_color(std::size_t i, std::size_t n);

} // namespace jointid::report
