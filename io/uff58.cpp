#include "io/uff58.hpp"

#include "io/files.hpp"
#include "io/uff_format.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <span>
#include <string_view>

namespace jointid::io {

using namespace detail;

namespace {

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

// Record 12 of a 58b: `header.bytes` bytes of little-endian IEEE 754 values, then the closing
// -1. `points` values of f's form (record 7).
std::vector<double> read_binary_values(Scanner& s, const Dataset& d, const Line& identifier,
                                       const BinaryHeader& header, const Uff58Function& f,
                                       int points) {
  const bool single = f.ordinate_type == 2 || f.ordinate_type == 5;
  const std::size_t per_point = (f.is_complex() ? 2u : 1u) + (f.even ? 0u : 1u);
  const std::size_t expected = static_cast<std::size_t>(points) * per_point;
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
    d.fail_at_byte(start, fmt::format("{} (binary): expected {} bytes ({}), the file ends after "
                                      "{}",
                                      record_name(12), count, data_form(f, points), s.remaining()));
  const std::string_view data = s.take(count);
  std::vector<double> values;
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
  return values;
}

// Record 12 as text, up to and with the closing -1 (`previous`: the line of record 11).
std::vector<double> read_ascii_values(Scanner& s, const Dataset& d, int previous,
                                      const Uff58Function& f, int points) {
  const bool single = f.ordinate_type == 2 || f.ordinate_type == 5;
  const std::size_t per_point = (f.is_complex() ? 2u : 1u) + (f.even ? 0u : 1u);
  const std::size_t expected = static_cast<std::size_t>(points) * per_point;
  std::vector<double> values;
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
                           record_name(12), values.size(), values.size() == 1 ? "" : "s", expected,
                           record_name(7), data_form(f, points)));
      return values;
    }
    for (const std::string_view token : blank_separated(line->text)) {
      const auto value = parse_real(token);
      if (!value)
        d.fail(line->number, fmt::format("{} value {}: expected a number, got {}", record_name(12),
                                         values.size() + 1, shown(token)));
      if (values.size() == expected)
        d.fail(line->number,
               fmt::format("{}: more than the {} values of {} ({}); is the "
                           "closing '    -1' missing?",
                           record_name(12), expected, data_form(f, points), record_name(7)));
      double v = *value;
      if (single) {
        if (beyond_single(v))
          d.fail(line->number,
                 fmt::format("{} value {}: {} is beyond single precision ({})", record_name(12),
                             values.size() + 1, shown(token), ordinate_type_text(f.ordinate_type)));
        v = static_cast<float>(v);
      }
      values.push_back(v);
    }
  }
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

  const std::vector<double> values = d.binary
                                         ? read_binary_values(s, d, identifier, header, f, points)
                                         : read_ascii_values(s, d, previous, f, points);
  const std::size_t per_point = (f.is_complex() ? 2u : 1u) + (f.even ? 0u : 1u);
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

} // namespace jointid::io
