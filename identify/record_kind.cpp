#include "identify/record_kind.hpp"

#include "fem/constants.hpp"
#include "fem/fft.hpp"
#include "identify/harmonics.hpp"
#include "identify/record_messages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace jointid::identify {

namespace {

// What the force's spectrum and autocorrelation say, kept for the refusal's message.
struct Evidence {
  double line_share = 0.0; // of the whole record's power, in the largest line + harmonics
  double repeat = 0.0;     // the largest normalised autocorrelation past the first zero
  double lag_from = 0.0, lag_to = 0.0; // s, the lags searched
  std::string sweep;                   // why it is not a sweep
};

Eigen::VectorXd hann_windowed(const Eigen::VectorXd& x) {
  const auto n = x.size();
  const double mean = x.mean();
  Eigen::VectorXd w(n);
  for (Eigen::Index i = 0; i < n; ++i)
    w(i) = (x(i) - mean) * 0.5 * (1.0 - std::cos(two_pi * static_cast<double>(i) / n));
  return w;
}

// Power of the Hann-windowed signal in bins 0 … n/2.
Eigen::VectorXd power_spectrum(const Eigen::VectorXd& x) {
  fem::RealFft fft(static_cast<int>(x.size()));
  return fft.forward(hann_windowed(x)).cwiseAbs2();
}

// The largest line (bin ≥ 1) interpolated between bins (a parabola through the logarithms).
double peak_bin(const Eigen::VectorXd& power) {
  Eigen::Index k = 1;
  power.tail(power.size() - 1).maxCoeff(&k);
  k += 1;
  if (k + 1 >= power.size()) return static_cast<double>(k);
  const double a = std::log(std::max(power(k - 1), 1e-300)),
               b = std::log(std::max(power(k), 1e-300)),
               c = std::log(std::max(power(k + 1), 1e-300));
  const double curvature = a - 2.0 * b + c;
  return static_cast<double>(k) +
         (curvature < 0.0 ? std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5) : 0.0);
}

// The share of the power (DC left out) within `width` bins of the line at `bin` and of its
// harmonics.
double line_share(const Eigen::VectorXd& power, double bin, double width) {
  const auto top = power.size() - 1;
  std::vector<bool> in(static_cast<std::size_t>(top + 1), false);
  for (int h = 1; h * bin - width <= static_cast<double>(top); ++h) {
    const auto lo =
        std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::floor(h * bin - width)));
    const auto hi =
        std::min<Eigen::Index>(top, static_cast<Eigen::Index>(std::ceil(h * bin + width)));
    for (Eigen::Index k = lo; k <= hi; ++k)
      in[static_cast<std::size_t>(k)] = true;
  }
  double line = 0.0, total = 0.0;
  for (Eigen::Index k = 1; k <= top; ++k) {
    total += power(k);
    if (in[static_cast<std::size_t>(k)]) line += power(k);
  }
  return total > 0.0 ? line / total : 0.0;
}

// The period, in samples, of a force that repeats: the first local maximum of its normalised
// autocorrelation past its first zero that reaches 0.9 of the largest there, accepted when the
// autocorrelation is at least 0.8 at it and at every multiple of it up to half the record. 0:
// it does not repeat (at least twice).
int detect_period(const Eigen::VectorXd& x, double dt, Evidence& e) {
  const auto n = x.size();
  const Eigen::VectorXd x0 = x.array() - x.mean();
  // Linear (not circular) autocorrelation by FFT, zero-padded to a power of 2 ≥ 2n.
  int m = 1;
  while (m < 2 * n)
    m *= 2;
  fem::RealFft fft(m);
  Eigen::VectorXd padded = Eigen::VectorXd::Zero(m);
  padded.head(n) = x0;
  const Eigen::VectorXcd S = fft.forward(padded);
  const Eigen::VectorXd acf = fft.inverse(S.cwiseAbs2().cast<std::complex<double>>()) / m;
  // r(τ) = Σ x_i x_{i+τ} / √(Σ_{i<n−τ} x_i² · Σ_{i≥τ} x_i²).
  Eigen::VectorXd head(n + 1), tail(n + 1); // energy of the first and the last j samples
  head(0) = tail(0) = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    head(j + 1) = head(j) + x0(j) * x0(j);
    tail(j + 1) = tail(j) + x0(n - 1 - j) * x0(n - 1 - j);
  }
  auto r = [&](Eigen::Index lag) {
    const double energy = std::sqrt(head(n - lag) * tail(n - lag));
    return energy > 0.0 ? acf(lag) / energy : 0.0;
  };
  const Eigen::Index last = n / 2;
  Eigen::Index first = 1;
  while (first <= last && r(first) > 0.0)
    ++first;
  e.lag_from = static_cast<double>(first) * dt;
  e.lag_to = static_cast<double>(last) * dt;
  if (first > last) return 0;
  double best = -1.0;
  for (Eigen::Index lag = first; lag <= last; ++lag)
    best = std::max(best, r(lag));
  e.repeat = best;
  if (best < 0.8) return 0;
  for (Eigen::Index lag = first; lag <= last; ++lag) {
    const double here = r(lag);
    if (here < 0.9 * best || here < r(lag - 1) || (lag < n - 1 && here < r(lag + 1))) continue;
    bool repeats = true;
    for (Eigen::Index multiple = 2 * lag; multiple <= last && repeats; multiple += lag) {
      // The multiple's own local maximum within a sample (a period a little off a whole number
      // of samples drifts by a fraction of a sample per period).
      double around = r(multiple);
      if (multiple + 1 < n) around = std::max(around, r(multiple + 1));
      around = std::max(around, r(multiple - 1));
      repeats = around >= 0.8;
    }
    if (repeats) return static_cast<int>(lag);
  }
  return 0;
}

// A sweep: the largest line of every window of a spectrogram (16 non-overlapping windows, those
// holding at least 1 % of the most energetic one's energy) moves one way through the record, by
// at least 3 bins in all, and holds at least half of its window's power (within the bins the
// frequency moves across a window). Its first and last frequencies through `from`, `to`.
bool detect_sweep(const Eigen::VectorXd& x, double dt, double& from, double& to, Evidence& e) {
  constexpr int windows = 16;
  const auto L = x.size() / windows;
  if (L < 64) {
    e.sweep = "too short for a spectrogram";
    return false;
  }
  const double bin = 1.0 / (static_cast<double>(L) * dt);
  std::vector<double> f, energy, share;
  std::vector<Eigen::VectorXd> powers;
  for (int w = 0; w < windows; ++w) {
    const Eigen::VectorXd segment = x.segment(w * L, L);
    powers.push_back(power_spectrum(segment));
    f.push_back(peak_bin(powers.back()));
    energy.push_back(powers.back().sum());
  }
  const double most = *std::max_element(energy.begin(), energy.end());
  std::vector<int> kept;
  for (int w = 0; w < windows; ++w)
    if (energy[static_cast<std::size_t>(w)] >= 0.01 * most) kept.push_back(w);
  if (kept.size() < 4) {
    e.sweep = "its force is in fewer than 4 of 16 windows";
    return false;
  }
  const double first = f[static_cast<std::size_t>(kept.front())],
               last = f[static_cast<std::size_t>(kept.back())];
  if (std::abs(last - first) < 3.0) {
    e.sweep = "the frequency of its largest line does not change through the record";
    return false;
  }
  const double direction = last > first ? 1.0 : -1.0;
  int concentrated = 0;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const auto w = static_cast<std::size_t>(kept[i]);
    if (i + 1 < kept.size()) {
      const double step = direction * (f[static_cast<std::size_t>(kept[i + 1])] - f[w]);
      if (step < -1.0) {
        e.sweep = fmt::format("the frequency of its largest line goes {} and back ({:.4g} Hz, "
                              "then {:.4g} Hz)",
                              direction > 0 ? "up" : "down", f[w] * bin,
                              f[static_cast<std::size_t>(kept[i + 1])] * bin);
        return false;
      }
    }
    const double before = i > 0 ? f[static_cast<std::size_t>(kept[i - 1])] : f[w];
    const double after = i + 1 < kept.size() ? f[static_cast<std::size_t>(kept[i + 1])] : f[w];
    const double moves = 0.5 * std::abs(after - before);
    if (line_share(powers[w], f[w], 4.0 + moves) >= 0.5) ++concentrated;
  }
  if (concentrated < static_cast<int>(0.8 * static_cast<double>(kept.size()))) {
    e.sweep = "its windows hold no dominant line (broadband)";
    return false;
  }
  from = first * bin;
  to = last * bin;
  return true;
}

} // namespace

const char* to_string(RecordKind kind) {
  switch (kind) {
  case RecordKind::sine:
    return "sine test";
  case RecordKind::periodic:
    return "periodic test";
  case RecordKind::sweep:
    return "sweep";
  }
  return "";
}

std::string channel_list(const Record& r) {
  std::string names;
  for (const auto& c : r.channels)
    names += (names.empty() ? "" : ", ") + c.name();
  return names.empty() ? std::string("none") : names;
}

double clipped_fraction(const Eigen::VectorXd& x, const Eigen::VectorXd* velocity) {
  const double hi = x.maxCoeff(), lo = x.minCoeff(),
               tol = 1e-9 * std::max(std::abs(hi), std::abs(lo));
  if (hi - lo <= tol) return 0.0;
  const double vmax = velocity ? velocity->cwiseAbs().maxCoeff() : 0.0;
  int at_edge = 0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const bool resting = velocity && std::abs((*velocity)(i)) <= 1e-6 * vmax;
    if ((hi - x(i) <= tol || x(i) - lo <= tol) && !resting) ++at_edge;
  }
  return static_cast<double>(at_edge) / static_cast<double>(x.size());
}

std::string no_force_channel(const Record& r) {
  return "no force channel among its channels (" + channel_list(r) +
         "): a test needs its excitation force (a channel f@NODE:DOF) recorded with the "
         "responses";
}

std::string no_response_channel(const Record& r) {
  const auto forces = r.all(Quantity::force);
  return "no response channel among its channels (" + channel_list(r) +
         "): a test needs a displacement, velocity or acceleration recorded with its force" +
         (forces.empty() ? std::string() : ", e.g. x@" + fem::to_string(forces.front()->at));
}

const Channel& driving_force(const Record& r) {
  const auto forces = r.all(Quantity::force);
  if (forces.empty()) throw std::invalid_argument(r.source + ": " + no_force_channel(r));
  for (const Channel* c : forces)
    if (c->samples.size() > 0 && c->samples.cwiseAbs().maxCoeff() > 0.0) return *c;
  throw std::invalid_argument(r.source + ": every force channel is zero in every sample (" +
                              forces.front()->name() +
                              "): no force was measured; a test needs its force");
}

RecordClass classify(const Record& r) {
  const Channel& force = driving_force(r);
  const auto n = r.t.size();
  const double dt = r.dt();
  if (n < 4 || !(dt > 0.0))
    throw std::invalid_argument(r.source + ": expected at least 4 uniformly spaced samples");
  RecordClass out;
  if (r.excitation_hz) {
    out.kind = RecordKind::sine;
    out.declared = true;
    out.frequency_hz = *r.excitation_hz;
    out.evidence = fmt::format("declared: excitation_hz = {}", *r.excitation_hz);
    return out;
  }
  if (r.period_s) {
    const double T = *r.period_s, samples = T / dt;
    if (!(std::abs(samples - std::round(samples)) <= 1e-6 * samples) || std::round(samples) < 4)
      throw std::invalid_argument(fmt::format(
          "{}: period_s = {} s holds {:.9g} samples at the record's sampling ({:.9g} Hz): a period "
          "must hold a whole number of samples (at least 4)",
          r.source, T, samples, 1.0 / dt));
    out.period_samples = static_cast<int>(std::lround(samples));
    if (out.period_samples > n)
      throw std::invalid_argument(fmt::format(
          "{}: period_s = {} s is longer than the record ({} s): a periodic test needs at least "
          "one whole period",
          r.source, T, static_cast<double>(n) * dt));
    out.kind = RecordKind::periodic;
    out.declared = true;
    out.period_s = out.period_samples * dt;
    out.evidence = fmt::format("declared: period_s = {}", T);
    return out;
  }
  Evidence e;
  if (r.sweep) {
    out.kind = RecordKind::sweep;
    out.declared = true;
    if (!detect_sweep(force.samples, dt, out.sweep_from_hz, out.sweep_to_hz, e))
      out.sweep_from_hz = out.sweep_to_hz = 0.0; // the reduction finds them
    out.evidence = "declared: excitation = sweep";
    return out;
  }

  // 1. One line (and its harmonics) holds the power: a sine test.
  const Eigen::VectorXd power = power_spectrum(force.samples);
  e.line_share = line_share(power, peak_bin(power), 4.0);
  if (e.line_share >= 0.9) {
    out.kind = RecordKind::sine;
    out.frequency_hz = estimate_frequency(r.t, force.samples);
    out.evidence = fmt::format("the force's line at {:.6g} Hz and its harmonics hold {:.3g} % of "
                               "its power",
                               out.frequency_hz, 100.0 * e.line_share);
    return out;
  }
  // 2. The force repeats: a periodic test.
  if (const int period = detect_period(force.samples, dt, e); period > 0) {
    out.kind = RecordKind::periodic;
    out.period_samples = period;
    out.period_s = period * dt;
    out.evidence = fmt::format("the force repeats every {} samples ({:.6g} s; autocorrelation "
                               "{:.3g})",
                               period, out.period_s, e.repeat);
    return out;
  }
  // 3. Its frequency rises or falls steadily: a sweep.
  if (detect_sweep(force.samples, dt, out.sweep_from_hz, out.sweep_to_hz, e)) {
    out.kind = RecordKind::sweep;
    out.evidence = fmt::format("the frequency of the force's largest line goes from {:.4g} to "
                               "{:.4g} Hz steadily",
                               out.sweep_from_hz, out.sweep_to_hz);
    return out;
  }
  throw std::invalid_argument(fmt::format(
      "{}: neither a sine test, a periodic test nor a sweep: the force {} has no dominant line "
      "(its largest, with its harmonics, holds {:.3g} % of its power; a sine test: 90 %), does "
      "not repeat (normalised autocorrelation at most {:.3g} at lags of {:.4g} to {:.4g} s; a "
      "periodic test: 0.8 at its period and every multiple, at least two periods recorded), and "
      "is not a sweep ({}). Joints are not identified from random or impact excitation (jointid "
      "compare takes random records). If the record is one of the three, say so in its comments: "
      "'# excitation_hz = F' (a sine test at F Hz), '# period_s = T' (a periodic test of "
      "period T s), or '# excitation = sweep'",
      r.source, force.name(), 100.0 * e.line_share, std::max(e.repeat, 0.0), e.lag_from, e.lag_to,
      e.sweep.empty() ? std::string("no steady rise or fall of its frequency") : e.sweep));
}

} // namespace jointid::identify
