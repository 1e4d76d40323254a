// jointid simulate: virtual tests of the model with its joints at their values. Sine tests: one
// record per frequency x amplitude, DIR/sine_f<freq>Hz_F<amp>N.csv, or with --table one
// stepped-sine table DIR/stepped_sine.csv. Other excitations: one record,
// DIR/<excitation>_<F0>-<F1>Hz_....csv, or DIR/<record stem>_simulated.csv for --excitation record.
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/random_tests.hpp"
#include "identify/sine_tests.hpp"
#include "identify/stepped_sine.hpp"
#include "io/arguments.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <set>
#include <tuple>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Simulate final : public Command {
public:
  explicit Simulate(CLI::App& parent);
  void run() override;

private:
  void run_sine();
  void run_signal();
  /// --excitation random, sweep, multisine: the band and the level; record: nothing.
  std::tuple<double, double, double> check_signal_options() const;

  std::string force_;               ///< NODE:DOF of the force
  std::vector<double> frequencies_; ///< Hz
  std::vector<double> amplitudes_;  ///< N or N·m (peak)
  std::string method_ = "time";
  identify::SimulationOptions sine_; ///< the library's defaults: periods, steps, harmonics
  std::vector<std::string> channels_{"x", "v"};
  std::vector<std::string> outputs_; ///< more response points, NODE:DOF
  double noise_ = 0.0;               ///< noise RMS / channel RMS
  unsigned long long seed_ = 1;
  bool table_ = false;
  std::string excitation_ = "sine";
  std::string band_;         ///< F0:F1, Hz
  double rms_ = 0.0;         ///< N or N·m
  double duration_ = 0.0;    ///< s
  double sample_rate_ = 0.0; ///< Hz
  double period_ = 0.0;      ///< s, multisine: its period (0: the duration)
  TransientOptions transient_;
  std::optional<double> fade_in_; ///< s; not given: the library's default
  fs::path force_from_;
};

Simulate::Simulate(CLI::App& parent)
    : Command(parent, "simulate",
              "Simulate tests of the model with its joints at their values; one record (CSV) "
              "per sine test (frequency x amplitude), or one under another force history") {
  CLI::App& app = this->app();
  add_model();
  app.add_option("--force", force_,
                 "NODE:DOF of the force, e.g. 7:uy; NODE may be a one-node Gmsh group (not with "
                 "--excitation record)");
  app.add_option("--freq", frequencies_, "Excitation frequencies, Hz (comma-separated; sine tests)")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_option("--amplitude", amplitudes_,
                 "Force amplitudes (peak), N or N m (comma-separated; one for a sweep)")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_option("--method", method_,
                 "time: Newmark integration to steady state; hb: harmonic balance")
      ->check(choices({"time", "hb"}))
      ->capture_default_str();
  app.add_option("--periods", sine_.periods, "Periods in each record")->capture_default_str();
  app.add_option("--steps-per-period", sine_.steps_per_period, "Time steps (samples) per period")
      ->capture_default_str();
  add_balance_harmonics(sine_.balance.harmonics,
                        "Harmonics 0 … K of the harmonic balance (--method hb)", true);
  app.add_option("--samples-per-period", sine_.samples_per_period,
                 "Samples recorded per period (a divisor of --steps-per-period; 0: every step)")
      ->capture_default_str();
  app.add_option("--channels", channels_,
                 "Response quantities recorded at every output: x, v, a (comma-separated)")
      ->check(choices({"x", "v", "a"}))
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  app.add_option("--outputs", outputs_,
                 "More response points beyond the joints and the force, NODE:DOF,...")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_option("--noise", noise_,
                 "Measurement noise: white Gaussian, RMS as a fraction of each channel's RMS "
                 "(e.g. 0.01)")
      ->capture_default_str();
  app.add_option("--seed", seed_, "Seed of the noise (record i uses seed + i)")
      ->capture_default_str();
  app.add_flag("--table", table_,
               "Write one stepped-sine table (the fundamentals) DIR/stepped_sine.csv instead of "
               "time records");
  add_output_dir();
  app.add_option("--excitation", excitation_,
                 "sine: steady-state sine tests (--freq, --amplitude); random: band-limited "
                 "Gaussian (--band, --rms); sweep: linear sine sweep over --band (--amplitude); "
                 "multisine: --band, --rms (these three need --duration and --sample-rate); "
                 "record: the force channels of --force-from. All but sine write one record")
      ->check(choices({"sine", "random", "sweep", "multisine", "record"}))
      ->capture_default_str();
  app.add_option("--band", band_, "F0:F1 in Hz (random, sweep, multisine)");
  app.add_option("--rms", rms_, "RMS force, N or N m (random, multisine)");
  app.add_option("--duration", duration_, "Record length, s (random, sweep, multisine)");
  app.add_option("--sample-rate", sample_rate_,
                 "Samples per second of the record, Hz (random, sweep, multisine)");
  app.add_option("--period", period_,
                 "Multisine: its period, s, repeated over --duration (a whole number of samples "
                 "and of periods; default: the duration, one period). The record says it in a "
                 "'# period_s' comment");
  transient_.add_to(app, " (random, sweep, multisine, record)");
  app.add_option("--force-from", force_from_,
                 "--excitation record: a record (CSV) whose f@NODE:DOF channels drive the model");
  app.add_option_function<double>(
      "--fade-in", [this](const double& s) { fade_in_ = s; },
      "Force faded in over this time from rest, s (default: 5 % of --duration; none for a "
      "record's force that starts at zero)");
  add_engine();
}

void Simulate::run() {
  if (excitation_ == "sine")
    run_sine();
  else
    run_signal();
}

void Simulate::run_sine() {
  // 1. The options, before anything is read or computed.
  if (!band_.empty() || rms_ != 0.0 || duration_ != 0.0 || sample_rate_ != 0.0 ||
      !force_from_.empty())
    throw io::Error("--band, --rms, --duration, --sample-rate, --force-from: only with "
                    "--excitation random, sweep, multisine or record");
  if (period_ != 0.0) throw io::Error("--period: only with --excitation multisine");
  if (force_.empty()) throw io::Error("--force: expected NODE:DOF of the sine force, e.g. 7:uy");
  io::check_sine_tests(
      {"--freq", "--periods", "--steps-per-period", "--samples-per-period", "--balance-harmonics"},
      frequencies_, sine_);
  check_amplitudes(amplitudes_);
  identify::SimulationOptions options = sine_;
  check_noise(noise_);
  options.quantities = parse_channels(channels_);
  options.method = method_ == "time" ? identify::SimulationMethod::time_integration
                                     : identify::SimulationMethod::harmonic_balance;
  check_output_dir(output_dir_);

  // 2. The model and the tests.
  const Model model(model_, engine());
  require_values(model.file, "simulate");
  if (options.method == identify::SimulationMethod::time_integration)
    check_time_simulation(model.file, "or simulate by harmonic balance (--method hb)");
  const fem::NodeDof force_at = model.dof("--force", force_);
  // Refused before the simulation, not after: the outputs never replace an input.
  io::check_not_an_input(output_dir_ / "stepped_sine.csv");
  for (const auto& text : outputs_)
    options.extra_outputs.push_back(model.dof("--outputs", text));
  std::vector<identify::SineTestPlan> plans;
  std::set<std::string> names;
  for (double f : frequencies_)
    for (double a : amplitudes_) {
      plans.push_back({f, a});
      if (!names.insert(identify::sine_test_name(plans.back())).second)
        throw io::Error(
            fmt::format("--freq, --amplitude: the test at {} Hz, {} N is listed twice", f, a));
      io::check_not_an_input(output_dir_ / identify::sine_test_name(plans.back()));
    }

  // 3. Simulate every test, keeping the records in memory: nothing is written unless all succeed.
  std::vector<identify::SimulatedTest> tests = with_progress(
      fmt::format("jointid simulate: {} sine tests", plans.size()), [&](const auto& progress) {
        options.progress = progress.callback();
        return for_model(model, [&] {
          return identify::simulate_sine_tests(model.sub, model.file.joints, force_at, plans,
                                               options);
        });
      });
  for (const auto& t : tests)
    require(t.status);
  identify::add_noise(tests, noise_, seed_);
  const std::vector<std::string> made_by{"jointid simulate", "model: " + model_.string()};
  for (auto& t : tests) {
    t.comments.insert(t.comments.begin(), made_by.begin(), made_by.end());
    for (const auto& w : t.warnings)
      warn(w);
  }

  // 4. Write (rank 0 of an MPI run): every record under a temporary name first, then all
  //    renamed into place together.
  if (!output_rank()) return;
  std::vector<std::pair<fs::path, std::string>> outputs;
  if (table_) {
    std::vector<std::string> comments = made_by;
    for (const auto& c : identify::stepped_sine_comments(tests))
      comments.push_back(c);
    std::vector<identify::Record> records;
    for (const auto& t : tests)
      records.push_back(t.record);
    outputs.push_back({output_dir_ / "stepped_sine.csv",
                       io::stepped_sine_csv(identify::stepped_sine_table(records), comments)});
  } else {
    for (const auto& t : tests)
      outputs.push_back({output_dir_ / t.record.source, io::record_csv(t.record, t.comments)});
  }
  make_output_dir(output_dir_);
  write_outputs(outputs);
}

std::tuple<double, double, double> Simulate::check_signal_options() const {
  const std::string& kind = excitation_;
  if (period_ != 0.0 && kind != "multisine")
    throw io::Error(fmt::format("--period: only with --excitation multisine, not {}", kind));
  if (!(std::isfinite(period_) && period_ >= 0.0))
    throw io::Error(fmt::format("--period: expected a period > 0 s, got {}", period_));
  if (!frequencies_.empty())
    throw io::Error(fmt::format("--freq: only for sine tests, not --excitation {}", kind));
  if (method_ != "time")
    throw io::Error(fmt::format("--method {}: --excitation {} is simulated in time (see --route)",
                                method_, kind));
  if (table_) throw io::Error("--table: only for sine tests");
  if (kind == "record") {
    if (force_from_.empty())
      throw io::Error("--force-from: expected the record (CSV) whose force channels drive the "
                      "model, for --excitation record");
    if (!force_.empty())
      throw io::Error("--force: not with --excitation record (the forces act where the record's "
                      "f@NODE:DOF channels say)");
    if (!band_.empty() || rms_ != 0.0 || !amplitudes_.empty() || duration_ != 0.0 ||
        sample_rate_ != 0.0)
      throw io::Error("--band, --rms, --amplitude, --duration, --sample-rate: not with "
                      "--excitation record (the record gives the force and its sampling)");
    return {0.0, 0.0, 0.0};
  }
  if (!force_from_.empty()) throw io::Error("--force-from: only with --excitation record");
  if (force_.empty()) throw io::Error("--force: expected NODE:DOF of the force, e.g. 7:uy");
  if (band_.empty())
    throw io::Error(fmt::format("--band: expected F0:F1 in Hz for --excitation {}", kind));
  const auto [f0, f1] = parse_band("--band", band_);
  if (!(std::isfinite(duration_) && duration_ > 0.0))
    throw io::Error(fmt::format("--duration: expected a duration > 0 s, got {}", duration_));
  if (!(std::isfinite(sample_rate_) && sample_rate_ > 0.0))
    throw io::Error(
        fmt::format("--sample-rate: expected a sample rate > 0 Hz, got {}", sample_rate_));
  if (!(f1 < 0.5 * sample_rate_))
    throw io::Error(fmt::format("--band {}: expected F1 below half the sample rate ({} Hz)", band_,
                                0.5 * sample_rate_));
  if (kind == "sweep") {
    if (amplitudes_.size() != 1 || !(std::isfinite(amplitudes_[0]) && amplitudes_[0] > 0.0))
      throw io::Error("--amplitude: expected one amplitude > 0 (N, peak) for the sweep");
    if (rms_ != 0.0) throw io::Error("--rms: not for a sweep (give --amplitude, the peak)");
    return {f0, f1, amplitudes_[0]};
  }
  if (!amplitudes_.empty())
    throw io::Error(fmt::format("--amplitude: not for --excitation {} (give --rms)", kind));
  if (!(std::isfinite(rms_) && rms_ > 0.0))
    throw io::Error(fmt::format("--rms: expected an RMS force > 0 (N), got {}", rms_));
  return {f0, f1, rms_};
}

// --excitation random, sweep, multisine or record: one record under that force history.
void Simulate::run_signal() {
  // 1. The options.
  const bool from_record = excitation_ == "record";
  const auto [f0, f1, level] = check_signal_options();
  identify::ForcedOptions options;
  transient_.apply(options);
  if (fade_in_ && !(std::isfinite(*fade_in_) && *fade_in_ >= 0.0))
    throw io::Error(fmt::format("--fade-in: expected seconds >= 0, got {}", *fade_in_));
  check_noise(noise_);
  options.quantities = parse_channels(channels_);
  check_output_dir(output_dir_);

  // 2. The force history, and the fade-in it needs unless told.
  identify::ForceInput input;
  std::string name;
  double duration = duration_, fade = 0.0;
  if (from_record) {
    const identify::Record record = io::read_record(force_from_);
    try {
      input = identify::force_input(record);
    } catch (const std::invalid_argument& e) {
      throw io::Error(std::string("--force-from ") + e.what());
    }
    duration = static_cast<double>(record.t.size()) / input.sample_rate_hz;
    fade = fade_in_.value_or(identify::default_fade_in_s(input));
    name = force_from_.stem().string() + "_simulated.csv";
  } else {
    const identify::ExcitationSpec spec{excitation_ == "random"  ? identify::Excitation::random
                                        : excitation_ == "sweep" ? identify::Excitation::sweep
                                                                 : identify::Excitation::multisine,
                                        f0,
                                        f1,
                                        level,
                                        seed_,
                                        duration_,
                                        sample_rate_,
                                        period_};
    try {
      input = identify::generated_force(spec, {}); // the DOF is resolved with the model
    } catch (const std::invalid_argument& e) {
      throw io::Error(std::string("--band, --duration, --sample-rate, --period: ") + e.what());
    }
    fade = fade_in_.value_or(identify::default_fade_in_s(spec));
    name = identify::excitation_record_name(spec);
  }
  if (!(fade >= 0.0 && fade < duration))
    throw io::Error(
        fmt::format("--fade-in: expected 0 to below the duration ({} s), got {}", duration, fade));
  options.fade_in_s = fade;

  // 3. The model and the simulation.
  const Model model(model_, engine());
  require_values(model.file, "simulate");
  check_time_simulation(model.file);
  if (!from_record) input.at = {model.dof("--force", force_)};
  for (const auto& at : input.at) // a record's force channel is its fault, not the model's
    if (const std::string why = model.sub.dofs().why_not_free(at); from_record && !why.empty())
      throw io::Error(fmt::format("{}: force channel f@{}: {}; a force must act on a free DOF of "
                                  "the model ({})",
                                  force_from_.string(), fem::to_string(at), why, model.name()));
  for (const auto& text : outputs_)
    options.extra_outputs.push_back(model.dof("--outputs", text));
  io::check_not_an_input(output_dir_ / name);
  identify::ForcedTest test =
      with_progress("jointid simulate: time simulation", [&](const auto& progress) {
        options.progress = progress.callback();
        return for_model(model, [&] {
          return identify::simulate_forced(model.sub, model.file.joints, input, options);
        });
      });
  require(test.status);
  test.record.source = name;
  test.comments.insert(test.comments.begin(), {"jointid simulate", "model: " + model_.string()});
  identify::add_noise(test, noise_, seed_);
  for (const auto& w : test.warnings)
    warn(w);

  // 4. Write.
  if (!output_rank()) return;
  make_output_dir(output_dir_);
  write_outputs({{output_dir_ / name, io::record_csv(test.record, test.comments)}});
}

} // namespace

std::unique_ptr<Command> simulate_command(CLI::App& parent) {
  return std::make_unique<Simulate>(parent);
}

} // namespace jointid::cli
