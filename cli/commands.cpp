#include "cli/commands.hpp"

#include "cli/engine.hpp"

#include "discover/discover.hpp"
#include "fem/excitation.hpp"
#include "fem/modal.hpp"
#include "fem/zero_modes.hpp"
#include "frf/substructure.hpp"
#include "frf/sweep.hpp"
#include "identify/compare.hpp"
#include "identify/design.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/output_error.hpp"
#include "identify/random_tests.hpp"
#include "identify/sine_tests.hpp"
#include "io/chart.hpp"
#include "io/discovery_report.hpp"
#include "io/files.hpp"
#include "io/frf_output.hpp"
#include "io/harmonic_fit_figure.hpp"
#include "io/model_file.hpp"
#include "io/record_csv.hpp"
#include "io/response_curves.hpp"
#include "io/results_json.hpp"
#include "io/spectra_comparison.hpp"
#include "io/terminal_progress.hpp"
#include "io/vtk_output.hpp"
#include "joints/joint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <unistd.h>

namespace jointid::cli {

namespace fs = std::filesystem;

namespace {

void warn(const std::string& what) {
  std::cerr << "jointid: warning: " << what << "\n";
}

void check_output_dir(const fs::path& dir) {
  std::error_code ec;
  if (dir.empty()) throw io::Error("-o: expected a directory");
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw io::Error(fmt::format("-o {}: exists and is not a directory", dir.string()));
}

void make_output_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw io::Error(fmt::format("{}: cannot create the directory: {}", dir.string(), ec.message()));
}

void check_output_file(const fs::path& file) {
  std::error_code ec;
  if (file.filename().empty() || fs::is_directory(file, ec))
    throw io::Error(fmt::format("-o {}: expected a file name, got a directory", file.string()));
  const fs::path parent = file.parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw io::Error(
        fmt::format("-o {}: the directory {} does not exist", file.string(), parent.string()));
}

void check_harmonics(const std::vector<int>& harmonics, int lowest) {
  if (harmonics.empty()) throw io::Error("--harmonics: expected at least one harmonic, e.g. 1,2,3");
  if (harmonics.size() == 1 && harmonics[0] == 0)
    throw io::Error("--harmonics: 0 alone is the mean (static) balance, which a sine test does not "
                    "excite: add harmonic 1 (e.g. 0,1,2,3)");
  std::set<int> seen;
  for (int k : harmonics) {
    if (k < lowest || k > 50)
      throw io::Error(
          fmt::format("--harmonics: expected harmonics from {} to 50, got {}", lowest, k));
    if (!seen.insert(k).second)
      throw io::Error(fmt::format("--harmonics: harmonic {} is listed twice", k));
  }
}

fem::NodeDof resolve(const io::ModelFile& file, const frf::Substructure& sub,
                     const std::string& option, const std::string& text) {
  try {
    const fem::NodeDof at = io::resolve_node_dof(file, text);
    sub.dofs().equation(at);
    return at;
  } catch (const std::invalid_argument& e) {
    throw io::Error(fmt::format("{} {}: {} (expected NODE:DOF of a free DOF of {}, e.g. 7:uy, or "
                                "a one-node Gmsh group such as tip:uy)",
                                option, text, e.what(), file.path.string()));
  }
}

identify::Quantity parse_quantity(const std::string& text) {
  if (text == "x") return identify::Quantity::displacement;
  if (text == "v") return identify::Quantity::velocity;
  if (text == "a") return identify::Quantity::acceleration;
  throw io::Error(fmt::format("--channels: expected x, v or a, got \"{}\"", text));
}

// --channels: x, v, a, each once.
std::vector<identify::Quantity> parse_channels(const std::vector<std::string>& channels) {
  std::vector<identify::Quantity> out;
  for (const auto& c : channels) {
    const identify::Quantity q = parse_quantity(c);
    if (std::find(out.begin(), out.end(), q) != out.end())
      throw io::Error(fmt::format("--channels: {} is listed twice", c));
    out.push_back(q);
  }
  if (out.empty()) throw io::Error("--channels: expected x, v and/or a");
  return out;
}

// --noise: a fraction of each channel's RMS.
void check_noise(double noise) {
  if (!(std::isfinite(noise) && noise >= 0.0 && noise < 1.0))
    throw io::Error(fmt::format(
        "--noise: expected a fraction of each channel's RMS from 0 to below 1, got {}", noise));
}

// "F0:F1" in Hz: two finite numbers; io::Error naming the option otherwise.
std::pair<double, double> parse_pair(const std::string& option, const std::string& text,
                                     const char* example) {
  double f0 = 0.0, f1 = 0.0;
  const auto colon = text.find(':');
  bool ok = colon != std::string::npos;
  if (ok) {
    try {
      std::size_t n0 = 0, n1 = 0;
      const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
      f0 = std::stod(a, &n0);
      f1 = std::stod(b, &n1);
      ok = n0 == a.size() && n1 == b.size() && std::isfinite(f0) && std::isfinite(f1);
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok)
    throw io::Error(
        fmt::format("{}: expected F0:F1 in Hz, e.g. {}, got \"{}\"", option, example, text));
  return {f0, f1};
}

// A band "F0:F1" in Hz with 0 <= F0 < F1.
std::pair<double, double> parse_band(const std::string& option, const std::string& text) {
  const auto [f0, f1] = parse_pair(option, text, "2:40");
  if (!(f0 >= 0.0 && f1 > f0))
    throw io::Error(fmt::format("{}: expected 0 <= F0 < F1 (Hz), got {} and {}", option, f0, f1));
  return {f0, f1};
}

// Progress on a terminal, from MPI rank 0 only.
struct TerminalProgress : io::TerminalProgress {
  explicit TerminalProgress(std::string label)
      : io::TerminalProgress(std::move(label), output_rank()) {}
};

identify::TransientRoute parse_route(const std::string& text) {
  if (text == "modal") return identify::TransientRoute::modal;
  if (text == "full") return identify::TransientRoute::full;
  throw io::Error(fmt::format("--route: expected modal or full, got \"{}\"", text));
}

// simulate --excitation random|sweep|multisine|record: one record under that force history.
void simulate_signal(const SimulateOptions& o) {
  // 1. The options.
  const std::string& kind = o.excitation;
  if (kind != "random" && kind != "sweep" && kind != "multisine" && kind != "record")
    throw io::Error(fmt::format(
        "--excitation: expected sine, random, sweep, multisine or record, got \"{}\"", kind));
  const bool from_record = kind == "record";
  if (!o.frequencies.empty())
    throw io::Error(fmt::format("--freq: only for sine tests, not --excitation {}", kind));
  if (o.method != "time")
    throw io::Error(fmt::format("--method {}: --excitation {} is simulated in time (see --route)",
                                o.method, kind));
  if (o.table) throw io::Error("--table: only for sine tests");
  double f0 = 0.0, f1 = 0.0, level = 0.0;
  if (from_record) {
    if (o.force_from.empty())
      throw io::Error("--force-from: expected the record (CSV) whose force channels drive the "
                      "model, for --excitation record");
    if (!o.force.empty())
      throw io::Error("--force: not with --excitation record (the forces act where the record's "
                      "f@NODE:DOF channels say)");
    if (!o.band.empty() || o.rms != 0.0 || !o.amplitudes.empty() || o.duration != 0.0 ||
        o.sample_rate != 0.0)
      throw io::Error(
          "--band, --rms, --amplitude, --duration, --sample-rate: not with --excitation "
          "record (the record gives the force and its sampling)");
  } else {
    if (!o.force_from.empty()) throw io::Error("--force-from: only with --excitation record");
    if (o.force.empty()) throw io::Error("--force: expected NODE:DOF of the force, e.g. 7:uy");
    if (o.band.empty())
      throw io::Error(fmt::format("--band: expected F0:F1 in Hz for --excitation {}", kind));
    std::tie(f0, f1) = parse_band("--band", o.band);
    if (!(std::isfinite(o.duration) && o.duration > 0.0))
      throw io::Error(fmt::format("--duration: expected a duration > 0 s, got {}", o.duration));
    if (!(std::isfinite(o.sample_rate) && o.sample_rate > 0.0))
      throw io::Error(
          fmt::format("--sample-rate: expected a sample rate > 0 Hz, got {}", o.sample_rate));
    if (!(f1 < 0.5 * o.sample_rate))
      throw io::Error(fmt::format("--band {}: expected F1 below half the sample rate ({} Hz)",
                                  o.band, 0.5 * o.sample_rate));
    if (kind == "sweep") {
      if (o.amplitudes.size() != 1 || !(std::isfinite(o.amplitudes[0]) && o.amplitudes[0] > 0.0))
        throw io::Error("--amplitude: expected one amplitude > 0 (N, peak) for the sweep");
      if (o.rms != 0.0) throw io::Error("--rms: not for a sweep (give --amplitude, the peak)");
      level = o.amplitudes[0];
    } else {
      if (!o.amplitudes.empty())
        throw io::Error(fmt::format("--amplitude: not for --excitation {} (give --rms)", kind));
      if (!(std::isfinite(o.rms) && o.rms > 0.0))
        throw io::Error(fmt::format("--rms: expected an RMS force > 0 (N), got {}", o.rms));
      level = o.rms;
    }
  }
  const identify::TransientRoute route = parse_route(o.route);
  if (o.substeps < 1)
    throw io::Error(fmt::format("--substeps: expected at least 1, got {}", o.substeps));
  if (!(std::isfinite(o.modal_cutoff) && o.modal_cutoff >= 0.0))
    throw io::Error(fmt::format("--modal-cutoff: expected >= 0 Hz, got {}", o.modal_cutoff));
  if (o.fade_in && !(std::isfinite(*o.fade_in) && *o.fade_in >= 0.0))
    throw io::Error(fmt::format("--fade-in: expected seconds >= 0, got {}", *o.fade_in));
  check_noise(o.noise);
  identify::ForcedOptions options;
  options.quantities = parse_channels(o.channels);
  options.route = route;
  options.modal_cutoff_hz = o.modal_cutoff;
  options.substeps = o.substeps;
  check_output_dir(o.output_dir);

  // 2. The force history.
  identify::ForceInput input;
  std::string name;
  double duration = o.duration;
  if (from_record) {
    const identify::Record record = io::read_record(o.force_from);
    try {
      input = identify::force_input(record);
    } catch (const std::invalid_argument& e) {
      throw io::Error(std::string("--force-from ") + e.what());
    }
    duration = static_cast<double>(record.t.size()) / input.sample_rate_hz;
    name = o.force_from.stem().string() + "_simulated.csv";
  } else {
    const identify::ExcitationSpec spec{kind == "random"  ? identify::Excitation::random
                                        : kind == "sweep" ? identify::Excitation::sweep
                                                          : identify::Excitation::multisine,
                                        f0,
                                        f1,
                                        level,
                                        o.seed,
                                        o.duration,
                                        o.sample_rate};
    try {
      input = identify::generated_force(spec, {}); // the DOF is resolved with the model
    } catch (const std::invalid_argument& e) {
      throw io::Error(std::string("--band, --duration, --sample-rate: ") + e.what());
    }
    name = identify::excitation_record_name(spec);
  }
  // Default: 5 % of the duration, none for a record's force that already starts at zero.
  const bool starts_at_zero =
      input.samples.row(0).cwiseAbs().maxCoeff() <= 1e-9 * input.samples.cwiseAbs().maxCoeff();
  const double fade = o.fade_in                       ? *o.fade_in
                      : from_record && starts_at_zero ? 0.0
                                                      : 0.05 * duration;
  if (!(fade >= 0.0 && fade < duration))
    throw io::Error(
        fmt::format("--fade-in: expected 0 to below the duration ({} s), got {}", duration, fade));
  options.fade_in_s = fade;

  // 3. The model and the simulation.
  const io::ModelFile file = io::read_model(o.model);
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  if (!from_record) input.at = {resolve(file, sub, "--force", o.force)};
  for (const auto& text : o.outputs)
    options.extra_outputs.push_back(resolve(file, sub, "--outputs", text));
  io::check_not_an_input(o.output_dir / name);
  identify::ForcedTest test;
  const TerminalProgress progress{"jointid simulate: time simulation"};
  options.progress = progress.callback();
  try {
    test = identify::simulate_forced(sub, file.joints, input, options);
  } catch (const std::invalid_argument& e) {
    progress.clear();
    throw io::Error(o.model.string() + ": " + e.what());
  }
  progress.clear();
  if (!test.status.ok()) throw std::runtime_error(test.status.reason);
  test.record.source = name;
  test.comments.insert(test.comments.begin(), {"jointid simulate", "model: " + o.model.string()});
  if (o.noise > 0.0) {
    // Not the random force's own seed: the same generator state would make the noise the very
    // white sequence the force was filtered from, correlated with it.
    const unsigned long long noise_seed = o.seed + 1000003ULL;
    identify::add_noise(test.record, o.noise, noise_seed);
    test.comments.push_back(fmt::format(
        "noise: white Gaussian, RMS {} of each channel's RMS, on every channel (seed {})", o.noise,
        noise_seed));
  }
  for (const auto& w : test.warnings)
    warn(w);

  // 4. Write.
  if (!output_rank()) return;
  make_output_dir(o.output_dir);
  const fs::path path = o.output_dir / name;
  io::OutputFiles files;
  files.add(path, io::record_csv(test.record, test.comments));
  files.commit();
  fmt::print("wrote {}\n", path.string());
}

} // namespace

void simulate(const SimulateOptions& o) {
  if (o.excitation != "sine") {
    simulate_signal(o);
    return;
  }
  if (!o.band.empty() || o.rms != 0.0 || o.duration != 0.0 || o.sample_rate != 0.0 ||
      !o.force_from.empty())
    throw io::Error("--band, --rms, --duration, --sample-rate, --force-from: only with "
                    "--excitation random, sweep, multisine or record");
  if (o.force.empty()) throw io::Error("--force: expected NODE:DOF of the sine force, e.g. 7:uy");
  // 1. The options, before anything is read or computed.
  if (o.frequencies.empty()) throw io::Error("--freq: expected at least one frequency (Hz)");
  if (o.amplitudes.empty()) throw io::Error("--amplitude: expected at least one amplitude (N)");
  for (double f : o.frequencies)
    if (!(std::isfinite(f) && f > 0.0))
      throw io::Error(fmt::format("--freq: expected frequencies > 0 Hz, got {}", f));
  for (double a : o.amplitudes)
    if (!(std::isfinite(a) && a > 0.0))
      throw io::Error(
          fmt::format("--amplitude: expected finite amplitudes > 0 (N or N m), got {}", a));
  if (o.method != "time" && o.method != "hb")
    throw io::Error(fmt::format("--method: expected time or hb, got \"{}\"", o.method));
  if (o.periods < 1)
    throw io::Error(fmt::format("--periods: expected at least 1, got {}", o.periods));
  if (o.steps_per_period < 8)
    throw io::Error(
        fmt::format("--steps-per-period: expected at least 8, got {}", o.steps_per_period));
  if (o.samples_per_period != 0 &&
      (o.samples_per_period < 8 || o.steps_per_period % o.samples_per_period != 0))
    throw io::Error(fmt::format("--samples-per-period: expected at least 8 and a divisor of "
                                "--steps-per-period ({}), got {}",
                                o.steps_per_period, o.samples_per_period));
  if (o.harmonics < 1)
    throw io::Error(fmt::format("--harmonics: expected at least 1, got {}", o.harmonics));
  check_noise(o.noise);
  identify::SimulationOptions options;
  options.quantities = parse_channels(o.channels);
  check_output_dir(o.output_dir);

  // 2. The model and the tests.
  const io::ModelFile file = io::read_model(o.model);
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  const fem::NodeDof force_at = resolve(file, sub, "--force", o.force);
  // Refused before the simulation, not after: the outputs never replace an input.
  io::check_not_an_input(o.output_dir / "stepped_sine.csv");
  for (const auto& text : o.outputs)
    options.extra_outputs.push_back(resolve(file, sub, "--outputs", text));
  std::vector<identify::SineTestPlan> plans;
  std::set<std::string> names;
  for (double f : o.frequencies)
    for (double a : o.amplitudes) {
      plans.push_back({f, a});
      if (!names.insert(identify::sine_test_name(plans.back())).second)
        throw io::Error(
            fmt::format("--freq, --amplitude: the test at {} Hz, {} N is listed twice", f, a));
      io::check_not_an_input(o.output_dir / identify::sine_test_name(plans.back()));
    }
  options.method = o.method == "time" ? identify::SimulationMethod::time_integration
                                      : identify::SimulationMethod::harmonic_balance;
  options.periods = o.periods;
  options.steps_per_period = o.steps_per_period;
  options.samples_per_period = o.samples_per_period;
  options.balance.harmonics = o.harmonics;

  // 3. Simulate every test, keeping the records in memory: nothing is written unless all succeed.
  std::vector<identify::SimulatedTest> tests;
  const TerminalProgress progress{fmt::format("jointid simulate: {} sine tests", plans.size())};
  options.progress = progress.callback();
  try {
    tests = identify::simulate_sine_tests(sub, file.joints, force_at, plans, options);
  } catch (const std::invalid_argument& e) {
    progress.clear();
    throw io::Error(o.model.string() + ": " + e.what());
  } catch (...) {
    progress.clear();
    throw;
  }
  progress.clear();
  for (const auto& t : tests)
    if (!t.status.ok()) throw std::runtime_error(t.status.reason);
  for (std::size_t i = 0; i < tests.size(); ++i) {
    auto& t = tests[i];
    t.comments.insert(t.comments.begin(), {"jointid simulate", "model: " + o.model.string()});
    if (o.noise > 0.0) {
      identify::add_noise(t.record, o.noise, o.seed + i);
      t.comments.push_back(fmt::format(
          "noise: white Gaussian, RMS {} of each channel's RMS, on every channel (seed {})",
          o.noise, o.seed + i));
    }
    for (const auto& w : t.warnings)
      warn(w);
  }

  // 4. Write (rank 0 of an MPI run).
  if (!output_rank()) return;
  std::vector<std::pair<fs::path, std::string>> outputs;
  if (o.table) {
    std::vector<std::string> comments{"jointid simulate", "model: " + o.model.string(),
                                      "one sine test a row: fundamentals of the records"};
    for (const auto& c : tests.front().comments) // how they were made, as in the records
      if (c.rfind("joint ", 0) == 0 || c.rfind("method", 0) == 0 || c.rfind("noise", 0) == 0)
        comments.push_back(c);
    std::vector<identify::Record> records;
    for (const auto& t : tests)
      records.push_back(t.record);
    const io::SteppedSineTable table = io::stepped_sine_table(records);
    outputs.push_back({o.output_dir / "stepped_sine.csv", io::stepped_sine_csv(table, comments)});
  } else {
    for (const auto& t : tests)
      outputs.push_back({o.output_dir / t.record.source, io::record_csv(t.record, t.comments)});
  }
  // Every record under a temporary name first, then all renamed into place together.
  make_output_dir(o.output_dir);
  io::OutputFiles files;
  for (const auto& [path, text] : outputs)
    files.add(path, text);
  files.commit();
  for (const auto& [path, text] : outputs)
    fmt::print("wrote {}\n", path.string());
}

void identify(const IdentifyOptions& o) {
  if (o.records.empty()) throw io::Error("expected at least one record or table (CSV file)");
  check_harmonics(o.harmonics, 0);
  if (o.output_error) {
    const int K = *std::max_element(o.harmonics.begin(), o.harmonics.end());
    if (o.balance_harmonics < std::max(K, 1) || o.balance_harmonics > 200)
      throw io::Error(fmt::format("--hb-harmonics: expected from {} (the largest of --harmonics) "
                                  "to 200, got {}",
                                  std::max(K, 1), o.balance_harmonics));
  }
  check_output_file(o.output);
  for (const fs::path& png : {o.fit_png, o.params_png})
    if (!png.empty()) check_output_file(png);
  if (!o.fit_png.empty() && o.fit_png == o.params_png)
    throw io::Error("--fit-png and --params-png: expected two different files");

  const io::ModelFile file = io::read_model(o.model);
  if (file.joints.empty()) throw io::Error(o.model.string() + ": no [[joints]] to identify");
  const std::vector<identify::SineTest> tests = io::read_tests(o.records);
  io::check_not_an_input(o.output);
  for (const fs::path& png : {o.fit_png, o.params_png})
    if (!png.empty()) io::check_not_an_input(png);
  identify::FitOptions options;
  options.harmonics = o.harmonics;
  const std::vector<identify::Measurement> measured =
      identify::measure(tests, identify::measure_options(options));
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  identify::OutputErrorOptions oe;
  oe.harmonics = o.harmonics;
  oe.balance.harmonics = o.balance_harmonics;
  const identify::FitResult result =
      o.output_error ? identify::output_error(sub, file.joints, measured, options, oe)
                     : identify::fit(sub, file.joints, measured, options);
  if (!result.status.ok()) throw io::Error("identify: " + result.status.reason);
  if (!output_rank()) return;
  io::write_json(o.output, io::identify_result_json(result, {}, &measured));
  fmt::print("{:<12} {:<5} {:<26} {:>14} {:>11}  {}\n", "joint", "term", "effect", "value", "std",
             "95 % interval");
  for (const auto& j : result.joints)
    for (const auto& t : j.terms)
      fmt::print("{:<12} {:<5} {:<26} {:>14.7g} {:>11.3g}  {}\n", j.name, joints::term_name(t.term),
                 joints::term_effect(t.term), t.value, t.std,
                 t.fixed ? std::string("(fixed)")
                         : fmt::format("[{:.7g}, {:.7g}]", t.ci_low, t.ci_high));
  fmt::print("{} equations, {} unknowns, condition number {:.3g}, residual {:.3g} m rms ({:.3g} "
             "relative)\n",
             result.equations, result.unknowns, result.condition_number, result.residual_rms,
             result.residual_relative);
  fmt::print("intervals: {}{}\n",
             result.interval_method == "residual"
                 ? "from the residual (the records' noise is unknown or negligible)"
             : result.interval_method == "output error"
                 ? "output error (maximum likelihood with the records' noise: its Cramér–Rao "
                   "bound)"
                 : "from the records' noise, propagated (generalised least squares)",
             std::isfinite(result.chi2_per_dof)
                 ? fmt::format("; chi2 per degree of freedom {:.3g}", result.chi2_per_dof)
                 : std::string());
  for (const auto& sentence : result.identifiability)
    fmt::print("not determined: {}\n", sentence);
  fmt::print("wrote {}\n", o.output.string());
  // The pictures (each optional; one that cannot be drawn is a warning, the result stands).
  std::vector<std::pair<fs::path, std::function<io::Figure()>>> pictures;
  if (!o.fit_png.empty())
    pictures.push_back({o.fit_png, [&] {
                          std::vector<fem::NodeDof> shown;
                          for (const joints::Joint& j : file.joints)
                            for (const int node : {j.node, j.node_b})
                              if (node != 0 && std::find(shown.begin(), shown.end(),
                                                         fem::NodeDof{node, j.dof}) == shown.end())
                                shown.push_back({node, j.dof});
                          return io::harmonic_fit_figure(measured, shown);
                        }});
  if (!o.params_png.empty())
    pictures.push_back({o.params_png, [&] { return io::parameter_figure(result, file.joints); }});
  std::string why;
  const bool drawable = pictures.empty() || io::can_render_charts(&why);
  for (const auto& [png, figure] : pictures) {
    if (!drawable) {
      warn("no " + png.string() + ": " + why + " (run under xvfb-run -a)");
      continue;
    }
    try {
      io::write_chart_png(png, figure());
      fmt::print("wrote {}\n", png.string());
    } catch (const std::invalid_argument& e) {
      warn("no " + png.string() + ": " + e.what());
    }
  }
  for (const auto& w : result.warnings)
    warn(w);
}

void discover(const DiscoverOptions& o) {
  if (o.records.empty()) throw io::Error("expected at least one record or table (CSV file)");
  check_harmonics(o.harmonics, 1);
  const int K = *std::max_element(o.harmonics.begin(), o.harmonics.end());
  if (o.balance_harmonics < K || o.balance_harmonics > 200)
    throw io::Error(fmt::format("--hb-harmonics: expected from {} (the largest of --harmonics) to "
                                "200, got {}",
                                K, o.balance_harmonics));
  if (o.max_steps < 1)
    throw io::Error(fmt::format("--max-steps: expected at least 1, got {}", o.max_steps));
  discover::Options options;
  options.harmonics = o.harmonics;
  options.balance.harmonics = o.balance_harmonics;
  options.max_steps = o.max_steps;
  options.substructure_damping = o.substructure_damping;
  if (!o.terms.empty()) {
    options.terms.clear();
    for (const auto& t : o.terms) {
      try {
        options.terms.push_back(joints::parse_term(t));
      } catch (const std::invalid_argument& e) {
        throw io::Error(std::string("--terms: ") + e.what());
      }
    }
  }
  check_output_dir(o.output_dir);

  const io::ModelFile file = io::read_model(o.model);
  if (file.joints.empty())
    throw io::Error(o.model.string() + ": no [[joints]]: discovery starts from the joints' terms");
  const std::vector<identify::SineTest> tests = io::read_tests(o.records);
  for (const char* name : {"discovery.json", "report.md"})
    io::check_not_an_input(o.output_dir / name);
  const std::vector<identify::Measurement> measured = identify::measure(tests, {.harmonics = K});
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  const discover::Result result = discover::discover(sub, file.joints, measured, options);

  if (!output_rank()) return;
  make_output_dir(o.output_dir);
  const fs::path json = o.output_dir / "discovery.json";
  io::write_json(json, io::discovery_json(result));
  std::vector<std::string> warnings = result.warnings;
  io::ReportContext context{o.model.string(), {}, o.plots};
  for (const auto& p : o.records)
    context.inputs.push_back(p.string());
  const std::vector<fs::path> written =
      io::write_discovery_report(o.output_dir, result, context, warnings);

  for (std::size_t i = 0; i + 1 < result.diagnosis.findings.size(); ++i)
    fmt::print("{}\n", result.diagnosis.findings[i]);
  fmt::print("\n{:<5} {:<28} {:<26} {:>12} {:>11} {:>11}\n", "step", "added", "effect", "value",
             "gap before", "gap after");
  for (std::size_t i = 0; i < result.steps.size(); ++i) {
    const auto& s = result.steps[i];
    fmt::print("{:<5} {:<28} {:<26} {:>12.5g} {:>11.4g} {:>11.4g}\n", i + 1, s.added.name(),
               s.added.effect(), s.added.value, s.gap_before, s.gap_after);
  }
  fmt::print("\n{}\nStopped: {}.\n", result.diagnosis.findings.back(), result.stop_reason);
  fmt::print("wrote {}", json.string());
  for (const auto& p : written)
    fmt::print(", {}", p.filename().string());
  fmt::print("\n");
  for (const auto& w : warnings)
    warn(w);
}

namespace {

// modes.json and the table of a substructure without a mesh ([modal], [matrices]).
void write_modes_without_mesh(const ModesOptions& o, const fem::Modes& modes, int count,
                              const std::string& why) {
  make_output_dir(o.output_dir);
  const fs::path out = o.output_dir / "modes.json";
  io::write_json(out,
                 io::modes_json(modes, count, {why + ": no mesh, so no VTK files or pictures"}));
  fmt::print("{:>5} {:>16}\n", "mode", "frequency (Hz)");
  for (int r = 0; r < std::min(count, modes.num_modes()); ++r)
    fmt::print("{:>5} {:>16.8g}\n", r + 1, modes.frequency_hz(r));
  fmt::print("wrote {}\n", out.string());
}

} // namespace

void modes(const ModesOptions& o) {
  if (o.count < 1) throw io::Error(fmt::format("--count: expected at least 1, got {}", o.count));
  if (!(o.tolerance > 0.0 && o.tolerance < 1.0))
    throw io::Error(
        fmt::format("--tolerance: expected a relative residual in (0, 1), got {}", o.tolerance));
  if (o.max_restarts < 1)
    throw io::Error(fmt::format("--max-restarts: expected at least 1, got {}", o.max_restarts));
  check_output_dir(o.output_dir);
  const io::ModelFile file = io::read_model(o.model);
  for (const char* name : {"modes.json", "mesh.vtu", "modes.vtu"})
    io::check_not_an_input(o.output_dir / name);
  if (file.measured)
    throw io::Error(o.model.string() +
                    ": the substructure is given by measured FRFs ([frf]): there are no modes to "
                    "compute (identify, discover, simulate --method hb, response and frf read "
                    "the FRFs)");
  if (!file.parts.empty())
    throw io::Error(o.model.string() +
                    ": the substructure is made of several ([[substructures]]), which the "
                    "joints alone connect: run `jointid modes` on each substructure's file");
  if (file.modal) { // a substructure given by its modes: report them; no mesh to draw
    fem::Modes modes;
    modes.omega = 2.0 * std::numbers::pi * file.modal->frequencies_hz;
    write_modes_without_mesh(o, modes, std::min(o.count, modes.num_modes()),
                             "the substructure is given by its modes ([modal])");
    return;
  }
  // The slepc engine assembles K and M distributed by rows: rank 0 assembles them whole only
  // afterwards, for the checks and the files.
  const Engine engine = parse_engine(o.engine);
  if (file.matrices && engine == Engine::slepc)
    throw io::Error(o.model.string() +
                    ": --engine slepc assembles the finite elements by rows; a substructure "
                    "given by its matrices ([matrices]) uses --engine auto, dense or sparse");
  std::optional<frf::Substructure> sub;
  if (engine != Engine::slepc) sub.emplace(file.substructure());
  const int count = std::min(o.count, sub ? sub->dofs().num_equations()
                                          : fem::DofMap(file.model).num_equations());
  fem::ModalOptions options;
  options.num_modes = count;
  options.tolerance = o.tolerance;
  options.max_iterations = o.max_restarts;
  const fem::Modes modes =
      compute_modes(file.model, sub ? sub->system() : nullptr, options, engine);
  if (!modes.status.ok()) throw std::runtime_error("modal analysis failed: " + modes.status.reason);
  if (!output_rank()) return;
  if (!sub) sub.emplace(file.substructure());
  const fem::Assembled& system = *sub->system();
  std::vector<std::string> warnings;
  if (file.matrices) { // K and M given: no mesh to draw, no element table for mechanisms
    write_modes_without_mesh(o, modes, count,
                             "the substructure is given by its matrices ([matrices])");
    return;
  }
  if (const fem::ZeroModes z = fem::zero_modes(file.model, system, modes); z.count > 0)
    warnings.push_back(z.describe());
  make_output_dir(o.output_dir);
  const fs::path out = o.output_dir / "modes.json";
  io::write_json(out, io::modes_json(modes, count, warnings));
  fmt::print("{:>5} {:>16}\n", "mode", "frequency (Hz)");
  for (int r = 0; r < std::min(count, modes.num_modes()); ++r)
    fmt::print("{:>5} {:>16.8g}\n", r + 1, modes.frequency_hz(r));
  if (!io::vtk_available()) {
    fmt::print("wrote {}\n", out.string());
    warnings.push_back(std::string(io::no_vtk_message) +
                       " (modes.json only: no .vtu/.pvd files, no modes.png)");
    for (const auto& w : warnings)
      warn(w);
    return;
  }
  io::write_modes_vtk(o.output_dir, file.model, system.dofs, modes);
  fmt::print("wrote {}, {} and {} (ParaView)\n", out.string(),
             (o.output_dir / "modes.vtu").string(), (o.output_dir / "mode_<r>.pvd").string());
  if (o.pictures > 0) {
    const fs::path png = o.output_dir / "modes.png";
    const char* display = std::getenv("DISPLAY");
    if (display && *display) {
      io::render_modes_png(png, file.model, system.dofs, modes,
                           std::min(o.pictures, modes.num_modes()));
      fmt::print("wrote {}\n", png.string());
    } else {
      warnings.push_back(
          "no X display: modes.png not drawn (install xvfb, or run under xvfb-run -a)");
    }
  }
  for (const auto& w : warnings)
    warn(w);
}

void response(const ResponseOptions& o) {
  // 1. The options.
  if (o.amplitudes.empty()) throw io::Error("--amplitude: expected at least one amplitude (N)");
  for (double a : o.amplitudes)
    if (!(std::isfinite(a) && a > 0.0))
      throw io::Error(
          fmt::format("--amplitude: expected finite amplitudes > 0 (N or N m), got {}", a));
  if (std::set<double>(o.amplitudes.begin(), o.amplitudes.end()).size() != o.amplitudes.size())
    throw io::Error("--amplitude: an amplitude is listed twice");
  const auto [f0, f1] = parse_pair("--freq-range", o.freq_range, "15:25");
  if (!(f0 > 0.0 && f1 > 0.0 && f0 != f1))
    throw io::Error(fmt::format(
        "--freq-range: expected two different frequencies > 0 Hz, got {} and {}", f0, f1));
  if (o.harmonics < 1 || o.harmonics > 200)
    throw io::Error(fmt::format("--harmonics: expected 1 to 200, got {}", o.harmonics));
  check_output_dir(o.output_dir);

  // 2. The model.
  const io::ModelFile file = io::read_model(o.model);
  if (file.joints.empty())
    warn(o.model.string() + ": no [[joints]]: the response is the linear substructure's");
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  const fem::NodeDof force_at = resolve(file, sub, "--force", o.force);
  const fem::NodeDof shown =
      o.plot_dof.empty() ? force_at : resolve(file, sub, "--plot-dof", o.plot_dof);
  bool drawable = shown == force_at;
  for (const joints::Joint& j : file.joints)
    drawable = drawable || shown == fem::NodeDof{j.node, j.dof} ||
               (j.node_b != 0 && shown == fem::NodeDof{j.node_b, j.dof});
  if (!drawable)
    throw io::Error(fmt::format("--plot-dof {}: expected the force DOF ({}) or a joint's DOF",
                                o.plot_dof, fem::to_string(force_at)));

  // 3. The curves (progress on a terminal only).
  frf::ContinuationOptions options;
  options.hb.harmonics = o.harmonics;
  const bool terminal = isatty(STDERR_FILENO) == 1 && output_rank();
  std::function<void(std::size_t, double)> progress;
  if (terminal)
    progress = [&](std::size_t curve, double fraction) {
      std::cerr << fmt::format("\rjointid response: {} N ({} of {}): {:3.0f} %",
                               o.amplitudes[curve], curve + 1, o.amplitudes.size(),
                               100.0 * fraction)
                << std::flush;
    };
  frf::ResponseCurves curves;
  try {
    curves =
        frf::response_curves(sub, file.joints, force_at, o.amplitudes, f0, f1, options, progress);
  } catch (const std::invalid_argument& e) {
    throw io::Error(o.model.string() + ": " + e.what());
  }
  if (!curves.status.ok()) throw std::runtime_error(curves.status.reason);
  if (terminal) std::cerr << "\r" << std::string(60, ' ') << "\r" << std::flush;
  if (!output_rank()) return;

  // 4. Write.
  make_output_dir(o.output_dir);
  const fs::path json = o.output_dir / "response.json";
  io::write_json(json, io::response_json(curves));
  fmt::print("wrote {}\n", json.string());
  if (o.plot) {
    std::string why;
    if (io::can_render_charts(&why)) {
      const fs::path png = o.output_dir / "response.png";
      io::write_chart_png(png, io::response_figure(curves, shown));
      fmt::print("wrote {}\n", png.string());
    } else {
      warn("no response.png: " + why + " (run under xvfb-run -a)");
    }
  }
  for (std::size_t i = 0; i < curves.curves.size(); ++i) {
    const frf::ResponseBranch& b = curves.curves[i];
    std::vector<std::string> folds;
    for (int f : b.folds)
      folds.push_back(fmt::format("{:.4f} Hz", b.points[f].hb.frequency_hz));
    int unstable = 0;
    for (const auto& p : b.points)
      unstable += p.stable.has_value() && !*p.stable;
    fmt::print("{:g} N: {} points, {} folds{}{}, {} unstable{}\n", o.amplitudes[i], b.points.size(),
               b.folds.size(), folds.empty() ? "" : " at ",
               fmt::format("{}", fmt::join(folds, ", ")), unstable,
               b.complete ? "" : " (incomplete)");
    for (const auto& n : b.notes)
      (b.complete ? fmt::print("  {}\n", n) : warn(fmt::format("{:g} N: {}", o.amplitudes[i], n)));
  }
  for (const auto& n : curves.notes)
    fmt::print("note: {}\n", n);
}

void frf(const FrfOptions& o) {
  // 1. The options.
  const auto [f0, f1] = parse_pair("--freq-range", o.freq_range, "0:100");
  if (!(f0 >= 0.0 && f1 > f0))
    throw io::Error(fmt::format(
        "--freq-range: expected F0 >= 0 Hz below F1, got {} and {} (e.g. 0:100)", f0, f1));
  if (o.points < 2 || o.points > 1000000)
    throw io::Error(fmt::format("--points: expected 2 to 1000000, got {}", o.points));
  frf::FrfKind kind{};
  try {
    kind = frf::parse_frf_kind(o.kind);
  } catch (const std::invalid_argument& e) {
    throw io::Error(std::string("--kind: ") + e.what());
  }
  check_output_dir(o.output_dir);

  // 2. The model and the DOFs.
  const io::ModelFile file = io::read_model(o.model);
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  const fem::NodeDof drive = resolve(file, sub, "--drive", o.drive);
  std::vector<int> responses;
  for (const std::string& r : o.responses) {
    const int e = sub.dofs().equation(resolve(file, sub, "--response", r));
    if (std::find(responses.begin(), responses.end(), e) != responses.end())
      throw io::Error(fmt::format("--response: {} is listed twice", r));
    responses.push_back(e);
  }
  if (responses.empty()) responses.push_back(sub.dofs().equation(drive));
  std::vector<double> freq(static_cast<std::size_t>(o.points));
  for (int i = 0; i < o.points; ++i) // exact ends; evenly spaced (dataset 58's even spacing)
    freq[static_cast<std::size_t>(i)] =
        i + 1 == o.points ? f1 : f0 + (f1 - f0) * i / (o.points - 1.0);

  // 3. The FRFs.
  frf::FrfSweep sweep;
  try {
    sweep = frf::frf_sweep(sub, sub.dofs().equation(drive), std::move(responses), std::move(freq),
                           kind);
  } catch (const std::invalid_argument& e) {
    throw io::Error(o.model.string() + ": " + e.what());
  }
  if (!sweep.status.ok()) throw std::runtime_error(sweep.status.reason);
  if (!output_rank()) return;
  if (!file.joints.empty())
    fmt::print("note: the FRFs are the linear substructure's; the {} joint{} of {} {} not in "
               "them (see jointid response for the structure with its joints)\n",
               file.joints.size(), file.joints.size() == 1 ? "" : "s", o.model.string(),
               file.joints.size() == 1 ? "is" : "are");
  for (const std::string& n : sweep.notes)
    fmt::print("note: {}\n", n);

  // 4. Write: the table and the universal file staged and renamed into place together (a
  //    failure leaves both as they were); the picture after them, atomically too.
  const fs::path csv = o.output_dir / "frf.csv", uff = o.output_dir / "frf.uff",
                 png = o.output_dir / "frf.png";
  const std::string table = io::frf_csv(sweep, sub.dofs());
  const std::string universal = io::uff58_text(io::frf_uff58(sweep, sub.dofs()));
  make_output_dir(o.output_dir);
  io::OutputFiles files;
  files.add(csv, table);
  files.add(uff, universal);
  files.commit();
  fmt::print("wrote {}\nwrote {}\n", csv.string(), uff.string());
  if (o.plot) {
    std::string why;
    if (io::can_render_charts(&why)) {
      io::write_chart_png(png, io::frf_figure(sweep, sub.dofs()));
      fmt::print("wrote {}\n", png.string());
    } else {
      warn("no frf.png: " + why + " (run under xvfb-run -a)");
    }
  }
}

namespace {

// "3", "1.5e3" or a range "F0:STEP:F1" (F0, F0 + STEP, … up to F1 within a millionth of STEP),
// every value finite and > 0.
std::vector<double> parse_values(const std::string& option, const std::vector<std::string>& items,
                                 const char* unit) {
  auto number = [&](const std::string& text, const std::string& item) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v))
      throw io::Error(fmt::format("{}: expected numbers ({}) or ranges START:STEP:STOP, got \"{}\"",
                                  option, unit, item));
    return v;
  };
  std::vector<double> out;
  for (const auto& item : items) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t c = item.find(':'); c != std::string::npos; c = item.find(':', start)) {
      parts.push_back(item.substr(start, c - start));
      start = c + 1;
    }
    parts.push_back(item.substr(start));
    if (parts.size() == 1) {
      out.push_back(number(parts[0], item));
    } else if (parts.size() == 3) {
      const double a = number(parts[0], item), step = number(parts[1], item),
                   b = number(parts[2], item);
      if (!(step > 0.0) || b < a)
        throw io::Error(fmt::format("{} {}: expected START:STEP:STOP with STEP > 0 and STOP >= "
                                    "START",
                                    option, item));
      const double n = std::floor((b - a) / step + 1e-6);
      if (n > 10000) throw io::Error(fmt::format("{} {}: more than 10000 values", option, item));
      for (int i = 0; i <= static_cast<int>(n); ++i)
        out.push_back(a + i * step);
    } else {
      throw io::Error(fmt::format("{}: expected numbers ({}) or ranges START:STEP:STOP, got \"{}\"",
                                  option, unit, item));
    }
  }
  if (out.empty())
    throw io::Error(fmt::format("{}: expected at least one value ({})", option, unit));
  for (double v : out)
    if (!(v > 0.0))
      throw io::Error(fmt::format("{}: expected values > 0 {}, got {}", option, unit, v));
  std::sort(out.begin(), out.end());
  if (std::adjacent_find(out.begin(), out.end()) != out.end())
    throw io::Error(fmt::format("{}: a value is listed twice", option));
  return out;
}

} // namespace

void design(const DesignOptions& o) {
  // 1. The options.
  const std::vector<double> freqs = parse_values("--freq", o.frequencies, "Hz");
  const std::vector<double> amps = parse_values("--amplitude", o.amplitudes, "N or N m");
  check_harmonics(o.harmonics, 0);
  if (o.count < 1) throw io::Error(fmt::format("-n: expected at least 1 test, got {}", o.count));
  if (!(o.noise > 0.0 && o.noise < 1.0))
    throw io::Error(
        fmt::format("--noise: expected a fraction between 0 and 1 (e.g. 0.01), got {}", o.noise));
  if (!(o.max_misfit > 0.0))
    throw io::Error(fmt::format("--max-misfit: expected a number > 0 (noise standard deviations), "
                                "got {}",
                                o.max_misfit));
  if (o.periods < 2 || o.periods > 100000)
    throw io::Error(fmt::format("--periods: expected 2 to 100000, got {}", o.periods));
  if (o.balance_harmonics < 1 || o.balance_harmonics > 200)
    throw io::Error(
        fmt::format("--balance-harmonics: expected 1 to 200, got {}", o.balance_harmonics));
  if (*std::max_element(o.harmonics.begin(), o.harmonics.end()) > o.balance_harmonics)
    throw io::Error(
        fmt::format("--harmonics: expected at most --balance-harmonics ({})", o.balance_harmonics));
  const std::size_t n_candidates = freqs.size() * amps.size();
  if (static_cast<std::size_t>(o.count) > n_candidates)
    throw io::Error(fmt::format("-n {}: more than the {} candidates ({} frequencies x {} "
                                "amplitudes)",
                                o.count, n_candidates, freqs.size(), amps.size()));
  check_output_dir(o.output_dir);

  // 2. The model and its unknowns.
  const io::ModelFile file = io::read_model(o.model);
  if (file.joints.empty())
    throw io::Error(o.model.string() + ": no [[joints]]: nothing to design tests for");
  const std::vector<identify::DesignUnknown> unknowns = identify::design_unknowns(file.joints);
  if (unknowns.empty())
    throw io::Error(o.model.string() + ": every joint term is fixed; nothing to identify");
  for (const auto& u : unknowns)
    if (u.prior == 0.0)
      warn(fmt::format("{}: joint '{}', term {}: its value (the prior guess) is 0; the prediction "
                       "has no such force",
                       o.model.string(), u.joint, joints::term_name(u.term)));
  frf::Substructure sub = file.substructure();
  use_engine(sub, parse_engine(o.engine));
  const fem::NodeDof force_at = resolve(file, sub, "--force", o.force);

  // 3. Predict the candidates, choose.
  std::vector<identify::SineTestPlan> plans;
  for (double f : freqs)
    for (double a : amps)
      plans.push_back({f, a});
  identify::DesignOptions options;
  options.harmonics = o.harmonics;
  options.noise = o.noise;
  options.periods = o.periods;
  options.balance.harmonics = o.balance_harmonics;
  options.samples_per_period = std::max(256, 8 * (o.balance_harmonics + 1));
  options.max_misfit = o.max_misfit;
  std::vector<identify::CandidateTest> candidates;
  identify::Design chosen;
  const TerminalProgress progress{
      fmt::format("jointid design: predicting {} candidates", plans.size())};
  options.progress = progress.callback();
  try {
    try {
      candidates = identify::predict_candidates(sub, file.joints, force_at, plans, options);
    } catch (...) {
      progress.clear();
      throw;
    }
    progress.clear();
    int usable = 0;
    for (const auto& c : candidates)
      usable += c.usable;
    if (usable < o.count)
      throw io::Error(fmt::format("-n {}: only {} of the {} candidates can be predicted at the "
                                  "model's values (no periodic solution, coexisting responses, "
                                  "or equations the basis functions do not describe: --max-misfit)",
                                  o.count, usable, candidates.size()));
    chosen = identify::choose_tests(candidates, unknowns, o.count);
  } catch (const std::invalid_argument& e) {
    throw io::Error(o.model.string() + ": " + e.what());
  }
  if (!output_rank()) return;

  // 4. Write and report.
  make_output_dir(o.output_dir);
  const fs::path json = o.output_dir / "design.json";
  io::write_json(json, io::design_json(chosen, candidates, unknowns, options));
  fmt::print("wrote {}\n", json.string());
  int skipped = 0;
  for (const auto& c : candidates)
    skipped += !c.usable;
  if (skipped > 0)
    warn(fmt::format("{} of {} candidates left out: no periodic solution at the model's values, "
                     "coexisting responses, or equations the basis functions do not describe, as "
                     "where a friction joint sticks (design.json gives each reason)",
                     skipped, candidates.size()));
  fmt::print("D-optimal {} of {} candidates ({} exchanges after the greedy choice), noise {:g} % "
             "RMS, {} periods a record, harmonics {}:\n",
             o.count, candidates.size(), chosen.exchanges, 100.0 * o.noise, o.periods,
             fmt::join(o.harmonics, ","));
  fmt::print("  {:>12} {:>12}\n", "freq (Hz)", "force (N)");
  for (int i : chosen.chosen)
    fmt::print("  {:>12.6g} {:>12.6g}\n", plans[static_cast<std::size_t>(i)].frequency_hz,
               plans[static_cast<std::size_t>(i)].amplitude);
  fmt::print("expected standard deviations and bias:\n  {:<12} {:<6} {:>14} {:>14} {:>10} {:>10}\n",
             "joint", "term", "prior", "std", "relative", "bias");
  for (std::size_t u = 0; u < unknowns.size(); ++u) {
    const double sd = chosen.std(static_cast<Eigen::Index>(u));
    const double prior = std::abs(unknowns[u].prior);
    fmt::print("  {:<12} {:<6} {:>14.6g} {:>14.4g} {:>9.3g}% {:>+9.2g}%\n", unknowns[u].joint,
               joints::term_name(unknowns[u].term), unknowns[u].prior, sd, 100.0 * sd / prior,
               100.0 * chosen.bias(static_cast<Eigen::Index>(u)) / prior);
  }
  for (const auto& w : chosen.warnings)
    warn(w);
}

void compare(const CompareOptions& o) {
  // 1. The options.
  identify::CompareOptions options;
  if (!o.band.empty()) {
    const auto [f0, f1] = parse_band("--band", o.band);
    options.f0_hz = f0;
    options.f1_hz = f1;
  }
  if (o.segment != 0 && o.segment < 8)
    throw io::Error(
        fmt::format("--segment: expected at least 8 samples (or 0: automatic), got {}", o.segment));
  options.segment = o.segment;
  if (o.skip && !(std::isfinite(*o.skip) && *o.skip >= 0.0))
    throw io::Error(fmt::format("--skip: expected seconds >= 0, got {}", *o.skip));
  options.skip_s = o.skip.value_or(-1.0); // < 0: the library's default, 10 % of the record
  options.simulation.route = parse_route(o.route);
  if (o.substeps < 1)
    throw io::Error(fmt::format("--substeps: expected at least 1, got {}", o.substeps));
  options.simulation.substeps = o.substeps;
  if (!(std::isfinite(o.modal_cutoff) && o.modal_cutoff >= 0.0))
    throw io::Error(fmt::format("--modal-cutoff: expected >= 0 Hz, got {}", o.modal_cutoff));
  options.simulation.modal_cutoff_hz = o.modal_cutoff;
  check_output_dir(o.output_dir);

  // 2. The inputs.
  const io::ModelFile file = io::read_model(o.model);
  if (file.joints.empty())
    warn(o.model.string() + ": no [[joints]]: the prediction is the linear substructure's");
  const identify::Record record = io::read_record(o.record);
  for (const char* name : {"compare.json", "compare.png"})
    io::check_not_an_input(o.output_dir / name);
  frf::Substructure sub = file.substructure();

  // 3. Predict and compare.
  identify::Comparison result;
  const TerminalProgress progress{"jointid compare: predicting"};
  options.simulation.progress = progress.callback();
  try {
    result = identify::compare_spectra(sub, file.joints, record, options);
  } catch (const std::invalid_argument& e) {
    progress.clear();
    throw io::Error(fmt::format("{} (model {})", e.what(), o.model.string()));
  }
  progress.clear();
  if (!result.status.ok()) throw std::runtime_error(result.status.reason);

  // 4. Write.
  make_output_dir(o.output_dir);
  const fs::path json = o.output_dir / "compare.json";
  io::write_json(json, io::compare_json(result));
  fmt::print("{:<12} {:>18} {:>18}\n", "channel", "RMS difference dB", "max difference dB");
  for (const auto& c : result.channels)
    fmt::print("{:<12} {:>18.3f} {:>18.3f}\n", c.channel, c.rms_db, c.max_db);
  fmt::print("band {:g}-{:g} Hz; {} averages, so two independent spectra would differ by about "
             "{:.2f} dB (one standard deviation)\n",
             result.f0_hz, result.f1_hz, result.averages, result.statistical_db);
  for (const auto& n : result.notes)
    fmt::print("note: {}\n", n);
  fmt::print("wrote {}\n", json.string());
  if (o.plot) {
    std::string why;
    if (io::can_render_charts(&why)) {
      const fs::path png = o.output_dir / "compare.png";
      io::write_chart_png(png, io::compare_figure(result));
      fmt::print("wrote {}\n", png.string());
    } else {
      warn("no compare.png: " + why + " (run under xvfb-run -a)");
    }
  }
}

} // namespace jointid::cli
