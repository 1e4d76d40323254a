// Writing universal files: datasets 58 and 58b, and 164 before the functions whose units
// change (io/uff58.hpp).
#include "io/uff58.hpp"

#include "io/files.hpp"
#include "io/uff_format.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string_view>

namespace jointid::io {

using namespace detail;

namespace {

std::string check_text(std::string_view text, std::size_t width, const std::string& what) {
  if (text.find_first_of("\r\n") != std::string_view::npos)
    throw Error(fmt::format("{}: holds a line break", what));
  if (is_delimiter(text))
    throw Error(fmt::format("{}: \"{}\" would read as the end of the dataset", what, text));
  if (text.size() > width)
    throw Error(fmt::format("{}: {} characters, at most {} fit ({})", what, text.size(), width,
                            shown(text)));
  const std::string_view t = trim(text);
  return t.empty() ? std::string("NONE") : std::string(text);
}

std::string int_field(long long value, int width, const std::string& what) {
  std::string text = fmt::format("{:>{}}", value, width);
  if (static_cast<int>(text.size()) > width)
    throw Error(fmt::format("{}: {} does not fit its {} columns", what, value, width));
  return text;
}

bool same_value(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b) ||
         (std::isnan(a) && std::isnan(b));
}

// Fortran's Ew.d: `digits` after the point, right-aligned in `width` columns; NaN and
// infinities as NAN, INF, -INF (fmt would not pad them).
std::string e_format(double value, int width, int digits) {
  if (!std::isfinite(value))
    return fmt::format("{:>{}}", std::isnan(value) ? "NAN" : value > 0 ? "INF" : "-INF", width);
  return fmt::format("{:{}.{}E}", value, width, digits);
}

// E13.5 when it reads back exactly, else E25.16.
std::string record7_real(double value) {
  const std::string short_form = e_format(value, 13, 5);
  const auto back = parse_real(short_form);
  if (back && same_value(*back, value)) return short_form;
  return e_format(value, 25, 16);
}

void write_164(std::string& out, const UffUnits& u, const std::string& what) {
  out += "    -1\n   164\n";
  out += int_field(u.code, 10, what + ": units code");
  out += fmt::format("{:<20}", check_text(u.description, 20, what + ": units description"));
  out += int_field(u.temperature_mode, 10, what + ": temperature mode") + "\n";
  for (const double factor : {u.length, u.force, u.temperature})
    if (!(std::isfinite(factor) && factor > 0.0))
      throw Error(fmt::format("{}: unit factors must be finite and > 0, got {}", what, factor));
  if (!std::isfinite(u.temperature_offset))
    throw Error(fmt::format("{}: the temperature offset is not finite", what));
  out += fmt::format("{:25.17E}{:25.17E}{:25.17E}\n{:25.17E}\n", u.length, u.force, u.temperature,
                     u.temperature_offset);
  out += "    -1\n";
}

void write_58(std::string& out, const Uff58Function& f, std::size_t position, bool binary) {
  const std::string what = fmt::format("function {}", position);
  if (f.ordinate_type != 2 && f.ordinate_type != 4 && f.ordinate_type != 5 && f.ordinate_type != 6)
    throw Error(fmt::format("{}: ordinate data type {}: expected 2, 4, 5 or 6 (real single, real "
                            "double, complex single, complex double precision)",
                            what, f.ordinate_type));
  const bool complex = f.is_complex();
  const Eigen::Index n = f.num_points();
  if (complex ? f.data.size() != 0 : f.complex_data.size() != 0)
    throw Error(fmt::format("{}: {} data given for ordinate data type {} ({}): expected only {} "
                            "data",
                            what, complex ? "real" : "complex", f.ordinate_type,
                            ordinate_type_text(f.ordinate_type), complex ? "complex" : "real"));
  if (n == 0) throw Error(fmt::format("{}: no data values", what));
  if (f.even && f.abscissa_values.size() != 0)
    throw Error(fmt::format("{}: abscissa values given for even spacing (only uneven spacing "
                            "stores them)",
                            what));
  if (!f.even && f.abscissa_values.size() != n)
    throw Error(fmt::format("{}: uneven spacing needs one abscissa value per data value: {} "
                            "abscissa values for {} data values",
                            what, f.abscissa_values.size(), n));
  if (f.even && !(std::isfinite(f.abscissa_min) && std::isfinite(f.abscissa_increment) &&
                  f.abscissa_increment > 0.0))
    throw Error(fmt::format("{}: even spacing needs a finite abscissa minimum and an increment "
                            "> 0, got {} and {}",
                            what, f.abscissa_min, f.abscissa_increment));
  for (const int direction : {f.response_direction, f.reference_direction})
    if (direction < -6 || direction > 6)
      throw Error(fmt::format("{}: direction {}: expected -6…6", what, direction));

  // The values in file order.
  const bool single = f.ordinate_type == 2 || f.ordinate_type == 5;
  const int per_point = (complex ? 2 : 1) + (f.even ? 0 : 1);
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(n * per_point));
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!f.even) values.push_back(f.abscissa_values(i));
    if (complex) {
      values.push_back(f.complex_data(i).real());
      values.push_back(f.complex_data(i).imag());
    } else {
      values.push_back(f.data(i));
    }
  }
  if (single)
    for (std::size_t k = 0; k < values.size(); ++k)
      if (beyond_single(values[k]))
        throw Error(fmt::format("{}: value {} ({}) is beyond single precision (ordinate data "
                                "type {})",
                                what, k + 1, values[k], f.ordinate_type));
  const int bytes = single ? 4 : 8;

  out += "    -1\n";
  if (binary)
    out += fmt::format("    58b{:6}{:6}{:12}{:12}{:6}{:6}{:12}{:12}\n", 1, 2, 11,
                       values.size() * static_cast<std::size_t>(bytes), 0, 0, 0, 0);
  else
    out += "    58\n";
  for (std::size_t r = 0; r < 5; ++r)
    out += check_text(f.id_lines[r], 80, fmt::format("{}: ID line {}", what, r + 1)) + "\n";
  out += int_field(f.function_type, 5, what + ": function type");
  out += int_field(f.function_id, 10, what + ": function identification number");
  out += int_field(f.version, 5, what + ": version number");
  out += int_field(f.load_case, 10, what + ": load case identification number");
  out += fmt::format(" {:<10}", check_text(f.response_entity, 10, what + ": response entity name"));
  out += int_field(f.response_node, 10, what + ": response node");
  out += int_field(f.response_direction, 4, what + ": response direction");
  out +=
      fmt::format(" {:<10}", check_text(f.reference_entity, 10, what + ": reference entity name"));
  out += int_field(f.reference_node, 10, what + ": reference node");
  out += int_field(f.reference_direction, 4, what + ": reference direction") + "\n";
  out += int_field(f.ordinate_type, 10, what + ": ordinate data type");
  out += int_field(n, 10, what + ": number of points");
  out += int_field(f.even ? 1 : 0, 10, what + ": abscissa spacing");
  out += record7_real(f.abscissa_min) + record7_real(f.abscissa_increment) +
         record7_real(f.z_value) + "\n";
  const Uff58Axis* axes[] = {&f.abscissa, &f.ordinate, &f.denominator, &f.z_axis};
  for (int r = 8; r <= 11; ++r) {
    const Uff58Axis& a = *axes[r - 8];
    const std::string where = fmt::format("{}: record {}", what, r);
    out += int_field(a.data_type, 10, where + " specific data type");
    out += int_field(a.length_exponent, 5, where + " length units exponent");
    out += int_field(a.force_exponent, 5, where + " force units exponent");
    out += int_field(a.temperature_exponent, 5, where + " temperature units exponent");
    out += fmt::format(" {:<20} {}\n", check_text(a.label, 20, where + " axis label"),
                       check_text(a.units_label, 20, where + " axis units label"));
  }
  if (binary) {
    for (const double v : values)
      append_le(out, v, bytes);
  } else {
    const int width = single ? 16 : 25;
    const int per_line = std::max(per_point, 80 / width / per_point * per_point);
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (single)
        out += e_format(static_cast<float>(values[k]), 16, 8);
      else
        out += e_format(values[k], 25, 16);
      if ((k + 1) % static_cast<std::size_t>(per_line) == 0 || k + 1 == values.size()) out += "\n";
    }
  }
  out += "    -1\n";
}

} // namespace

std::string uff58_text(const std::vector<Uff58Function>& functions, bool binary) {
  std::string out;
  std::optional<UffUnits> written; // the unit system in force in the file written so far
  for (std::size_t i = 0; i < functions.size(); ++i) {
    const Uff58Function& f = functions[i];
    const UffUnits wanted = f.units.value_or(UffUnits{});
    if (f.units ? written != f.units : (written && *written != UffUnits{})) {
      write_164(out, wanted, fmt::format("function {}: units (dataset 164)", i + 1));
      written = wanted;
    }
    write_58(out, f, i + 1, binary);
  }
  return out;
}

void write_uff58(const std::filesystem::path& path, const std::vector<Uff58Function>& functions,
                 bool binary) {
  std::string text;
  try {
    text = uff58_text(functions, binary);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", path.string(), e.what()));
  }
  write_file_atomically(path, text);
}

} // namespace jointid::io
