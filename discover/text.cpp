#include "discover/text.hpp"

#include <fmt/format.h>

namespace jointid::discover::detail {

std::string pct(double fraction) {
  return fmt::format("{:.3g} %", 100.0 * fraction);
}

std::string number(double value) {
  return fmt::format("{:.4g}", value);
}

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i)
    s += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + items[i];
  return s;
}

std::string channel_name(const identify::Measurement& test, std::size_t response) {
  return std::string(1, identify::quantity_letter(test.measured_as[response])) + "@" +
         fem::to_string(test.response_at[response]);
}

} // namespace jointid::discover::detail
