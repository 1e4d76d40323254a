// jointid compare: measured vs predicted response spectra; DIR/compare.json and DIR/compare.png.
#include "identify/compare.hpp"
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "io/results_json.hpp"
#include "io/spectra_comparison.hpp"
#include "report/compare_figure.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Compare final : public Command {
public:
  explicit Compare(CLI::App& parent)
      : Command(parent, "compare",
                "Measured vs predicted response spectra: drive the model (joints at their "
                "values) with a record's measured force, compare the Welch PSD of every "
                "response channel; writes DIR/compare.json and DIR/compare.png") {
    add_model();
    app()
        .add_option("RECORD", record_, "Measurement record (CSV) with force and responses")
        ->required();
    app().add_option("--band", band_, "F0:F1 in Hz compared (default: the whole spectrum)");
    app()
        .add_option("--segment", segment_,
                    "Welch segment, samples (0: largest power of two giving >= 16 averages)")
        ->capture_default_str();
    app().add_option_function<double>(
        "--skip", [this](const double& s) { skip_ = s; },
        "Seconds left out at the start of both records (default: 10 % of the record; the "
        "simulation starts from rest)");
    transient_.add_to(app());
    add_no_plot("compare.png");
    add_output_dir();
  }

  void run() override;

private:
  void print(const identify::Comparison& result) const;

  fs::path record_;
  std::string band_;           ///< F0:F1, Hz; empty: the whole spectrum
  int segment_ = 0;            ///< Welch segment, samples; 0: automatic
  std::optional<double> skip_; ///< s; not given: the library's default
  TransientOptions transient_;
};

void Compare::run() {
  // 1. The options.
  identify::CompareOptions options;
  if (!band_.empty()) std::tie(options.f0_hz, options.f1_hz) = parse_band("--band", band_);
  if (segment_ != 0 && segment_ < 8)
    throw io::Error(
        fmt::format("--segment: expected at least 8 samples (or 0: automatic), got {}", segment_));
  options.segment = segment_;
  if (skip_ && !(std::isfinite(*skip_) && *skip_ >= 0.0))
    throw io::Error(fmt::format("--skip: expected seconds >= 0, got {}", *skip_));
  if (skip_) options.skip_s = *skip_;
  transient_.apply(options.simulation);
  check_output_dir(output_dir_);

  // 2. The inputs.
  const io::ModelFile file = io::read_model(model_);
  check_time_simulation(file); // the prediction is a time simulation
  require_values(file, "compare");
  if (file.joints.empty())
    warn(model_.string() + ": no [[joints]]: the prediction is the linear substructure's");
  const identify::Record record = io::read_record(record_);
  for (const char* name : {"compare.json", "compare.png"})
    io::check_not_an_input(output_dir_ / name);
  const frf::Substructure sub = file.substructure();

  // 3. Predict and compare; the record's name leads a message about it.
  const identify::Comparison result =
      with_progress("jointid compare: predicting", [&](const auto& progress) {
        options.simulation.progress = progress.callback();
        try {
          return identify::compare_spectra(sub, file.joints, record, options);
        } catch (const std::invalid_argument& e) {
          throw io::Error(fmt::format("{} (model {})", e.what(), model_.string()));
        }
      });
  require(result.status);
  for (const auto& w : result.prediction.warnings)
    warn(w);

  // 4. Write.
  make_output_dir(output_dir_);
  const fs::path json = output_dir_ / "compare.json";
  io::write_json(json, io::compare_json(result));
  print(result);
  fmt::print("wrote {}\n", json.string());
  if (plot_)
    draw_chart(output_dir_ / "compare.png", [&] { return report::compare_figure(result); });
}

void Compare::print(const identify::Comparison& result) const {
  fmt::print("{:<12} {:>18} {:>18}\n", "channel", "RMS difference dB", "max difference dB");
  for (const auto& c : result.channels)
    fmt::print("{:<12} {:>18.3f} {:>18.3f}\n", c.channel, c.rms_db, c.max_db);
  fmt::print("band {:g}-{:g} Hz; {} averages, so two independent spectra would differ by about "
             "{:.2f} dB (one standard deviation)\n",
             result.f0_hz, result.f1_hz, result.averages, result.statistical_db);
  for (const auto& n : result.notes)
    fmt::print("note: {}\n", n);
}

} // namespace

std::unique_ptr<Command> compare_command(CLI::App& parent) {
  return std::make_unique<Compare>(parent);
}

} // namespace jointid::cli
