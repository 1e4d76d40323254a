#include "fem/zero_modes.hpp"

namespace jointid::fem {

std::string ZeroModes::describe() const {
  if (count == 0) return {};
  const std::string n = std::to_string(count);
  if (!mechanism)
    return "free structure: " + n + " rigid-body mode" + (count > 1 ? "s" : "") + " at 0 Hz";
  // Ranked by kinetic energy (radians and metres do not compare): not always the DOF that
  // moves farthest, so say what it is.
  const std::string where = " (most of its kinetic energy at " + to_string(largest_motion) + ")";
  if (supported)
    return "mechanism: " + n + " zero-frequency mode" + (count > 1 ? "s" : "") +
           " although the model is supported; it cannot carry load in " +
           (count > 1 ? "those shapes" : "that shape") + where +
           ": add supports, stiffer connections or springs";
  return "mechanism: " + n + " zero-frequency modes, more than the " +
         std::to_string(rigid_expected) + " rigid-body modes of a free structure" + where;
}

ZeroModes zero_modes(const Model& model, const Assembled& system, const Modes& modes) {
  ZeroModes z;
  z.supported = false;
  for (const auto& s : model.supports)
    for (Dof d : s.fixed)
      if (system.dofs.state({s.node, d}) == DofMap::State::fixed) z.supported = true;
  const Eigen::VectorXd kd = system.K.diagonal(), md = system.M.diagonal();
  const double scale = kd.mean() / std::max(md.mean(), 1e-300);
  for (int r = 0; r < modes.num_modes(); ++r)
    if (modes.omega(r) * modes.omega(r) < 1e-9 * scale) ++z.count;
  bool planar_beam_only = model.dimension == 2, any_element = !model.elements.empty();
  for (const auto& e : model.elements)
    if (e.type != ElementType::beam) planar_beam_only = false;
  z.rigid_expected = z.supported                         ? 0
                     : model.dimension == 3              ? 6
                     : (planar_beam_only && any_element) ? 2
                                                         : 3;
  z.mechanism = z.count > z.rigid_expected;
  if (z.mechanism) {
    // Rank DOFs by their share of the mode's kinetic energy |φ_i (Mφ)_i|: comparing |φ_i|
    // directly would weigh radians against metres.
    const Eigen::VectorXd phi = modes.phi.col(z.rigid_expected);
    const Eigen::VectorXd Mphi = system.M * phi;
    Eigen::Index worst = 0;
    phi.cwiseProduct(Mphi).cwiseAbs().maxCoeff(&worst);
    z.largest_motion = system.dofs.node_dof(static_cast<int>(worst));
  }
  return z;
}

} // namespace jointid::fem
