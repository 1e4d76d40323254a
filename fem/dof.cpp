#include "fem/dof.hpp"

#include <charconv>
#include <stdexcept>

namespace jointid::fem {

namespace {
constexpr std::array<std::string_view, 6> names{"ux", "uy", "uz", "rx", "ry", "rz"};
}

std::string_view dof_name(Dof dof) {
  return names[static_cast<int>(dof)];
}

Dof parse_dof(std::string_view text) {
  for (int i = 0; i < num_dof_kinds; ++i)
    if (names[i] == text) return static_cast<Dof>(i);
  throw std::invalid_argument("unknown DOF '" + std::string(text) +
                              "': expected one of ux, uy, uz, rx, ry, rz");
}

bool is_rotation(Dof dof) {
  return static_cast<int>(dof) >= 3;
}

std::string to_string(const NodeDof& nd) {
  return std::to_string(nd.node) + ":" + std::string(dof_name(nd.dof));
}

NodeDof parse_node_dof(std::string_view text) {
  const auto colon = text.find(':');
  if (colon == std::string_view::npos)
    throw std::invalid_argument("'" + std::string(text) + "' is not NODE:DOF (expected e.g. 7:uy)");
  NodeDof nd;
  const auto node_text = text.substr(0, colon);
  const auto [end, ec] =
      std::from_chars(node_text.data(), node_text.data() + node_text.size(), nd.node);
  if (ec != std::errc() || end != node_text.data() + node_text.size())
    throw std::invalid_argument("'" + std::string(text) + "': node id '" + std::string(node_text) +
                                "' is not an integer (expected e.g. 7:uy)");
  nd.dof = parse_dof(text.substr(colon + 1));
  return nd;
}

} // namespace jointid::fem
