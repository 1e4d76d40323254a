#include "report/discovery_figures.hpp"

#include "fem/constants.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>

namespace jointid::report {

namespace {

using Complex = std::complex<double>;

// The tests' force levels grouped within 3 % (as discovery groups them): the groups' means,
// ascending.
std::vector<double> levels_of(const std::vector<discover::Comparison>& tests) {
  std::vector<double> forces;
  for (const auto& c : tests)
    forces.push_back(c.force);
  std::sort(forces.begin(), forces.end());
  std::vector<double> means;
  std::vector<int> counts;
  double last = 0.0;
  for (double f : forces) {
    if (means.empty() || f - last > 0.03 * std::abs(f))
      means.push_back(f), counts.push_back(1);
    else
      means.back() += f, ++counts.back();
    last = f;
  }
  for (std::size_t g = 0; g < means.size(); ++g)
    means[g] /= counts[g];
  return means;
}

// The level nearest to `force` (in ratio).
std::size_t level_index(const std::vector<double>& levels, double force) {
  std::size_t best = 0;
  for (std::size_t g = 1; g < levels.size(); ++g)
    if (std::abs(std::log(force / levels[g])) < std::abs(std::log(force / levels[best]))) best = g;
  return best;
}

std::vector<std::string> channels_of(const std::vector<discover::Comparison>& list) {
  std::vector<std::string> out;
  for (const auto& c : list)
    if (std::find(out.begin(), out.end(), c.channel) == out.end()) out.push_back(c.channel);
  if (out.size() > 4) out.resize(4);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Stepped-sine sweeps: FRF magnitude and phase over frequency, a colour per level.

// The FRF in the quantity the channel measured: X/F times (iω)^p, p = 0 (x), 1 (v), 2 (a).
struct Quantity {
  int power = 0;
  std::string symbol, unit;
};

Quantity quantity_of(const std::string& channel) {
  const bool rotation = channel.find(":r") != std::string::npos;
  const std::string d = rotation ? "rad" : "m", f = rotation ? "(N m)" : "N";
  switch (channel.empty() ? 'x' : channel.front()) {
  case 'v':
    return {1, "V/F", "(" + d + "/s)/" + f};
  case 'a':
    return {2, "A/F", "(" + d + "/s²)/" + f};
  default:
    return {0, "X/F", d + "/" + f};
  }
}

Complex frf(const Quantity& q, double frequency_hz, Complex X, Complex F) {
  return X / F * std::pow(Complex(0.0, two_pi * frequency_hz), q.power);
}

// A phase in degrees, within 180° of `centre`.
double wrapped(double degrees, double centre) {
  double d = std::remainder(degrees - centre, 360.0);
  if (d <= -180.0) d += 360.0;
  return centre + d;
}

// One level's points: the measured tests (sorted by frequency) and the model's curves.
struct LevelPoints {
  std::vector<std::pair<double, Complex>> measured, model, model_down;
  std::vector<std::pair<double, Complex>> simulated; // at the tests, when there are no curves
};

std::vector<LevelPoints> level_points(const std::vector<discover::Comparison>& tests,
                                      const std::vector<discover::ResponseCurve>& curves,
                                      const std::string& channel, const std::vector<double>& levels,
                                      const Quantity& q) {
  std::vector<LevelPoints> out(levels.size());
  for (const auto& c : tests)
    if (c.channel == channel && std::abs(c.force_phasor) > 0.0) {
      LevelPoints& at = out[level_index(levels, c.force)];
      at.measured.push_back({c.frequency_hz, frf(q, c.frequency_hz, c.measured, c.force_phasor)});
      if (c.converged)
        at.simulated.push_back(
            {c.frequency_hz, frf(q, c.frequency_hz, c.simulated, c.force_phasor)});
    }
  for (const auto& curve : curves) {
    if (!curve.over_frequency || !(curve.level > 0.0)) continue;
    const auto it = std::find(curve.channels.begin(), curve.channels.end(), channel);
    if (it == curve.channels.end()) continue;
    const auto& X = curve.X1[static_cast<std::size_t>(it - curve.channels.begin())];
    LevelPoints& at = out[level_index(levels, curve.level)];
    const Complex F(0.0, -curve.level); // driven by F0 sin ωt
    for (std::size_t p = 0; p < curve.x.size(); ++p)
      if (std::isfinite(std::abs(X[p])))
        (curve.descending ? at.model_down : at.model)
            .push_back({curve.x[p], frf(q, curve.x[p], X[p], F)});
  }
  for (auto& at : out) {
    const auto by_x = [](const auto& a, const auto& b) { return a.first < b.first; };
    std::sort(at.measured.begin(), at.measured.end(), by_x);
    std::sort(at.simulated.begin(), at.simulated.end(), by_x);
  }
  return out;
}

// The phase shown at the centre of the values' own range: their circular mean.
double phase_centre(const std::vector<LevelPoints>& points) {
  Complex sum = 0.0;
  for (const auto& at : points)
    for (const auto* list : {&at.measured, &at.model, &at.model_down, &at.simulated})
      for (const auto& [x, H] : *list)
        if (std::abs(H) > 0.0) sum += H / std::abs(H);
  return std::abs(sum) > 0.0 ? std::arg(sum) * 180.0 / std::numbers::pi : 0.0;
}

Series series_of(const std::vector<std::pair<double, Complex>>& points, bool phase, double centre,
                 Series::Style style, const std::array<int, 3>& color, double width) {
  Series s;
  s.style = style;
  s.color = color;
  s.width = width;
  for (const auto& [x, H] : points) {
    const double y = phase ? wrapped(std::arg(H) * 180.0 / std::numbers::pi, centre) : std::abs(H);
    if (std::isfinite(y) && (phase || y > 0.0)) s.x.push_back(x), s.y.push_back(y);
  }
  return s;
}

// A channel's FRF magnitude (or phase) over frequency, a colour per force level: measured dots,
// model lines (the level's sweep up; dashed, down where that is another branch). The model's
// lines carry the legend, one entry per level.
Chart frf_chart(const std::vector<discover::Comparison>& tests,
                const std::vector<discover::ResponseCurve>& curves, const std::string& channel,
                const std::string& title, const std::vector<double>& levels, bool phase) {
  const Quantity q = quantity_of(channel);
  const std::vector<LevelPoints> points = level_points(tests, curves, channel, levels, q);
  const double centre = phase ? phase_centre(points) : 0.0;
  Chart chart;
  chart.title = title;
  chart.x_label = "excitation frequency (Hz)";
  chart.y_label = phase ? fmt::format("phase of {} at {} (deg)", q.symbol, channel)
                        : fmt::format("|{}| at {} ({})", q.symbol, channel, q.unit);
  chart.log_y = !phase;
  for (std::size_t g = 0; g < levels.size(); ++g) {
    const std::array<int, 3> color = level_color(g, levels.size());
    const LevelPoints& at = points[g];
    Series model = series_of(at.model.empty() ? at.simulated : at.model, phase, centre,
                             Series::Style::line, color, 2.0);
    model.label = fmt::format("{:.3g} N", levels[g]);
    if (!model.x.empty()) chart.series.push_back(std::move(model));
    Series down = series_of(at.model_down, phase, centre, Series::Style::dashed, color, 2.0);
    if (!down.x.empty()) chart.series.push_back(std::move(down));
    Series measured = series_of(at.measured, phase, centre, Series::Style::points, color, 2.0);
    if (!measured.x.empty()) chart.series.push_back(std::move(measured));
  }
  return chart;
}

Figure stepped_sine_figure(const discover::Result& r, std::size_t step) {
  const bool none = step == 0;
  const auto& before = r.comparisons[none ? 0 : step - 1];
  const auto& after = r.comparisons[none ? 0 : step];
  const std::vector<double> levels = levels_of(after);
  const auto channels = channels_of(after);
  Figure f;
  f.columns = none ? 1 : 2;
  f.width = none ? 1000 : 1800;
  f.height = 2 * 440 * static_cast<int>(channels.size());
  const std::string key = " (dots: measured; lines: model)";
  for (const auto& ch : channels)
    for (bool phase : {false, true}) {
      if (none) {
        f.charts.push_back(frf_chart(after, r.curves.front(), ch,
                                     phase ? "" : "Starting model (nothing added)" + key, levels,
                                     phase));
        continue;
      }
      f.charts.push_back(frf_chart(
          before, r.curves[step - 1], ch,
          phase ? ""
                : fmt::format("Before step {}: {}", step, model_text(r.states[step - 1])) + key,
          levels, phase));
      f.charts.push_back(frf_chart(after, r.curves[step], ch,
                                   phase ? ""
                                         : fmt::format("After step {} ({} {})", step,
                                                       r.steps[step - 1].removed ? "−" : "+",
                                                       r.steps[step - 1].added.name()),
                                   levels, phase));
    }
  return f;
}

// ---------------------------------------------------------------------------------------------
// Sine tests at a few frequencies: the receptance over frequency, or over level.

// One panel for one channel: measured receptance (points) and the model's response curves
// (lines), one colour per force level (or per frequency, for sweeps over level).
Chart response_chart(const std::vector<discover::Comparison>& list,
                     const std::vector<discover::ResponseCurve>& curves, const std::string& channel,
                     const std::string& title) {
  std::vector<const discover::Comparison*> rows;
  for (const auto& c : list)
    if (c.channel == channel) rows.push_back(&c);
  const bool over_frequency = curves.empty() || curves.front().over_frequency;
  const bool by_force =
      std::all_of(rows.begin(), rows.end(), [](auto* c) { return c->force > 0.0; });
  Chart chart;
  chart.title = title;
  chart.x_label = over_frequency ? "excitation frequency (Hz)" : "force amplitude (N)";
  chart.y_label = by_force ? fmt::format("|X1/F1| at {} (m/N)", channel)
                           : fmt::format("|X1| at {} (m)", channel);
  chart.log_y = true;
  // The sweeps up give the colours; a sweep down (another branch) is drawn dashed in its colour.
  std::vector<const discover::ResponseCurve*> up, down;
  for (const auto& c : curves)
    (c.descending ? down : up).push_back(&c);
  auto same = [&](const discover::ResponseCurve& a, const discover::ResponseCurve& b) {
    return over_frequency ? a.level == b.level : a.frequency_hz == b.frequency_hz;
  };
  // Each test belongs to the curve of the nearest level (or frequency).
  auto nearest = [&](const discover::Comparison& c) {
    std::size_t best = 0;
    for (std::size_t g = 0; g < up.size(); ++g) {
      auto key = [&](std::size_t i) {
        return over_frequency ? std::abs(std::log(c.force / up[i]->level))
                              : std::abs(std::log(c.frequency_hz / up[i]->frequency_hz));
      };
      if (key(g) < key(best)) best = g;
    }
    return best;
  };
  auto line = [&](const discover::ResponseCurve& curve, Series& model) {
    const auto it = std::find(curve.channels.begin(), curve.channels.end(), channel);
    if (it == curve.channels.end()) return;
    const auto& X = curve.X1[static_cast<std::size_t>(it - curve.channels.begin())];
    for (std::size_t p = 0; p < curve.x.size(); ++p) {
      const double force = over_frequency ? curve.level : curve.x[p];
      const double y = std::abs(X[p]) / (by_force ? force : 1.0);
      if (std::isfinite(y) && y > 0.0) model.x.push_back(curve.x[p]), model.y.push_back(y);
    }
  };
  for (std::size_t g = 0; g < std::max<std::size_t>(1, up.size()); ++g) {
    Series measured, model;
    measured.style = Series::Style::points;
    measured.width = 2.5;
    model.style = Series::Style::line;
    measured.color = model.color = palette_color(g);
    std::vector<std::pair<double, double>> pts;
    for (const auto* c : rows) {
      if (!up.empty() && nearest(*c) != g) continue;
      const double y = std::abs(c->measured) / (by_force ? c->force : 1.0);
      if (y > 0.0) pts.push_back({over_frequency ? c->frequency_hz : c->force, y});
    }
    std::sort(pts.begin(), pts.end());
    for (const auto& [x, y] : pts)
      measured.x.push_back(x), measured.y.push_back(y);
    if (!up.empty()) {
      const auto& curve = *up[g];
      const std::string label = over_frequency ? fmt::format("{:.3g} N", curve.level)
                                               : fmt::format("{:.3g} Hz", curve.frequency_hz);
      measured.label = "measured, " + label;
      model.label = "model, " + label;
      line(curve, model);
      for (const auto* d : down)
        if (same(*d, curve)) {
          Series back = model;
          back.label = "model, " + label + ", swept down";
          back.style = Series::Style::dashed;
          back.x.clear(), back.y.clear();
          line(*d, back);
          if (!back.x.empty()) chart.series.push_back(std::move(back));
        }
    } else { // no curves: the model at the tests
      measured.label = "measured";
      model.label = "model";
      std::vector<std::pair<double, double>> sim;
      for (const auto* c : rows) {
        const double y = std::abs(c->simulated) / (by_force ? c->force : 1.0);
        if (c->converged && std::isfinite(y) && y > 0.0) sim.push_back({c->frequency_hz, y});
      }
      std::sort(sim.begin(), sim.end());
      for (const auto& [x, y] : sim)
        model.x.push_back(x), model.y.push_back(y);
    }
    if (!model.x.empty()) chart.series.push_back(std::move(model));
    if (!measured.x.empty()) chart.series.push_back(std::move(measured));
  }
  return chart;
}

Figure sine_figure(const discover::Result& r, std::size_t step) {
  const bool none = step == 0;
  const auto& before = r.comparisons[none ? 0 : step - 1];
  const auto& after = r.comparisons[none ? 0 : step];
  const auto channels = channels_of(after);
  Figure f;
  f.columns = none ? 1 : 2;
  f.width = none ? 900 : 1600;
  f.height = 520 * static_cast<int>(channels.size());
  for (const auto& ch : channels) {
    if (none) {
      f.charts.push_back(
          response_chart(after, r.curves.front(), ch, "Starting model (nothing added)"));
      continue;
    }
    f.charts.push_back(
        response_chart(before, r.curves[step - 1], ch,
                       fmt::format("Before step {}: {}", step, model_text(r.states[step - 1]))));
    f.charts.push_back(response_chart(after, r.curves[step], ch,
                                      fmt::format("After step {} ({} {})", step,
                                                  r.steps[step - 1].removed ? "−" : "+",
                                                  r.steps[step - 1].added.name())));
  }
  return f;
}

} // namespace

Figure joint_behaviour_figure(const discover::JointBehaviour& b) {
  Figure figure{1200, 500, 2, {}};
  if (b.amplitude.empty()) return figure;
  const std::string unit_note = fmt::format(" (lines at {:.3g} Hz)", b.model_frequency_hz);
  Chart D;
  D.title = fmt::format("Joint '{}': dissipation per cycle{}", b.joint,
                        b.behaviour.empty() ? std::string() : " — " + b.behaviour);
  D.x_label = "deformation amplitude |Y1| (m)";
  D.y_label = "dissipation per cycle (J)";
  D.log_x = D.log_y = true;
  Chart K;
  K.title = fmt::format("Joint '{}': equivalent stiffness", b.joint);
  K.x_label = "deformation amplitude |Y1| (m)";
  K.y_label = "k_eq (N/m)";
  K.log_x = true;
  Series dots{"measured, each test alone", {}, {}, Series::Style::points, palette_color(0), 6.0};
  Series kdots = dots;
  for (std::size_t i = 0; i < b.amplitude.size(); ++i) {
    if (b.dissipation[i] > 0.0)
      dots.x.push_back(b.amplitude[i]), dots.y.push_back(b.dissipation[i]);
    kdots.x.push_back(b.amplitude[i]), kdots.y.push_back(b.stiffness[i]);
  }
  if (!dots.x.empty()) D.series.push_back(dots);
  K.series.push_back(kdots);
  const auto line = [&](const std::string& label, const std::vector<double>& y, std::size_t colour,
                        Series::Style style, bool positive) {
    Series s{label + unit_note, {}, {}, style, palette_color(colour), 2.0};
    for (std::size_t i = 0; i < b.model_amplitude.size() && i < y.size(); ++i)
      if (std::isfinite(y[i]) && (!positive || y[i] > 0.0))
        s.x.push_back(b.model_amplitude[i]), s.y.push_back(y[i]);
    return s;
  };
  for (auto [chart, start, last, positive] :
       {std::tuple{&D, &b.start_dissipation, &b.final_dissipation, true},
        std::tuple{&K, &b.start_stiffness, &b.final_stiffness, false}}) {
    const Series s0 = line("starting model", *start, 1, Series::Style::dashed, positive);
    const Series s1 = line("final model", *last, 2, Series::Style::line, positive);
    if (s0.x.size() > 1) chart->series.push_back(s0);
    if (s1.x.size() > 1) chart->series.push_back(s1);
  }
  if (!D.series.empty()) figure.charts.push_back(D);
  figure.charts.push_back(K);
  figure.columns = static_cast<int>(figure.charts.size());
  return figure;
}

std::string model_text(const discover::State& s) {
  std::string text;
  for (const auto& j : s.joints) {
    std::string terms;
    for (const auto t : j.terms)
      terms += (terms.empty() ? "" : " + ") + std::string(joints::term_name(t));
    text += fmt::format("{}'{}': {}", text.empty() ? "" : "; ", j.name, terms);
  }
  if (s.damping_scale != 1.0)
    text += fmt::format("; substructure damping ×{:.4g}", s.damping_scale);
  return text;
}

bool stepped_sine_sweeps(const std::vector<discover::Comparison>& tests) {
  const std::vector<double> levels = levels_of(tests);
  std::vector<std::vector<double>> frequencies(levels.size());
  for (const auto& c : tests)
    frequencies[level_index(levels, c.force)].push_back(c.frequency_hz);
  std::vector<std::size_t> distinct;
  for (auto& f : frequencies) {
    std::sort(f.begin(), f.end());
    std::size_t n = 0;
    for (std::size_t i = 0; i < f.size(); ++i)
      n += i == 0 || f[i] - f[i - 1] > 1e-4 * f[i] ? 1 : 0;
    distinct.push_back(n);
  }
  if (distinct.empty()) return false;
  std::nth_element(distinct.begin(), distinct.begin() + distinct.size() / 2, distinct.end());
  return distinct[distinct.size() / 2] >= 8;
}

Figure discovery_response_figure(const discover::Result& r, std::size_t step) {
  return stepped_sine_sweeps(r.comparisons.front()) ? stepped_sine_figure(r, step)
                                                    : sine_figure(r, step);
}

std::array<int, 3> level_color(std::size_t i, std::size_t n) {
  // Viridis at 0, ¼, ½, ¾ and 1 (#440154, #3b528b, #21918c, #5ec962, #fde725), linearly
  // between; the levels take 0 … 0.85 of it.
  constexpr std::array<std::array<double, 3>, 5> map{
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  const double t = n > 1 ? 0.85 * static_cast<double>(i) / static_cast<double>(n - 1) : 0.0;
  const double u = 4.0 * t;
  const auto k = std::min<std::size_t>(3, static_cast<std::size_t>(u));
  const double w = u - static_cast<double>(k);
  std::array<int, 3> rgb{};
  for (std::size_t c = 0; c < 3; ++c)
    rgb[c] = static_cast<int>(std::lround((1.0 - w) * map[k][c] + w * map[k + 1][c]));
  return rgb;
}

} // namespace jointid::report
