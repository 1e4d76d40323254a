#include "identify/periodic.hpp"

#include "fem/constants.hpp"
#include "fem/fft.hpp"
#include "fem/text.hpp"
#include "identify/record_messages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace jointid::identify {

namespace {

using Complex = std::complex<double>;

// One channel cut into its kept periods, transformed: per period its FFT (bins 0 … N/2).
struct PeriodSpectra {
  std::vector<Eigen::VectorXcd> S; // per kept period
  Eigen::VectorXcd mean;           // their mean
  Eigen::VectorXd line_variance;   // E|δ mean_k|² (FFT units), NaN with one period
  Eigen::VectorXd mean_samples;    // the periods' average, N samples
  double sample_variance = nan;    // the scatter of a sample about the average
};

PeriodSpectra period_spectra(const Eigen::VectorXd& samples, int first, int periods, int N,
                             fem::RealFft& fft) {
  PeriodSpectra out;
  const int P = periods - first;
  out.mean = Eigen::VectorXcd::Zero(N / 2 + 1);
  out.mean_samples = Eigen::VectorXd::Zero(N);
  for (int p = first; p < periods; ++p) {
    const auto segment = samples.segment(static_cast<Eigen::Index>(p) * N, N);
    out.S.push_back(fft.forward(segment));
    out.mean += out.S.back();
    out.mean_samples += segment;
  }
  out.mean /= P;
  out.mean_samples /= P;
  out.line_variance = Eigen::VectorXd::Constant(N / 2 + 1, nan);
  if (P >= 2) {
    out.line_variance.setZero();
    double ss = 0.0;
    for (int p = first; p < periods; ++p) {
      out.line_variance += (out.S[static_cast<std::size_t>(p - first)] - out.mean).cwiseAbs2();
      ss += (samples.segment(static_cast<Eigen::Index>(p) * N, N) - out.mean_samples).squaredNorm();
    }
    out.line_variance /= static_cast<double>(P) * (P - 1);
    out.sample_variance = ss / (static_cast<double>(N) * (P - 1));
  }
  return out;
}

// The lines 1 … top where a spectrum stands out of its noise: |S_k|² above `sigmas`² times its
// variance and above 1e-6 of the largest line (1e-4 where the variance is unknown).
std::vector<bool> significant(const Eigen::VectorXcd& S, const Eigen::VectorXd& variance, int top,
                              double sigmas) {
  std::vector<bool> out(static_cast<std::size_t>(top + 1), false);
  double largest = 0.0;
  for (int k = 1; k <= top; ++k)
    largest = std::max(largest, std::abs(S(k)));
  for (int k = 1; k <= top; ++k) {
    const double a2 = std::norm(S(k));
    const bool known = std::isfinite(variance(k));
    out[static_cast<std::size_t>(k)] =
        known ? a2 > sigmas * sigmas * variance(k) && std::abs(S(k)) > 1e-6 * largest
              : std::abs(S(k)) > 1e-4 * largest;
  }
  return out;
}

// A period's samples from its lines (FFT units) k in `use`, each times (ikω)^power.
Eigen::VectorXd from_lines(const Eigen::VectorXcd& S, const std::vector<bool>& use, double omega,
                           int power, fem::RealFft& fft) {
  Eigen::VectorXcd Y = Eigen::VectorXcd::Zero(S.size());
  for (std::size_t k = 1; k < use.size(); ++k)
    if (use[k])
      Y(static_cast<Eigen::Index>(k)) =
          S(static_cast<Eigen::Index>(k)) *
          std::pow(Complex(0.0, static_cast<double>(k) * omega), power);
  return fft.inverse(Y) / fft.size();
}

} // namespace

std::vector<std::string> clipping_warnings(const Record& r) {
  std::vector<std::string> out;
  for (const auto& c : r.channels) {
    const Channel* v =
        c.quantity == Quantity::displacement ? r.find(Quantity::velocity, c.at) : nullptr;
    const double clipped = clipped_fraction(c.samples, v ? &v->samples : nullptr);
    if (clipped > 0.01)
      out.push_back(r.source + ": channel " + c.name() + " looks clipped (" + percent(clipped) +
                    " of samples at its extremes)");
  }
  return out;
}

double off_line_noise_variance(const Eigen::Ref<const Eigen::VectorXd>& x, int periods) {
  if (periods < 2) return nan;
  const auto N = x.size() / periods;
  const auto n = N * periods;
  if (N < 2) return nan;
  // With four periods or more the record is Hann-windowed, so that a transient's spectrum falls
  // off fast away from its frequency (the rectangular window's tails, 1/f², would lift every
  // band's median); a line at bin kP then spills onto kP ± 1 only, left out with it.
  const bool hann = periods >= 4;
  const int guard = hann ? 1 : 0;
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
  if (hann)
    for (Eigen::Index i = 0; i < n; ++i)
      w(i) = 0.5 * (1.0 - std::cos(two_pi * static_cast<double>(i) / static_cast<double>(n)));
  fem::RealFft fft(static_cast<int>(n));
  const Eigen::VectorXd power = fft.forward(x.head(n).cwiseProduct(w)).cwiseAbs2();
  auto off_line = [&](Eigen::Index k) {
    const Eigen::Index r = k % periods;
    return r > guard && r < periods - guard;
  };
  // Bins 1 … n/2 − 1 (DC and Nyquist are lines or half-weighted: left out).
  const auto top = n / 2 - (n % 2 == 0 ? 1 : 0);
  Eigen::Index off_lines = 0;
  for (Eigen::Index k = 1; k <= top; ++k)
    off_lines += off_line(k) ? 1 : 0;
  if (off_lines < 4) return nan;
  const auto bands = std::clamp<Eigen::Index>(off_lines / 16, 1, 32);
  double total = 0.0;
  std::vector<double> values;
  for (Eigen::Index b = 0; b < bands; ++b) {
    const Eigen::Index lo = 1 + b * top / bands, hi = (b + 1) * top / bands; // inclusive
    values.clear();
    for (Eigen::Index k = lo; k <= hi; ++k)
      if (off_line(k)) values.push_back(power(k));
    if (values.empty()) continue;
    auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    total += *middle / std::numbers::ln2 * static_cast<double>(hi - lo + 1);
  }
  // White noise of variance σ² gives E|S_k|² = σ² Σ w²: σ² = 2 Σ_k E|S_k|² / (n Σ w²) over the
  // one-sided bins.
  return 2.0 * total / (static_cast<double>(n) * w.squaredNorm());
}

SteadyPeriods steady_periods(const std::vector<const Channel*>& channels, int N, int periods,
                             double tolerance) {
  SteadyPeriods out;
  out.periods = periods;
  if (periods < 2 || N < 2) {
    out.noise_variance.assign(channels.size(), nan);
    return out;
  }
  std::vector<bool> flagged(static_cast<std::size_t>(periods - 1), false);
  // Per pair of periods: the largest difference over its allowance of any channel.
  std::vector<double> largest(static_cast<std::size_t>(periods - 1), 0.0);
  double worst = 0.0; // the largest D over its allowance
  const double spread = 1.0 + 8.0 * std::sqrt(2.0 / N);
  for (const Channel* c : channels) {
    const Eigen::VectorXd& x = c->samples;
    std::vector<double> D(static_cast<std::size_t>(periods - 1));
    for (int p = 0; p + 1 < periods; ++p)
      D[static_cast<std::size_t>(p)] = (x.segment(static_cast<Eigen::Index>(p + 1) * N, N) -
                                        x.segment(static_cast<Eigen::Index>(p) * N, N))
                                           .squaredNorm();
    // The noise off the lines, but never more than the steadiest pair of periods shows: where
    // there is hardly any noise (a simulated record) a transient fills the bins off the lines.
    double sigma2 =
        off_line_noise_variance(x.head(static_cast<Eigen::Index>(N) * periods), periods);
    const double steadiest = *std::min_element(D.begin(), D.end()) / (2.0 * N);
    if (!(sigma2 <= steadiest)) sigma2 = steadiest;
    out.noise_variance.push_back(sigma2);
    const auto last = x.segment(static_cast<Eigen::Index>(periods - 1) * N, N);
    const double energy = (last.array() - last.mean()).matrix().squaredNorm();
    if (!(energy > 0.0)) continue;
    const double noise_allowance = 2.0 * N * sigma2 * spread;
    const double allowance = std::max(noise_allowance, tolerance * tolerance * energy);
    for (int p = 0; p + 1 < periods; ++p) {
      const double D_p = D[static_cast<std::size_t>(p)];
      largest[static_cast<std::size_t>(p)] =
          std::max(largest[static_cast<std::size_t>(p)], D_p / allowance);
      if (!(D_p > allowance)) continue;
      flagged[static_cast<std::size_t>(p)] = true;
      if (D_p / allowance > worst) {
        worst = D_p / allowance;
        out.channel = c->name();
        out.change = std::sqrt(D_p / energy);
      }
    }
  }
  // A transient decays: the leading periods that differ beyond the allowance are dropped. When
  // the differences do not fall (the largest within 4 times the smallest: drift, a response
  // that does not repeat) nothing is a transient: every such period is kept and named.
  const bool decays = *std::max_element(largest.begin(), largest.end()) >
                      4.0 * *std::min_element(largest.begin(), largest.end());
  while (decays && out.first < periods - 1 && flagged[static_cast<std::size_t>(out.first)])
    ++out.first;
  for (int p = out.first; p + 1 < periods; ++p)
    if (flagged[static_cast<std::size_t>(p)]) out.unsteady.push_back(p);
  return out;
}

std::string period_span(int from, int to, int of) {
  return from == to ? fmt::format("period {} of {}", from, of)
                    : fmt::format("periods {} to {} of {}", from, to, of);
}

bool judge_periods(const SteadyPeriods& steady, const std::string& source, double tolerance,
                   Measurement& m) {
  const int first = steady.first, P = steady.periods - first;
  auto leave_out = [&](const std::string& why) {
    m.left_out = why;
    m.warnings.push_back(why);
    return false;
  };
  if (first > 0) {
    for (int p = 0; p < first; ++p)
      m.dropped_periods.push_back(p + 1);
    const std::string what =
        fmt::format("{}: {} not steady: a transient ({} changes by {} from one period to the "
                    "next, beyond its noise and the steady tolerance {})",
                    source, period_span(1, first, steady.periods), steady.channel,
                    percent(steady.change), percent(tolerance));
    if (P < 2)
      return leave_out(what + "; fewer than two steady periods are left: the record is left out "
                              "(record more periods, or start recording once the response is "
                              "steady)");
    m.warnings.push_back(what + fmt::format("; dropped, {} periods averaged", P));
  }
  if (steady.unsteady.empty()) return true;
  std::string list;
  for (int p : steady.unsteady)
    list += fmt::format("{}{} and {}", list.empty() ? "" : ", ", p + 1, p + 2);
  // More than half of the pairs kept differ: the response does not repeat (a drift, or a
  // non-linear response that is not periodic at all), and its lines would mean nothing.
  if (2 * static_cast<int>(steady.unsteady.size()) > P - 1)
    return leave_out(fmt::format(
        "{}: periods {} differ beyond the noise: the response does not repeat (not periodic, or "
        "drifting); the record is left out",
        source, list));
  m.warnings.push_back(
      fmt::format("{}: periods {} differ beyond the noise (not steady; kept)", source, list));
  return true;
}

Measurement measure_periodic(const Record& r, const RecordClass& kind, const MeasureOptions& o) {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(r.source + ": " + what); };
  Measurement m;
  m.source = r.source;
  m.kind = RecordKind::periodic;
  const int N = kind.period_samples;
  const auto n = r.t.size();
  const int periods = static_cast<int>(n / N);
  if (N < 4 || periods < 1) fail("shorter than one period of its excitation");
  const double dt = r.dt();
  m.frequency_hz = 1.0 / (N * dt);
  const double omega = two_pi * m.frequency_hz;
  const auto forces = r.all(Quantity::force);
  if (forces.empty()) fail(no_force_channel(r));

  const std::vector<const Channel*> best = best_response_channels(r, m);
  if (best.empty()) fail(no_response_channel(r));
  for (const Channel* c : forces)
    if (c->samples.cwiseAbs().maxCoeff() == 0.0)
      m.warnings.push_back(r.source + ": channel " + c->name() +
                           ": zero in every sample (no force was measured there)");
  for (auto& w : clipping_warnings(r))
    m.warnings.push_back(std::move(w));

  // 1. The steady periods: a transient at the start is dropped.
  std::vector<const Channel*> all;
  for (const auto& c : r.channels)
    all.push_back(&c);
  const SteadyPeriods steady = steady_periods(all, N, periods, o.period_tolerance);
  const int first = steady.first, P = periods - first;
  if (periods == 1)
    m.warnings.push_back(r.source + ": one period recorded: its steady state and its noise cannot "
                                    "be checked (record at least 2 periods)");
  if (!judge_periods(steady, r.source, o.period_tolerance, m)) return m;
  m.periods_averaged = P;
  m.averaging = P;
  const Eigen::Index start = static_cast<Eigen::Index>(first) * N;
  m.t = r.t.segment(start, N);
  const double t0 = r.t(start);

  // 2. Every period's spectrum; their mean and scatter.
  fem::RealFft fft(N);
  const int top = (N - 1) / 2; // the highest line strictly below Nyquist
  auto scale = [&](int k) {    // FFT units → a harmonic of x(t) = Re(X e^{ikωt}), absolute time
    return (k == 0 ? 1.0 / N : 2.0 / N) * std::polar(1.0, -k * omega * t0);
  };
  std::vector<PeriodSpectra> force_spectra, response_spectra;
  for (const Channel* c : forces)
    force_spectra.push_back(period_spectra(c->samples, first, periods, N, fft));
  for (const Channel* c : best)
    response_spectra.push_back(period_spectra(c->samples, first, periods, N, fft));

  // 3. The excited lines: within 40 dB of the largest force line, out of the force's noise, in
  //    the band.
  double largest = 0.0;
  for (const auto& s : force_spectra)
    largest = std::max(largest, s.mean.segment(1, top).cwiseAbs2().maxCoeff());
  std::vector<bool> excited(static_cast<std::size_t>(top + 1), false);
  for (int k = 1; k <= top; ++k) {
    const double f = k * m.frequency_hz;
    if (f < o.band_from_hz * (1.0 - 1e-9) || f > o.band_to_hz * (1.0 + 1e-9)) continue;
    for (const auto& s : force_spectra) {
      const double a2 = std::norm(s.mean(k));
      const bool above_noise = !std::isfinite(s.line_variance(k)) || a2 > 25.0 * s.line_variance(k);
      if (a2 >= 1e-4 * largest && above_noise) excited[static_cast<std::size_t>(k)] = true;
    }
  }
  for (int k = 1; k <= top; ++k)
    if (excited[static_cast<std::size_t>(k)]) m.excited_lines.push_back(k);
  if (m.excited_lines.empty())
    fail(fmt::format("no excited line in the band {:g} to {:g} Hz (lines every {:.6g} Hz up to "
                     "{:.6g} Hz)",
                     o.band_from_hz, o.band_to_hz, m.frequency_hz, top * m.frequency_hz));

  // 4. The response lines: every excited one, and up to `harmonics` times the highest of them
  //    (from the band's lower end) those where a response stands out of its noise.
  const bool noise_known = P >= 2;
  const int reach = std::min<long long>(top, static_cast<long long>(std::max(1, o.harmonics)) *
                                                 m.excited_lines.back());
  std::vector<bool> used = excited;
  if (noise_known) {
    for (const auto& s : response_spectra) {
      const std::vector<bool> out = significant(s.mean, s.line_variance, reach, 5.0);
      for (int k = 1; k <= reach; ++k)
        if (out[static_cast<std::size_t>(k)] && k * m.frequency_hz >= o.band_from_hz * (1.0 - 1e-9))
          used[static_cast<std::size_t>(k)] = true;
    }
  } else {
    m.warnings.push_back(r.source + ": one period: only its excited lines are used (where the "
                                    "joints alone put response cannot be told from the noise)");
  }
  for (int k = 1; k <= top; ++k)
    if (used[static_cast<std::size_t>(k)]) m.lines.push_back(k);
  const int K = m.lines.back();
  m.harmonics = K;

  // 5. Force and displacement at lines 0 … K, with their noise.
  const auto nf = static_cast<Eigen::Index>(forces.size()),
             nr = static_cast<Eigen::Index>(best.size());
  m.F.resize(K + 1, nf);
  m.F_variance.resize(K + 1, nf);
  for (Eigen::Index i = 0; i < nf; ++i) {
    const PeriodSpectra& s = force_spectra[static_cast<std::size_t>(i)];
    m.force_at.push_back(forces[static_cast<std::size_t>(i)]->at);
    m.force_noise.push_back(std::sqrt(s.sample_variance));
    for (int k = 0; k <= K; ++k) {
      m.F(k, i) = s.mean(k) * scale(k);
      m.F_variance(k, i) = s.line_variance(k) * std::norm(scale(k));
    }
  }
  m.X.resize(K + 1, nr);
  m.X_variance.resize(K + 1, nr);
  m.x.resize(N, nr);
  m.v.resize(N, nr);
  m.derived_harmonics = top;
  m.periods.resize(static_cast<std::size_t>(P));
  for (auto& period : m.periods) {
    period.F.resize(static_cast<Eigen::Index>(m.lines.size()), nf);
    period.X.resize(static_cast<Eigen::Index>(m.lines.size()), nr);
    period.x.resize(N, nr);
    period.v.resize(N, nr);
  }
  for (int p = 0; p < P; ++p)
    for (Eigen::Index i = 0; i < nf; ++i)
      for (std::size_t l = 0; l < m.lines.size(); ++l)
        m.periods[static_cast<std::size_t>(p)].F(static_cast<Eigen::Index>(l), i) =
            force_spectra[static_cast<std::size_t>(i)].S[static_cast<std::size_t>(p)](m.lines[l]) *
            scale(m.lines[l]);
  for (Eigen::Index j = 0; j < nr; ++j) {
    const Channel& c = *best[static_cast<std::size_t>(j)];
    const PeriodSpectra& s = response_spectra[static_cast<std::size_t>(j)];
    const int power = c.quantity == Quantity::displacement ? 0
                      : c.quantity == Quantity::velocity   ? 1
                                                           : 2;
    m.channel_noise.push_back(std::sqrt(s.sample_variance));
    m.has_mean.push_back(power == 0);
    // Line k of the displacement: Q_k / (ikω)^p.
    auto displacement = [&](const Eigen::VectorXcd& S, int k) {
      return k == 0 ? (power == 0 ? S(0) * scale(0) : Complex(0.0))
                    : S(k) * scale(k) * std::pow(Complex(0.0, k * omega), -power);
    };
    for (int k = 0; k <= K; ++k) {
      m.X(k, j) = displacement(s.mean, k);
      const double gain = k == 0 ? 1.0 : std::pow(k * omega, -2.0 * power);
      m.X_variance(k, j) =
          k == 0 && power != 0 ? nan : s.line_variance(k) * std::norm(scale(k)) * gain;
    }
    // Samples for the basis functions: measured, or derived over the lines out of the noise.
    const std::vector<bool> keep = significant(s.mean, s.line_variance, top, 3.0);
    const Channel* velocity = power == 0 ? r.find(Quantity::velocity, c.at) : nullptr;
    std::optional<PeriodSpectra> measured_v;
    if (velocity) measured_v = period_spectra(velocity->samples, first, periods, N, fft);
    m.velocity_noise.push_back(measured_v ? std::sqrt(measured_v->sample_variance) : nan);
    // raw_v: a separately measured velocity's samples, or nullptr.
    auto samples = [&](const Eigen::VectorXcd& S, const Eigen::VectorXd& raw,
                       const Eigen::VectorXd* raw_v, Eigen::Ref<Eigen::VectorXd> x,
                       Eigen::Ref<Eigen::VectorXd> v) {
      x = power == 0 ? raw : from_lines(S, keep, omega, -power, fft);
      if (power == 1)
        v = raw;
      else if (raw_v)
        v = *raw_v;
      else
        v = from_lines(S, keep, omega, 1 - power, fft);
    };
    samples(s.mean, s.mean_samples, measured_v ? &measured_v->mean_samples : nullptr, m.x.col(j),
            m.v.col(j));
    for (int p = 0; p < P; ++p) {
      auto& period = m.periods[static_cast<std::size_t>(p)];
      const Eigen::VectorXd raw = c.samples.segment(start + static_cast<Eigen::Index>(p) * N, N);
      const Eigen::VectorXd raw_v = velocity ? Eigen::VectorXd(velocity->samples.segment(
                                                   start + static_cast<Eigen::Index>(p) * N, N))
                                             : Eigen::VectorXd();
      const auto& Sp = s.S[static_cast<std::size_t>(p)];
      samples(Sp, raw, velocity ? &raw_v : nullptr, period.x.col(j), period.v.col(j));
      for (std::size_t l = 0; l < m.lines.size(); ++l)
        period.X(static_cast<Eigen::Index>(l), j) = displacement(Sp, m.lines[l]);
    }
    if (power != 0)
      m.warnings.push_back(
          r.source + ": no displacement channel x@" + fem::to_string(c.at) +
          "; displacement derived from " + (power == 1 ? "velocity" : "acceleration") +
          " line by line (its mean is unknown and taken as 0: under a broadband force an odd "
          "non-linear joint, k3 or c2, has a mean response too, which biases its terms by about "
          "that mean over the amplitude; measure displacement at the joints where it matters)");
    else if (!velocity)
      m.warnings.push_back(r.source + ": no velocity channel v@" + fem::to_string(c.at) +
                           "; velocity derived from displacement");
  }
  return m;
}

} // namespace jointid::identify
