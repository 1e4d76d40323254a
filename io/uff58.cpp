#include "io/uff58.hpp"

#include "io/files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <string_view>
#include <variant>

namespace jointid::io {

namespace {

// ---------------------------------------------------------------------------------------------
// Text helpers

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

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

// ---------------------------------------------------------------------------------------------
// Lines of the file, with their numbers and byte offsets.

struct Line {
  std::string_view text; ///< without the line break
  int number = 0;        ///< 1-based
  std::size_t offset = 0;
};

class Scanner {
public:
  explicit Scanner(std::string_view data) : data_(data) {
    if (data_.starts_with("\xEF\xBB\xBF")) pos_ = 3; // a UTF-8 byte-order mark
  }
  std::optional<Line> next() {
    if (pos_ >= data_.size()) return std::nullopt;
    const auto newline = data_.find('\n', pos_);
    const std::size_t end = newline == std::string_view::npos ? data_.size() : newline;
    std::string_view text = data_.substr(pos_, end - pos_);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    Line line{text, ++line_, pos_};
    pos_ = newline == std::string_view::npos ? data_.size() : newline + 1;
    return line;
  }
  /// The next n bytes (binary data); line numbers keep counting the line breaks among them.
  std::string_view take(std::size_t n) {
    const std::string_view bytes = data_.substr(pos_, n);
    line_ += static_cast<int>(std::count(bytes.begin(), bytes.end(), '\n'));
    pos_ += bytes.size();
    return bytes;
  }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  int line() const { return line_; } ///< the number of the last line read

private:
  std::string_view data_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Records as fields: by the standard's columns, or separated by blanks.

enum class Kind { integer, real, text };

struct FieldSpec {
  std::string_view name;
  Kind kind;
  std::size_t begin, end; ///< 0-based columns [begin, end); end npos: to the end of the line
};

struct Value {
  int i = 0;
  double r = 0.0;
  std::string s;
};

struct FieldFailure {
  std::size_t field = 0; ///< 1-based; 0: the record as a whole
  std::string what;
};

using Fields = std::variant<std::vector<Value>, FieldFailure>;

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

struct Dataset {
  const std::string& file;
  int index = 0;       ///< 1-based among all datasets of the file
  int number = 0;      ///< 58, 164, ...
  bool binary = false; ///< 58b
  int open_line = 0;

  std::string tag() const {
    return fmt::format("dataset {} ({}{})", index, number, binary ? "b" : "");
  }
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw Error(fmt::format("{}:{}: {}, {}", file, line, tag(), what));
  }
  [[noreturn]] void fail_at_byte(std::size_t offset, const std::string& what) const {
    throw Error(fmt::format("{}: byte {}: {}, {}", file, offset, tag(), what));
  }
};

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

// The next line of a dataset's records; the file's end or the closing -1 are errors.
Line record_line(Scanner& s, const Dataset& d, int record, int previous_line) {
  const auto line = s.next();
  if (!line)
    d.fail(previous_line,
           fmt::format("the file ends before {} (the dataset is truncated)", record_name(record)));
  if (is_delimiter(line->text))
    d.fail(line->number,
           fmt::format("{}: got the closing '    -1' (the dataset ends early: records 1–11 "
                       "come before the data values)",
                       record_name(record)));
  return *line;
}

constexpr FieldSpec record6_fields[] = {
    {"function type", Kind::integer, 0, 5},
    {"function identification number", Kind::integer, 5, 15},
    {"version number", Kind::integer, 15, 20},
    {"load case identification number", Kind::integer, 20, 30},
    {"response entity name", Kind::text, 30, 41},
    {"response node", Kind::integer, 41, 51},
    {"response direction", Kind::integer, 51, 55},
    {"reference entity name", Kind::text, 55, 66},
    {"reference node", Kind::integer, 66, 76},
    {"reference direction", Kind::integer, 76, 80},
};

constexpr FieldSpec record7_fields[] = {
    {"ordinate data type", Kind::integer, 0, 10}, {"number of points", Kind::integer, 10, 20},
    {"abscissa spacing", Kind::integer, 20, 30},  {"abscissa minimum", Kind::real, 30, 43},
    {"abscissa increment", Kind::real, 43, 56},   {"z-axis value", Kind::real, 56, 69},
};

constexpr FieldSpec axis_fields[] = {
    {"specific data type", Kind::integer, 0, 10},
    {"length units exponent", Kind::integer, 10, 15},
    {"force units exponent", Kind::integer, 15, 20},
    {"temperature units exponent", Kind::integer, 20, 25},
    {"axis label", Kind::text, 25, 46},
    {"axis units label", Kind::text, 46, std::string_view::npos},
};

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

// What record 7 says the data are, for messages: "1024 points of real double precision data,
// even spacing".
std::string data_form(const Uff58Function& f, Eigen::Index points) {
  return fmt::format("{} point{} of {} data, {} spacing", points, points == 1 ? "" : "s",
                     ordinate_type_text(f.ordinate_type), f.even ? "even" : "uneven");
}

void read_record6(const Line& line, const Dataset& d, Uff58Function& f) {
  Fields fields = by_columns(line.text, record6_fields);
  if (std::holds_alternative<FieldFailure>(fields)) {
    Fields blanks = by_blanks(line.text, record6_fields, 10);
    if (std::holds_alternative<FieldFailure>(blanks))
      d.fail(line.number, field_failure(6, record6_fields, std::get<FieldFailure>(fields)) +
                              " (Format(2(I5,I10),2(1X,10A1,I10,I4)))");
    fields = std::move(blanks);
  }
  const auto& v = std::get<std::vector<Value>>(fields);
  f.function_type = v[0].i;
  f.function_id = v[1].i;
  f.version = v[2].i;
  f.load_case = v[3].i;
  f.response_entity = v[4].s;
  f.response_node = v[5].i;
  f.response_direction = v[6].i;
  f.reference_entity = v[7].s;
  f.reference_node = v[8].i;
  f.reference_direction = v[9].i;
  for (const int k : {6, 9}) {
    const int direction = v[k].i;
    if (direction < -6 || direction > 6)
      d.fail(line.number, fmt::format("{} field {} ({}): expected a direction -6…6 (0 scalar, 1…6 "
                                      "+X +Y +Z +RX +RY +RZ, negative: the negative direction), "
                                      "got {}",
                                      record_name(6), k + 1, record6_fields[k].name, direction));
  }
  if (f.function_type < 0)
    d.fail(line.number, fmt::format("{} field 1 (function type): expected a code ≥ 0, got {}",
                                    record_name(6), f.function_type));
}

// Record 7; returns the number of points.
int read_record7(const Line& line, const Dataset& d, Uff58Function& f) {
  Fields fields = by_blanks(line.text, record7_fields, 5);
  if (std::holds_alternative<FieldFailure>(fields)) {
    Fields columns = by_columns(line.text, record7_fields);
    if (std::holds_alternative<FieldFailure>(columns))
      d.fail(line.number, field_failure(7, record7_fields, std::get<FieldFailure>(fields)) +
                              " (Format(3I10,3E13.5))");
    fields = std::move(columns);
  }
  const auto& v = std::get<std::vector<Value>>(fields);
  const auto fail = [&](int field, const std::string& what) {
    d.fail(line.number, fmt::format("{} field {} ({}): {}", record_name(7), field,
                                    record7_fields[field - 1].name, what));
  };
  f.ordinate_type = v[0].i;
  if (f.ordinate_type != 2 && f.ordinate_type != 4 && f.ordinate_type != 5 && f.ordinate_type != 6)
    fail(1, fmt::format("expected 2, 4, 5 or 6 (real single, real double, complex single, "
                        "complex double precision), got {}",
                        f.ordinate_type));
  if (v[1].i < 1) fail(2, fmt::format("expected at least 1, got {}", v[1].i));
  if (v[2].i != 0 && v[2].i != 1)
    fail(3, fmt::format("expected 0 (uneven) or 1 (even), got {}", v[2].i));
  f.even = v[2].i == 1;
  f.abscissa_min = v[3].r;
  f.abscissa_increment = v[4].r;
  f.z_value = v[5].r;
  if (f.even && !std::isfinite(f.abscissa_min))
    fail(4, fmt::format("expected a finite number, got {}", f.abscissa_min));
  if (f.even && !(std::isfinite(f.abscissa_increment) && f.abscissa_increment > 0.0))
    fail(5, fmt::format("expected a finite number > 0 for even spacing, got {}",
                        f.abscissa_increment));
  return v[1].i;
}

Uff58Axis read_axis(const Line& line, const Dataset& d, int record) {
  Fields fields = by_columns(line.text, axis_fields);
  if (std::holds_alternative<FieldFailure>(fields)) {
    Fields blanks = by_blanks(line.text, axis_fields, 4);
    if (std::holds_alternative<FieldFailure>(blanks))
      d.fail(line.number, field_failure(record, axis_fields, std::get<FieldFailure>(fields)) +
                              " (Format(I10,3I5,2(1X,20A1)))");
    fields = std::move(blanks);
  }
  const auto& v = std::get<std::vector<Value>>(fields);
  return {v[0].i, v[1].i, v[2].i, v[3].i, v[4].s, v[5].s};
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

struct BinaryHeader {
  int byte_ordering = 1, float_format = 2, ascii_lines = 11;
  long long bytes = 0;
};

BinaryHeader read_binary_header(const Line& line, const Dataset& d) {
  // "    58b     1     2          11        8192     0     0           0           0"
  std::string_view rest = line.text.substr(line.text.find_first_of("bB") + 1);
  const auto tokens = blank_separated(rest);
  static constexpr const char* names[] = {"byte ordering", "floating-point format",
                                          "number of ASCII lines", "number of bytes"};
  const std::string record = "identifier line (58b: I6,A1,I6,I6,I12,I12,I6,I6,I12,I12)";
  if (tokens.size() < 4)
    d.fail(line.number,
           fmt::format("{}: expected the byte ordering, floating-point format, number of ASCII "
                       "lines and number of bytes after '58b', got {} field{}",
                       record, tokens.size(), tokens.size() == 1 ? "" : "s"));
  long long v[4];
  for (int k = 0; k < 4; ++k) {
    std::string_view t = tokens[static_cast<std::size_t>(k)];
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v[k]);
    if (ec != std::errc() || end != t.data() + t.size())
      d.fail(line.number, fmt::format("{} field {} ({}): expected an integer, got {}", record,
                                      k + 3, names[k], shown(t)));
  }
  if (v[0] != 1)
    d.fail(line.number, fmt::format("{} field 3 (byte ordering): {} ({}) is not supported: only 1 "
                                    "(little-endian) is read",
                                    record, v[0], v[0] == 2 ? "big-endian" : "unknown"));
  if (v[1] != 2)
    d.fail(line.number,
           fmt::format("{} field 4 (floating-point format): {} ({}) is not supported: only 2 "
                       "(IEEE 754) is read",
                       record, v[1],
                       v[1] == 1   ? "DEC VMS"
                       : v[1] == 3 ? "IBM 5/370"
                                   : "unknown"));
  if (v[2] != 11)
    d.fail(line.number, fmt::format("{} field 5 (number of ASCII lines): expected 11 (records "
                                    "1–11), got {}",
                                    record, v[2]));
  if (v[3] < 0)
    d.fail(line.number,
           fmt::format("{} field 6 (number of bytes): expected a count ≥ 0, got {}", record, v[3]));
  return {1, 2, 11, v[3]};
}

Uff58Function read_58(Scanner& s, const Dataset& d, const Line& identifier,
                      const std::optional<UffUnits>& units) {
  Uff58Function f;
  f.dataset = d.index;
  f.line = d.open_line;
  f.binary = d.binary;
  f.units = units;
  BinaryHeader header;
  if (d.binary) header = read_binary_header(identifier, d);

  int previous = identifier.number;
  for (int r = 1; r <= 5; ++r) {
    const Line line = record_line(s, d, r, previous);
    f.id_lines[static_cast<std::size_t>(r - 1)] = std::string(trim_right(line.text));
    previous = line.number;
  }
  const Line r6 = record_line(s, d, 6, previous);
  read_record6(r6, d, f);
  const Line r7 = record_line(s, d, 7, r6.number);
  const int points = read_record7(r7, d, f);
  Uff58Axis* axes[] = {&f.abscissa, &f.ordinate, &f.denominator, &f.z_axis};
  previous = r7.number;
  for (int r = 8; r <= 11; ++r) {
    const Line line = record_line(s, d, r, previous);
    *axes[r - 8] = read_axis(line, d, r);
    previous = line.number;
  }

  const bool single = f.ordinate_type == 2 || f.ordinate_type == 5;
  const std::size_t per_point = (f.is_complex() ? 2u : 1u) + (f.even ? 0u : 1u);
  const std::size_t expected = static_cast<std::size_t>(points) * per_point;
  std::vector<double> values;

  if (d.binary) {
    const std::size_t bytes = single ? 4 : 8;
    const std::size_t same = expected * bytes;
    // Uneven double precision: the abscissa in double (pyuff and most writers) or in single
    // precision (the standard's "the abscissa is always real single precision").
    const std::size_t single_abscissa =
        !f.even && !single ? static_cast<std::size_t>(points) * (4 + (per_point - 1) * 8) : 0;
    const auto count = static_cast<std::size_t>(header.bytes);
    if (count != same && (single_abscissa == 0 || count != single_abscissa))
      d.fail(identifier.number,
             fmt::format("identifier line field 6 (number of bytes): {} does not fit {} (record "
                         "7): expected {} bytes{}",
                         header.bytes, data_form(f, points), same,
                         single_abscissa ? fmt::format(" (or {} with a single-precision abscissa)",
                                                       single_abscissa)
                                         : ""));
    const std::size_t start = s.pos();
    if (s.remaining() < count)
      d.fail_at_byte(start,
                     fmt::format("{} (binary): expected {} bytes ({}), the file ends after "
                                 "{}",
                                 record_name(12), count, data_form(f, points), s.remaining()));
    const std::string_view data = s.take(count);
    values.reserve(expected);
    const bool abscissa_single = count != same;
    std::size_t at = 0;
    for (std::size_t i = 0; i < expected; ++i) {
      const std::size_t b = abscissa_single && i % per_point == 0 ? 4 : bytes;
      values.push_back(read_le(data.data() + at, static_cast<int>(b)));
      at += b;
    }
    // The closing -1 follows the data at once (some writers put a line break between).
    std::optional<Line> close = s.next();
    while (close && close->text.empty())
      close = s.next();
    if (!close)
      d.fail_at_byte(start + count, fmt::format("the file ends after the {} bytes of binary data: "
                                                "expected the closing '    -1'",
                                                count));
    if (!is_delimiter(close->text))
      d.fail_at_byte(close->offset,
                     fmt::format("expected the closing '    -1' right after the {} bytes of binary "
                                 "data ({}), got {}",
                                 count, data_form(f, points), shown(close->text)));
  } else {
    values.reserve(std::min<std::size_t>(expected, s.remaining() / 2 + 1));
    int last = previous;
    while (true) {
      const auto line = s.next();
      if (!line)
        d.fail(last, fmt::format("the file ends in {} after {} of {} values ({}): the dataset "
                                 "opened at line {} has no closing '    -1'",
                                 record_name(12), values.size(), expected, data_form(f, points),
                                 d.open_line));
      last = line->number;
      if (is_delimiter(line->text)) {
        if (values.size() != expected)
          d.fail(line->number,
                 fmt::format("{}: {} value{} before the closing '    -1', expected {} ({}: {})",
                             record_name(12), values.size(), values.size() == 1 ? "" : "s",
                             expected, record_name(7), data_form(f, points)));
        break;
      }
      for (const std::string_view token : blank_separated(line->text)) {
        const auto value = parse_real(token);
        if (!value)
          d.fail(line->number, fmt::format("{} value {}: expected a number, got {}",
                                           record_name(12), values.size() + 1, shown(token)));
        if (values.size() == expected)
          d.fail(line->number,
                 fmt::format("{}: more than the {} values of {} ({}); is the "
                             "closing '    -1' missing?",
                             record_name(12), expected, data_form(f, points), record_name(7)));
        double v = *value;
        if (single) {
          if (beyond_single(v))
            d.fail(line->number, fmt::format("{} value {}: {} is beyond single precision ({})",
                                             record_name(12), values.size() + 1, shown(token),
                                             ordinate_type_text(f.ordinate_type)));
          v = static_cast<float>(v);
        }
        values.push_back(v);
      }
    }
  }

  const auto n = static_cast<Eigen::Index>(points);
  if (!f.even) f.abscissa_values.resize(n);
  if (f.is_complex())
    f.complex_data.resize(n);
  else
    f.data.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    std::size_t at = static_cast<std::size_t>(i) * per_point;
    if (!f.even) f.abscissa_values(i) = values[at++];
    if (f.is_complex())
      f.complex_data(i) = {values[at], values[at + 1]};
    else
      f.data(i) = values[at];
  }
  return f;
}

UffUnits read_164(Scanner& s, const Dataset& d, const Line& identifier) {
  UffUnits u;
  const auto first = s.next();
  if (!first || is_delimiter(first->text))
    d.fail(first ? first->number : identifier.number,
           "record 1 (units code, description, temperature mode): missing");
  // Record 1: Format(I10,20A1,I10).
  const std::string_view text = first->text;
  if (const auto code = parse_int(text.substr(0, std::min<std::size_t>(10, text.size())))) {
    u.code = *code;
    u.description = text.size() > 10 ? std::string(trim(text.substr(10, 20))) : std::string();
    if (text.size() > 30)
      if (const auto mode = parse_int(text.substr(30))) u.temperature_mode = *mode;
  } else {
    const auto tokens = blank_separated(text);
    const auto code_token = tokens.empty() ? std::optional<int>() : parse_int(tokens.front());
    if (!code_token)
      d.fail(first->number,
             fmt::format("record 1 field 1 (units code): expected an integer, got {}",
                         shown(trim(text))));
    u.code = *code_token;
    u.description.clear();
  }
  // Records 2 and 3: Format(3D25.17): length, force, temperature, temperature offset.
  static constexpr const char* names[] = {"length", "force", "temperature", "temperature offset"};
  std::vector<double> factors;
  int last = first->number;
  while (true) {
    const auto line = s.next();
    if (!line)
      d.fail(last,
             fmt::format("the dataset opened at line {} has no closing '    -1'", d.open_line));
    last = line->number;
    if (is_delimiter(line->text)) break;
    for (const std::string_view token : blank_separated(line->text)) {
      const std::size_t k = factors.size();
      if (k == 4)
        d.fail(line->number, fmt::format("more than the 4 unit factors (length, force, "
                                         "temperature, temperature offset), got {}",
                                         shown(token)));
      const auto value = parse_real(token);
      if (!value || !std::isfinite(*value) || (k < 3 && !(*value > 0.0)))
        d.fail(line->number,
               fmt::format("record {} field {} ({} factor): expected a {}number{}, "
                           "got {}",
                           k < 3 ? 2 : 3, k < 3 ? k + 1 : 1, names[k], k < 3 ? "" : "finite ",
                           k < 3 ? " > 0" : "", shown(token)));
      factors.push_back(*value);
    }
  }
  if (factors.size() < 3)
    d.fail(last, fmt::format("record 2 (unit factors): expected the length, force and "
                             "temperature factors, got {} number{}",
                             factors.size(), factors.size() == 1 ? "" : "s"));
  u.length = factors[0];
  u.force = factors[1];
  u.temperature = factors[2];
  u.temperature_offset = factors.size() > 3 ? factors[3] : 0.0;
  return u;
}

void skip_dataset(Scanner& s, const Dataset& d, int identifier_line) {
  int last = identifier_line;
  while (const auto line = s.next()) {
    if (is_delimiter(line->text)) return;
    last = line->number;
  }
  d.fail(last, fmt::format("the file ends without the closing '    -1' of the dataset opened at "
                           "line {}",
                           d.open_line));
}

} // namespace

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

std::vector<Uff58Function> read_uff58(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string content = read_file(path);
  Scanner s(content);
  std::vector<Uff58Function> functions;
  std::optional<UffUnits> units;
  int index = 0, last_close = 0;
  while (const auto open = s.next()) {
    if (trim(open->text).empty()) continue;
    if (!is_delimiter(open->text))
      throw Error(fmt::format(
          "{}:{}: expected '    -1' opening a dataset, got {}{}", name, open->number,
          shown(open->text),
          index == 0 ? " (a universal file is a sequence of datasets, each between two '    -1' "
                       "lines)"
                     : fmt::format(" after dataset {}, which closed at line {}; is that "
                                   "dataset's closing '    -1' missing, or one too many?",
                                   index, last_close)));
    ++index;
    const auto identifier = s.next();
    if (!identifier)
      throw Error(fmt::format("{}:{}: the file ends after the opening '    -1' of dataset {}: "
                              "expected its number",
                              name, open->number, index));
    // The dataset number, I6, right-justified; 58b marks the binary form of dataset 58.
    const std::string_view id = trim(identifier->text);
    int number = 0;
    const auto [end, ec] = std::from_chars(id.data(), id.data() + id.size(), number);
    const std::string_view after(end, static_cast<std::size_t>(id.data() + id.size() - end));
    if (ec != std::errc() || number <= 0 ||
        (!after.empty() && after.front() != ' ' && after.front() != 'b' && after.front() != 'B'))
      throw Error(fmt::format("{}:{}: dataset {}: expected the dataset number (I6, e.g. "
                              "'    58') after the opening '    -1', got {}",
                              name, identifier->number, index, shown(identifier->text)));
    const bool binary = !after.empty() && (after.front() == 'b' || after.front() == 'B');
    const Dataset d{name, index, number, binary, open->number};
    if (number == 58)
      functions.push_back(read_58(s, d, *identifier, units));
    else if (number == 164 && !binary)
      units = read_164(s, d, *identifier);
    else
      skip_dataset(s, d, identifier->number);
    last_close = s.line(); // the closing -1 just read
  }
  return functions;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Writing

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

// ---------------------------------------------------------------------------------------------
// Time responses as records

namespace {

enum class Unit {
  length,
  velocity,
  acceleration,
  force,
  angle,
  angular_velocity,
  angular_acceleration,
  moment
};

std::string_view unit_noun(Unit u) {
  switch (u) {
  case Unit::length:
    return "a displacement";
  case Unit::velocity:
    return "a velocity";
  case Unit::acceleration:
    return "an acceleration";
  case Unit::force:
    return "a force";
  case Unit::angle:
    return "a rotation";
  case Unit::angular_velocity:
    return "an angular velocity";
  case Unit::angular_acceleration:
    return "an angular acceleration";
  case Unit::moment:
    return "a moment";
  }
  return "";
}

struct KnownUnit {
  std::string_view label; ///< normalised (see normalise_unit)
  double to_si;
};

constexpr double g_n = 9.80665;                     // standard gravity, m/s²
constexpr double pound_force = 4.4482216152605;     // N
constexpr double degree = std::numbers::pi / 180.0; // rad

std::span<const KnownUnit> known_units(Unit u) {
  static constexpr KnownUnit length[] = {
      {"m", 1.0}, {"mm", 1e-3}, {"cm", 1e-2}, {"um", 1e-6}, {"in", 0.0254}};
  static constexpr KnownUnit velocity[] = {
      {"m/s", 1.0}, {"mm/s", 1e-3}, {"cm/s", 1e-2}, {"um/s", 1e-6}, {"in/s", 0.0254}};
  static constexpr KnownUnit acceleration[] = {{"m/s2", 1.0},     {"mm/s2", 1e-3}, {"cm/s2", 1e-2},
                                               {"in/s2", 0.0254}, {"g", g_n},      {"G", g_n}};
  static constexpr KnownUnit force[] = {
      {"N", 1.0}, {"kN", 1e3}, {"mN", 1e-3}, {"lbf", pound_force}};
  static constexpr KnownUnit angle[] = {{"rad", 1.0}, {"mrad", 1e-3}, {"deg", degree}};
  static constexpr KnownUnit angular_velocity[] = {
      {"rad/s", 1.0}, {"mrad/s", 1e-3}, {"deg/s", degree}};
  static constexpr KnownUnit angular_acceleration[] = {
      {"rad/s2", 1.0}, {"mrad/s2", 1e-3}, {"deg/s2", degree}};
  static constexpr KnownUnit moment[] = {{"Nm", 1.0}, {"kNm", 1e3}, {"Nmm", 1e-3}, {"mNm", 1e-3}};
  switch (u) {
  case Unit::length:
    return length;
  case Unit::velocity:
    return velocity;
  case Unit::acceleration:
    return acceleration;
  case Unit::force:
    return force;
  case Unit::angle:
    return angle;
  case Unit::angular_velocity:
    return angular_velocity;
  case Unit::angular_acceleration:
    return angular_acceleration;
  case Unit::moment:
    return moment;
  }
  return {};
}

// "m/s^2", "m/s**2", "m/s²" → "m/s2"; "N m", "N*m", "N.m", "N·m" → "Nm"; "µm", "μm" → "um";
// "m/sec" → "m/s".
std::string normalise_unit(std::string_view label) {
  std::string out;
  for (std::size_t i = 0; i < label.size(); ++i) {
    const std::string_view rest = label.substr(i);
    if (rest.starts_with("\xC2\xB2")) { // ²
      out += '2';
      ++i;
    } else if (rest.starts_with("\xC2\xB5") || rest.starts_with("\xCE\xBC")) { // µ, μ
      out += 'u';
      ++i;
    } else if (rest.starts_with("\xC2\xB7")) { // ·
      ++i;
    } else if (rest.starts_with("sec")) {
      out += 's';
      i += 2;
    } else if (label[i] != ' ' && label[i] != '*' && label[i] != '.' && label[i] != '^') {
      out += label[i];
    }
  }
  return out;
}

bool no_label(std::string_view label) {
  const std::string_view t = trim(label);
  return t.empty() || t == "NONE" || t == "none";
}

std::string unit_list(Unit u) {
  std::string list;
  for (const KnownUnit& k : known_units(u))
    list += (list.empty() ? "" : ", ") + std::string(k.label);
  return list;
}

// The function's place, for messages: "a.uff: dataset 3 (line 14)".
std::string where(const std::filesystem::path& path, const Uff58Function& f) {
  return f.dataset > 0 ? fmt::format("{}: dataset {} (line {})", path.string(), f.dataset, f.line)
                       : path.string();
}

// The channel a time response holds, and the factor (sign included) that makes its values SI.
struct ChannelOf {
  identify::Quantity quantity = identify::Quantity::force;
  fem::NodeDof at;
  double factor = 1.0;
  double time_factor = 1.0;
  std::optional<double> excitation_hz;
  int excitation_line = 0; ///< the ID line (1–5) that gave it
};

// What an ordinate axis (record 9, or the denominator's record 10) holds, and the factor that
// makes its values SI: the quantity from the specific data type, the unit from the axis units
// label or, without one, from the file's dataset 164. `rotation`: at a rotational DOF.
struct AxisScale {
  identify::Quantity quantity = identify::Quantity::force;
  double factor = 1.0;
};

template <class Error>
AxisScale axis_scale(const Uff58Function& f, const Uff58Axis& o, int record, bool rotation,
                     const Error& error) {
  AxisScale c;
  // The quantity from the specific data type.
  int length_exponent = 0, force_exponent = 0;
  Unit unit = Unit::length;
  switch (o.data_type) {
  case uff_data_type::excitation_force:
    c.quantity = identify::Quantity::force;
    unit = rotation ? Unit::moment : Unit::force;
    length_exponent = rotation ? 1 : 0;
    force_exponent = 1;
    break;
  case uff_data_type::displacement:
    c.quantity = identify::Quantity::displacement;
    unit = rotation ? Unit::angle : Unit::length;
    length_exponent = rotation ? 0 : 1;
    break;
  case uff_data_type::velocity:
    c.quantity = identify::Quantity::velocity;
    unit = rotation ? Unit::angular_velocity : Unit::velocity;
    length_exponent = rotation ? 0 : 1;
    break;
  case uff_data_type::acceleration:
    c.quantity = identify::Quantity::acceleration;
    unit = rotation ? Unit::angular_acceleration : Unit::acceleration;
    length_exponent = rotation ? 0 : 1;
    break;
  default:
    throw error(fmt::format("record {} field 1 ({} specific data type) is {} ({}): cannot tell the "
                            "quantity; expected 13 (excitation force), 8 (displacement), 11 "
                            "(velocity) or 12 (acceleration)",
                            record, record == 9 ? "ordinate" : "denominator", o.data_type,
                            uff_data_type_name(o.data_type)));
  }

  // Unit exponents: not given (0 0 0), or those of the standard's Addendum A.
  const bool none = o.length_exponent == 0 && o.force_exponent == 0 && o.temperature_exponent == 0;
  const bool addendum = o.length_exponent == length_exponent &&
                        o.force_exponent == force_exponent && o.temperature_exponent == 0;
  if (!none && !addendum)
    throw error(
        fmt::format("record {} fields 2–4 (length, force, temperature units exponents) are {} {} "
                    "{}, which do not fit {} at a {} DOF (expected {} {} 0 as in the standard's "
                    "Addendum A, or 0 0 0)",
                    record, o.length_exponent, o.force_exponent, o.temperature_exponent,
                    uff_data_type_name(o.data_type), rotation ? "rotational" : "translational",
                    length_exponent, force_exponent));

  // Scale to SI: the units label says the unit; without one, the unit system of dataset 164.
  if (!no_label(o.units_label)) {
    const std::string label = normalise_unit(trim(o.units_label));
    const auto units = known_units(unit);
    const auto it = std::find_if(units.begin(), units.end(),
                                 [&](const KnownUnit& k) { return k.label == label; });
    if (it == units.end())
      throw error(
          fmt::format("record {} field 6 (axis units label) '{}' is not a unit of {} that jointid "
                      "reads ({}); convert the data to one of these or to SI",
                      record, trim(o.units_label), unit_noun(unit), unit_list(unit)));
    c.factor = it->to_si;
  } else if (f.units) {
    c.factor = 1.0 / (std::pow(f.units->length, length_exponent) *
                      std::pow(f.units->force, force_exponent));
  }
  return c;
}

ChannelOf channel_of(const Uff58Function& f, const std::filesystem::path& path) {
  const std::string at = where(path, f);
  const auto error = [&](const std::string& what) {
    return Error(fmt::format("{}: {}", at, what));
  };
  if (f.function_type != uff_function_type::time_response)
    throw error(
        fmt::format("record 6 field 1 (function type) is {} ({}): only time responses (1) are "
                    "sine tests; measured FRFs (4) describe the substructure: give them in the "
                    "model file's [frf] section",
                    f.function_type, uff_function_type_name(f.function_type)));
  if (f.is_complex())
    throw error(
        fmt::format("record 7 field 1 (ordinate data type) is {} ({}): a time response must be "
                    "real (2 or 4)",
                    f.ordinate_type, ordinate_type_text(f.ordinate_type)));
  if (!f.even)
    throw error("record 7 field 3 (abscissa spacing) is 0 (uneven): a time record must be evenly "
                "sampled (1)");
  if (!(std::isfinite(f.abscissa_min) && std::isfinite(f.abscissa_increment) &&
        f.abscissa_increment > 0.0))
    throw error(fmt::format("record 7 fields 4–5 (abscissa minimum, increment) are {} and {}: a "
                            "time record needs a finite start and a step > 0",
                            f.abscissa_min, f.abscissa_increment));
  if (f.data.size() < 4)
    throw error(
        fmt::format("record 7 field 2 (number of points) is {}: a time record needs at least 4 "
                    "samples",
                    f.data.size()));
  for (Eigen::Index i = 0; i < f.data.size(); ++i)
    if (!std::isfinite(f.data(i)))
      throw error(
          fmt::format("record 12 (data values) value {} is {}: a time record must be finite", i + 1,
                      f.data(i)));

  ChannelOf c;
  if (f.response_node <= 0)
    throw error(fmt::format("record 6 field 6 (response node) is {}: expected a node id > 0",
                            f.response_node));
  if (f.response_direction == 0 || std::abs(f.response_direction) > 6)
    throw error(
        fmt::format("record 6 field 7 (response direction) is {}: a channel needs a direction "
                    "±1…6 (X, Y, Z, RX, RY, RZ)",
                    direction_text(f.response_direction)));
  c.at = {f.response_node,
          fem::all_dofs[static_cast<std::size_t>(std::abs(f.response_direction) - 1)]};
  const bool rotation = fem::is_rotation(c.at.dof);

  const AxisScale scale = axis_scale(f, f.ordinate, 9, rotation, error);
  c.quantity = scale.quantity;
  c.factor = scale.factor;
  if (f.response_direction < 0) c.factor = -c.factor;

  // The abscissa: time in s (the unit systems of dataset 164 do not scale time).
  const Uff58Axis& a = f.abscissa;
  if (a.data_type != uff_data_type::time && a.data_type != uff_data_type::unknown &&
      a.data_type != uff_data_type::general)
    throw error(
        fmt::format("record 8 field 1 (abscissa specific data type) is {} ({}): a time response's "
                    "abscissa is time (17)",
                    a.data_type, uff_data_type_name(a.data_type)));
  if (!no_label(a.units_label)) {
    const std::string label = normalise_unit(trim(a.units_label));
    // "Time" names the quantity, not a unit (some writers put it there): seconds.
    if (label == "s" || label == "Time" || label == "time")
      c.time_factor = 1.0;
    else if (label == "ms" || label == "msec")
      c.time_factor = 1e-3;
    else
      throw error(fmt::format("record 8 field 6 (axis units label) '{}' is not a unit of time that "
                              "jointid reads (s, ms)",
                              trim(a.units_label)));
  }

  // `excitation_hz = <Hz>` in an ID line.
  for (std::size_t r = 0; r < 5; ++r) {
    const std::string_view text = trim(f.id_lines[r]);
    if (!text.starts_with("excitation_hz")) continue;
    const std::string_view after = trim(text.substr(std::string_view("excitation_hz").size()));
    if (after.empty() || after.front() != '=') continue;
    const std::string_view value_text = trim(after.substr(1));
    const auto value = parse_real(value_text);
    if (!value || !std::isfinite(*value) || !(*value > 0.0))
      throw error(
          fmt::format("record {} (ID line {}): excitation_hz: expected a frequency > 0 Hz, got {}",
                      r + 1, r + 1, shown(value_text)));
    if (c.excitation_hz && *c.excitation_hz != *value)
      throw error(
          fmt::format("excitation_hz given twice ({} Hz in ID line {}, {} Hz in ID line {})",
                      *c.excitation_hz, c.excitation_line, *value, r + 1));
    c.excitation_hz = *value;
    c.excitation_line = static_cast<int>(r + 1);
  }
  return c;
}

} // namespace

std::vector<identify::SineTest> uff58_tests(const std::vector<Uff58Function>& functions,
                                            const std::filesystem::path& path) {
  if (functions.empty())
    throw Error(fmt::format("{}: no dataset 58 (function at nodal DOF) in the file; expected the "
                            "time responses of a sine test",
                            path.string()));
  struct Group {
    double t0, dt;
    Eigen::Index n;
    identify::Record record;
    std::vector<const Uff58Function*> members;
    const Uff58Function* excitation_from = nullptr;
  };
  std::vector<Group> groups;
  for (const Uff58Function& f : functions) {
    const ChannelOf c = channel_of(f, path);
    const double t0 = f.abscissa_min * c.time_factor, dt = f.abscissa_increment * c.time_factor;
    const Eigen::Index n = f.data.size();
    auto group = std::find_if(groups.begin(), groups.end(),
                              [&](const Group& g) { return g.t0 == t0 && g.dt == dt && g.n == n; });
    if (group == groups.end()) {
      Group g{t0, dt, n, {}, {}, nullptr};
      g.record.source = fmt::format("{}#{}", path.string(), f.dataset);
      g.record.t.resize(n);
      for (Eigen::Index i = 0; i < n; ++i)
        g.record.t(i) = t0 + static_cast<double>(i) * dt;
      // The sample times must stay finite, increasing and uniform in double precision: an
      // increment lost against a large minimum, or times beyond the range of a double, are not.
      const auto& t = g.record.t;
      const double mean_step = (t(n - 1) - t(0)) / static_cast<double>(n - 1);
      for (Eigen::Index i = 1; i < n; ++i) {
        const double step = t(i) - t(i - 1);
        if (!std::isfinite(t(i)) || !(step > 0.0) || !std::isfinite(mean_step) ||
            std::abs(step - mean_step) > 1e-6 * mean_step)
          throw Error(fmt::format(
              "{}: record 7 fields 4–5 (abscissa minimum, increment) are {} and {} s: the {} "
              "sample times are not finite, increasing and uniform in double precision (sample "
              "{} is at {} s); a time record starts near 0 with a step that is not lost against "
              "its start",
              where(path, f), t0, dt, n, i + 1, t(i)));
      }
      groups.push_back(std::move(g));
      group = groups.end() - 1;
    }
    identify::Channel channel{c.quantity, c.at,
                              c.factor == 1.0 ? f.data : Eigen::VectorXd(c.factor * f.data)};
    for (Eigen::Index i = 0; i < n; ++i)
      if (!std::isfinite(channel.samples(i)))
        throw Error(fmt::format("{}: record 12 (data values) value {} is {}, which is {} in SI "
                                "units (factor {}): not a finite number",
                                where(path, f), i + 1, f.data(i), channel.samples(i), c.factor));
    for (std::size_t k = 0; k < group->record.channels.size(); ++k)
      if (group->record.channels[k].name() == channel.name()) {
        const Uff58Function& other = *group->members[k];
        throw Error(fmt::format(
            "{}: channel {} is given twice in one record (datasets {} at line {} and {} at line "
            "{}, with the same abscissa: {} s + {} s × {} points); each test needs its own file "
            "or abscissa",
            path.string(), channel.name(), other.dataset, other.line, f.dataset, f.line, t0, dt,
            n));
      }
    if (c.excitation_hz) {
      if (group->record.excitation_hz && *group->record.excitation_hz != *c.excitation_hz)
        throw Error(fmt::format("{}: excitation_hz differs within one record: {} Hz (dataset {} "
                                "at line {}) and {} Hz (dataset {} at line {})",
                                path.string(), *group->record.excitation_hz,
                                group->excitation_from->dataset, group->excitation_from->line,
                                *c.excitation_hz, f.dataset, f.line));
      group->record.excitation_hz = c.excitation_hz;
      group->excitation_from = &f;
    }
    group->record.channels.push_back(std::move(channel));
    group->members.push_back(&f);
  }
  std::vector<identify::SineTest> tests;
  tests.reserve(groups.size());
  for (Group& g : groups)
    tests.emplace_back(std::move(g.record));
  return tests;
}

Uff58Axis uff58_axis(identify::Quantity quantity, bool rotation) {
  switch (quantity) {
  case identify::Quantity::force:
    return rotation ? Uff58Axis{uff_data_type::excitation_force, 1, 1, 0, "Moment", "N m"}
                    : Uff58Axis{uff_data_type::excitation_force, 0, 1, 0, "Force", "N"};
  case identify::Quantity::displacement:
    return rotation ? Uff58Axis{uff_data_type::displacement, 0, 0, 0, "Rotation", "rad"}
                    : Uff58Axis{uff_data_type::displacement, 1, 0, 0, "Displacement", "m"};
  case identify::Quantity::velocity:
    return rotation ? Uff58Axis{uff_data_type::velocity, 0, 0, 0, "Angular velocity", "rad/s"}
                    : Uff58Axis{uff_data_type::velocity, 1, 0, 0, "Velocity", "m/s"};
  case identify::Quantity::acceleration:
    return rotation
               ? Uff58Axis{uff_data_type::acceleration, 0, 0, 0, "Angular acceleration", "rad/s^2"}
               : Uff58Axis{uff_data_type::acceleration, 1, 0, 0, "Acceleration", "m/s^2"};
  }
  throw std::logic_error("uff58_axis: unknown quantity");
}

std::vector<Uff58Function> uff58_from_record(const identify::Record& record) {
  const std::string name = record.source.empty() ? std::string("record") : record.source;
  const Eigen::Index n = record.t.size();
  if (n < 2)
    throw Error(fmt::format("{}: {} sample{}, expected at least 2", name, n, n == 1 ? "" : "s"));
  if (!record.t.allFinite()) throw Error(name + ": t has NaN or infinite values");
  const double dt = record.dt();
  if (!(dt > 0.0)) throw Error(fmt::format("{}: time does not increase (step {} s)", name, dt));
  for (Eigen::Index i = 1; i < n; ++i) {
    const double step = record.t(i) - record.t(i - 1);
    if (std::abs(step - dt) > 1e-6 * dt)
      throw Error(fmt::format("{}: time step {} s at sample {} differs from the mean step {} s by "
                              "more than 1e-6 (relative): dataset 58 needs uniform sampling",
                              name, step, i + 1, dt));
  }
  if (record.excitation_hz && !(std::isfinite(*record.excitation_hz) && *record.excitation_hz > 0))
    throw Error(
        fmt::format("{}: excitation_hz {} is not a frequency > 0", name, *record.excitation_hz));

  std::vector<Uff58Function> functions;
  for (std::size_t c = 0; c < record.channels.size(); ++c) {
    const identify::Channel& channel = record.channels[c];
    if (channel.samples.size() != n)
      throw Error(fmt::format("{}: channel {} has {} samples but t has {}", name, channel.name(),
                              channel.samples.size(), n));
    if (!channel.samples.allFinite())
      throw Error(fmt::format("{}: channel {} has NaN or infinite values", name, channel.name()));
    const bool rotation = fem::is_rotation(channel.at.dof);
    Uff58Function f;
    f.id_lines[0] = channel.name();
    if (record.excitation_hz)
      f.id_lines[1] = fmt::format("excitation_hz = {}", *record.excitation_hz);
    f.function_type = uff_function_type::time_response;
    f.function_id = static_cast<int>(c + 1);
    f.response_node = channel.at.node;
    f.response_direction = static_cast<int>(channel.at.dof) + 1;
    f.ordinate_type = 4;
    f.even = true;
    f.abscissa_min = record.t(0);
    f.abscissa_increment = dt;
    f.abscissa = {uff_data_type::time, 0, 0, 0, "Time", "s"};
    f.ordinate = uff58_axis(channel.quantity, rotation);
    f.data = channel.samples;
    functions.push_back(std::move(f));
  }
  return functions;
}

std::vector<frf::MeasuredFunction> uff58_frfs(const std::vector<Uff58Function>& functions,
                                              const std::filesystem::path& path) {
  if (functions.empty())
    throw Error(fmt::format("{}: no dataset 58 (function at nodal DOF) in the file; expected "
                            "FRFs (function type 4)",
                            path.string()));
  std::vector<frf::MeasuredFunction> out;
  for (const Uff58Function& f : functions) {
    const std::string at = where(path, f);
    const auto error = [&](const std::string& what) {
      return Error(fmt::format("{}: {}", at, what));
    };
    if (f.function_type != uff_function_type::frequency_response)
      throw error(fmt::format("record 6 field 1 (function type) is {} ({}): the substructure's "
                              "FRFs are frequency response functions (4)",
                              f.function_type, uff_function_type_name(f.function_type)));
    if (!f.is_complex())
      throw error(fmt::format("record 7 field 1 (ordinate data type) is {} ({}): an FRF must be "
                              "complex (5 or 6)",
                              f.ordinate_type, ordinate_type_text(f.ordinate_type)));
    frf::MeasuredFunction m;
    m.source = at;
    const auto dof_of = [&](int node, int direction, int field, const char* what) {
      if (node <= 0)
        throw error(fmt::format("record 6 field {} ({} node) is {}: expected a node id > 0", field,
                                what, node));
      if (direction == 0 || std::abs(direction) > 6)
        throw error(fmt::format("record 6 field {} ({} direction) is {}: an FRF needs a "
                                "direction ±1…6 (X, Y, Z, RX, RY, RZ)",
                                field + 1, what, direction_text(direction)));
      return fem::NodeDof{node, fem::all_dofs[static_cast<std::size_t>(std::abs(direction) - 1)]};
    };
    m.response = dof_of(f.response_node, f.response_direction, 6, "response");
    m.drive = dof_of(f.reference_node, f.reference_direction, 9, "reference");
    // Numerator: displacement, velocity or acceleration; denominator: the force (or moment).
    const AxisScale num = axis_scale(f, f.ordinate, 9, fem::is_rotation(m.response.dof), error);
    if (num.quantity == identify::Quantity::force)
      throw error("record 9 field 1 (ordinate specific data type) is 13 (excitation force): an "
                  "FRF's numerator is the response (8 displacement, 11 velocity, 12 "
                  "acceleration)");
    AxisScale den;
    if (f.denominator.data_type == uff_data_type::unknown && no_label(f.denominator.units_label))
      den.factor = f.units ? 1.0 / (fem::is_rotation(m.drive.dof) ? f.units->length * f.units->force
                                                                  : f.units->force)
                           : 1.0; // not given: a force in the file's units
    else
      den = axis_scale(f, f.denominator, 10, fem::is_rotation(m.drive.dof), error);
    if (den.quantity != identify::Quantity::force)
      throw error(fmt::format("record 10 field 1 (denominator specific data type) is {} ({}): an "
                              "FRF is per excitation force (13)",
                              f.denominator.data_type,
                              uff_data_type_name(f.denominator.data_type)));
    double sign = num.factor / den.factor;
    if ((f.response_direction < 0) != (f.reference_direction < 0)) sign = -sign;
    // Abscissa: frequency in Hz.
    const Uff58Axis& a = f.abscissa;
    if (a.data_type != uff_data_type::frequency && a.data_type != uff_data_type::unknown &&
        a.data_type != uff_data_type::general)
      throw error(fmt::format("record 8 field 1 (abscissa specific data type) is {} ({}): an "
                              "FRF's abscissa is frequency (18)",
                              a.data_type, uff_data_type_name(a.data_type)));
    if (!no_label(a.units_label)) {
      const std::string label = normalise_unit(trim(a.units_label));
      if (label != "Hz" && label != "hz" && label != "Frequency" && label != "frequency")
        throw error(fmt::format("record 8 field 6 (axis units label) '{}' is not a unit of "
                                "frequency that jointid reads (Hz)",
                                trim(a.units_label)));
    }
    const Eigen::Index n = f.complex_data.size();
    for (Eigen::Index i = 0; i < n; ++i) {
      const double freq = f.even ? f.abscissa_min + static_cast<double>(i) * f.abscissa_increment
                                 : f.abscissa_values(i);
      if (!std::isfinite(freq) || freq < 0.0)
        throw error(fmt::format("record {} (abscissa) point {} is at {} Hz: expected a finite "
                                "frequency >= 0",
                                f.even ? 7 : 12, i + 1, freq));
      if (!m.frequencies_hz.empty() && !(freq > m.frequencies_hz.back()))
        throw error(fmt::format("record 12 (data values) point {} is at {} Hz, not above the "
                                "previous point ({} Hz): the frequencies must increase",
                                i + 1, freq, m.frequencies_hz.back()));
      std::complex<double> v = sign * f.complex_data(i);
      const double w = 2.0 * std::numbers::pi * freq;
      if (num.quantity != identify::Quantity::displacement && freq == 0.0)
        continue; // mobility and accelerance say nothing of the receptance at 0 Hz
      if (num.quantity == identify::Quantity::velocity) v /= std::complex<double>(0.0, w);
      if (num.quantity == identify::Quantity::acceleration) v /= -w * w;
      if (!std::isfinite(v.real()) || !std::isfinite(v.imag()))
        throw error(fmt::format("record 12 (data values) point {} ({} Hz) is {}{:+}i, not a "
                                "finite receptance in SI units",
                                i + 1, freq, f.complex_data(i).real(), f.complex_data(i).imag()));
      m.frequencies_hz.push_back(freq);
      m.receptance.push_back(v);
    }
    if (m.frequencies_hz.size() < 2)
      throw error(fmt::format("record 7 field 2 (number of points) gives {} usable line(s): an "
                              "FRF needs at least 2",
                              m.frequencies_hz.size()));
    for (const frf::MeasuredFunction& other : out)
      if (other.response == m.response && other.drive == m.drive)
        throw error(fmt::format("the FRF {}/{} (response/reference) is already in {}",
                                fem::to_string(m.response), fem::to_string(m.drive), other.source));
    out.push_back(std::move(m));
  }
  return out;
}

} // namespace jointid::io
