// jointid response: response curves by harmonic balance with continuation; DIR/response.json
// (README's contract) and DIR/response.png. Progress on a terminal (stderr), nothing otherwise.
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "frf/continuation.hpp"
#include "io/files.hpp"
#include "io/response_curves.hpp"
#include "io/results_json.hpp"
#include "report/response_figure.hpp"

#include <fmt/format.h>

#include <cmath>
#include <set>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Response final : public Command {
public:
  explicit Response(CLI::App& parent)
      : Command(parent, "response",
                "Response curves (harmonic balance with continuation, stability, folds) of the "
                "model with its joints; writes DIR/response.json and DIR/response.png") {
    add_model();
    app().add_option("--force", force_, "DOF of the sine force, NODE:DOF (e.g. 7:uy)")->required();
    app()
        .add_option("--amplitude", amplitudes_,
                    "Force amplitudes, N or N m (peak; comma-separated, one curve each)")
        ->required()
        ->delimiter(',')
        ->allow_extra_args(false);
    app()
        .add_option("--freq-range", freq_range_, "Band F0:F1 in Hz, traced from F0 to F1")
        ->required();
    add_balance_harmonics(options_.hb.harmonics, "Harmonics 0 … K of the harmonic balance", true);
    app()
        .add_option("--stability-stride", options_.stability_stride,
                    "Floquet multipliers computed at least at every N-th point, and wherever the "
                    "stability may change (folds, symmetry breaking, disagreeing neighbours); "
                    "1: at every point")
        ->capture_default_str();
    app().add_option("--plot-dof", plot_dof_,
                     "DOF drawn in response.png, NODE:DOF (default: the force DOF)");
    add_no_plot("response.png");
    add_output_dir();
    add_engine();
  }

  void run() override;

private:
  void print(const frf::ResponseCurves& curves) const;

  std::string force_;                ///< NODE:DOF of the sine force
  std::vector<double> amplitudes_;   ///< N or N·m (peak), one curve each
  std::string freq_range_;           ///< F0:F1, Hz (traced from F0 to F1; either order)
  frf::ContinuationOptions options_; ///< the library's defaults
  std::string plot_dof_;             ///< NODE:DOF drawn in response.png; empty: the force DOF
};

void Response::run() {
  // 1. The options.
  check_amplitudes(amplitudes_);
  if (std::set<double>(amplitudes_.begin(), amplitudes_.end()).size() != amplitudes_.size())
    throw io::Error("--amplitude: an amplitude is listed twice");
  const auto [f0, f1] = parse_pair("--freq-range", freq_range_, "15:25");
  if (!(f0 > 0.0 && f1 > 0.0 && f0 != f1))
    throw io::Error(fmt::format(
        "--freq-range: expected two different frequencies > 0 Hz, got {} and {}", f0, f1));
  check_balance_harmonics(options_.hb.harmonics, 1);
  if (options_.stability_stride < 1)
    throw io::Error(fmt::format("--stability-stride: expected a whole number >= 1 (1: every "
                                "point), got {}",
                                options_.stability_stride));
  check_output_dir(output_dir_);

  // 2. The model.
  const Model model(model_, engine());
  require_values(model.file, "response");
  if (model.file.joints.empty())
    warn(model.name() + ": no [[joints]]: the response is the linear substructure's");
  const fem::NodeDof force_at = model.dof("--force", force_);
  const fem::NodeDof shown = plot_dof_.empty() ? force_at : model.dof("--plot-dof", plot_dof_);
  if (!report::response_figure_can_show(model.file.joints, force_at, shown))
    throw io::Error(fmt::format("--plot-dof {}: expected the force DOF ({}) or a joint's DOF",
                                plot_dof_, fem::to_string(force_at)));

  // 3. The curves (progress on a terminal only).
  const frf::ResponseCurves curves =
      with_progress("jointid response", [&](const TerminalProgress& progress) {
        std::function<void(std::size_t, double)> each;
        if (progress.on())
          each = [&](std::size_t curve, double fraction) {
            progress.show(
                fmt::format("{} N ({} of {})", amplitudes_[curve], curve + 1, amplitudes_.size()),
                fraction);
          };
        return for_model(model, [&] {
          return frf::response_curves(model.sub, model.file.joints, force_at, amplitudes_, f0, f1,
                                      options_, each);
        });
      });
  require(curves.status);
  if (!output_rank()) return;

  // 4. Write.
  make_output_dir(output_dir_);
  const fs::path json = output_dir_ / "response.json";
  io::write_json(json, io::response_json(curves));
  fmt::print("wrote {}\n", json.string());
  if (plot_)
    draw_chart(output_dir_ / "response.png",
               [&] { return report::response_figure(curves, shown); });
  print(curves);
}

void Response::print(const frf::ResponseCurves& curves) const {
  for (std::size_t i = 0; i < curves.curves.size(); ++i) {
    const frf::ResponseBranch& b = curves.curves[i];
    std::vector<std::string> folds;
    for (int f : b.folds)
      folds.push_back(fmt::format("{:.4f} Hz", b.points[f].hb.frequency_hz));
    int unstable = 0;
    for (const auto& p : b.points)
      unstable += p.stable.has_value() && !*p.stable;
    fmt::print("{:g} N: {} points, {} folds{}{}, {} unstable{}\n", amplitudes_[i], b.points.size(),
               b.folds.size(), folds.empty() ? "" : " at ",
               fmt::format("{}", fmt::join(folds, ", ")), unstable,
               b.complete ? "" : " (incomplete)");
    for (const auto& n : b.notes)
      (b.complete ? fmt::print("  {}\n", n) : warn(fmt::format("{:g} N: {}", amplitudes_[i], n)));
  }
  for (const auto& n : curves.notes)
    fmt::print("note: {}\n", n);
}

} // namespace

std::unique_ptr<Command> response_command(CLI::App& parent) {
  return std::make_unique<Response>(parent);
}

} // namespace jointid::cli
