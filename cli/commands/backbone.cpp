// jointid backbone: a mode's natural frequency and damping ratio against amplitude (EPMC), and
// the measured backbone from stepped-sine tables (a one-mode fit per force level);
// DIR/backbone.json and DIR/backbone.png.
#include "frf/backbone.hpp"
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/one_mode_fit.hpp"
#include "io/backbone_json.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "io/results_json.hpp"
#include "report/backbone_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Backbone final : public Command {
public:
  explicit Backbone(CLI::App& parent)
      : Command(parent, "backbone",
                "Natural frequency and damping ratio of a mode against amplitude (a non-linear "
                "mode by harmonic balance) and, from stepped-sine tables, the measured ones; "
                "writes DIR/backbone.json and DIR/backbone.png") {
    add_model();
    app()
        .add_option("--mode", mode_,
                    "Mode N of the structure with its joints' linear terms "
                    "(1 = the lowest)")
        ->required();
    app().add_option("--amplitude-range", range_,
                     "Amplitudes A0:A1 of the fundamental at --dof (m or rad, peak); default with "
                     "--tables: the measured levels' span, widened 3 times either way");
    app().add_option("--dof", dof_,
                     "DOF whose amplitude the backbone is drawn against, NODE:DOF (default: the "
                     "first joint's node and DOF)");
    app()
        .add_option("--points", options_.points, "Amplitudes on the backbone (log-spaced)")
        ->capture_default_str();
    app()
        .add_option("--tables", tables_,
                    "Stepped-sine tables, one force level each (a force channel f@…, the response "
                    "at --dof as x, v or a): the measured backbone")
        ->expected(1, -1);
    add_balance_harmonics(options_.hb.harmonics, "Harmonics 0 … K of the harmonic balance");
    add_no_plot("backbone.png");
    add_output_dir();
    add_engine();
  }

  void run() override;

private:
  int mode_ = 0;
  std::string range_; ///< A0:A1 at dof_
  std::string dof_;   ///< NODE:DOF; empty: the first joint's
  std::vector<fs::path> tables_;
  frf::BackboneOptions options_;
};

void Backbone::run() {
  // 1. The options.
  if (mode_ < 1) throw io::Error(fmt::format("--mode: expected a mode number >= 1, got {}", mode_));
  if (options_.points < 2 || options_.points > 10000)
    throw io::Error(fmt::format("--points: expected 2 to 10000, got {}", options_.points));
  check_balance_harmonics(options_.hb.harmonics, 1);
  check_output_dir(output_dir_);
  double from = 0.0, to = 0.0;
  if (!range_.empty()) {
    std::tie(from, to) = parse_pair("--amplitude-range", range_, "1e-5:1e-2");
    if (!(from > 0.0 && to > from))
      throw io::Error(fmt::format(
          "--amplitude-range: expected 0 < A0 < A1 (m or rad), got {} and {}", from, to));
  } else if (tables_.empty()) {
    throw io::Error("--amplitude-range: required without --tables (the amplitudes of the "
                    "fundamental at --dof, A0:A1 in m or rad)");
  }

  // 2. The model and the DOF of the amplitude.
  const Model model(model_, engine());
  require_values(model.file, "backbone");
  if (model.file.joints.empty())
    throw io::Error(model.name() + ": no [[joints]]: the structure is linear, its modes do not "
                                   "change with amplitude (see `jointid modes`)");
  const joints::Joint& first = model.file.joints.front();
  const fem::NodeDof at =
      dof_.empty() ? fem::NodeDof{first.node, first.dof} : model.dof("--dof", dof_);

  // 3. The measured backbone: a one-mode fit per table.
  std::vector<identify::MeasuredBackbonePoint> measured;
  std::vector<io::SteppedSineTable> tables;
  for (const fs::path& path : tables_) {
    tables.push_back(io::read_stepped_sine(path));
    identify::MeasuredBackbonePoint point{path.string(), {}};
    try {
      point.fit = identify::fit_one_mode(tables.back(), at);
    } catch (const std::invalid_argument& e) {
      throw io::Error(path.string() + ": " + e.what());
    }
    if (!point.fit.status.ok()) warn(path.string() + ": " + point.fit.status.reason);
    measured.push_back(std::move(point));
  }
  identify::share_residue(measured, tables, at); // the most nearly linear level's residue
  if (range_.empty()) {
    double lo = INFINITY, hi = 0.0;
    for (const auto& m : measured)
      if (m.fit.status.ok()) lo = std::min(lo, m.fit.amplitude), hi = std::max(hi, m.fit.amplitude);
    if (!(hi > 0.0))
      throw io::Error("--amplitude-range: no table gave a level to take the range from; give "
                      "it, A0:A1 in m or rad");
    from = lo / 3.0, to = hi * 3.0;
  }

  // 4. The backbone.
  const frf::Backbone backbone = with_progress("jointid backbone", [&](const TerminalProgress&) {
    return for_model(model, [&] {
      return frf::backbone(model.sub, model.file.joints, mode_, at, from, to, options_);
    });
  });
  if (backbone.points.empty()) require(backbone.status);
  if (!backbone.status.ok()) warn(backbone.status.reason);
  if (!output_rank()) return;

  // 5. Write.
  make_output_dir(output_dir_);
  const fs::path json = output_dir_ / "backbone.json";
  io::write_json(json, io::backbone_json(backbone, model.file.joints, measured));
  fmt::print("wrote {}\n", json.string());
  if (plot_)
    draw_chart(output_dir_ / "backbone.png",
               [&] { return report::backbone_figure(backbone, measured); });
  const frf::BackbonePoint& last = backbone.points.back();
  fmt::print("mode {}: linear {:.6g} Hz, damping ratio {:.4g} %; at |X1| = {:.4g} at {}: "
             "{:.6g} Hz, {:.4g} %\n",
             mode_, backbone.linear.frequency_hz, 100.0 * backbone.linear.damping_ratio,
             last.amplitude, fem::to_string(at), last.frequency_hz, 100.0 * last.damping_ratio);
  for (const auto& m : measured)
    if (m.fit.status.ok())
      fmt::print("{}: |X1| = {:.4g}, {:.6g} ± {:.2g} Hz, {:.4g} ± {:.2g} %\n", m.table,
                 m.fit.amplitude, m.fit.frequency_hz, m.fit.frequency_std_hz,
                 100.0 * m.fit.damping_ratio, 100.0 * m.fit.damping_ratio_std);
  for (const auto& n : backbone.notes)
    fmt::print("note: {}\n", n);
}

} // namespace

std::unique_ptr<Command> backbone_command(CLI::App& parent) {
  return std::make_unique<Backbone>(parent);
}

} // namespace jointid::cli
