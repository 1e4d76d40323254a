// jointid identify: the joints' non-fixed terms from the tests; the JSON result, a table, and
// optionally pictures of the harmonic fits and of the identified values against the model's.
#include "cli/command.hpp"
#include "cli/common.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/output_error.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "io/results_json.hpp"
#include "joints/basis.hpp"
#include "report/harmonic_fit_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace jointid::cli {

namespace {

namespace fs = std::filesystem;

class Identify final : public Command {
public:
  explicit Identify(CLI::App& parent)
      : Command(parent, "identify",
                "Identify the joints' terms from measured records; writes JSON") {
    add_model();
    app()
        .add_option("TESTS", records_, "Measurement records or stepped-sine tables (CSV)")
        ->required();
    app().add_option("-o,--output", output_, "Result file (JSON)")->required();
    add_harmonics(fit_.harmonics,
                  "Harmonics whose equations are used, e.g. 1,2,3 (a periodic test: its lines "
                  "where a response stands out of the noise, up to the largest of these times the "
                  "highest excited line)");
    app().add_option("--band", band_,
                     "F0:F1 in Hz: a periodic test's excited lines used (default: all); its other "
                     "lines from F0 up");
    app().add_option("--fit-png", fit_png_,
                     "Picture (PNG) of each test's joint displacements with their harmonic fits");
    app().add_option("--params-png", params_png_,
                     "Picture (PNG) of the identified values / the model's, with 95 % intervals");
    add_no_plot("pictures (not even with --fit-png or --params-png)");
    app().add_flag("--output-error", output_error_,
                   "Refine by output error (maximum likelihood: the harmonic balance of the model "
                   "fitted to the measured harmonics, each weighted by its noise); needs records "
                   "of two or more periods. Identifies a non-fixed jenkins, iwan or gap term "
                   "(one a joint), started from a describing-function fit");
    add_balance_harmonics(refined_.balance.harmonics,
                          "Harmonics 0 … K of the output error's harmonic balance");
    add_engine();
  }

  bool draws() const override { return plot_ && !(fit_png_.empty() && params_png_.empty()); }
  void run() override;

private:
  void print(const identify::FitResult& result) const;
  void draw(const identify::FitResult& result, const std::vector<joints::Joint>& model_joints,
            const std::vector<identify::Measurement>& measured) const;

  std::vector<fs::path> records_;
  fs::path output_;
  identify::FitOptions fit_;             ///< harmonics; the library's defaults
  identify::OutputErrorOptions refined_; ///< its harmonic balance; the library's defaults
  fs::path fit_png_, params_png_;        ///< not empty: the pictures
  bool output_error_ = false;
  std::string band_; ///< F0:F1, Hz; empty: every line
};

void Identify::run() {
  // 1. The options.
  if (records_.empty()) throw io::Error("expected at least one record or table (CSV file)");
  check_harmonics(fit_.harmonics, 0);
  if (output_error_) {
    const int K = *std::max_element(fit_.harmonics.begin(), fit_.harmonics.end());
    check_balance_harmonics(refined_.balance.harmonics, std::max(K, 1),
                            "the largest of --harmonics");
  }
  identify::MeasureOptions measure = identify::measure_options(fit_);
  if (!band_.empty())
    std::tie(measure.band_from_hz, measure.band_to_hz) = parse_band("--band", band_);
  check_output_file(output_);
  for (const fs::path& png : {fit_png_, params_png_})
    if (!png.empty()) check_output_file(png);
  if (!fit_png_.empty() && fit_png_ == params_png_)
    throw io::Error("--fit-png and --params-png: expected two different files");

  // 2. The inputs.
  const Model model(model_, engine());
  if (model.file.joints.empty()) throw io::Error(model.name() + ": no [[joints]] to identify");
  check_identifiable(model,
                     output_error_ ? Parametric::output_error : Parametric::needs_output_error);
  const std::vector<identify::SineTest> tests = io::read_tests(records_);
  io::check_not_an_input(output_);
  for (const fs::path& png : {fit_png_, params_png_})
    if (!png.empty()) io::check_not_an_input(png);
  const std::vector<identify::Measurement> measured = identify::measure(tests, measure);

  // 3. Identify. A status other than ok is the reason, passed up whole.
  identify::OutputErrorOptions refined = refined_;
  refined.harmonics = fit_.harmonics;
  const identify::FitResult result =
      output_error_ ? identify::output_error(model.sub, model.file.joints, measured, fit_, refined)
                    : identify::fit(model.sub, model.file.joints, measured, fit_);
  if (!result.status.ok()) throw io::Error("identify: " + result.status.reason);
  if (!output_rank()) return;

  // 4. Write and report.
  io::write_json(output_, io::identify_result_json(result, {}, &measured));
  print(result);
  fmt::print("wrote {}\n", output_.string());
  if (plot_) draw(result, model.file.joints, measured);
  for (const auto& w : result.warnings)
    warn(w);
}

void Identify::print(const identify::FitResult& result) const {
  // The joint and term columns as wide as their longest entry ("iwan.beta", a long joint name).
  std::size_t jw = 12, tw = 5;
  for (const auto& j : result.joints) {
    jw = std::max(jw, j.name.size());
    for (const auto& t : j.terms) {
      tw = std::max(tw, joints::term_name(t.term).size());
      for (const auto& p : t.parameters)
        tw = std::max(tw, joints::term_name(t.term).size() + 1 + p.name.size());
    }
  }
  const auto row = [&](std::string_view joint, std::string_view term, std::string_view effect,
                       std::string_view value, std::string_view std, std::string_view interval) {
    fmt::print("{:<{}} {:<{}} {:<26} {:>14} {:>11}  {}\n", joint, jw, term, tw, effect, value, std,
               interval);
  };
  row("joint", "term", "effect", "value", "std", "95 % interval");
  for (const auto& j : result.joints)
    for (const auto& t : j.terms) {
      if (!t.parameters.empty()) { // a parametric term: one line per parameter
        for (const auto& p : t.parameters)
          row(j.name, fmt::format("{}.{}", joints::term_name(t.term), p.name),
              joints::term_effect(t.term),
              p.determined ? fmt::format("{:.7g}", p.value) : std::string("undetermined"),
              p.fixed || !p.determined ? std::string() : fmt::format("{:.3g}", p.std),
              p.fixed        ? std::string("(fixed)")
              : p.determined ? fmt::format("[{:.7g}, {:.7g}]", p.ci_low, p.ci_high)
                             : std::string("(see below)"));
        continue;
      }
      if (std::isnan(t.value)) { // not determined apart from another term: no value
        row(j.name, joints::term_name(t.term), joints::term_effect(t.term), "undetermined", "",
            "(see below)");
        continue;
      }
      row(j.name, joints::term_name(t.term), joints::term_effect(t.term),
          fmt::format("{:.7g}", t.value), fmt::format("{:.3g}", t.std),
          t.fixed ? std::string("(fixed)") : fmt::format("[{:.7g}, {:.7g}]", t.ci_low, t.ci_high));
    }
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
}

// The pictures, each optional; one that cannot be drawn is a warning, the result stands.
void Identify::draw(const identify::FitResult& result,
                    const std::vector<joints::Joint>& model_joints,
                    const std::vector<identify::Measurement>& measured) const {
  if (!fit_png_.empty())
    draw_chart(fit_png_, [&] {
      return report::harmonic_fit_figure(measured, report::harmonic_fit_dofs(model_joints));
    });
  if (!params_png_.empty())
    draw_chart(params_png_, [&] { return report::parameter_figure(result, model_joints); });
}

} // namespace

std::unique_ptr<Command> identify_command(CLI::App& parent) {
  return std::make_unique<Identify>(parent);
}

} // namespace jointid::cli
