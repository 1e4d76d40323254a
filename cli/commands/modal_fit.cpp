// jointid modal-fit: the linear substructure from a low-level test. FRFs by H1 from time records
// (or read from FRF files), modal parameters by LSCF with a stabilisation diagram and LSFD
// residues; writes DIR/substructure.toml (a model file with [modal]), DIR/modal_fit.json,
// DIR/stabilisation.png and DIR/fit.png.
#include "identify/modal_fit.hpp"
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/measured_frfs.hpp"
#include "io/files.hpp"
#include "io/measured_frf_file.hpp"
#include "io/modal_fit_output.hpp"
#include "io/record_csv.hpp"
#include "io/uff58.hpp"
#include "report/modal_fit_figure.hpp"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <variant>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

enum class InputKind { csv_record, uff_record, frf };

std::string_view trim(std::string_view s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string_view::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// What a file holds: a universal file (first non-blank line "-1") of time responses or of FRFs;
// a CSV file by its header's first column, `t` (a record) or `freq_hz` with NODE:DOF columns (an
// FRF table). A stepped-sine table (`freq_hz` with channel columns) is refused.
InputKind kind_of(const fs::path& path) {
  const std::string text = io::read_file(path);
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
    const std::vector<io::Uff58Function> functions = io::read_uff58(path);
    if (!functions.empty() &&
        functions.front().function_type == io::uff_function_type::frequency_response)
      return InputKind::frf;
    return InputKind::uff_record; // uff58_tests says what it refuses
  }
  const std::string_view column = trim(first.substr(0, first.find(',')));
  if (column != "freq_hz") return InputKind::csv_record; // read_record says what it refuses
  if (first.find('@') != std::string_view::npos)
    throw io::Error(path.string() +
                    ": a stepped-sine table (freq_hz and channel columns such as f@7:uy.re): "
                    "modal-fit reads time records (t, f@..., a@...) or FRF files (freq_hz and "
                    "NODE:DOF.re, NODE:DOF.im columns, or universal files of FRFs)");
  return InputKind::frf;
}

class ModalFit final : public Command {
public:
  explicit ModalFit(CLI::App& parent)
      : Command(parent, "modal-fit",
                "The linear substructure from a low-level test: FRFs by H1 from time records "
                "(or FRF files), modes by LSCF with a stabilisation diagram, residues with lower "
                "and upper residuals, shapes mass-normalised at the driving point; writes "
                "DIR/substructure.toml ([modal]), DIR/modal_fit.json, DIR/stabilisation.png and "
                "DIR/fit.png") {
    app()
        .add_option("FILES", inputs_,
                    "Time records (CSV or universal files: one force channel f@NODE:DOF and x, v "
                    "or a channels) or FRF files (CSV tables or universal files of FRFs from one "
                    "driving point)")
        ->required();
    app().add_option("--band", band_, "F0:F1 in Hz, the band fitted")->required();
    app()
        .add_option("--modes", modes_,
                    "Number of modes to fit (0: as many as the stabilisation diagram shows)")
        ->capture_default_str();
    app()
        .add_option("--max-order", max_order_,
                    "Highest LSCF model order (even, >= 4; 0: max(40, 4 N + 20), at most the "
                    "lines in the band less 2)")
        ->capture_default_str();
    app()
        .add_option("--spectra", spectra_,
                    "How records become FRFs: auto (periods when a record states "
                    "# period_s = T, else welch), welch (Hann, 50 % overlap; random), periods "
                    "(each whole period; periodic), whole (each record one block; impacts, "
                    "sweeps from rest to rest)")
        ->check(choices({"auto", "welch", "periods", "whole"}))
        ->capture_default_str();
    app()
        .add_option("--segment", segment_,
                    "Welch segment, samples (0: the largest power of two giving >= 8 averages)")
        ->capture_default_str();
    app().add_option("--period", period_,
                     "The records' period, s (instead of their # period_s comment)");
    add_no_plot("stabilisation.png and fit.png");
    add_output_dir();
  }

  void run() override;

private:
  void print(const identify::ModalFit& fit, const identify::MeasuredFrfs& data) const;

  std::vector<fs::path> inputs_;
  std::string band_;
  int modes_ = 0;
  int max_order_ = 0;
  std::string spectra_ = "auto";
  int segment_ = 0;
  double period_ = 0.0;
};

void ModalFit::run() {
  // 1. The options.
  const auto [f0, f1] = parse_band("--band", band_);
  if (modes_ < 0) throw io::Error(fmt::format("--modes: expected 0 or more, got {}", modes_));
  if (max_order_ != 0 && max_order_ < 4)
    throw io::Error(
        fmt::format("--max-order: expected 0 (automatic) or at least 4, got {}", max_order_));
  if (segment_ != 0 && segment_ < 8)
    throw io::Error(
        fmt::format("--segment: expected at least 8 samples (or 0: automatic), got {}", segment_));
  if (!(std::isfinite(period_) && period_ >= 0.0))
    throw io::Error(fmt::format("--period: expected seconds > 0, got {}", period_));
  const identify::SpectraMethod method = spectra_ == "welch"     ? identify::SpectraMethod::welch
                                         : spectra_ == "periods" ? identify::SpectraMethod::periods
                                         : spectra_ == "whole"   ? identify::SpectraMethod::whole
                                                               : identify::SpectraMethod::automatic;
  if (segment_ != 0 && method != identify::SpectraMethod::welch &&
      method != identify::SpectraMethod::automatic)
    throw io::Error(fmt::format("--segment: only with --spectra welch or auto, not {}", spectra_));
  if (period_ > 0.0 && method != identify::SpectraMethod::periods &&
      method != identify::SpectraMethod::automatic)
    throw io::Error(fmt::format("--period: only with --spectra periods or auto, not {}", spectra_));
  check_output_dir(output_dir_);

  // 2. The inputs: time records or FRF files, not both.
  std::vector<identify::Record> records;
  std::vector<fs::path> frf_files;
  std::map<fs::path, std::string> seen;
  for (const fs::path& path : inputs_) {
    std::error_code ec;
    fs::path key = fs::weakly_canonical(path, ec);
    if (ec) key = path;
    if (!seen.emplace(key, path.string()).second)
      throw io::Error(path.string() + ": given twice (its blocks would count twice)");
    const InputKind kind = kind_of(path);
    if (kind == InputKind::frf) {
      frf_files.push_back(path);
    } else if (kind == InputKind::csv_record) {
      records.push_back(io::read_record(path));
    } else {
      for (auto& test : io::uff58_tests(io::read_uff58(path), path))
        records.push_back(std::get<identify::Record>(std::move(test)));
    }
  }
  if (!records.empty() && !frf_files.empty())
    throw io::Error(fmt::format("{} is a time record but {} holds FRFs: give modal-fit one or the "
                                "other",
                                records.front().source, frf_files.front().string()));
  if (!frf_files.empty() && (segment_ != 0 || period_ > 0.0 || spectra_ != "auto"))
    throw io::Error("--spectra, --segment, --period: for time records, not FRF files");
  const fs::path toml = output_dir_ / "substructure.toml", json = output_dir_ / "modal_fit.json";
  for (const fs::path& p : {toml, json, output_dir_ / "stabilisation.png", output_dir_ / "fit.png"})
    io::check_not_an_input(p);

  // 3. The FRFs and the fit.
  identify::MeasuredFrfs data;
  identify::ModalFit fit;
  try {
    if (!frf_files.empty()) {
      data = identify::frfs_from_measured(io::read_measured_frf(frf_files), f0, f1);
    } else {
      identify::FrfEstimateOptions options;
      options.f0_hz = f0;
      options.f1_hz = f1;
      options.method = method;
      options.segment = segment_;
      options.period_s = period_;
      data = identify::frfs_from_records(records, options);
    }
    identify::ModalFitOptions options;
    options.modes = modes_;
    options.max_order = max_order_;
    fit = identify::modal_fit(data, options);
  } catch (const std::invalid_argument& e) {
    throw io::Error(e.what()); // it names the record, the band or the channels
  }
  require(fit.status.within("no substructure: "));

  // 4. Write: the model file and the JSON together, then the pictures.
  std::vector<std::string> inputs;
  for (const fs::path& p : inputs_)
    inputs.push_back(p.string());
  std::string sources;
  for (const auto& s : inputs)
    sources += (sources.empty() ? "" : ", ") + s;
  const std::vector<std::string> comments{
      "jointid modal-fit", "from " + sources,
      fmt::format("band {} to {} Hz: {} lines; FRFs: {}", f0, f1, data.num_lines(),
                  identify::spectra_method_name(data.method)),
      fmt::format("fit error (relative, per DOF) in modal_fit.json; the figures: "
                  "stabilisation.png, fit.png")};
  const io::ModalFitRun run{f0, f1, inputs, "substructure.toml"};
  std::string model_text = io::modal_fit_toml(fit, data, comments);
  std::string json_text = io::modal_fit_json(fit, data, run);
  make_output_dir(output_dir_);
  print(fit, data);
  write_outputs({{toml, std::move(model_text)}, {json, std::move(json_text)}});
  for (const auto& n : data.notes)
    fmt::print("note: {}\n", n);
  for (const auto& w : fit.warnings)
    warn(w);
  if (plot_) {
    draw_chart(output_dir_ / "stabilisation.png",
               [&] { return report::stabilisation_figure(fit, data); });
    draw_chart(output_dir_ / "fit.png", [&] { return report::modal_fit_figure(fit, data); });
  }
}

void ModalFit::print(const identify::ModalFit& fit, const identify::MeasuredFrfs& data) const {
  fmt::print("{:>5} {:>16} {:>10} {:>14} {:>9}\n", "mode", "frequency (Hz)", "damping",
             "stable orders", "in model");
  for (std::size_t r = 0; r < fit.modes.size(); ++r) {
    const identify::FittedMode& m = fit.modes[r];
    fmt::print("{:>5} {:>16.8g} {:>10.5f} {:>14} {:>9}\n", r + 1, m.frequency_hz, m.damping,
               m.stable_orders, m.in_model() ? "yes" : "no");
  }
  fmt::print("{:<12} {:>10} {:>12} {:>16}\n", "response", "fit error", "model error",
             "mean coherence");
  for (int c = 0; c < data.num_responses(); ++c) {
    const Eigen::VectorXd g = data.coherence.col(c);
    const std::string coherence =
        g.size() > 0 && g.allFinite() ? fmt::format("{:.4f}", g.mean()) : std::string("-");
    fmt::print("{:<12} {:>10.4f} {:>12.4f} {:>16}\n",
               data.response_names[static_cast<std::size_t>(c)], fit.fit_error(c),
               fit.model_error(c), coherence);
  }
}

} // namespace

std::unique_ptr<Command> modal_fit_command(CLI::App& parent) {
  return std::make_unique<ModalFit>(parent);
}

} // namespace jointid::cli
