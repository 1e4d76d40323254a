#pragma once
/// What the commands' runs share: warnings, the checks of options and output paths, the model
/// with its substructure and modal engine, a picture drawn or a warning why not, and progress on
/// a terminal. Errors are io::Error naming the option or file.
#include "cli/engine.hpp"
#include "cli/terminal_progress.hpp"
#include "fem/dof.hpp"
#include "fem/status.hpp"
#include "frf/substructure.hpp"
#include "identify/random_tests.hpp"
#include "identify/record.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "report/chart.hpp"

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace jointid::cli {

/// "jointid: warning: <what>" on stderr.
void warn(const std::string& what);

/// A numerical outcome that ends the command: throws std::runtime_error with the status's
/// reason (main() prints it as the one-line reason) unless `status` is ok.
void require(const fem::Status& status);

/// -o DIR: not empty, and not an existing file.
void check_output_dir(const std::filesystem::path& dir);
/// Creates DIR (and its parents) before the outputs are written.
void make_output_dir(const std::filesystem::path& dir);
/// -o FILE (and the other file outputs): a file name in an existing directory.
void check_output_file(const std::filesystem::path& file, const std::string& option = "-o");

/// --harmonics: at least one, each >= `lowest` and once, not 0 alone (no upper cap: the
/// sampling sets the highest harmonic a record has).
void check_harmonics(const std::vector<int>& harmonics, int lowest);
/// --balance-harmonics K from `lowest` to 200; `why` says where the lowest comes from.
void check_balance_harmonics(int harmonics, int lowest, const std::string& why = "");
/// --amplitude: at least one, each finite and > 0 (N or N·m).
void check_amplitudes(const std::vector<double>& amplitudes);
/// --noise: a fraction of each channel's RMS, from 0 to below 1.
void check_noise(double noise);
/// "F0:F1": two finite numbers (Hz); `example` shows the form.
std::pair<double, double> parse_pair(const std::string& option, const std::string& text,
                                     const char* example);
/// A band "F0:F1" in Hz with 0 <= F0 < F1.
std::pair<double, double> parse_band(const std::string& option, const std::string& text);
/// Values of an option given as numbers ("3", "1.5e3") or ranges START:STEP:STOP (START,
/// START + STEP, … up to STOP within a millionth of STEP; at most 10000 a range), every one
/// finite and > 0 (`unit` names them in messages): sorted, each once.
std::vector<double> parse_values(const std::string& option, const std::vector<std::string>& items,
                                 const char* unit);
/// --channels x, v, a: each once.
std::vector<identify::Quantity> parse_channels(const std::vector<std::string>& channels);
/// --route modal or full.
identify::TransientRoute parse_route(const std::string& text);

/// Time simulation (simulate --method time or another excitation, compare): refuses a model
/// whose substructure, or one of its [[substructures]], is given by measured FRFs ([frf]),
/// which have no time-domain model: io::Error naming the model file and the part's file, and
/// `alternative` after the reason ("or simulate by harmonic balance, --method hb").
void check_time_simulation(const io::ModelFile& file, const std::string& alternative = "");
/// Every joint term has its value in the model file (a command that runs the model with its
/// joints at their values: simulate, compare, response, backbone); else io::Error naming the
/// file, the joint's line, the joint and the terms without one, never a term taken as 0 unsaid.
void require_values(const io::ModelFile& file, const std::string& command);

/// The model file, its substructure (modes of a large model by the chosen engine), and the
/// NODE:DOF options resolved against it.
struct Model {
  Model(const std::filesystem::path& path, Engine engine);
  /// `text` (NODE:DOF, or a one-node Gmsh group and a DOF) as a free DOF of the substructure;
  /// io::Error naming `option` otherwise.
  fem::NodeDof dof(const std::string& option, const std::string& text) const;
  std::string name() const { return file.path.string(); }

  io::ModelFile file;
  frf::Substructure sub;
};

/// How a command takes a joint's parametric term (jenkins, iwan, gap) whose parameters are not
/// all fixed.
enum class Parametric {
  fixed_only,         ///< refused (the equation error takes it only as a known force)
  needs_output_error, ///< refused, saying that `identify --output-error` identifies it
  output_error,       ///< identified by output error: one such term a joint
};

/// The joints' terms as the command identifies them; io::Error naming the model file, the
/// joint's line, the term and its parameters otherwise.
void check_identifiable(const Model& model, Parametric how = Parametric::fixed_only);

/// Runs `compute()`; a std::invalid_argument from the library (the model's data or the
/// options refused) becomes io::Error after the model file's name, its reason intact.
template <class Compute>
auto for_model(const Model& model, Compute&& compute) -> decltype(compute()) {
  try {
    return compute();
  } catch (const std::invalid_argument& e) {
    throw io::Error(model.name() + ": " + e.what());
  }
}

/// Runs `compute(progress)` with its progress on the terminal under `label` (MPI rank 0), the
/// line wiped however it ends.
template <class Compute> auto with_progress(const std::string& label, Compute&& compute) {
  const TerminalProgress progress(label, output_rank());
  return compute(progress);
}

/// Draws `figure()` into `png` and says so; when charts cannot be drawn here, or the figure
/// has nothing to show (std::invalid_argument), a warning says why and the results stand.
void draw_chart(const std::filesystem::path& png, const std::function<report::Figure()>& figure);

/// Writes every (path, text) under a temporary name, then renames them all into place together
/// (a failure leaves every target as it was), and says so.
void write_outputs(const std::vector<std::pair<std::filesystem::path, std::string>>& outputs);

} // namespace jointid::cli
