// jointid modal-fit: the linear substructure from a low-level test. FRFs by H1 from time records
// (or read from FRF files), modal parameters by LSCF with a stabilisation diagram and LSFD
// residues; writes DIR/substructure.toml (a model file with [modal]), DIR/modal_fit.json,
// DIR/stabilisation.png and DIR/fit.png.
#include "identify/modal_fit.hpp"
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/measured_frfs.hpp"
#include "io/files.hpp"
#include "io/low_level_test.hpp"
#include "io/modal_fit_output.hpp"
#include "report/modal_fit_figure.hpp"

#include <fmt/format.h>

#include <cmath>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

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
  const io::ModalFitArguments arguments{f0,       f1,       modes_,  max_order_,
                                        spectra_, segment_, period_, true};
  io::check_modal_fit_arguments(arguments);
  check_output_dir(output_dir_);

  // 2. The inputs: time records or FRF files, not both.
  io::LowLevelTest test;
  io::add_low_level_files(test, inputs_);
  const fs::path toml = output_dir_ / "substructure.toml", json = output_dir_ / "modal_fit.json";
  for (const fs::path& p : {toml, json, output_dir_ / "stabilisation.png", output_dir_ / "fit.png"})
    io::check_not_an_input(p);

  // 3. The FRFs and the fit.
  const auto [data, fit] = io::fit_low_level_test(test, arguments);
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
