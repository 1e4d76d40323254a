#include "io/uff_format.hpp"

#include "fem/text.hpp"
#include "io/files.hpp"
#include "io/uff58.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>

namespace jointid::io::detail {

// ---------------------------------------------------------------------------------------------
// Text helpers

std::string_view trim_right(std::string_view s) {
  const auto last = s.find_last_not_of(" \t\r\n");
  return last == std::string_view::npos ? std::string_view{} : s.substr(0, last + 1);
}

std::vector<std::string_view> blank_separated(std::string_view s) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r'))
      ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r')
      ++i;
    if (i > start) tokens.push_back(s.substr(start, i - start));
  }
  return tokens;
}

// A line or field as it may be shown in a message: at most 40 characters, non-printable bytes
// (binary data read as text) as '?'.
std::string shown(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 40))
    out += (static_cast<unsigned char>(c) >= 32 && c != 127) || c == '\t' ? c : '?';
  if (s.size() > 40) out += "...";
  return "\"" + out + "\"";
}

std::optional<int> parse_int(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max())
    return std::nullopt;
  return static_cast<int>(value);
}

// A real number in E, D (Fortran) or plain form; "nan" and "inf" too.
std::optional<double> parse_real(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  char buffer[64];
  if (s.empty() || s.size() >= sizeof buffer) return std::nullopt;
  for (std::size_t i = 0; i < s.size(); ++i)
    buffer[i] = s[i] == 'D' || s[i] == 'd' ? 'E' : s[i];
  double value = 0.0;
  const auto [end, ec] = std::from_chars(buffer, buffer + s.size(), value);
  if (ec != std::errc() || end != buffer + s.size()) return std::nullopt;
  return value;
}

// Values at or beyond this magnitude round to infinity in single precision: FLT_MAX plus half
// its last place, (2 − 2⁻²⁴) · 2¹²⁷.
const double single_limit = std::ldexp(2.0 - std::ldexp(1.0, -24), 127);

bool beyond_single(double v) {
  return std::isfinite(v) && std::abs(v) >= single_limit;
}

bool is_delimiter(std::string_view line) {
  return trim(line) == "-1";
}

std::string ordinal(std::size_t n) {
  const char* suffix = "th";
  if (n % 100 < 11 || n % 100 > 13) {
    if (n % 10 == 1) suffix = "st";
    if (n % 10 == 2) suffix = "nd";
    if (n % 10 == 3) suffix = "rd";
  }
  return std::to_string(n) + suffix;
}

std::string direction_text(int direction) {
  static constexpr const char* names[] = {"X", "Y", "Z", "RX", "RY", "RZ"};
  if (direction == 0) return "0 (scalar)";
  if (direction < -6 || direction > 6) return std::to_string(direction);
  return fmt::format("{} ({}{})", direction, direction > 0 ? "+" : "-",
                     names[std::abs(direction) - 1]);
}

std::string ordinate_type_text(int type) {
  switch (type) {
  case 2:
    return "real single precision";
  case 4:
    return "real double precision";
  case 5:
    return "complex single precision";
  case 6:
    return "complex double precision";
  default:
    return fmt::format("ordinate data type {}", type);
  }
}

// Little-endian IEEE 754 values from bytes.
double read_le(const char* p, int bytes) {
  std::uint64_t bits = 0;
  for (int b = bytes - 1; b >= 0; --b)
    bits = (bits << 8) | static_cast<unsigned char>(p[b]);
  if (bytes == 4) return std::bit_cast<float>(static_cast<std::uint32_t>(bits));
  return std::bit_cast<double>(bits);
}

void append_le(std::string& out, double value, int bytes) {
  const std::uint64_t bits = bytes == 4 ? std::bit_cast<std::uint32_t>(static_cast<float>(value))
                                        : std::bit_cast<std::uint64_t>(value);
  for (int b = 0; b < bytes; ++b)
    out += static_cast<char>((bits >> (8 * b)) & 0xFF);
}

// ---------------------------------------------------------------------------------------------
// Lines of the file

Scanner::Scanner(std::string_view data) : data_(data) {
  if (data_.starts_with("\xEF\xBB\xBF")) pos_ = 3; // a UTF-8 byte-order mark
}

std::optional<Line> Scanner::next() {
  if (pos_ >= data_.size()) return std::nullopt;
  const auto newline = data_.find('\n', pos_);
  const std::size_t end = newline == std::string_view::npos ? data_.size() : newline;
  std::string_view text = data_.substr(pos_, end - pos_);
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  Line line{text, ++line_, pos_};
  pos_ = newline == std::string_view::npos ? data_.size() : newline + 1;
  return line;
}

std::string_view Scanner::take(std::size_t n) {
  const std::string_view bytes = data_.substr(pos_, n);
  line_ += static_cast<int>(std::count(bytes.begin(), bytes.end(), '\n'));
  pos_ += bytes.size();
  return bytes;
}

// ---------------------------------------------------------------------------------------------
// Records as fields

namespace {

std::optional<FieldFailure> parse_field(std::string_view text, const FieldSpec& spec,
                                        std::size_t field, std::string_view where, Value& v) {
  const std::string_view t = trim(text);
  switch (spec.kind) {
  case Kind::text:
    v.s = std::string(t);
    return std::nullopt;
  case Kind::integer:
    if (t.empty()) return std::nullopt; // a blank Fortran integer field reads as 0
    if (const auto value = parse_int(t)) {
      v.i = *value;
      return std::nullopt;
    }
    return FieldFailure{field, fmt::format("{}: expected an integer, got {}", where, shown(t))};
  case Kind::real:
    if (t.empty()) return std::nullopt;
    if (const auto value = parse_real(t)) {
      v.r = *value;
      return std::nullopt;
    }
    return FieldFailure{field, fmt::format("{}: expected a number, got {}", where, shown(t))};
  }
  return std::nullopt;
}

} // namespace

Fields by_columns(std::string_view line, std::span<const FieldSpec> specs) {
  std::vector<Value> values(specs.size());
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const FieldSpec& spec = specs[k];
    std::string_view text;
    if (spec.begin < line.size())
      text = line.substr(spec.begin, spec.end == std::string_view::npos
                                         ? std::string_view::npos
                                         : std::min(spec.end, line.size()) - spec.begin);
    const std::string where = spec.end == std::string_view::npos
                                  ? fmt::format("columns {}–", spec.begin + 1)
                                  : fmt::format("columns {}–{}", spec.begin + 1, spec.end);
    if (auto failure = parse_field(text, spec, k + 1, where, values[k])) return *failure;
  }
  return values;
}

Fields by_blanks(std::string_view line, std::span<const FieldSpec> specs, std::size_t at_least) {
  const auto tokens = blank_separated(line);
  if (tokens.size() < at_least || tokens.size() > specs.size()) {
    std::string names;
    for (std::size_t k = 0; k < specs.size(); ++k)
      names += (k == 0 ? "" : ", ") + std::string(specs[k].name);
    return FieldFailure{
        0, fmt::format("expected {} fields ({}), got {}", specs.size(), names, tokens.size())};
  }
  std::vector<Value> values(specs.size());
  for (std::size_t k = 0; k < tokens.size(); ++k)
    if (auto failure =
            parse_field(tokens[k], specs[k], k + 1,
                        fmt::format("{} blank-separated field", ordinal(k + 1)), values[k]))
      return *failure;
  return values;
}

// ---------------------------------------------------------------------------------------------
// The dataset being read, for messages.

std::string Dataset::tag() const {
  return fmt::format("dataset {} ({}{})", index, number, binary ? "b" : "");
}

void Dataset::fail(int line, const std::string& what) const {
  throw Error(fmt::format("{}:{}: {}, {}", file, line, tag(), what));
}

void Dataset::fail_at_byte(std::size_t offset, const std::string& what) const {
  throw Error(fmt::format("{}: byte {}: {}, {}", file, offset, tag(), what));
}

std::string record_name(int record) {
  switch (record) {
  case 6:
    return "record 6 (DOF identification)";
  case 7:
    return "record 7 (data form)";
  case 8:
    return "record 8 (abscissa data characteristics)";
  case 9:
    return "record 9 (ordinate data characteristics)";
  case 10:
    return "record 10 (ordinate denominator data characteristics)";
  case 11:
    return "record 11 (z-axis data characteristics)";
  case 12:
    return "record 12 (data values)";
  default:
    return fmt::format("record {} (ID line {})", record, record);
  }
}

std::string field_failure(int record, std::span<const FieldSpec> specs, const FieldFailure& f) {
  if (f.field == 0) return fmt::format("{}: {}", record_name(record), f.what);
  return fmt::format("{} field {} ({}), {}", record_name(record), f.field, specs[f.field - 1].name,
                     f.what);
}

} // namespace jointid::io::detail

namespace jointid::io {

std::string uff_function_type_name(int type) {
  static constexpr const char* names[] = {"general",
                                          "time response",
                                          "auto spectrum",
                                          "cross spectrum",
                                          "frequency response function",
                                          "transmissibility",
                                          "coherence",
                                          "auto correlation",
                                          "cross correlation",
                                          "power spectral density",
                                          "energy spectral density",
                                          "probability density function",
                                          "spectrum",
                                          "cumulative frequency distribution",
                                          "peaks valley",
                                          "stress/cycles",
                                          "strain/cycles",
                                          "orbit",
                                          "mode indicator function",
                                          "force pattern",
                                          "partial power",
                                          "partial coherence",
                                          "eigenvalue",
                                          "eigenvector",
                                          "shock response spectrum",
                                          "finite impulse response filter",
                                          "multiple coherence",
                                          "order function",
                                          "phase compensation"};
  if (type >= 0 && type < static_cast<int>(std::size(names))) return names[type];
  return fmt::format("function type {}", type);
}

std::string uff_data_type_name(int type) {
  switch (type) {
  case 0:
    return "unknown";
  case 1:
    return "general";
  case 2:
    return "stress";
  case 3:
    return "strain";
  case 5:
    return "temperature";
  case 6:
    return "heat flux";
  case 8:
    return "displacement";
  case 9:
    return "reaction force";
  case 11:
    return "velocity";
  case 12:
    return "acceleration";
  case 13:
    return "excitation force";
  case 15:
    return "pressure";
  case 16:
    return "mass";
  case 17:
    return "time";
  case 18:
    return "frequency";
  case 19:
    return "rpm";
  case 20:
    return "order";
  case 21:
    return "sound pressure";
  case 22:
    return "sound intensity";
  case 23:
    return "sound power";
  default:
    return fmt::format("data type {}", type);
  }
}

} // namespace jointid::io
