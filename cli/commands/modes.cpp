// jointid modes: the natural frequencies of the linear substructure, DIR/modes.json, the VTK
// files of the mode shapes and DIR/modes.png.
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "fem/zero_modes.hpp"
#include "io/files.hpp"
#include "io/results_json.hpp"
#include "report/vtk_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Modes final : public Command {
public:
  explicit Modes(CLI::App& parent)
      : Command(parent, "modes",
                "Natural frequencies of the linear substructure; writes DIR/modes.json") {
    add_model();
    add_output_dir();
    app().add_option("--count", count_, "Number of modes")->capture_default_str();
    app()
        .add_option("--pictures", pictures_, "Modes drawn in DIR/modes.png (0: none)")
        ->capture_default_str();
    add_no_plot("modes.png (as --pictures 0)");
    app()
        .add_option("--tolerance", tolerance_,
                    "sparse and slepc engines: relative residual at which a mode has converged")
        ->capture_default_str();
    app()
        .add_option("--max-restarts", max_restarts_,
                    "sparse and slepc engines: restarts of the Lanczos (Krylov-Schur) iteration "
                    "before it gives up")
        ->capture_default_str();
    add_engine(true);
  }

  bool draws() const override { return plot_ && pictures_ > 0; }

  /// DIR/modes.json with the lowest `count` natural frequencies (and warnings about rigid-body
  /// modes or mechanisms), the VTK files of the mode shapes (DIR/modes.vtu, DIR/mesh.vtu,
  /// DIR/mode_<r>.pvd animations) and DIR/modes.png with the first `pictures` modes. The picture
  /// needs an X display (main() re-runs the command under xvfb-run when there is none); without
  /// one it is skipped with a warning.
  void run() override;

private:
  void write_without_mesh(const fem::Modes& modes, int count, const std::string& why) const;
  void print_table(const fem::Modes& modes, int count) const;

  int count_ = 10;
  int pictures_ = 4;
  /// The iterative engines' (sparse, slepc) convergence: fem::ModalOptions's defaults.
  double tolerance_ = fem::ModalOptions{}.tolerance;
  int max_restarts_ = fem::ModalOptions{}.max_iterations;
};

void Modes::print_table(const fem::Modes& modes, int count) const {
  fmt::print("{:>5} {:>16}\n", "mode", "frequency (Hz)");
  for (int r = 0; r < std::min(count, modes.num_modes()); ++r)
    fmt::print("{:>5} {:>16.8g}\n", r + 1, modes.frequency_hz(r));
}

// modes.json and the table of a substructure without a mesh ([modal], [matrices]).
void Modes::write_without_mesh(const fem::Modes& modes, int count, const std::string& why) const {
  make_output_dir(output_dir_);
  const fs::path out = output_dir_ / "modes.json";
  io::write_json(out,
                 io::modes_json(modes, count, {why + ": no mesh, so no VTK files or pictures"}));
  print_table(modes, count);
  fmt::print("wrote {}\n", out.string());
}

void Modes::run() {
  // 1. The options and the model.
  if (count_ < 1) throw io::Error(fmt::format("--count: expected at least 1, got {}", count_));
  if (!(tolerance_ > 0.0 && tolerance_ < 1.0))
    throw io::Error(
        fmt::format("--tolerance: expected a relative residual in (0, 1), got {}", tolerance_));
  if (max_restarts_ < 1)
    throw io::Error(fmt::format("--max-restarts: expected at least 1, got {}", max_restarts_));
  check_output_dir(output_dir_);
  const io::ModelFile file = io::read_model(model_);
  for (const char* name : {"modes.json", "mesh.vtu", "modes.vtu"})
    io::check_not_an_input(output_dir_ / name);
  if (file.measured)
    throw io::Error(model_.string() +
                    ": the substructure is given by measured FRFs ([frf]): there are no modes to "
                    "compute (identify, discover, simulate --method hb, response and frf read "
                    "the FRFs)");
  if (!file.parts.empty())
    throw io::Error(model_.string() +
                    ": the substructure is made of several ([[substructures]]), which the "
                    "joints alone connect: run `jointid modes` on each substructure's file");
  if (file.modal) { // a substructure given by its modes: report them; no mesh to draw
    fem::Modes modes;
    modes.omega = 2.0 * std::numbers::pi * file.modal->frequencies_hz;
    write_without_mesh(modes, std::min(count_, modes.num_modes()),
                       "the substructure is given by its modes ([modal])");
    return;
  }
  // The slepc engine assembles K and M distributed by rows: rank 0 assembles them whole only
  // afterwards, for the checks and the files.
  const Engine engine = this->engine();
  if (file.matrices && engine == Engine::slepc)
    throw io::Error(model_.string() +
                    ": --engine slepc assembles the finite elements by rows; a substructure "
                    "given by its matrices ([matrices]) uses --engine auto, dense or sparse");
  std::optional<frf::Substructure> sub;
  if (engine != Engine::slepc) sub.emplace(file.substructure());
  const int count =
      std::min(count_, sub ? sub->dofs().num_equations() : fem::DofMap(file.model).num_equations());

  // 2. The modes.
  fem::ModalOptions options;
  options.num_modes = count;
  options.tolerance = tolerance_;
  options.max_iterations = max_restarts_;
  const fem::Modes modes =
      compute_modes(file.model, sub ? sub->system() : nullptr, options, engine);
  if (!modes.status.ok()) throw std::runtime_error("modal analysis failed: " + modes.status.reason);
  if (!output_rank()) return;

  // 3. Write.
  if (!sub) sub.emplace(file.substructure());
  const fem::Assembled& system = *sub->system();
  if (file.matrices) { // K and M given: no mesh to draw, no element table for mechanisms
    write_without_mesh(modes, count, "the substructure is given by its matrices ([matrices])");
    return;
  }
  std::vector<std::string> warnings;
  if (const fem::ZeroModes z = fem::zero_modes(file.model, system, modes); z.count > 0)
    warnings.push_back(z.describe());
  make_output_dir(output_dir_);
  const fs::path out = output_dir_ / "modes.json";
  io::write_json(out, io::modes_json(modes, count, warnings));
  print_table(modes, count);
  if (!report::vtk_available()) {
    fmt::print("wrote {}\n", out.string());
    warnings.push_back(std::string(report::no_vtk_message) +
                       " (modes.json only: no .vtu/.pvd files, no modes.png)");
  } else {
    report::write_modes_vtk(output_dir_, file.model, system.dofs, modes);
    fmt::print("wrote {}, {} and {} (ParaView)\n", out.string(),
               (output_dir_ / "modes.vtu").string(), (output_dir_ / "mode_<r>.pvd").string());
    const char* display = std::getenv("DISPLAY");
    if (draws() && display && *display) {
      const fs::path png = output_dir_ / "modes.png";
      report::render_modes_png(png, file.model, system.dofs, modes,
                               std::min(pictures_, modes.num_modes()));
      fmt::print("wrote {}\n", png.string());
    } else if (draws()) {
      warnings.push_back(
          "no X display: modes.png not drawn (install xvfb, or run under xvfb-run -a)");
    }
  }
  for (const auto& w : warnings)
    warn(w);
}

} // namespace

std::unique_ptr<Command> modes_command(CLI::App& parent) {
  return std::make_unique<Modes>(parent);
}

} // namespace jointid::cli
