// jointid: the command line. Only parses arguments and calls the commands; every error ends
// here as one line on stderr and exit status 1.
#include "cli/commands.hpp"
#include "cli/engine.hpp"
#include "io/files.hpp"
#include "report/vtk_output.hpp"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
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
  app.require_subcommand(1);

  cli::SimulateOptions sim;
  auto* simulate = app.add_subcommand(
      "simulate", "Simulate sine tests of the model with its joints at their values; "
                  "one record (CSV) per frequency x amplitude");
  simulate->add_option("MODEL", sim.model, "Model file (TOML)")->required();
  simulate->add_option(
      "--force", sim.force,
      "NODE:DOF of the force, e.g. 7:uy; NODE may be a one-node Gmsh group (not with "
      "--excitation record)");
  simulate
      ->add_option("--freq", sim.frequencies,
                   "Excitation frequencies, Hz (comma-separated; sine tests)")
      ->delimiter(',')
      ->allow_extra_args(false);
  simulate
      ->add_option("--amplitude", sim.amplitudes,
                   "Force amplitudes (peak), N or N m (comma-separated; one for a sweep)")
      ->delimiter(',')
      ->allow_extra_args(false);
  simulate
      ->add_option("--method", sim.method,
                   "time: Newmark integration to steady state; hb: harmonic balance")
      ->capture_default_str();
  simulate->add_option("--periods", sim.periods, "Periods in each record")->capture_default_str();
  simulate
      ->add_option("--steps-per-period", sim.steps_per_period, "Time steps (samples) per period")
      ->capture_default_str();
  simulate->add_option("--harmonics", sim.harmonics, "Harmonics of the harmonic balance (hb)")
      ->capture_default_str();
  simulate
      ->add_option("--samples-per-period", sim.samples_per_period,
                   "Samples recorded per period (a divisor of --steps-per-period; 0: every step)")
      ->capture_default_str();
  simulate
      ->add_option("--channels", sim.channels,
                   "Response quantities recorded at every output: x, v, a (comma-separated)")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  simulate
      ->add_option("--outputs", sim.outputs,
                   "More response points beyond the joints and the force, NODE:DOF,...")
      ->delimiter(',')
      ->allow_extra_args(false);
  simulate
      ->add_option("--noise", sim.noise,
                   "Measurement noise: white Gaussian, RMS as a fraction of each channel's RMS "
                   "(e.g. 0.01)")
      ->capture_default_str();
  simulate->add_option("--seed", sim.seed, "Seed of the noise (record i uses seed + i)")
      ->capture_default_str();
  simulate->add_flag("--table", sim.table,
                     "Write one stepped-sine table (the fundamentals) DIR/stepped_sine.csv "
                     "instead of time records");
  simulate->add_option("-o,--output", sim.output_dir, "Output directory (created if missing)")
      ->required();
  simulate
      ->add_option("--excitation", sim.excitation,
                   "sine: steady-state sine tests (--freq, --amplitude); random: band-limited "
                   "Gaussian (--band, --rms); sweep: linear sine sweep over --band "
                   "(--amplitude); multisine: --band, --rms (these three need --duration and "
                   "--sample-rate); record: the force channels of --force-from. All but sine "
                   "write one record")
      ->capture_default_str();
  simulate->add_option("--band", sim.band, "F0:F1 in Hz (random, sweep, multisine)");
  simulate->add_option("--rms", sim.rms, "RMS force, N or N m (random, multisine)");
  simulate->add_option("--duration", sim.duration, "Record length, s (random, sweep, multisine)");
  simulate->add_option("--sample-rate", sim.sample_rate,
                       "Samples per second of the record, Hz (random, sweep, multisine)");
  simulate
      ->add_option("--route", sim.route,
                   "modal: retained modes + static correction (fast); full: the whole FE model")
      ->capture_default_str();
  simulate
      ->add_option("--modal-cutoff", sim.modal_cutoff,
                   "Modal route: modes below this are integrated, Hz (0: the Nyquist frequency)")
      ->capture_default_str();
  simulate->add_option("--substeps", sim.substeps, "Newmark steps per sample (random, ...)")
      ->capture_default_str();
  simulate->add_option("--force-from", sim.force_from,
                       "--excitation record: a record (CSV) whose f@NODE:DOF channels drive the "
                       "model");
  simulate->add_option_function<double>(
      "--fade-in", [&sim](const double& s) { sim.fade_in = s; },
      "Force faded in over this time from rest, s (default: 5 % of --duration; none "
      "for a record's force that starts at zero)");

  cli::CompareOptions cmp;
  auto* compare = app.add_subcommand(
      "compare", "Measured vs predicted response spectra: drive the model (joints at their "
                 "values) with a record's measured force, compare the Welch PSD of every "
                 "response channel; writes DIR/compare.json and DIR/compare.png");
  compare->add_option("MODEL", cmp.model, "Model file (TOML)")->required();
  compare->add_option("RECORD", cmp.record, "Measurement record (CSV) with force and responses")
      ->required();
  compare->add_option("--band", cmp.band, "F0:F1 in Hz compared (default: the whole spectrum)");
  compare
      ->add_option("--segment", cmp.segment,
                   "Welch segment, samples (0: largest power of two giving >= 16 averages)")
      ->capture_default_str();
  compare->add_option_function<double>(
      "--skip", [&cmp](const double& s) { cmp.skip = s; },
      "Seconds left out at the start of both records (default: 10 % of the "
      "record; the simulation starts from rest)");
  compare
      ->add_option("--route", cmp.route,
                   "modal: retained modes + static correction (fast); full: the whole FE model")
      ->capture_default_str();
  compare
      ->add_option("--modal-cutoff", cmp.modal_cutoff,
                   "Modal route: modes below this are integrated, Hz (0: the Nyquist frequency)")
      ->capture_default_str();
  compare->add_option("--substeps", cmp.substeps, "Newmark steps per sample")
      ->capture_default_str();
  compare->add_flag("!--no-plot", cmp.plot, "Write no compare.png");
  compare->add_option("-o,--output", cmp.output_dir, "Output directory (created if missing)")
      ->required();

  cli::IdentifyOptions ident;
  auto* identify = app.add_subcommand(
      "identify", "Identify the joints' terms from measured records; writes JSON");
  identify->add_option("MODEL", ident.model, "Model file (TOML)")->required();
  identify->add_option("TESTS", ident.records, "Measurement records or stepped-sine tables (CSV)")
      ->required();
  identify->add_option("-o,--output", ident.output, "Result file (JSON)")->required();
  identify
      ->add_option("--harmonics", ident.harmonics, "Harmonics whose equations are used, e.g. 1,2,3")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  identify->add_option("--fit-png", ident.fit_png,
                       "Picture (PNG) of each test's joint displacements with their harmonic fits");
  identify->add_option("--params-png", ident.params_png,
                       "Picture (PNG) of the identified values / the model's, with 95 % intervals");
  identify->add_flag("--output-error", ident.output_error,
                     "Refine by output error (maximum likelihood: the harmonic balance of the "
                     "model fitted to the measured harmonics, each weighted by its noise); needs "
                     "records of two or more periods");
  identify
      ->add_option("--hb-harmonics", ident.balance_harmonics,
                   "Harmonics of the output-error model's harmonic balance")
      ->capture_default_str();

  cli::DiscoverOptions disc;
  auto* discover = app.add_subcommand(
      "discover", "Find where the model and the measurement disagree, name the missing joint "
                  "effect, add it and show the gap shrink; writes DIR/discovery.json and "
                  "DIR/report.md with plots");
  discover->add_option("MODEL", disc.model, "Model file (TOML): the starting model")->required();
  discover->add_option("TESTS", disc.records, "Measurement records or stepped-sine tables (CSV)")
      ->required();
  discover->add_option("-o,--output", disc.output_dir, "Output directory (created if missing)")
      ->required();
  discover
      ->add_option("--harmonics", disc.harmonics,
                   "Harmonics used in the fits; 0 to the largest are compared")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  discover
      ->add_option("--hb-harmonics", disc.balance_harmonics,
                   "Harmonics of the harmonic-balance re-simulations")
      ->capture_default_str();
  discover->add_option("--max-steps", disc.max_steps, "Most terms added")->capture_default_str();
  discover
      ->add_option("--terms", disc.terms,
                   "Candidate terms tried at every joint (default: k, c, k2, k3, c2, c3, fc)")
      ->delimiter(',')
      ->allow_extra_args(false);
  discover->add_flag("!--no-damping-candidate", disc.substructure_damping,
                     "Do not try scaling the substructure's damping");
  discover->add_flag("!--no-plots", disc.plots, "Write the report without plots");

  cli::ModesOptions mod;
  auto* modes = app.add_subcommand(
      "modes", "Natural frequencies of the linear substructure; writes DIR/modes.json");
  modes->add_option("MODEL", mod.model, "Model file (TOML)")->required();
  modes->add_option("-o,--output", mod.output_dir, "Output directory (created if missing)")
      ->required();
  modes->add_option("--count", mod.count, "Number of modes")->capture_default_str();
  modes->add_option("--pictures", mod.pictures, "Modes drawn in DIR/modes.png (0: none)")
      ->capture_default_str();
  modes
      ->add_option("--tolerance", mod.tolerance,
                   "sparse and slepc engines: relative residual at which a mode has converged")
      ->capture_default_str();
  modes
      ->add_option("--max-restarts", mod.max_restarts,
                   "sparse and slepc engines: restarts of the Lanczos (Krylov-Schur) iteration "
                   "before it gives up")
      ->capture_default_str();

  cli::ResponseOptions resp;
  auto* response = app.add_subcommand(
      "response", "Response curves (harmonic balance with continuation, stability, folds) of the "
                  "model with its joints; writes DIR/response.json and DIR/response.png");
  response->add_option("MODEL", resp.model, "Model file (TOML)")->required();
  response->add_option("--force", resp.force, "DOF of the sine force, NODE:DOF (e.g. 7:uy)")
      ->required();
  response
      ->add_option("--amplitude", resp.amplitudes,
                   "Force amplitudes, N or N m (peak; comma-separated, one curve each)")
      ->required()
      ->delimiter(',')
      ->allow_extra_args(false);
  response->add_option("--freq-range", resp.freq_range, "Band F0:F1 in Hz, traced from F0 to F1")
      ->required();
  response->add_option("--harmonics", resp.harmonics, "Harmonics 0 … K of the harmonic balance")
      ->capture_default_str();
  response->add_option("--plot-dof", resp.plot_dof,
                       "DOF drawn in response.png, NODE:DOF (default: the force DOF)");
  response->add_flag("!--no-plot", resp.plot, "Write no response.png");
  response->add_option("-o,--output", resp.output_dir, "Output directory (created if missing)")
      ->required();

  cli::FrfOptions fr;
  auto* frf = app.add_subcommand(
      "frf", "FRFs of the linear substructure (modal synthesis) from one force: receptance, "
             "mobility or accelerance; writes DIR/frf.csv, DIR/frf.uff (UFF58) and DIR/frf.png");
  frf->add_option("MODEL", fr.model, "Model file (TOML)")->required();
  frf->add_option("--drive", fr.drive, "DOF of the force, NODE:DOF (e.g. 7:uy)")->required();
  frf->add_option("--response", fr.responses,
                  "Response DOFs, NODE:DOF (comma-separated; default: the drive DOF)")
      ->delimiter(',')
      ->allow_extra_args(false);
  frf->add_option("--freq-range", fr.freq_range, "Band F0:F1 in Hz (F0 >= 0)")->required();
  frf->add_option("--points", fr.points, "Evenly spaced frequencies, both ends included")
      ->capture_default_str();
  frf->add_option("--kind", fr.kind,
                  "receptance (m/N), mobility ((m/s)/N) or accelerance ((m/s^2)/N)")
      ->capture_default_str();
  frf->add_flag("!--no-plot", fr.plot, "Write no frf.png");
  frf->add_option("-o,--output", fr.output_dir, "Output directory (created if missing)")
      ->required();

  cli::DesignOptions des;
  auto* design = app.add_subcommand(
      "design", "Experiment design: choose the N sine tests (of candidate frequencies x force "
                "levels) that determine the joints' terms best (D-optimal, predicted at the "
                "model's values as prior guesses); writes DIR/design.json");
  design->add_option("MODEL", des.model, "Model file (TOML); joint values = prior guesses")
      ->required();
  design->add_option("--force", des.force, "DOF of the sine force, NODE:DOF (e.g. 7:uy)")
      ->required();
  design
      ->add_option("--freq", des.frequencies,
                   "Candidate frequencies, Hz: values or ranges START:STEP:STOP (comma-separated)")
      ->required()
      ->delimiter(',')
      ->allow_extra_args(false);
  design
      ->add_option("--amplitude", des.amplitudes,
                   "Candidate force amplitudes (peak), N or N m: values or ranges START:STEP:STOP")
      ->required()
      ->delimiter(',')
      ->allow_extra_args(false);
  design->add_option("-n", des.count, "Number of tests to choose")->capture_default_str();
  design
      ->add_option("--harmonics", des.harmonics,
                   "Harmonics whose equations the identification will use, e.g. 1,2,3")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  design
      ->add_option("--noise", des.noise,
                   "Expected measurement noise: RMS as a fraction of each channel's RMS, on "
                   "force and response")
      ->capture_default_str();
  design->add_option("--periods", des.periods, "Periods in each record (averaged)")
      ->capture_default_str();
  design
      ->add_option("--balance-harmonics", des.balance_harmonics,
                   "Harmonics 0 … K of the harmonic balance that predicts the tests")
      ->capture_default_str();
  design
      ->add_option("--max-misfit", des.max_misfit,
                   "Leave out candidates whose equations, at the model's values, miss by more than "
                   "this many noise standard deviations (e.g. where a friction joint sticks)")
      ->capture_default_str();
  design->add_option("-o,--output", des.output_dir, "Output directory (created if missing)")
      ->required();

  // --engine: every command that computes modes. slepc runs under mpirun -np N.
  const std::string large_help =
      "Modes of models above the dense limit: auto (CHOLMOD on this machine) or slepc "
      "(distributed, run under mpirun -np N; only rank 0 writes)";
  simulate->add_option("--engine", sim.engine, large_help)
      ->check(CLI::IsMember({"auto", "slepc"}))
      ->capture_default_str();
  identify->add_option("--engine", ident.engine, large_help)
      ->check(CLI::IsMember({"auto", "slepc"}))
      ->capture_default_str();
  discover->add_option("--engine", disc.engine, large_help)
      ->check(CLI::IsMember({"auto", "slepc"}))
      ->capture_default_str();
  response->add_option("--engine", resp.engine, large_help)
      ->check(CLI::IsMember({"auto", "slepc"}))
      ->capture_default_str();
  frf->add_option("--engine", fr.engine, large_help)
      ->check(CLI::IsMember({"auto", "slepc"}))
      ->capture_default_str();
  design->add_option("--engine", des.engine, large_help)
      ->check(CLI::IsMember({"auto", "slepc"}))
      ->capture_default_str();
  modes
      ->add_option("--engine", mod.engine,
                   "auto (dense up to 1500 equations, else CHOLMOD), dense, sparse (CHOLMOD) or "
                   "slepc (distributed, run under mpirun -np N; only rank 0 writes)")
      ->check(CLI::IsMember({"auto", "dense", "sparse", "slepc"}))
      ->capture_default_str();

  try {
    app.parse(argc, argv);
    const std::string engine = simulate->parsed()   ? sim.engine
                               : identify->parsed() ? ident.engine
                               : discover->parsed() ? disc.engine
                               : response->parsed() ? resp.engine
                               : design->parsed()   ? des.engine
                               : frf->parsed()      ? fr.engine
                                                    : mod.engine;
    // MPI for the distributed engine; no X display is looked for under it (a picture is
    // then drawn only when one exists).
    const cli::EngineSession session(cli::parse_engine(engine));
    const bool distributed = engine == "slepc";
    if (simulate->parsed()) cli::simulate(sim);
    if (identify->parsed() && !(ident.fit_png.empty() && ident.params_png.empty()) && !distributed)
      rerun_with_display(argv);
    if (identify->parsed()) cli::identify(ident);
    if (discover->parsed() && disc.plots && !distributed) rerun_with_display(argv);
    if (discover->parsed()) cli::discover(disc);
    if (response->parsed() && resp.plot && !distributed) rerun_with_display(argv);
    if (response->parsed()) cli::response(resp);
    if (design->parsed()) cli::design(des);
    if (modes->parsed() && mod.pictures > 0 && !distributed) rerun_with_display(argv);
    if (modes->parsed()) cli::modes(mod);
    if (frf->parsed() && fr.plot && !distributed) rerun_with_display(argv);
    if (frf->parsed()) cli::frf(fr);
    if (compare->parsed() && cmp.plot) rerun_with_display(argv);
    if (compare->parsed()) cli::compare(cmp);
    return 0;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e); // --help
    std::cerr << "jointid: " << one_line(e.what()) << " (run with --help for usage)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "jointid: " << one_line(e.what()) << "\n";
    return 1;
  }
}
