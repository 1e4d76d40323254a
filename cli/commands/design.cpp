// jointid design: D-optimal experiment design. The `-n` candidate tests (sine: frequencies x
// amplitudes; multisine: RMS levels over a band) that determine the joints' non-fixed terms best,
// predicted at the model's values; DIR/design.json, and the chosen tests and the standard
// deviations to expect printed.
#include "identify/design.hpp"
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/parametric.hpp"
#include "io/files.hpp"
#include "io/results_json.hpp"
#include "joints/basis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Design final : public Command {
public:
  explicit Design(CLI::App& parent)
      : Command(parent, "design",
                "Experiment design: choose the N tests (sine: of candidate frequencies x force "
                "levels; multisine: of RMS levels over a band) that determine the joints' terms "
                "best (D-optimal, predicted at the model's values as prior guesses); writes "
                "DIR/design.json") {
    add_model("Model file (TOML); joint values = prior guesses");
    app().add_option("--force", force_, "DOF of the sine force, NODE:DOF (e.g. 7:uy)")->required();
    app()
        .add_option("--freq", frequencies_,
                    "Sine candidates' frequencies, Hz: values or ranges START:STEP:STOP "
                    "(comma-separated)")
        ->delimiter(',')
        ->allow_extra_args(false);
    app()
        .add_option("--amplitude", amplitudes_,
                    "Sine candidates' force amplitudes (peak), N or N m: values or ranges "
                    "START:STEP:STOP")
        ->delimiter(',')
        ->allow_extra_args(false);
    app().add_option("--band", band_, "Multisine candidates: F0:F1, the band excited, Hz");
    app()
        .add_option("--rms", rms_,
                    "Multisine candidates' RMS forces, N or N m: values or ranges START:STEP:STOP")
        ->delimiter(',')
        ->allow_extra_args(false);
    app().add_option("--period", period_, "Multisine candidates: the period, s");
    app().add_option("--sample-rate", sample_rate_,
                     "Multisine candidates: samples per second (default: the smallest power of "
                     "two at least 32 x F1 and 8 x (largest --harmonics + 1) x F1)");
    app().add_option("-n", count_, "Number of tests to choose")->capture_default_str();
    add_harmonics(options_.harmonics,
                  "Harmonics whose equations the identification will use, e.g. 1,2,3");
    app()
        .add_option("--noise", options_.noise,
                    "Expected measurement noise: RMS as a fraction of each channel's RMS, on "
                    "force and response")
        ->capture_default_str();
    app()
        .add_option("--periods", options_.periods, "Periods in each record (averaged)")
        ->capture_default_str();
    add_balance_harmonics(options_.balance.harmonics,
                          "Harmonics 0 … K of the harmonic balance that predicts the tests");
    app()
        .add_option("--max-misfit", options_.max_misfit,
                    "Leave out candidates whose equations, at the model's values, miss by more "
                    "than this many noise standard deviations (e.g. where a friction joint sticks)")
        ->capture_default_str();
    app()
        .add_option("--excitation", excitation_,
                    "Kind of candidate test: sine (--freq, --amplitude) or multisine (--band, "
                    "--rms, --period)")
        ->capture_default_str();
    add_output_dir();
    add_engine();
  }

  void run() override;

private:
  void check_options() const;
  /// The multisine candidates of --band, --rms, --period and --sample-rate (checked).
  std::vector<identify::PeriodicPlan> periodic_plans() const;
  void print(const identify::Design& chosen, const std::vector<identify::CandidateTest>& candidates,
             const std::vector<identify::DesignUnknown>& unknowns) const;

  std::string force_;                    ///< NODE:DOF of the sine force
  std::vector<std::string> frequencies_; ///< Hz: values or ranges F0:STEP:F1
  std::vector<std::string> amplitudes_;  ///< N or N·m (peak): values or ranges A0:STEP:A1
  int count_ = 10;                       ///< tests to choose
  std::string excitation_ = "sine";      ///< the candidates' kind: sine or multisine
  std::string band_;                     ///< multisine: F0:F1, Hz
  std::vector<std::string> rms_;         ///< multisine: RMS forces, values or ranges
  double period_ = 0.0;                  ///< multisine: s
  double sample_rate_ = 0.0;             ///< multisine: Hz; 0: the default
  identify::DesignOptions options_;      ///< the library's defaults
};

void Design::check_options() const {
  if (excitation_ != "sine" && excitation_ != "multisine")
    throw io::Error(
        fmt::format("--excitation: expected sine or multisine, got \"{}\"", excitation_));
  const bool sine = excitation_ == "sine";
  if (sine && (frequencies_.empty() || amplitudes_.empty()))
    throw io::Error("--excitation sine: expected --freq and --amplitude (the candidate "
                    "frequencies and force amplitudes)");
  if (sine && (!band_.empty() || !rms_.empty() || period_ != 0.0 || sample_rate_ != 0.0))
    throw io::Error("--band, --rms, --period, --sample-rate: only with --excitation multisine");
  if (!sine && (band_.empty() || rms_.empty() || period_ == 0.0))
    throw io::Error("--excitation multisine: expected --band F0:F1, --rms (the candidate RMS "
                    "forces) and --period (s)");
  if (!sine && (!frequencies_.empty() || !amplitudes_.empty()))
    throw io::Error("--freq, --amplitude: only with --excitation sine (a multisine candidate is "
                    "--band, --rms and --period)");
  check_harmonics(options_.harmonics, 0);
  if (count_ < 1) throw io::Error(fmt::format("-n: expected at least 1 test, got {}", count_));
  if (!(options_.noise > 0.0 && options_.noise < 1.0))
    throw io::Error(fmt::format("--noise: expected a fraction between 0 and 1 (e.g. 0.01), got {}",
                                options_.noise));
  if (!(options_.max_misfit > 0.0))
    throw io::Error(fmt::format("--max-misfit: expected a number > 0 (noise standard deviations), "
                                "got {}",
                                options_.max_misfit));
  if (options_.periods < 2 || options_.periods > 100000)
    throw io::Error(fmt::format("--periods: expected 2 to 100000, got {}", options_.periods));
  check_balance_harmonics(options_.balance.harmonics, 1);
  if (*std::max_element(options_.harmonics.begin(), options_.harmonics.end()) >
      options_.balance.harmonics)
    throw io::Error(fmt::format("--harmonics: expected at most --balance-harmonics ({})",
                                options_.balance.harmonics));
}

std::vector<identify::PeriodicPlan> Design::periodic_plans() const {
  const auto [f0, f1] = parse_band("--band", band_);
  const std::vector<double> levels = parse_values("--rms", rms_, "N or N m");
  if (!(period_ > 0.0 && std::isfinite(period_)))
    throw io::Error(fmt::format("--period: expected seconds > 0, got {}", period_));
  if (f1 * period_ < 1.0)
    throw io::Error(fmt::format("--band {}: holds no line of the period's spacing ({:g} Hz): "
                                "lengthen --period or raise F1",
                                band_, 1.0 / period_));
  double rate = sample_rate_;
  if (rate == 0.0)
    rate = identify::default_periodic_sample_rate(
        f1, *std::max_element(options_.harmonics.begin(), options_.harmonics.end()));
  if (!(rate > 2.0 * f1 && std::isfinite(rate)))
    throw io::Error(fmt::format("--sample-rate: expected more than twice F1 ({:g} Hz), got {}",
                                2.0 * f1, rate));
  const double n = period_ * rate;
  if (std::abs(n - std::round(n)) > 1e-6 * n)
    throw io::Error(fmt::format("--period {} at --sample-rate {}: a period must hold a whole "
                                "number of samples (it holds {})",
                                period_, rate, n));
  std::vector<identify::PeriodicPlan> plans;
  for (double r : levels)
    plans.push_back({f0, f1, r, period_, rate});
  return plans;
}

void Design::run() {
  // 1. The options.
  check_options();
  const bool periodic = excitation_ == "multisine";
  std::vector<double> freqs, amps;
  std::vector<identify::PeriodicPlan> periodic_candidates;
  if (periodic) {
    periodic_candidates = periodic_plans();
  } else {
    freqs = parse_values("--freq", frequencies_, "Hz");
    amps = parse_values("--amplitude", amplitudes_, "N or N m");
  }
  const std::size_t n_candidates =
      periodic ? periodic_candidates.size() : freqs.size() * amps.size();
  if (static_cast<std::size_t>(count_) > n_candidates)
    throw io::Error(periodic
                        ? fmt::format("-n {}: more than the {} candidates (RMS levels of --rms)",
                                      count_, n_candidates)
                        : fmt::format("-n {}: more than the {} candidates ({} frequencies x {} "
                                      "amplitudes)",
                                      count_, n_candidates, freqs.size(), amps.size()));
  check_output_dir(output_dir_);

  // 2. The model and its unknowns.
  const Model model(model_, engine());
  if (model.file.joints.empty())
    throw io::Error(model.name() + ": no [[joints]]: nothing to design tests for");
  // A parametric term not fixed (one a joint, identified by output error) is held at its
  // values for the D-optimal choice of the coefficient terms' tests; the levels that reach its
  // regime are said apart.
  check_identifiable(model, Parametric::output_error);
  const std::vector<joints::Joint> held = identify::with_parametric_fixed(model.file.joints);
  const std::vector<identify::DesignUnknown> unknowns = identify::design_unknowns(held);
  const bool parametric_open =
      std::any_of(model.file.joints.begin(), model.file.joints.end(), [](const joints::Joint& j) {
        for (std::size_t t = 0; t < j.terms.size(); ++t)
          if (joints::has_parameters(j.terms[t]) && !j.fixed[t]) return true;
        return false;
      });
  if (unknowns.empty())
    throw io::Error(model.name() + ": every joint term " +
                    (!parametric_open ? "is fixed; nothing to identify"
                                      : "but the parametric ones (jenkins, iwan, gap) "
                                        "is fixed: the D-optimal design chooses tests "
                                        "for the terms k … fc; give the joint k or c "
                                        "unknown beside it"));
  for (const auto& u : unknowns)
    if (u.prior == 0.0)
      warn(fmt::format("{}: joint '{}', term {}: its value (the prior guess) is 0; the prediction "
                       "has no such force",
                       model.name(), u.joint, joints::term_name(u.term)));
  const fem::NodeDof force_at = model.dof("--force", force_);
  if (periodic) check_time_simulation(model.file); // a multisine is predicted in time

  // 3. Predict the candidates, choose.
  std::vector<identify::SineTestPlan> plans;
  for (double f : freqs)
    for (double a : amps)
      plans.push_back({f, a});
  identify::DesignOptions options = options_;
  const std::vector<identify::CandidateTest> candidates = with_progress(
      fmt::format("jointid design: predicting {} candidates", n_candidates),
      [&](const auto& progress) {
        options.progress = progress.callback();
        return for_model(model, [&] {
          return periodic ? identify::predict_periodic_candidates(model.sub, held, force_at,
                                                                  periodic_candidates, options)
                          : identify::predict_candidates(model.sub, held, force_at, plans, options);
        });
      });
  const auto usable = std::count_if(candidates.begin(), candidates.end(),
                                    [](const identify::CandidateTest& c) { return c.usable; });
  if (usable < count_)
    throw io::Error(fmt::format("-n {}: only {} of the {} candidates can be predicted at the "
                                "model's values (no periodic solution, coexisting responses, "
                                "or equations the basis functions do not describe: --max-misfit)",
                                count_, usable, candidates.size()));
  const identify::Design chosen =
      for_model(model, [&] { return identify::choose_tests(candidates, unknowns, count_); });
  const std::vector<identify::ParametricLevel> levels =
      for_model(model, [&] { return identify::parametric_levels(model.file.joints, candidates); });
  if (!output_rank()) return;

  // 4. Write and report.
  make_output_dir(output_dir_);
  const fs::path json = output_dir_ / "design.json";
  io::write_json(json, io::design_json(chosen, candidates, unknowns, options, levels));
  fmt::print("wrote {}\n", json.string());
  if (const auto skipped = static_cast<std::ptrdiff_t>(candidates.size()) - usable; skipped > 0)
    warn(fmt::format("{} of {} candidates left out: no periodic solution at the model's values, "
                     "coexisting responses, or equations the basis functions do not describe, as "
                     "where a friction joint sticks (design.json gives each reason)",
                     skipped, candidates.size()));
  print(chosen, candidates, unknowns);
  for (const auto& level : levels)
    fmt::print("parametric term: {}\n", level.sentence);
}

void Design::print(const identify::Design& chosen,
                   const std::vector<identify::CandidateTest>& candidates,
                   const std::vector<identify::DesignUnknown>& unknowns) const {
  fmt::print("D-optimal {} of {} candidates ({} exchanges after the greedy choice), noise {:g} % "
             "RMS, {} periods a record, harmonics {}:\n",
             count_, candidates.size(), chosen.exchanges, 100.0 * options_.noise, options_.periods,
             fmt::join(options_.harmonics, ","));
  if (excitation_ == "multisine") {
    fmt::print("  {:>12} {:>12} {:>10}\n", "band (Hz)", "RMS (N)", "period (s)");
    for (int i : chosen.chosen) {
      const identify::PeriodicPlan& p = *candidates[static_cast<std::size_t>(i)].periodic;
      fmt::print("  {:>12} {:>12.6g} {:>10.6g}\n", fmt::format("{:g}-{:g}", p.f0_hz, p.f1_hz),
                 p.rms, p.period_s);
    }
  } else {
    fmt::print("  {:>12} {:>12}\n", "freq (Hz)", "force (N)");
    for (int i : chosen.chosen)
      fmt::print("  {:>12.6g} {:>12.6g}\n",
                 candidates[static_cast<std::size_t>(i)].plan.frequency_hz,
                 candidates[static_cast<std::size_t>(i)].plan.amplitude);
  }
  fmt::print("expected standard deviations and bias:\n  {:<12} {:<6} {:>14} {:>14} {:>10} {:>10}\n",
             "joint", "term", "prior", "std", "relative", "bias");
  for (std::size_t u = 0; u < unknowns.size(); ++u) {
    const double sd = chosen.std(static_cast<Eigen::Index>(u));
    const double prior = std::abs(unknowns[u].prior);
    const double bias = chosen.bias(static_cast<Eigen::Index>(u));
    fmt::print("  {:<12} {:<6} {:>14.6g} {:>14.4g} {:>9.3g}% {:>10}\n", unknowns[u].joint,
               joints::term_name(unknowns[u].term), unknowns[u].prior, sd, 100.0 * sd / prior,
               std::isfinite(bias) ? fmt::format("{:+.2g}%", 100.0 * bias / prior)
                                   : std::string("n/a"));
  }
  if (excitation_ == "multisine")
    fmt::print("(the bias is not predicted for multisine candidates: each one's prediction holds "
               "a realisation of the noise)\n");
  for (const auto& w : chosen.warnings)
    warn(w);
}

} // namespace

std::unique_ptr<Command> design_command(CLI::App& parent) {
  return std::make_unique<Design>(parent);
}

} // namespace jointid::cli
