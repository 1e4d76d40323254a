#include "io/low_level_test.hpp"

#include "fem/text.hpp"
#include "io/files.hpp"
#include "io/measured_frf_file.hpp"
#include "io/record_csv.hpp"
#include "io/uff58.hpp"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <stdexcept>
#include <string_view>
#include <variant>

namespace jointid::io {

namespace {

namespace fs = std::filesystem;

// "--max-order" on the command line, "max_order" in Python.
std::string option(const ModalFitArguments& a, std::string name) {
  if (a.cli) return "--" + name;
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

} // namespace

LowLevelInput low_level_input(const fs::path& path) {
  const std::string text = read_file(path);
  std::string_view rest = text;
  if (rest.starts_with("\xEF\xBB\xBF")) rest.remove_prefix(3);
  std::string_view first; // the first line that is neither blank nor a comment
  bool universal = false, seen = false;
  while (!rest.empty()) {
    const auto end = rest.find('\n');
    const std::string_view line = trim(rest.substr(0, end));
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    if (line.empty()) continue;
    if (!seen && line == "-1") universal = true;
    seen = true;
    if (universal) break;
    if (line.front() == '#') continue;
    first = line;
    break;
  }
  if (universal) {
    const std::vector<Uff58Function> functions = read_uff58(path);
    if (!functions.empty() &&
        functions.front().function_type == uff_function_type::frequency_response)
      return LowLevelInput::frf;
    return LowLevelInput::uff_record; // uff58_tests says what it refuses
  }
  const std::string_view column = trim(first.substr(0, first.find(',')));
  if (column != "freq_hz") return LowLevelInput::csv_record; // read_record says what it refuses
  if (first.find('@') != std::string_view::npos)
    throw Error(path.string() +
                ": a stepped-sine table (freq_hz and channel columns such as f@7:uy.re): "
                "modal-fit reads time records (t, f@..., a@...) or FRF files (freq_hz and "
                "NODE:DOF.re, NODE:DOF.im columns, or universal files of FRFs)");
  return LowLevelInput::frf;
}

void add_low_level_files(LowLevelTest& test, const std::vector<fs::path>& paths) {
  std::map<fs::path, std::string> seen;
  for (const fs::path& path : paths) {
    std::error_code ec;
    fs::path key = fs::weakly_canonical(path, ec);
    if (ec) key = path;
    if (!seen.emplace(key, path.string()).second)
      throw Error(path.string() + ": given twice (its blocks would count twice)");
    const LowLevelInput kind = low_level_input(path);
    if (kind == LowLevelInput::frf) {
      test.frf_files.push_back(path);
    } else if (kind == LowLevelInput::csv_record) {
      test.records.push_back(read_record(path));
    } else {
      for (auto& t : uff58_tests(read_uff58(path), path))
        test.records.push_back(std::get<identify::Record>(std::move(t)));
    }
  }
  if (!test.records.empty() && !test.frf_files.empty())
    throw Error(fmt::format("{} is a time record but {} holds FRFs: give modal-fit one or the "
                            "other",
                            test.records.front().source, test.frf_files.front().string()));
}

void check_modal_fit_arguments(const ModalFitArguments& a) {
  if (!(std::isfinite(a.f0_hz) && std::isfinite(a.f1_hz) && a.f0_hz >= 0.0 && a.f1_hz > a.f0_hz))
    throw Error(fmt::format("{}: expected 0 <= F0 < F1 (Hz), got {} and {}", option(a, "band"),
                            a.f0_hz, a.f1_hz));
  if (a.modes < 0)
    throw Error(fmt::format("{}: expected 0 or more, got {}", option(a, "modes"), a.modes));
  if (a.max_order != 0 && a.max_order < 4)
    throw Error(fmt::format("{}: expected 0 (automatic) or at least 4, got {}",
                            option(a, "max-order"), a.max_order));
  if (a.spectra != "auto" && a.spectra != "welch" && a.spectra != "periods" && a.spectra != "whole")
    throw Error(fmt::format("{}: expected auto, welch, periods or whole, got \"{}\"",
                            option(a, "spectra"), a.spectra));
  if (a.segment != 0 && a.segment < 8)
    throw Error(fmt::format("{}: expected at least 8 samples (or 0: automatic), got {}",
                            option(a, "segment"), a.segment));
  if (!(std::isfinite(a.period_s) && a.period_s >= 0.0))
    throw Error(fmt::format("{}: expected seconds > 0, got {}", option(a, "period"), a.period_s));
  if (a.segment != 0 && a.spectra != "welch" && a.spectra != "auto")
    throw Error(fmt::format("{}: only with {} welch or auto, not {}", option(a, "segment"),
                            option(a, "spectra"), a.spectra));
  if (a.period_s > 0.0 && a.spectra != "periods" && a.spectra != "auto")
    throw Error(fmt::format("{}: only with {} periods or auto, not {}", option(a, "period"),
                            option(a, "spectra"), a.spectra));
}

LowLevelFit fit_low_level_test(const LowLevelTest& test, const ModalFitArguments& a) {
  check_modal_fit_arguments(a);
  if (test.records.empty() && test.frf_files.empty())
    throw Error("modal-fit: expected time records or FRF files, got none");
  if (!test.frf_files.empty() && (a.segment != 0 || a.period_s > 0.0 || a.spectra != "auto"))
    throw Error(fmt::format("{}, {}, {}: for time records, not FRF files", option(a, "spectra"),
                            option(a, "segment"), option(a, "period")));
  LowLevelFit out;
  try {
    if (!test.frf_files.empty()) {
      out.data = identify::frfs_from_measured(read_measured_frf(test.frf_files), a.f0_hz, a.f1_hz);
    } else {
      identify::FrfEstimateOptions o;
      o.f0_hz = a.f0_hz;
      o.f1_hz = a.f1_hz;
      o.method = a.spectra == "welch"     ? identify::SpectraMethod::welch
                 : a.spectra == "periods" ? identify::SpectraMethod::periods
                 : a.spectra == "whole"   ? identify::SpectraMethod::whole
                                          : identify::SpectraMethod::automatic;
      o.segment = a.segment;
      o.period_s = a.period_s;
      out.data = identify::frfs_from_records(test.records, o);
    }
    identify::ModalFitOptions o;
    o.modes = a.modes;
    o.max_order = a.max_order;
    out.fit = identify::modal_fit(out.data, o);
  } catch (const std::invalid_argument& e) {
    throw Error(e.what()); // it names the record, the band or the channels
  }
  return out;
}

} // namespace jointid::io
