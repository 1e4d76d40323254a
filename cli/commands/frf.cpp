// jointid frf: the linear substructure's FRFs from one force: DIR/frf.csv, DIR/frf.uff
// (dataset 58) and DIR/frf.png.
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "frf/sweep.hpp"
#include "io/files.hpp"
#include "io/frf_output.hpp"
#include "io/uff58.hpp"
#include "report/frf_figure.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Frf final : public Command {
public:
  explicit Frf(CLI::App& parent)
      : Command(parent, "frf",
                "FRFs of the linear substructure (modal synthesis) from one force: receptance, "
                "mobility or accelerance; writes DIR/frf.csv, DIR/frf.uff (UFF58) and "
                "DIR/frf.png") {
    add_model();
    app().add_option("--drive", drive_, "DOF of the force, NODE:DOF (e.g. 7:uy)")->required();
    app()
        .add_option("--response", responses_,
                    "Response DOFs, NODE:DOF (comma-separated; default: the drive DOF)")
        ->delimiter(',')
        ->allow_extra_args(false);
    app().add_option("--freq-range", freq_range_, "Band F0:F1 in Hz (F0 >= 0)")->required();
    app()
        .add_option("--points", points_, "Evenly spaced frequencies, both ends included")
        ->capture_default_str();
    std::vector<std::string> kinds;
    for (const frf::FrfKind k :
         {frf::FrfKind::receptance, frf::FrfKind::mobility, frf::FrfKind::accelerance})
      kinds.emplace_back(frf::frf_kind_name(k));
    app()
        .add_option("--kind", kind_,
                    "receptance (m/N), mobility ((m/s)/N) or accelerance ((m/s^2)/N)")
        ->check(choices(kinds))
        ->capture_default_str();
    add_no_plot("frf.png");
    add_output_dir();
    add_engine();
  }

  void run() override;

private:
  std::string drive_;
  std::vector<std::string> responses_;
  std::string freq_range_;
  int points_ = 1000;
  std::string kind_ = "receptance";
};

void Frf::run() {
  // 1. The options.
  const auto [f0, f1] = parse_pair("--freq-range", freq_range_, "0:100");
  if (!(f0 >= 0.0 && f1 > f0))
    throw io::Error(fmt::format(
        "--freq-range: expected F0 >= 0 Hz below F1, got {} and {} (e.g. 0:100)", f0, f1));
  if (points_ < 2 || points_ > 1000000)
    throw io::Error(fmt::format("--points: expected 2 to 1000000, got {}", points_));
  const frf::FrfKind kind = frf::parse_frf_kind(kind_); // checked by --kind's choices
  check_output_dir(output_dir_);

  // 2. The model and the DOFs.
  const Model model(model_, engine());
  const fem::NodeDof drive = model.dof("--drive", drive_);
  std::vector<int> responses;
  for (const std::string& r : responses_) {
    const int e = model.sub.dofs().equation(model.dof("--response", r));
    if (std::find(responses.begin(), responses.end(), e) != responses.end())
      throw io::Error(fmt::format("--response: {} is listed twice", r));
    responses.push_back(e);
  }
  if (responses.empty()) responses.push_back(model.sub.dofs().equation(drive));

  // 3. The FRFs.
  const frf::FrfSweep sweep = for_model(model, [&] {
    return frf::frf_sweep(model.sub, model.sub.dofs().equation(drive), std::move(responses),
                          frf::evenly_spaced_hz(f0, f1, points_), kind);
  });
  require(sweep.status);
  if (!output_rank()) return;
  const std::size_t joints = model.file.joints.size();
  if (joints > 0)
    fmt::print("note: the FRFs are the linear substructure's; the {} joint{} of {} {} not in "
               "them (see jointid response for the structure with its joints)\n",
               joints, joints == 1 ? "" : "s", model.name(), joints == 1 ? "is" : "are");
  for (const std::string& n : sweep.notes)
    fmt::print("note: {}\n", n);

  // 4. Write: the table and the universal file staged and renamed into place together (a
  //    failure leaves both as they were); the picture after them, atomically too.
  std::string table = io::frf_csv(sweep, model.sub.dofs());
  std::string universal = io::uff58_text(io::frf_uff58(sweep, model.sub.dofs()));
  make_output_dir(output_dir_);
  write_outputs({{output_dir_ / "frf.csv", std::move(table)},
                 {output_dir_ / "frf.uff", std::move(universal)}});
  if (plot_)
    draw_chart(output_dir_ / "frf.png",
               [&] { return report::frf_figure(sweep, model.sub.dofs()); });
}

} // namespace

std::unique_ptr<Command> frf_command(CLI::App& parent) {
  return std::make_unique<Frf>(parent);
}

} // namespace jointid::cli
