#include "report/discovery_report.hpp"

#include "io/files.hpp"
#include "report/chart.hpp"
#include "report/discovery_figures.hpp"
#include "report/vtk_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace jointid::report {

namespace fs = std::filesystem;

namespace {

std::string g4(double v) {
  return std::isfinite(v) ? fmt::format("{:.4g}", v) : std::string("—");
}

std::string pct(double f) {
  return std::isfinite(f) ? fmt::format("{:.3g} %", 100.0 * f) : std::string("—");
}

// An interval as the report shows it: "[lo, hi]", or "undetermined" (never a number ± 0).
std::string interval(double lo, double hi) {
  if (!(std::isfinite(lo) && std::isfinite(hi) && hi > lo)) return "undetermined";
  return fmt::format("[{}, {}]", g4(lo), g4(hi));
}

std::string capitalised(std::string text) {
  if (!text.empty() && text.front() >= 'a' && text.front() <= 'z') text.front() -= 'a' - 'A';
  return text;
}

// "a, b, c" (at most six, then "and n more").
std::string listed(const std::vector<std::string>& items) {
  std::string text;
  for (std::size_t i = 0; i < items.size() && i < 6; ++i)
    text += (i ? ", " : "") + items[i];
  if (items.size() > 6) text += fmt::format(" and {} more", items.size() - 6);
  return text;
}

// A parametric term's parameters with their units and intervals: "kt = 5000 N/m [4990, 5010],
// fs = 5 N [4.9, 5.1]"; "undetermined" where the tests do not determine one.
std::string parameters_text(const std::vector<identify::ParameterEstimate>& list,
                            joints::Term term) {
  std::string out;
  const auto& info = joints::term_info(term).parameters;
  for (std::size_t p = 0; p < list.size(); ++p) {
    const auto& e = list[p];
    const std::string unit =
        p < info.size() && info[p].unit != "1" ? fmt::format(" {}", info[p].unit) : std::string();
    out += fmt::format("{}{} = {}", out.empty() ? "" : ", ", e.name,
                       e.fixed        ? g4(e.value) + unit + " (fixed)"
                       : e.determined ? g4(e.value) + unit + " " + interval(e.ci_low, e.ci_high)
                                      : std::string("undetermined"));
  }
  return out;
}

// A parametric candidate's parameters; two terms added together: "jenkins: kt = …; gap: …".
std::string parameters_text(const discover::Candidate& c) {
  if (!c.with) return parameters_text(c.parameters, *c.term);
  return fmt::format("{}: {}; {}: {}", joints::term_name(*c.term),
                     parameters_text(c.parameters, *c.term), joints::term_name(*c.with),
                     parameters_text(c.with_parameters, *c.with));
}

std::string short_name(const discover::Candidate& c) {
  if (c.refit) return "refit";
  if (!c.term) return "damping scale";
  if (c.with)
    return fmt::format("{}+{}@{}", joints::term_name(*c.term), joints::term_name(*c.with), c.joint);
  return fmt::format("{}@{}", joints::term_name(*c.term), c.joint);
}

} // namespace

std::vector<fs::path> write_discovery_report(const fs::path& dir, const discover::Result& r,
                                             const ReportContext& context,
                                             std::vector<std::string>& warnings) {
  std::vector<fs::path> written;
  std::string why;
  const bool plots = context.plots && can_render_charts(&why);
  if (context.plots && !plots)
    warnings.push_back("no plots in the report: " + why +
                       (vtk_available() ? " (run under xvfb-run -a)" : ""));
  auto plot = [&](const std::string& name, const Figure& figure) -> std::string {
    if (!plots) return "";
    write_chart_png(dir / name, figure);
    written.push_back(dir / name);
    return fmt::format("![{}]({})\n\n", name, name);
  };

  std::string md = "# Model discovery\n\n";
  md += fmt::format("Model `{}`; {} tests", context.model, r.tests);
  if (!context.inputs.empty()) {
    md += " from ";
    for (std::size_t i = 0; i < context.inputs.size() && i < 6; ++i)
      md += fmt::format("{}`{}`", i ? ", " : "", context.inputs[i]);
    if (context.inputs.size() > 6) md += fmt::format(" and {} more", context.inputs.size() - 6);
  }
  md += fmt::format("; {} real values compared.\n\n", r.compared_values);
  md += "The **gap** is `sqrt(Σ|X_meas − X_sim|² / Σ|X_meas|²)` over every test, response channel "
        "and compared harmonic (all as displacements); the **noise level** is the gap a perfect "
        "model would leave, from the noise the records themselves show (the response's, and "
        "the force's propagated through the model).\n\n";
  md += fmt::format("**Result.** {}\n\n",
                    r.diagnosis.findings.empty() ? std::string() : r.diagnosis.findings.back());
  if (!r.limits.empty()) {
    md += "## What these tests cannot tell\n\n";
    for (const auto& l : r.limits)
      md += "- " + capitalised(l) + ".\n";
    md += "\n";
  }
  {
    // The tests a model could not re-simulate: named, with the model.
    std::string left_out;
    for (std::size_t i = 0; i < r.comparisons.size(); ++i) {
      std::vector<std::string> tests;
      for (const auto& c : r.comparisons[i])
        if (!c.converged && (tests.empty() || tests.back() != c.test)) tests.push_back(c.test);
      if (tests.empty()) continue;
      left_out += fmt::format("- {}: {}\n",
                              i == 0 ? std::string("the starting model")
                                     : fmt::format("after step {} ({} {})", i,
                                                   r.steps[i - 1].removed ? "−" : "+",
                                                   r.steps[i - 1].added.name()),
                              listed(tests));
    }
    if (!left_out.empty())
      md += "## Tests left out\n\nTheir re-simulation did not converge, even from the measured "
            "response and from the nearest tests: each is left out of that model's gap, and of "
            "its comparison with the model before it.\n\n" +
            left_out + "\n";
  }

  md += "## Diagnosis\n\n";
  for (std::size_t i = 0; i + 1 < r.diagnosis.findings.size(); ++i)
    md += "- " + r.diagnosis.findings[i] + "\n";
  // What the tests show of each joint against its amplitude: slip, or a clearance.
  for (const auto& b : r.diagnosis.behaviour) {
    const Figure f = joint_behaviour_figure(b);
    if (f.charts.empty()) continue;
    md += fmt::format("\n### Joint '{}' against its amplitude\n\n", b.joint);
    md += "Each test alone: the joint replaced by the spring and damper that give its force's "
          "fundamental (equation error at harmonic 1), its dissipation per cycle π a² ω c_eq "
          "and stiffness k_eq at the amplitude a of its deformation. On log axes the dissipation "
          "grows as a² for viscous damping, a for Coulomb sliding (macroslip), a^(3 + chi) for "
          "microslip; a clearance stiffens the joint from an amplitude on.\n\n";
    md += plot(fmt::format("joint_{}_amplitude.png", b.joint), f);
  }
  md += "\n## Starting model\n\n";
  for (const auto& n : r.start_notes)
    md += n + "\n\n";
  md += fmt::format("Model: {}. Gap {}.\n\n", model_text(r.states.front()), g4(r.gap.front()));

  md += "## Steps\n\n";
  if (r.steps.empty()) {
    md += "Nothing was added.\n\n";
  } else {
    md += "| step | added (− taken out) | effect | value | 95 % interval | gap before | gap after "
          "| explained "
          "|\n|---|---|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < r.steps.size(); ++i) {
      const auto& s = r.steps[i];
      const bool parametric = !s.added.parameters.empty();
      md += fmt::format("| {} | {}{} | {} | {} | {} | {} | {} | {} |\n", i + 1,
                        s.removed ? "− " : "", s.added.name(), s.added.effect(),
                        parametric ? parameters_text(s.added) : g4(s.added.value),
                        parametric             ? std::string("(with each parameter)")
                        : s.added.determined() ? interval(s.added.ci_low, s.added.ci_high)
                                               : std::string("undetermined"),
                        g4(s.gap_before), g4(s.gap_after), pct(s.added.explained));
    }
    md += "\n";
  }
  md += fmt::format("Stopped: {}.\n\n", r.stop_reason);
  // A coefficient that changes between tests, when that was the best explanation: its values.
  for (const auto& c : r.last_ranking)
    if (c.rejected.empty()) {
      if (c.varies) {
        md += fmt::format("{}, identified from each test alone (the other terms held):\n\n"
                          "| test | frequency (Hz) | deformation amplitude | value | std |\n"
                          "|---|---|---|---|---|\n",
                          c.name());
        const discover::Variation& v = *c.varies;
        for (std::size_t i = 0; i < v.tests.size(); ++i)
          md +=
              fmt::format("| {} | {} | {} | {} | {} |\n", fs::path(v.tests[i]).filename().string(),
                          g4(v.frequency_hz[i]), g4(v.amplitude[i]), g4(v.value[i]), g4(v.std[i]));
        md += "\n";
      }
      break;
    }

  // The gap per step.
  {
    Chart c;
    c.title = "Gap after each step";
    c.y_label = "gap";
    c.log_y = true;
    c.x_categories.push_back("start");
    for (const auto& s : r.steps)
      c.x_categories.push_back((s.removed ? "− " : "+ ") + short_name(s.added));
    Series gap;
    gap.label = "gap";
    gap.style = Series::Style::line_points;
    for (std::size_t i = 0; i < r.gap.size(); ++i)
      if (r.gap[i] > 0.0 && std::isfinite(r.gap[i])) // (not a model that simulated no test)
        gap.x.push_back(static_cast<double>(i + 1)), gap.y.push_back(r.gap[i]);
    if (gap.x.size() == 1) { // one point: draw it as a short flat segment
      gap.x.push_back(1.25);
      gap.y.push_back(gap.y.front());
    }
    if (!gap.x.empty()) c.series.push_back(gap);
    const double right = std::max(2.0, static_cast<double>(r.gap.size()));
    if (r.noise_gap > 0.0) {
      Series noise;
      noise.label = "noise level";
      noise.style = Series::Style::dashed;
      noise.x = {1.0, right};
      noise.y = {r.noise_gap, r.noise_gap};
      c.series.push_back(noise);
      if (r.simulation_gap > 0.0) {
        Series floor = noise;
        floor.label = "noise and simulation error (final model)";
        const double level = std::hypot(r.noise_gap, r.simulation_gap);
        floor.y = {level, level};
        c.series.push_back(floor);
      }
    }
    md += "## Gap per step\n\n" + plot("gap.png", Figure{1000, 600, 1, {c}});
  }

  // Measured and simulated responses, before and after each step.
  md += "## Measured and simulated response\n\n";
  md += stepped_sine_sweeps(r.comparisons.front())
            ? "Stepped-sine sweeps, as frequency response functions in the quantity each "
              "channel measured (magnitude, and phase below it): dots measured, lines the "
              "model's response (harmonic balance, continued from point to point, dashed where "
              "a sweep down finds another branch) driven by a pure sine at each force level; one "
              "colour per level, dark for the lowest, light for the highest.\n\n"
            : "Points: measured; lines: the model's response (harmonic balance, continued from "
              "point to point) driven by a pure sine at each force level. Colours: force levels "
              "(or frequencies).\n\n";
  const std::size_t figures = std::max<std::size_t>(1, r.steps.size());
  for (std::size_t i = 0; i < figures; ++i) {
    const bool none = r.steps.empty();
    md += none ? "" : fmt::format("### Step {}: {}\n\n", i + 1, r.steps[i].finding);
    md +=
        plot(fmt::format("response_{}.png", i + 1), discovery_response_figure(r, none ? 0 : i + 1));
  }

  // The candidates of every step.
  md += "## Candidates\n\n";
  md += fmt::format(
      "The gap after adding each candidate (every non-fixed term identified again, every test "
      "re-simulated; equation-error estimates, the best few refined by output error), best "
      "first by the information criterion; the dashed line is the gap before the step. A "
      "candidate may be added only if it is admissible, lowers the information criterion, "
      "explains at least {} of the squared gap and lowers the cross-validated gap. Candidates "
      "that could not be simulated (e.g. negative friction) are in the table only.\n\n",
      pct(r.min_explained));
  struct Ranking {
    std::string title;
    const std::vector<discover::Candidate>* candidates;
    double gap_now;
  };
  std::vector<Ranking> rankings;
  for (std::size_t i = 0; i < r.steps.size(); ++i)
    if (!r.steps[i].removed) // (a backward step tried no candidates)
      rankings.push_back({fmt::format("Step {} (added {})", i + 1, r.steps[i].added.name()),
                          &r.steps[i].ranking, r.steps[i].gap_before});
  if (!r.last_ranking.empty()) {
    // Its candidates were tried on the model of the last addition (backward steps follow it).
    std::size_t forward = r.steps.size();
    while (forward > 0 && r.steps[forward - 1].removed)
      --forward;
    rankings.push_back({forward < r.steps.size()
                            ? std::string("The forward search's last step (nothing added)")
                            : fmt::format("Step {} (nothing added)", r.steps.size() + 1),
                        &r.last_ranking, r.gap[forward]});
  }
  for (std::size_t i = 0; i < rankings.size(); ++i) {
    const auto& [title, ranking, gap_now] = rankings[i];
    Chart c;
    c.title = title + ": the gap after adding each candidate";
    c.y_label = "gap";
    c.log_y = true;
    Series bars, now;
    bars.style = Series::Style::bars;
    bars.label = "with the candidate";
    now.style = Series::Style::dashed;
    now.label = fmt::format("now ({})", g4(gap_now));
    now.color = {214, 39, 40};
    for (const auto& cand : *ranking) {
      if (!std::isfinite(cand.gap) || !(cand.gap > 0.0)) continue;
      c.x_categories.push_back(short_name(cand));
      bars.x.push_back(static_cast<double>(c.x_categories.size()));
      bars.y.push_back(cand.gap);
    }
    if (!bars.x.empty() && gap_now > 0.0) {
      now.x = {0.5, static_cast<double>(c.x_categories.size()) + 0.5};
      now.y = {gap_now, gap_now};
      c.series.push_back(bars);
      c.series.push_back(now);
      md += "### " + title + "\n\n" +
            plot(fmt::format("candidates_{}.png", i + 1), Figure{1200, 500, 1, {c}});
    }
    md += "| candidate | effect | value | 95 % interval | gap | explained | verdict |\n"
          "|---|---|---|---|---|---|---|\n";
    for (const auto& cand : *ranking) {
      std::string verdict = cand.rejected.empty() ? "admissible" : cand.rejected;
      if (!cand.left_out.empty() && cand.rejected.find("did not converge") == std::string::npos)
        verdict += fmt::format(" (compared without the {} test{} it could not re-simulate: {})",
                               cand.left_out.size(), cand.left_out.size() == 1 ? "" : "s",
                               listed(cand.left_out));
      // A parametric term (jenkins, iwan, gap) has no single value: its parameters, each with
      // its interval, or "—" where its fit gave none.
      const bool parametric = cand.term && joints::has_parameters(*cand.term);
      const std::string value = !parametric               ? g4(cand.value)
                                : cand.parameters.empty() ? std::string("—")
                                                          : parameters_text(cand);
      const std::string ci = !parametric               ? interval(cand.ci_low, cand.ci_high)
                             : cand.parameters.empty() ? std::string("—")
                                                       : std::string("(with each parameter)");
      md += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", cand.name(), cand.effect(), value,
                        ci, g4(cand.gap), pct(cand.explained), verdict);
    }
    md += "\n";
  }

  // Final model and per-test agreement.
  md += "## Final model\n\n";
  md += "| joint | term | effect | value | unit | 95 % interval |\n|---|---|---|---|---|---|\n";
  const auto& last = r.states.back();
  for (const auto& j : last.joints)
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      std::string ci = j.fixed[t] ? "fixed" : "—";
      if (joints::has_parameters(j.terms[t])) { // its parameters, as identified
        std::vector<identify::ParameterEstimate> list = identify::parameters_of(j, t);
        for (const auto& je : last.fit.joints)
          if (je.name == j.name)
            for (const auto& te : je.terms)
              if (te.term == j.terms[t] && te.parameters.size() == list.size())
                list = te.parameters;
        md += fmt::format("| {} | {} | {} | {} | — | {} |\n", j.name, joints::term_name(j.terms[t]),
                          joints::term_effect(j.terms[t]), parameters_text(list, j.terms[t]),
                          j.fixed[t] ? "fixed" : "(with each parameter)");
        continue;
      }
      for (const auto& je : last.fit.joints)
        if (je.name == j.name)
          for (const auto& te : je.terms)
            if (te.term == j.terms[t] && !te.fixed) ci = interval(te.ci_low, te.ci_high);
      md += fmt::format("| {} | {} | {} | {} | {} | {} |\n", j.name, joints::term_name(j.terms[t]),
                        joints::term_effect(j.terms[t]), g4(j.values[t]),
                        joints::term_unit(j.terms[t]), ci);
    }
  if (last.damping_scale != 1.0)
    md += fmt::format("| substructure | damping_scale | substructure damping | {} | — | — |\n",
                      g4(last.damping_scale));
  md += "\n## Agreement per test (fundamental)\n\n";
  md += "| test | channel | f (Hz) | force | amplitude error, start | final | phase error (deg), "
        "start | final | harmonics 2+ measured | final model |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  const auto& first = r.comparisons.front();
  const auto& final = r.comparisons.back();
  // A model that could not re-simulate a test has no error there: "left out".
  auto error = [](const discover::Comparison& c, double value, bool percent) {
    return !c.converged ? std::string("left out") : percent ? pct(value) : g4(value);
  };
  for (std::size_t i = 0; i < final.size(); ++i)
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", final[i].test,
                      final[i].channel, g4(final[i].frequency_hz), g4(final[i].force),
                      error(first[i], first[i].amplitude_error, true),
                      error(final[i], final[i].amplitude_error, true),
                      error(first[i], first[i].phase_error_deg, false),
                      error(final[i], final[i].phase_error_deg, false),
                      pct(final[i].harmonics_measured),
                      error(final[i], final[i].harmonics_simulated, true));
  // The limits are said near the top; the other warnings here.
  std::vector<std::string> others;
  for (const auto& w : r.warnings)
    if (std::find(r.limits.begin(), r.limits.end(), w) == r.limits.end()) others.push_back(w);
  if (!others.empty()) {
    md += "\n## Warnings\n\n";
    for (const auto& w : others)
      md += "- " + w + "\n";
  }
  io::write_file_atomically(dir / "report.md", md);
  written.push_back(dir / "report.md");
  return written;
}

} // namespace jointid::report
