// jointid: the command line. Creates the commands (cli/commands/<command>.cpp), parses, runs the
// one chosen; every error ends here as one line on stderr and exit status 1.
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "cli/engine.hpp"
#include "io/files.hpp"
#include "report/vtk_output.hpp"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace {

// Messages are printed on one line.
std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  while (!text.empty() && text.back() == ' ')
    text.pop_back();
  return text;
}

// Debian's VTK draws through GLX and needs an X server. Without a display, run this same
// command again under `xvfb-run -a` (a virtual one), once; if that is impossible, carry on and
// the picture is skipped with a warning.
void rerun_with_display(char** argv) {
  if (!jointid::report::vtk_available()) return; // nothing to draw with
  const char* display = std::getenv("DISPLAY");
  if ((display && *display) || std::getenv("JOINTID_UNDER_XVFB")) return;
  setenv("JOINTID_UNDER_XVFB", "1", 1);
  std::vector<char*> args{const_cast<char*>("xvfb-run"), const_cast<char*>("-a"),
                          const_cast<char*>("-s"), const_cast<char*>("-screen 0 1600x1200x24")};
  static std::string self = "/proc/self/exe";
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) self = exe.string();
  args.push_back(self.data());
  for (char** a = argv + 1; *a; ++a)
    args.push_back(*a);
  args.push_back(nullptr);
  std::cout.flush();
  execvp("xvfb-run", args.data()); // returns only on failure (xvfb-run not installed)
}

// Runs the command chosen: under MPI for the distributed engine (no X display is looked for
// there: a picture is drawn only when one exists), else under a display when it draws.
void run(jointid::cli::Command& command, char** argv) {
  namespace cli = jointid::cli;
  const cli::Engine engine = command.engine();
  const cli::EngineSession session(engine);
  if (command.draws() && engine != cli::Engine::slepc) rerun_with_display(argv);
  for (const std::string& renamed : cli::renamed_options()) // once, after any re-run
    cli::warn(renamed);
  command.run();
}

} // namespace

int main(int argc, char** argv) {
  namespace cli = jointid::cli;
  // An interrupt (SIGINT, SIGTERM, SIGHUP) removes the temporary files of outputs in progress
  // and exits with 128 + the signal; finished outputs are renamed into place whole, and never
  // over a file this run reads.
  jointid::io::install_interrupt_cleanup();
  jointid::io::protect_inputs();
  CLI::App app{"jointid: identify non-linear joints of structures from measured responses",
               "jointid"};
  app.set_version_flag("--version", "jointid " JOINTID_VERSION);
  app.require_subcommand(1);
  std::vector<std::unique_ptr<cli::Command>> commands;
  for (auto* add :
       {cli::modes_command, cli::frf_command, cli::simulate_command, cli::identify_command,
        cli::discover_command, cli::response_command, cli::design_command, cli::compare_command,
        cli::modal_fit_command, cli::backbone_command})
    commands.push_back(add(app));

  try {
    app.parse(argc, argv);
    for (const auto& command : commands)
      if (command->chosen()) run(*command, argv);
    return 0;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e); // --help, --version
    std::cerr << "jointid: " << one_line(e.what()) << " (run with --help for usage)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "jointid: " << one_line(e.what()) << "\n";
    return 1;
  }
}
