#pragma once
/// Zero-frequency modes: rigid-body motion of an unsupported structure, or mechanisms (a
/// supported structure that cannot carry load in some shape, e.g. a chain of hinges).
#include "fem/assembly.hpp"
#include "fem/modal.hpp"

#include <string>

namespace jointid::fem {

struct ZeroModes {
  int count = 0;          ///< modes with ω² below the threshold
  int rigid_expected = 0; ///< rigid-body modes an unsupported model of this kind has
  bool supported = false; ///< the model has at least one support
  bool mechanism = false; ///< more zero modes than rigid-body motion explains
  NodeDof largest_motion; ///< of the first surplus zero mode, to point at the mechanism
  /// A sentence for users; empty when there are no zero modes.
  std::string describe() const;
};

/// Counts modes with ω_r² < 1e-9 · (mean diag K / mean diag M) among `modes` (which should
/// include the lowest modes), and classifies them. Rigid-body motion of an unsupported model:
/// 6 in 3D, 3 for planar frames, 2 for planar beams (uy, rz only).
ZeroModes zero_modes(const Model& model, const Assembled& system, const Modes& modes);

} // namespace jointid::fem
