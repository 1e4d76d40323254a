#pragma once
/// A measurement record: uniformly sampled time signals of one test (DESIGN.md's CSV contract).
/// Channels are named <quantity>@<node>:<dof>: f force (N, N·m), x displacement (m, rad),
/// v velocity, a acceleration (SI).
#include "fem/dof.hpp"

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace jointid::identify {

enum class Quantity { force, displacement, velocity, acceleration };
char quantity_letter(Quantity q);

struct Channel {
  Quantity quantity = Quantity::force;
  fem::NodeDof at;
  Eigen::VectorXd samples;
  std::string name() const; ///< "x@7:uy"
};
/// Parses "x@7:uy"; throws std::invalid_argument saying what was expected.
Channel parse_channel_name(const std::string& name);

struct Record {
  std::string source; ///< file name, for messages
  Eigen::VectorXd t;  ///< s, uniform
  std::vector<Channel> channels;
  std::optional<double> excitation_hz; ///< Hz: a sine test (`# excitation_hz = F`)
  /// s: a periodic broadband test, e.g. a multisine (`# period_s = T`)
  std::optional<double> period_s;
  /// The channel of this quantity at this DOF, or nullptr.
  const Channel* find(Quantity q, const fem::NodeDof& at) const;
  std::vector<const Channel*> all(Quantity q) const;
  double dt() const { return t.size() > 1 ? (t(t.size() - 1) - t(0)) / (t.size() - 1) : 0.0; }
};

} // namespace jointid::identify
