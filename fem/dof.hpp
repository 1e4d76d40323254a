#pragma once
/// Degrees of freedom of a node. SI units throughout jointid: m, rad, N, N·m, kg, s.
#include <array>
#include <string>
#include <string_view>

namespace jointid::fem {

/// The six nodal DOFs: translations ux uy uz (m) and rotations rx ry rz (rad).
enum class Dof { ux = 0, uy, uz, rx, ry, rz };
inline constexpr int num_dof_kinds = 6;
inline constexpr std::array<Dof, 6> all_dofs{Dof::ux, Dof::uy, Dof::uz, Dof::rx, Dof::ry, Dof::rz};

std::string_view dof_name(Dof dof);
/// Parses "ux".."rz"; throws std::invalid_argument naming the text and the accepted names.
Dof parse_dof(std::string_view text);
bool is_rotation(Dof dof);

/// A node and one of its DOFs, e.g. node 7, uy.
struct NodeDof {
  int node = 0;
  Dof dof = Dof::uy;
  friend bool operator==(const NodeDof&, const NodeDof&) = default;
};
/// "7:uy"
std::string to_string(const NodeDof& nd);
/// Parses "7:uy"; throws std::invalid_argument.
NodeDof parse_node_dof(std::string_view text);

} // namespace jointid::fem
