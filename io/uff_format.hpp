#pragma once
/// Internal to jointid_io: the text of a universal file as its reader (io/uff58.cpp), its writer
/// (io/uff58_write.cpp) and the mapping of its functions into tests and FRFs
/// (io/uff58_mapping.cpp) share it: blank-separated fields, numbers in E or Fortran D form,
/// lines with their numbers, records cut by the standard's columns or at blanks, and the
/// messages that name a dataset, record and field.
#include "fem/text.hpp"

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace jointid::io::detail {

// ---------------------------------------------------------------------------------------------
// Text

using jointid::trim; // fem/text.hpp
std::string_view trim_right(std::string_view s);
std::vector<std::string_view> blank_separated(std::string_view s);
/// A line or field as it may be shown in a message: at most 40 characters, non-printable bytes
/// (binary data read as text) as '?', in double quotes.
std::string shown(std::string_view s);
std::optional<int> parse_int(std::string_view s);
/// A real number in E, D (Fortran) or plain form; "nan" and "inf" too.
std::optional<double> parse_real(std::string_view s);
/// Finite, but rounds to infinity in single precision.
bool beyond_single(double v);
/// The `    -1` that opens and closes a dataset.
bool is_delimiter(std::string_view line);
/// "1st", "2nd", "11th", ...
std::string ordinal(std::size_t n);
/// "real double precision", ... (record 7 field 1).
std::string ordinate_type_text(int type);
/// "2 (+Y)", "-6 (-RZ)", "0 (scalar)" (record 6 fields 7 and 10).
std::string direction_text(int direction);

/// Little-endian IEEE 754 values of 4 or 8 bytes (58b).
double read_le(const char* p, int bytes);
void append_le(std::string& out, double value, int bytes);

// ---------------------------------------------------------------------------------------------
// Lines of the file, with their numbers and byte offsets.

struct Line {
  std::string_view text; ///< without the line break
  int number = 0;        ///< 1-based
  std::size_t offset = 0;
};

class Scanner {
public:
  explicit Scanner(std::string_view data);
  std::optional<Line> next();
  /// The next n bytes (binary data); line numbers keep counting the line breaks among them.
  std::string_view take(std::size_t n);
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

Fields by_columns(std::string_view line, std::span<const FieldSpec> specs);
/// At least `at_least` and at most specs.size() fields; missing ones keep their defaults.
Fields by_blanks(std::string_view line, std::span<const FieldSpec> specs, std::size_t at_least);

// ---------------------------------------------------------------------------------------------
// The dataset being read, for messages.

struct Dataset {
  const std::string& file;
  int index = 0;       ///< 1-based among all datasets of the file
  int number = 0;      ///< 58, 164, ...
  bool binary = false; ///< 58b
  int open_line = 0;

  std::string tag() const;
  [[noreturn]] void fail(int line, const std::string& what) const;
  [[noreturn]] void fail_at_byte(std::size_t offset, const std::string& what) const;
};

/// "record 7 (data form)", "record 2 (ID line 2)", ...
std::string record_name(int record);
/// "record 6 field 7 (response direction), <what>" or "record 6: <what>".
std::string field_failure(int record, std::span<const FieldSpec> specs, const FieldFailure& f);

} // namespace jointid::io::detail
