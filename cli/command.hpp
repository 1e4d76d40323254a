#pragma once
/// One `jointid` command: its subcommand with its options, and its run. Every command's
/// constructor sets up its options (cli/commands/<command>.cpp); the options that several
/// commands share are set up here, once, so that an option means the same in every command:
/// MODEL, -o/--output, --engine, --no-plot, --harmonics (the harmonics compared or identified)
/// and --balance-harmonics (the harmonic balance's truncation).
#include "cli/engine.hpp"
#include "identify/random_tests.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace jointid::cli {

class Command {
public:
  virtual ~Command() = default;
  Command(const Command&) = delete;
  Command& operator=(const Command&) = delete;

  /// Checks the options, reads the inputs, calls the library and only then writes the
  /// outputs. Bad input: io::Error naming the option or file.
  virtual void run() = 0;
  /// The run draws a picture (main() then looks for an X display first): by default, when the
  /// command has --no-plot and it is not given.
  virtual bool draws() const { return has_plot_ && plot_; }
  /// Chosen on this command line.
  bool chosen() const { return app_->parsed(); }
  /// --engine (automatic for a command without one).
  Engine engine() const { return parse_engine(engine_); }

protected:
  Command(CLI::App& parent, const std::string& name, const std::string& description);

  CLI::App& app() { return *app_; }

  // The shared options.
  /// MODEL, the model file (required, first positional).
  void add_model(const std::string& description = "Model file (TOML)");
  /// -o/--output DIR (required).
  void add_output_dir();
  /// --engine: `auto` or `slepc` (modes of large models); with `every_engine`, also `dense` and
  /// `sparse` (modes).
  void add_engine(bool every_engine = false);
  /// --no-plot: `what` is not drawn (plot_ false). The old --no-plots still works, with a
  /// warning.
  void add_no_plot(const std::string& what);
  /// --harmonics H,H,...: the harmonics compared or identified.
  void add_harmonics(std::vector<int>& harmonics, const std::string& description);
  /// --balance-harmonics K: the harmonic balance's harmonics 0 … K. The old --hb-harmonics
  /// still works, with a warning; so does --harmonics where it meant this (`was_harmonics`:
  /// simulate and response).
  void add_balance_harmonics(int& harmonics, const std::string& description,
                             bool was_harmonics = false);

  std::filesystem::path model_;
  std::filesystem::path output_dir_;
  std::string engine_ = "auto";
  bool plot_ = true;

private:
  bool has_plot_ = false; ///< --no-plot set up
  /// An old spelling of `now`: hidden from --help, still sets `set(value)`, and warns.
  template <class T, class Set>
  void add_old_spelling(const std::string& old, const std::string& now, Set set);

  CLI::App* app_;
};

/// The options of a time simulation, shared by simulate and compare: --route, --modal-cutoff,
/// --substeps (defaults: identify::ForcedOptions's).
struct TransientOptions {
  std::string route = "modal";
  double modal_cutoff = identify::ForcedOptions{}.modal_cutoff_hz; ///< Hz; 0: Nyquist
  int substeps = identify::ForcedOptions{}.substeps;

  /// Sets them up in `app`; `which` says which excitations they apply to.
  void add_to(CLI::App& app, const std::string& which = "");
  /// Checked, into `options`; io::Error naming the option otherwise.
  void apply(identify::ForcedOptions& options) const;
};

/// A validator admitting only `names`, shown in --help as {a,b,c}; another value is refused
/// with "expected a, b or c, got "x"" (after the option's name).
CLI::Validator choices(const std::vector<std::string>& names);

/// The old spellings used on this command line, each as "--old is now --new", for main() to warn
/// about once the run starts (on MPI rank 0).
const std::vector<std::string>& renamed_options();

/// The commands, each added to `parent`.
std::unique_ptr<Command> modes_command(CLI::App& parent);
std::unique_ptr<Command> frf_command(CLI::App& parent);
std::unique_ptr<Command> simulate_command(CLI::App& parent);
std::unique_ptr<Command> identify_command(CLI::App& parent);
std::unique_ptr<Command> discover_command(CLI::App& parent);
std::unique_ptr<Command> response_command(CLI::App& parent);
std::unique_ptr<Command> design_command(CLI::App& parent);
std::unique_ptr<Command> compare_command(CLI::App& parent);
std::unique_ptr<Command> modal_fit_command(CLI::App& parent);
std::unique_ptr<Command> backbone_command(CLI::App& parent);

} // namespace jointid::cli
