#include "identify/record.hpp"

#include <stdexcept>

namespace jointid::identify {

char quantity_letter(Quantity q) {
  switch (q) {
  case Quantity::force:
    return 'f';
  case Quantity::displacement:
    return 'x';
  case Quantity::velocity:
    return 'v';
  case Quantity::acceleration:
    return 'a';
  }
  return '?';
}

std::string Channel::name() const {
  return std::string(1, quantity_letter(quantity)) + "@" + fem::to_string(at);
}

Channel parse_channel_name(const std::string& name) {
  const auto at = name.find('@');
  if (at != 1)
    throw std::invalid_argument(
        "channel '" + name +
        "' is not <quantity>@<node>:<dof> (e.g. x@7:uy; quantity f, x, v or a)");
  Channel c;
  switch (name[0]) {
  case 'f':
    c.quantity = Quantity::force;
    break;
  case 'x':
    c.quantity = Quantity::displacement;
    break;
  case 'v':
    c.quantity = Quantity::velocity;
    break;
  case 'a':
    c.quantity = Quantity::acceleration;
    break;
  default:
    throw std::invalid_argument("channel '" + name + "': quantity must be f, x, v or a");
  }
  try {
    c.at = fem::parse_node_dof(name.substr(2));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("channel '" + name + "': " + e.what());
  }
  return c;
}

const Channel* Record::find(Quantity q, const fem::NodeDof& at) const {
  for (const auto& c : channels)
    if (c.quantity == q && c.at == at) return &c;
  return nullptr;
}

std::vector<const Channel*> Record::all(Quantity q) const {
  std::vector<const Channel*> out;
  for (const auto& c : channels)
    if (c.quantity == q) out.push_back(&c);
  return out;
}

} // namespace jointid::identify
