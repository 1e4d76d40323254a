#include "io/record_csv.hpp"

#include "fem/text.hpp"
#include "identify/harmonics.hpp"
#include "io/files.hpp"
#include "io/uff58.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <iterator>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string_view>

namespace jointid::io {

namespace {

struct CsvLine {
  int number = 0; ///< 1-based line in the file, 0 = none
  std::string_view text;
};

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    fields.push_back(trim(line.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// A CSV file split into its comment block, header and data rows, with line numbers.
struct CsvText {
  std::string name;
  std::string text;
  std::vector<CsvLine> comments; ///< text after '#'
  CsvLine header;
  std::vector<CsvLine> rows;

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw Error(line > 0 ? fmt::format("{}:{}: {}", name, line, what)
                         : fmt::format("{}: {}", name, what));
  }
};

CsvText scan(const std::filesystem::path& path, std::string_view header_example) {
  CsvText csv;
  csv.name = path.string();
  csv.text = read_file(path);
  std::string_view rest = csv.text;
  // Some test systems start their CSV files with a UTF-8 byte-order mark: skip it.
  if (rest.starts_with("\xEF\xBB\xBF")) rest.remove_prefix(3);
  int number = 0;
  while (!rest.empty()) {
    const auto newline = rest.find('\n');
    const std::string_view raw = rest.substr(0, newline);
    rest = newline == std::string_view::npos ? std::string_view{} : rest.substr(newline + 1);
    ++number;
    const std::string_view line = trim(raw);
    if (line.empty()) continue;
    if (line.front() == '#') {
      if (csv.header.number != 0)
        csv.fail(number,
                 "comment after the header (comment lines must come before the header row)");
      csv.comments.push_back({number, trim(line.substr(1))});
    } else if (csv.header.number == 0) {
      csv.header = {number, line};
    } else {
      csv.rows.push_back({number, line});
    }
  }
  if (csv.header.number == 0)
    csv.fail(
        0, fmt::format("missing header: the file has no header row (expected e.g. {}) and no data",
                       header_example));
  if (parse_double(split_fields(csv.header.text).front()))
    csv.fail(csv.header.number,
             fmt::format("missing header: expected a header row such as {} before the numbers, got "
                         "a row of numbers",
                         header_example));
  return csv;
}

// The rows as numbers, one vector per column; checks field counts and finiteness.
std::vector<std::vector<double>> parse_rows(const CsvText& csv,
                                            const std::vector<std::string>& columns,
                                            std::string_view what_columns) {
  const std::size_t width = columns.size();
  std::vector<std::vector<double>> data(width);
  for (auto& column : data)
    column.reserve(csv.rows.size());
  for (const CsvLine& row : csv.rows) {
    const auto fields = split_fields(row.text);
    if (fields.size() != width)
      csv.fail(row.number, fmt::format("row has {} field{}, expected {} ({})", fields.size(),
                                       fields.size() == 1 ? "" : "s", width, what_columns));
    for (std::size_t c = 0; c < width; ++c) {
      const auto value = parse_double(fields[c]);
      const std::string where = fmt::format("column {} ({})", c + 1, columns[c]);
      if (!value)
        csv.fail(row.number, fmt::format("{}: expected a number, got {}", where,
                                         fields[c].empty() ? std::string("an empty field")
                                                           : fmt::format("\"{}\"", fields[c])));
      if (!std::isfinite(*value))
        csv.fail(row.number,
                 fmt::format("{}: expected a finite number, got \"{}\" (NaN or infinite)", where,
                             fields[c]));
      data[c].push_back(*value);
    }
  }
  return data;
}

// `key = value` (spaces around '=' optional): the value, else nothing.
std::optional<std::string_view> declared_value(std::string_view text, std::string_view key) {
  if (!text.starts_with(key)) return std::nullopt;
  const std::string_view after = trim(text.substr(key.size()));
  if (after.empty() || after.front() != '=') return std::nullopt; // some other comment
  return trim(after.substr(1));
}

} // namespace

identify::Record read_record(const std::filesystem::path& path) {
  const CsvText csv = scan(path, "t,f@7:uy,x@7:uy");
  identify::Record record;
  record.source = path.string();

  // The comments that declare what the record is: `key = value`, other comments ignored.
  auto declared = [](const CsvLine& c, std::string_view key) {
    return declared_value(c.text, key);
  };
  int sine_line = 0, period_line = 0, sweep_line = 0;
  for (const CsvLine& c : csv.comments) {
    if (const auto value_text = declared(c, "excitation_hz")) {
      const auto value = parse_double(*value_text);
      if (!value || !std::isfinite(*value) || !(*value > 0.0))
        csv.fail(c.number, fmt::format("excitation_hz: expected a frequency > 0 Hz, got \"{}\"",
                                       *value_text));
      if (record.excitation_hz && *record.excitation_hz != *value)
        csv.fail(c.number, fmt::format("excitation_hz given twice ({} and {} Hz)",
                                       *record.excitation_hz, *value));
      record.excitation_hz = *value;
      sine_line = c.number;
    } else if (const auto period_text = declared(c, "period_s")) {
      const auto value = parse_double(*period_text);
      if (!value || !std::isfinite(*value) || !(*value > 0.0))
        csv.fail(c.number,
                 fmt::format("period_s: expected a period > 0 s, got \"{}\"", *period_text));
      if (record.period_s && *record.period_s != *value)
        csv.fail(c.number,
                 fmt::format("period_s given twice ({} and {} s)", *record.period_s, *value));
      record.period_s = *value;
      period_line = c.number;
    } else if (const auto kind = declared(c, "excitation")) {
      if (*kind != "sweep")
        csv.fail(c.number,
                 fmt::format("excitation: expected \"sweep\" (a sine sweep), got \"{}\" (a sine "
                             "test is declared by excitation_hz = F, a periodic test by "
                             "period_s = T)",
                             *kind));
      record.sweep = true;
      sweep_line = c.number;
    }
  }
  // One record is one kind of test.
  const std::pair<int, const char*> kinds[] = {{sine_line, "excitation_hz (a sine test)"},
                                               {period_line, "period_s (a periodic test)"},
                                               {sweep_line, "excitation = sweep (a sweep)"}};
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t b = a + 1; b < 3; ++b)
      if (kinds[a].first > 0 && kinds[b].first > 0)
        csv.fail(std::max(kinds[a].first, kinds[b].first),
                 fmt::format("{} and {} both declared (lines {} and {}): a record is one kind "
                             "of test",
                             kinds[a].second, kinds[b].second, kinds[a].first, kinds[b].first));

  // Header: t, then channels.
  const auto names = split_fields(csv.header.text);
  if (names.front() != "t")
    csv.fail(
        csv.header.number,
        fmt::format("header: the first column must be 't' (time in s), got \"{}\"", names.front()));
  if (names.size() < 2)
    csv.fail(csv.header.number, "header: no channels after 't' (expected e.g. t,f@7:uy,x@7:uy)");
  std::vector<std::string> columns{"t"};
  std::map<std::string, std::size_t> seen;
  for (std::size_t c = 1; c < names.size(); ++c) {
    const std::string name(names[c]);
    identify::Channel channel;
    try {
      channel = identify::parse_channel_name(name);
    } catch (const std::invalid_argument& e) {
      csv.fail(csv.header.number, fmt::format("header: column {}: {}", c + 1, e.what()));
    }
    const auto [it, inserted] = seen.emplace(channel.name(), c + 1);
    if (!inserted)
      csv.fail(csv.header.number,
               fmt::format("header: column {}: channel {} appears twice (columns {} and {})", c + 1,
                           name, it->second, c + 1));
    record.channels.push_back(std::move(channel));
    columns.push_back(name);
  }

  const auto data = parse_rows(
      csv, columns,
      fmt::format("t and {} channel{}", columns.size() - 1, columns.size() == 2 ? "" : "s"));
  const std::size_t n = csv.rows.size();
  if (n < 4)
    csv.fail(csv.header.number,
             fmt::format("only {} data row{}, expected at least 4", n, n == 1 ? "" : "s"));

  // Time: strictly increasing and uniform.
  const std::vector<double>& t = data[0];
  for (std::size_t i = 1; i < n; ++i)
    if (!(t[i] > t[i - 1]))
      csv.fail(csv.rows[i].number,
               fmt::format("t = {} does not increase from the previous row's t = {} (time must "
                           "increase strictly)",
                           t[i], t[i - 1]));
  const double mean_step = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
  if (!std::isfinite(mean_step)) // the span overflows: then every deviation would be NaN
    csv.fail(csv.rows[n - 1].number,
             fmt::format("t runs from {} to {} s, a span beyond the range of a double (expected "
                         "the times of a test, in s)",
                         t[0], t[n - 1]));
  for (std::size_t i = 1; i < n; ++i) {
    const double deviation = std::abs((t[i] - t[i - 1]) - mean_step) / mean_step;
    if (deviation > 1e-6)
      csv.fail(csv.rows[i].number, fmt::format("time step {} s differs from the mean step {} s by "
                                               "{:.3g} (relative; sampling must be "
                                               "uniform to 1e-6)",
                                               t[i] - t[i - 1], mean_step, deviation));
  }

  record.t = Eigen::Map<const Eigen::VectorXd>(t.data(), static_cast<Eigen::Index>(n));
  for (std::size_t c = 0; c < record.channels.size(); ++c)
    record.channels[c].samples =
        Eigen::Map<const Eigen::VectorXd>(data[c + 1].data(), static_cast<Eigen::Index>(n));
  return record;
}

std::vector<identify::Record> read_records(const std::vector<std::filesystem::path>& paths) {
  std::vector<identify::Record> records;
  records.reserve(paths.size());
  for (const auto& p : paths)
    records.push_back(read_record(p));
  return records;
}

std::string record_csv(const identify::Record& record, const std::vector<std::string>& comments) {
  const std::string name = record.source.empty() ? std::string("record") : record.source;
  const Eigen::Index n = record.t.size();
  for (const auto& c : record.channels) {
    if (c.samples.size() != n)
      throw Error(fmt::format("{}: channel {} has {} samples but t has {}", name, c.name(),
                              c.samples.size(), n));
    if (!c.samples.allFinite())
      throw Error(fmt::format("{}: channel {} has NaN or infinite values", name, c.name()));
  }
  if (!record.t.allFinite()) throw Error(name + ": t has NaN or infinite values");
  if (record.excitation_hz && !std::isfinite(*record.excitation_hz))
    throw Error(name + ": excitation_hz is not a finite number");
  if (record.period_s && !(std::isfinite(*record.period_s) && *record.period_s > 0.0))
    throw Error(name + ": period_s is not a time > 0 s");
  if (static_cast<int>(record.excitation_hz.has_value()) +
          static_cast<int>(record.period_s.has_value()) + static_cast<int>(record.sweep) >
      1)
    throw Error(name + ": excitation_hz, period_s and sweep: a record is one kind of test");

  std::string out;
  out.reserve(static_cast<std::size_t>(n) * (record.channels.size() + 1) * 24 + 256);
  auto inserter = std::back_inserter(out);
  for (const auto& comment : comments) {
    std::string_view rest = comment;
    while (true) { // one "# " line per line of the comment
      const auto newline = rest.find('\n');
      const std::string_view line = trim(rest.substr(0, newline));
      for (const char* key : {"excitation_hz", "period_s", "excitation"})
        if (declared_value(line, key))
          throw Error(name + ": a comment may not be '" + key +
                      " = ...' (it is written from the record)");
      out += line.empty() ? std::string("#\n") : fmt::format("# {}\n", line);
      if (newline == std::string_view::npos) break;
      rest = rest.substr(newline + 1);
    }
  }
  if (record.excitation_hz)
    fmt::format_to(inserter, "# excitation_hz = {}\n", shortest(*record.excitation_hz));
  if (record.period_s) fmt::format_to(inserter, "# period_s = {}\n", shortest(*record.period_s));
  if (record.sweep) out += "# excitation = sweep\n";
  out += "t";
  for (const auto& c : record.channels)
    fmt::format_to(inserter, ",{}", c.name());
  out += "\n";
  for (Eigen::Index i = 0; i < n; ++i) {
    fmt::format_to(inserter, "{}", record.t(i));
    for (const auto& c : record.channels)
      fmt::format_to(inserter, ",{}", c.samples(i));
    out += "\n";
  }
  return out;
}

void write_record(const std::filesystem::path& path, const identify::Record& record,
                  const std::vector<std::string>& comments) {
  write_file_atomically(path, record_csv(record, comments));
}

namespace {

// The phase conventions a stepped-sine table may state (`# convention = ...`), each as the
// map of its complex amplitude into jointid's x(t) = Re(X e^{iωt}).
enum class PhaseConvention {
  positive, ///< x(t) = Re(X e^{iωt}): jointid's (the default)
  negative, ///< x(t) = Re(X e^{-iωt}): X is the complex conjugate of jointid's
  sine      ///< x(t) = Im(X e^{iωt}) = |X| sin(ωt + arg X): jointid's is −i X
};

// A convention as written, without blanks, '*' or '·', in lower case, with ω or w, i or j,
// e^{...}, e^(...) or exp(...), and an optional "x(t) =" before it.
std::optional<PhaseConvention> parse_phase_convention(std::string_view text) {
  std::string s;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const std::string_view rest = text.substr(i);
    if (rest.starts_with("\xCF\x89")) { // ω
      s += 'w';
      ++i;
    } else if (rest.starts_with("\xC2\xB7")) { // ·
      ++i;
    } else if (rest.starts_with("exp(")) {
      s += "e^(";
      i += 3;
    } else if (text[i] == '{' || text[i] == '}') {
      s += text[i] == '{' ? '(' : ')';
    } else if (text[i] != ' ' && text[i] != '\t' && text[i] != '*') {
      const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
      s += c == 'j' ? 'i' : c;
    }
  }
  if (s.starts_with("x(t)=")) s.erase(0, 5);
  if (s == "re(xe^(iwt))" || s == "re(xe^(+iwt))") return PhaseConvention::positive;
  if (s == "re(xe^(-iwt))") return PhaseConvention::negative;
  if (s == "im(xe^(iwt))" || s == "im(xe^(+iwt))") return PhaseConvention::sine;
  return std::nullopt;
}

} // namespace

SteppedSineTable read_stepped_sine(const std::filesystem::path& path) {
  const CsvText csv = scan(path, "freq_hz,f@7:uy.re,f@7:uy.im,x@7:uy.re,x@7:uy.im");
  // `# convention = x(t) = Re(X e^{iωt})` (the default), `Re(X e^{-iωt})` or `Im(X e^{iωt})`.
  PhaseConvention convention = PhaseConvention::positive;
  int convention_line = 0;
  for (const CsvLine& c : csv.comments) {
    if (!c.text.starts_with("convention")) continue;
    const std::string_view after = trim(c.text.substr(std::string_view("convention").size()));
    if (after.empty() || after.front() != '=') continue; // some other comment
    const std::string_view value_text = trim(after.substr(1));
    const std::optional<PhaseConvention> read = parse_phase_convention(value_text);
    if (!read)
      csv.fail(c.number,
               fmt::format("convention: expected x(t) = Re(X e^{{iωt}}) (jointid's, the "
                           "default), x(t) = Re(X e^{{-iωt}}) or x(t) = Im(X e^{{iωt}}) (a sine "
                           "reference), got \"{}\"",
                           value_text));
    if (convention_line > 0 && *read != convention)
      csv.fail(c.number, fmt::format("convention given twice, differently (first at line {})",
                                     convention_line));
    convention = *read;
    convention_line = c.number;
  }
  const auto names = split_fields(csv.header.text);
  if (names.front() != "freq_hz")
    csv.fail(
        csv.header.number,
        fmt::format(
            "header: the first column must be 'freq_hz' (excitation frequency in Hz), got \"{}\"",
            names.front()));
  if (names.size() < 3 || (names.size() - 1) % 2 != 0)
    csv.fail(csv.header.number, fmt::format("header: expected freq_hz then two columns per channel "
                                            "(<channel>.re, <channel>.im), got {} "
                                            "column{} after freq_hz",
                                            names.size() - 1, names.size() == 2 ? "" : "s"));
  SteppedSineTable table;
  std::map<std::string, std::size_t> seen;
  for (std::size_t c = 1; c < names.size(); c += 2) {
    const std::string_view re = names[c], im = names[c + 1];
    if (!re.ends_with(".re"))
      csv.fail(csv.header.number,
               fmt::format("header: column {}: expected <channel>.re, got \"{}\"", c + 1, re));
    const std::string channel(re.substr(0, re.size() - 3));
    if (im != channel + ".im")
      csv.fail(csv.header.number,
               fmt::format("header: column {}: expected \"{}.im\" after \"{}\", got \"{}\"", c + 2,
                           channel, re, im));
    try {
      identify::parse_channel_name(channel);
    } catch (const std::invalid_argument& e) {
      csv.fail(csv.header.number, fmt::format("header: column {}: {}", c + 1, e.what()));
    }
    const auto [it, inserted] = seen.emplace(channel, c + 1);
    if (!inserted)
      csv.fail(csv.header.number,
               fmt::format("header: column {}: channel {} appears twice (columns {} and {})", c + 1,
                           channel, it->second, c + 1));
    table.channels.push_back(channel);
  }
  std::vector<std::string> columns;
  for (auto name : names)
    columns.emplace_back(name);
  const auto data =
      parse_rows(csv, columns,
                 fmt::format("freq_hz and .re, .im for {} channel{}", table.channels.size(),
                             table.channels.size() == 1 ? "" : "s"));
  const std::size_t n = csv.rows.size();
  if (n == 0) csv.fail(csv.header.number, "no data rows (expected one row per test)");
  for (std::size_t i = 0; i < n; ++i)
    if (!(data[0][i] > 0.0))
      csv.fail(csv.rows[i].number,
               fmt::format("column 1 (freq_hz): expected a frequency > 0 Hz, got {}", data[0][i]));
  table.freq_hz = data[0];
  for (const CsvLine& row : csv.rows)
    table.lines.push_back(row.number);
  table.values.resize(static_cast<Eigen::Index>(n),
                      static_cast<Eigen::Index>(table.channels.size()));
  // Into x(t) = Re(X e^{iωt}): exact (a sign change, or a swap of the parts).
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < table.channels.size(); ++c) {
      const double re = data[1 + 2 * c][i], im = data[2 + 2 * c][i];
      table.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) =
          convention == PhaseConvention::positive   ? std::complex<double>(re, im)
          : convention == PhaseConvention::negative ? std::complex<double>(re, -im)
                                                    : std::complex<double>(im, -re);
    }
  return table;
}

std::string stepped_sine_csv(const SteppedSineTable& table,
                             const std::vector<std::string>& comments) {
  const auto rows = static_cast<Eigen::Index>(table.freq_hz.size());
  if (table.values.rows() != rows ||
      table.values.cols() != static_cast<Eigen::Index>(table.channels.size()))
    throw Error(fmt::format("stepped-sine table: {} × {} values for {} tests and {} channels",
                            table.values.rows(), table.values.cols(), rows, table.channels.size()));
  if (!table.values.allFinite()) throw Error("stepped-sine table: NaN or infinite values");
  std::string out;
  auto inserter = std::back_inserter(out);
  for (const auto& comment : comments)
    out += fmt::format("# {}\n", comment);
  out += "freq_hz";
  for (const auto& c : table.channels)
    fmt::format_to(inserter, ",{}.re,{}.im", c, c);
  out += "\n";
  for (Eigen::Index i = 0; i < rows; ++i) {
    if (!std::isfinite(table.freq_hz[static_cast<std::size_t>(i)]))
      throw Error("stepped-sine table: a frequency is not finite");
    fmt::format_to(inserter, "{}", table.freq_hz[static_cast<std::size_t>(i)]);
    for (Eigen::Index c = 0; c < table.values.cols(); ++c)
      fmt::format_to(inserter, ",{},{}", table.values(i, c).real(), table.values(i, c).imag());
    out += "\n";
  }
  return out;
}

std::vector<identify::SineTest> stepped_sine_tests(const SteppedSineTable& table,
                                                   const std::filesystem::path& path) {
  std::vector<identify::Channel> channels;
  for (const auto& name : table.channels)
    channels.push_back(identify::parse_channel_name(name));
  std::vector<identify::SineTest> tests;
  for (std::size_t i = 0; i < table.freq_hz.size(); ++i) {
    identify::Phasors row;
    row.source = fmt::format("{}:{}", path.string(), i < table.lines.size() ? table.lines[i] : 0);
    row.frequency_hz = table.freq_hz[i];
    for (std::size_t c = 0; c < channels.size(); ++c)
      row.channels.push_back(
          {channels[c].quantity, channels[c].at,
           table.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c))});
    tests.emplace_back(std::move(row));
  }
  return tests;
}

namespace {

// Universal files: .uff, .unv, .uf58, in any case.
bool is_universal_file(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".uff" || extension == ".unv" || extension == ".uf58";
}

} // namespace

std::vector<identify::SineTest> read_tests(const std::vector<std::filesystem::path>& paths) {
  std::vector<identify::SineTest> tests;
  std::map<std::filesystem::path, std::string> seen;
  for (const auto& path : paths) {
    std::error_code ec;
    std::filesystem::path key = std::filesystem::weakly_canonical(path, ec);
    if (ec) key = path;
    if (const auto [it, inserted] = seen.emplace(key, path.string()); !inserted)
      throw Error(fmt::format("{}: given twice{} (each test would count twice and the "
                              "uncertainty come out falsely small)",
                              path.string(),
                              it->second == path.string() ? "" : " (also as " + it->second + ")"));
    if (is_universal_file(path)) {
      for (auto& t : uff58_tests(read_uff58(path), path))
        tests.push_back(std::move(t));
      continue;
    }
    const CsvText csv = scan(path, "t,f@7:uy,x@7:uy (a time record) or "
                                   "freq_hz,f@7:uy.re,f@7:uy.im,x@7:uy.re,x@7:uy.im (a "
                                   "stepped-sine table)");
    const std::string_view first = split_fields(csv.header.text).front();
    if (first == "t") {
      tests.emplace_back(read_record(path));
    } else if (first == "freq_hz") {
      for (auto& t : stepped_sine_tests(read_stepped_sine(path), path))
        tests.push_back(std::move(t));
    } else {
      csv.fail(csv.header.number,
               fmt::format("header: the first column must be 't' (a time record) or 'freq_hz' (a "
                           "stepped-sine table), got \"{}\"",
                           first));
    }
  }
  return tests;
}

} // namespace jointid::io
