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
  /// What the record's comments declare it to be (DESIGN.md's contract); unset: told from the
  /// force channel (identify/record_kind.hpp).
  std::optional<double> excitation_hz; ///< `# excitation_hz = F`: a sine test at F Hz
  std::optional<double> period_s;      ///< `# period_s = T`: a periodic broadband test
  bool sweep = false;                  ///< `# excitation = sweep`: a sine sweep
  /// The channel of this quantity at this DOF, or nullptr.
  const Channel* find(Quantity q, const fem::NodeDof& at) const;
  std::vector<const Channel*> all(Quantity q) const;
  double dt() const { return t.size() > 1 ? (t(t.size() - 1) - t(0)) / (t.size() - 1) : 0.0; }
};

} // namespace jointid::identify
