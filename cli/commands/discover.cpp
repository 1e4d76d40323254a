// jointid discover: model discovery; DIR/discovery.json and DIR/report.md with its plots.
#include "discover/discover.hpp"
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/measurement.hpp"
#include "io/files.hpp"
#include "io/model_write.hpp"
#include "io/record_csv.hpp"
#include "io/results_json.hpp"
#include "joints/basis.hpp"
#include "report/discovery_json.hpp"
#include "report/discovery_report.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Discover final : public Command {
public:
  explicit Discover(CLI::App& parent)
      : Command(parent, "discover",
                "Find where the model and the measurement disagree, name the missing joint "
                "effect, add it and show the gap shrink; writes DIR/discovery.json, "
                "DIR/model.toml (the model it ends at) and DIR/report.md with plots") {
    add_model("Model file (TOML): the starting model");
    app()
        .add_option("TESTS", records_, "Measurement records or stepped-sine tables (CSV)")
        ->required();
    add_output_dir();
    add_harmonics(options_.harmonics,
                  "Harmonics used in the fits; 0 to the largest are compared (a periodic test: "
                  "its lines where a response stands out of the noise, up to the largest of "
                  "these times the highest excited line)");
    app().add_option("--band", band_,
                     "F0:F1 in Hz: a periodic test's excited lines used (default: all); its other "
                     "lines from F0 up");
    add_balance_harmonics(options_.balance.harmonics,
                          "Harmonics 0 … K of the harmonic-balance re-simulations");
    app().add_option("--max-steps", options_.max_steps, "Most terms added")->capture_default_str();
    app()
        .add_option("--max-balance-lines", options_.max_balance_lines,
                    "Most lines of a periodic test's harmonic balance (a solve's cost grows "
                    "with them); a test that needs more is refused")
        ->capture_default_str();
    std::vector<std::string> names;
    for (const joints::Term t : joints::all_terms)
      names.emplace_back(joints::term_name(t));
    app()
        .add_option("--terms", terms_,
                    "Candidate terms tried at every joint (default: every term, k, c, k2, k3, "
                    "c2, c3, fc, jenkins, iwan, gap)")
        ->check(choices(names))
        ->delimiter(',')
        ->allow_extra_args(false);
    app().add_flag_callback(
        "--no-damping-candidate", [this] { options_.substructure_damping = false; },
        "Do not try scaling the substructure's damping");
    add_no_plot("plots in the report");
    add_engine();
  }

  void run() override;

private:
  void print(const discover::Result& result) const;

  std::vector<fs::path> records_;
  discover::Options options_; ///< the library's defaults
  std::vector<std::string> terms_;
  std::string band_; ///< F0:F1, Hz; empty: every line
};

void Discover::run() {
  // 1. The options.
  if (records_.empty()) throw io::Error("expected at least one record or table (CSV file)");
  check_harmonics(options_.harmonics, 1);
  const int K = *std::max_element(options_.harmonics.begin(), options_.harmonics.end());
  check_balance_harmonics(options_.balance.harmonics, K, "the largest of --harmonics");
  if (options_.max_steps < 1)
    throw io::Error(fmt::format("--max-steps: expected at least 1, got {}", options_.max_steps));
  if (options_.max_balance_lines < 1)
    throw io::Error(fmt::format("--max-balance-lines: expected at least 1, got {}",
                                options_.max_balance_lines));
  discover::Options options = options_;
  if (!terms_.empty()) {
    options.terms.clear();
    for (const auto& t : terms_)
      options.terms.push_back(joints::parse_term(t)); // checked by --terms' choices
  }
  identify::MeasureOptions measure{.harmonics = K};
  if (!band_.empty())
    std::tie(measure.band_from_hz, measure.band_to_hz) = parse_band("--band", band_);
  check_output_dir(output_dir_);

  // 2. The inputs.
  const Model model(model_, engine());
  if (model.file.joints.empty())
    throw io::Error(model.name() + ": no [[joints]]: discovery starts from the joints' terms");
  check_identifiable(model);
  const std::vector<identify::SineTest> tests = io::read_tests(records_);
  for (const char* name : {"discovery.json", "model.toml", "report.md"})
    io::check_not_an_input(output_dir_ / name);
  const std::vector<identify::Measurement> measured = identify::measure(tests, measure);

  // 3. Discover.
  const discover::Result result =
      discover::discover(model.sub, model.file.joints, measured, options);
  if (!output_rank()) return;

  // 4. Write and report. The model it ends at as a model file, unless it cannot be written as
  // one (a part's joint changed, a damping scale on parts): then no model.toml, and one left
  // by an earlier run is removed rather than left beside a discovery.json it does not match.
  std::vector<std::string> warnings = result.warnings;
  make_output_dir(output_dir_); // (model.toml's paths are checked from it)
  const fs::path toml = output_dir_ / "model.toml";
  std::string model_text;
  const discover::State& last = result.states.back();
  try {
    model_text = io::model_with_joints(
        model_, last.joints, last.damping_scale, toml,
        fmt::format("The model `jointid discover` ended at ({}: final_model), written from\n{} "
                    "with its joints' terms and values as discovered.",
                    (output_dir_ / "discovery.json").string(), model_.string()));
  } catch (const io::Error& e) {
    warnings.push_back(fmt::format("{} not written: {}", toml.string(), e.what()));
  }
  const fs::path json = output_dir_ / "discovery.json";
  io::write_json(json, report::discovery_json(result));
  if (!model_text.empty())
    io::write_file_atomically(toml, model_text);
  else if (std::error_code ec; fs::remove(toml, ec))
    warnings.push_back(fmt::format("removed {} of an earlier run", toml.string()));
  report::ReportContext context{model_.string(), {}, plot_};
  for (const auto& p : records_)
    context.inputs.push_back(p.string());
  const std::vector<fs::path> written =
      report::write_discovery_report(output_dir_, result, context, warnings);
  print(result);
  fmt::print("wrote {}", json.string());
  if (!model_text.empty()) fmt::print(", {}", toml.filename().string());
  for (const auto& p : written)
    fmt::print(", {}", p.filename().string());
  fmt::print("\n");
  for (const auto& w : warnings)
    warn(w);
}

void Discover::print(const discover::Result& result) const {
  for (std::size_t i = 0; i + 1 < result.diagnosis.findings.size(); ++i)
    fmt::print("{}\n", result.diagnosis.findings[i]);
  fmt::print("\n{:<5} {:<28} {:<26} {:>12} {:>11} {:>11}\n", "step", "added", "effect", "value",
             "gap before", "gap after");
  for (std::size_t i = 0; i < result.steps.size(); ++i) {
    const auto& s = result.steps[i];
    fmt::print("{:<5} {:<28} {:<26} {:>12} {:>11.4g} {:>11.4g}\n", i + 1,
               (s.removed ? "− " : "") + s.added.name(), s.added.effect(),
               s.added.parameters.empty() ? fmt::format("{:.5g}", s.added.value) : "(below)",
               s.gap_before, s.gap_after);
    // A parametric term (and one added with it): its parameters below it.
    for (const auto& [term, list] : {std::pair{s.added.term, &s.added.parameters},
                                     std::pair{s.added.with, &s.added.with_parameters}})
      for (const auto& p : *list)
        fmt::print("      {:<33} {}\n", fmt::format("{}.{}", joints::term_name(*term), p.name),
                   p.determined
                       ? fmt::format("{:.5g} [{:.5g}, {:.5g}]", p.value, p.ci_low, p.ci_high)
                       : std::string("undetermined"));
  }
  fmt::print("\n{}\nStopped: {}.\n", result.diagnosis.findings.back(), result.stop_reason);
}

} // namespace

std::unique_ptr<Command> discover_command(CLI::App& parent) {
  return std::make_unique<Discover>(parent);
}

} // namespace jointid::cli
