#include "io/measured_frf_file.hpp"

#include "fem/text.hpp"
#include "frf/sweep.hpp"
#include "io/files.hpp"
#include "io/uff58.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>

namespace jointid::io {

namespace {

std::vector<std::string_view> split(std::string_view s, char by) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t at = s.find(by, start);
    out.push_back(trim(s.substr(start, at == std::string_view::npos ? at : at - start)));
    if (at == std::string_view::npos) return out;
    start = at + 1;
  }
}

std::optional<double> number(std::string_view s) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

bool is_uff(const std::string& text) {
  const std::size_t b = text.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return false;
  const std::size_t e = text.find('\n', b);
  return trim(std::string_view(text).substr(b, e == std::string::npos ? e : e - b)) == "-1";
}

} // namespace

std::vector<frf::MeasuredFunction> read_frf_csv(const std::filesystem::path& path) {
  std::string text = read_file(path);
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  const std::string file = path.string();
  const auto fail = [&](int line, const std::string& what) -> Error {
    return Error(fmt::format("{}:{}: {}", file, line, what));
  };
  std::optional<fem::NodeDof> drive;
  int drive_line = 0;
  frf::FrfKind kind = frf::FrfKind::receptance;
  std::vector<fem::NodeDof> responses;
  std::vector<frf::MeasuredFunction> out;
  bool header = false;
  int line_no = 0;
  std::size_t pos = 0;
  const auto set_drive = [&](std::string_view dof, int line) {
    if (drive)
      throw fail(line, fmt::format("the drive is given twice (line {} and here)", drive_line));
    try {
      drive = fem::parse_node_dof(dof);
    } catch (const std::invalid_argument&) {
      throw fail(line, fmt::format("expected the drive as NODE:DOF such as 7:uy, got '{}'", dof));
    }
    if (drive->node <= 0)
      throw fail(line, fmt::format("the drive {} has node id {}: expected > 0 (0 means ground)",
                                   dof, drive->node));
    drive_line = line;
  };
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = trim(std::string_view(text).substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (line.empty()) continue;
    if (line.front() == '#') {
      if (header) continue;
      const std::string_view c = trim(line.substr(1));
      // "<kind> from a force|moment at N:dof: ..." (jointid frf), "drive = N:dof", "kind = k".
      for (const char* k : {"receptance", "mobility", "accelerance"})
        if (c.starts_with(k)) {
          const std::size_t at = c.find(" at ");
          const std::string_view rest = at == std::string_view::npos ? "" : c.substr(at + 4);
          const std::size_t colon2 = rest.find(':', rest.find(':') + 1);
          if (c.substr(std::string_view(k).size()).starts_with(" from a ") && !rest.empty()) {
            kind = frf::parse_frf_kind(k);
            set_drive(trim(rest.substr(0, colon2)), line_no);
          }
        }
      const auto parts = split(c, '=');
      if (parts.size() == 2 && parts[0] == "drive") set_drive(parts[1], line_no);
      if (parts.size() == 2 && parts[0] == "kind") {
        try {
          kind = frf::parse_frf_kind(parts[1]);
        } catch (const std::invalid_argument& e) {
          throw fail(line_no, e.what());
        }
      }
      continue;
    }
    const std::vector<std::string_view> cells = split(line, ',');
    if (!header) {
      if (!drive)
        throw fail(line_no, "no drive given before the header: add a comment line '# drive = "
                            "NODE:DOF' (e.g. '# drive = 7:uy'), as `jointid frf` writes it");
      if (cells[0] != "freq_hz")
        throw fail(line_no,
                   fmt::format("expected the header to start with freq_hz, got '{}'", cells[0]));
      if (cells.size() < 3 || cells.size() % 2 == 0)
        throw fail(line_no, "expected freq_hz and a pair of columns NODE:DOF.re, NODE:DOF.im per "
                            "response");
      for (std::size_t c = 1; c < cells.size(); c += 2) {
        const std::string_view re = cells[c], im = cells[c + 1];
        if (!re.ends_with(".re") || !im.ends_with(".im") ||
            re.substr(0, re.size() - 3) != im.substr(0, im.size() - 3))
          throw fail(line_no, fmt::format("columns {} and {} ('{}', '{}'): expected "
                                          "NODE:DOF.re and NODE:DOF.im of the same DOF",
                                          c + 1, c + 2, re, im));
        fem::NodeDof at;
        try {
          at = fem::parse_node_dof(re.substr(0, re.size() - 3));
        } catch (const std::invalid_argument&) {
          throw fail(line_no, fmt::format("column {} ('{}'): expected NODE:DOF.re such as 7:uy.re",
                                          c + 1, re));
        }
        if (at.node <= 0)
          throw fail(line_no, fmt::format("column {} ('{}'): node id {}: expected > 0 (0 means "
                                          "ground)",
                                          c + 1, re, at.node));
        if (std::find(responses.begin(), responses.end(), at) != responses.end())
          throw fail(line_no,
                     fmt::format("response {} has two pairs of columns", fem::to_string(at)));
        responses.push_back(at);
        frf::MeasuredFunction f;
        f.response = at;
        f.drive = *drive;
        f.source = file;
        out.push_back(std::move(f));
      }
      header = true;
      continue;
    }
    if (cells.size() != 1 + 2 * responses.size())
      throw fail(line_no, fmt::format("expected {} values (freq_hz and {} pairs), got {}",
                                      1 + 2 * responses.size(), responses.size(), cells.size()));
    std::vector<double> v(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const auto x = number(cells[c]);
      if (!x || !std::isfinite(*x))
        throw fail(line_no,
                   fmt::format("column {}: expected a finite number, got '{}'", c + 1, cells[c]));
      v[c] = *x;
    }
    const double freq = v[0];
    if (freq < 0.0) throw fail(line_no, fmt::format("freq_hz {} is negative", freq));
    if (!out.front().frequencies_hz.empty() && !(freq > out.front().frequencies_hz.back()))
      throw fail(line_no, fmt::format("freq_hz {} is not above the previous row's", freq));
    if (kind != frf::FrfKind::receptance && freq == 0.0) continue;
    const double w = 2.0 * std::numbers::pi * freq;
    for (std::size_t r = 0; r < responses.size(); ++r) {
      std::complex<double> h(v[1 + 2 * r], v[2 + 2 * r]);
      if (kind == frf::FrfKind::mobility) h /= std::complex<double>(0.0, w);
      if (kind == frf::FrfKind::accelerance) h /= -w * w;
      if (!std::isfinite(h.real()) || !std::isfinite(h.imag()))
        throw fail(line_no, fmt::format("columns {} and {}: {} {} at {} Hz is not a finite "
                                        "receptance (H = {} / {})",
                                        2 + 2 * r, 3 + 2 * r, v[1 + 2 * r], v[2 + 2 * r], freq,
                                        kind == frf::FrfKind::mobility ? "Y" : "A",
                                        kind == frf::FrfKind::mobility ? "iω" : "−ω²"));
      out[r].frequencies_hz.push_back(freq);
      out[r].receptance.push_back(h);
    }
  }
  if (!header)
    throw fail(line_no, "no header freq_hz,NODE:DOF.re,NODE:DOF.im,... (the file holds only "
                        "comments)");
  if (out.front().frequencies_hz.size() < 2)
    throw fail(line_no, fmt::format("{} row(s) of values: an FRF needs at least 2 lines",
                                    out.front().frequencies_hz.size()));
  return out;
}

frf::MeasuredFrf read_measured_frf(const std::vector<std::filesystem::path>& files) {
  frf::MeasuredFrf out;
  for (const auto& path : files) {
    const std::string text = read_file(path);
    std::vector<frf::MeasuredFunction> functions =
        is_uff(text) ? uff58_frfs(read_uff58(path), path) : read_frf_csv(path);
    for (frf::MeasuredFunction& f : functions) {
      for (const frf::MeasuredFunction& other : out.functions)
        if (other.response == f.response && other.drive == f.drive)
          throw Error(fmt::format("{}: the FRF {}/{} (response/drive) is also in {}", f.source,
                                  fem::to_string(f.response), fem::to_string(f.drive),
                                  other.source));
      for (const fem::NodeDof& at : {f.response, f.drive})
        if (std::find(out.dofs.begin(), out.dofs.end(), at) == out.dofs.end())
          out.dofs.push_back(at);
      out.functions.push_back(std::move(f));
    }
  }
  if (out.functions.empty()) throw Error("measured FRFs: no file given");
  return out;
}

} // namespace jointid::io
