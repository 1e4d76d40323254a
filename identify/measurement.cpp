#include "identify/measurement.hpp"

#include "fem/constants.hpp"
#include "fem/text.hpp"
#include "identify/harmonics.hpp"
#include "identify/periodic.hpp"
#include "identify/record_messages.hpp"
#include "identify/sweep.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace jointid::identify {

namespace {

using Complex = std::complex<double>;

// The samples of one channel's data over the analysed span (whole periods), with the span's
// noise estimate: either the synchronous average of the periods or the trimmed record.
struct Span {
  Eigen::VectorXd t; // analysed times (one period when averaged)
  int samples = 0;   // samples of the record behind the span (n)
  int periods = 1;   // periods averaged
  bool averaged = false;
  int dense_harmonics = 0; // harmonics a many-harmonic fit can resolve here
};

Eigen::VectorXd average_periods(const Eigen::VectorXd& x, int per_period, int periods) {
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(per_period);
  for (int p = 0; p < periods; ++p)
    mean += x.segment(static_cast<Eigen::Index>(p) * per_period, per_period);
  return mean / periods;
}

// Noise variance of a channel's samples: scatter about the synchronous average (averaged
// spans), or the residual of a many-harmonic fit; NaN when neither has degrees of freedom.
double noise_variance(const Eigen::VectorXd& raw, const Span& span, double omega) {
  if (span.averaged) {
    const int per = static_cast<int>(span.t.size());
    const Eigen::VectorXd mean = average_periods(raw, per, span.periods);
    double ss = 0.0;
    for (int p = 0; p < span.periods; ++p)
      ss += (raw.segment(static_cast<Eigen::Index>(p) * per, per) - mean).squaredNorm();
    return ss / (span.samples - per);
  }
  const int K = span.dense_harmonics, dof = span.samples - (2 * K + 1);
  if (K < 1 || dof < std::max(20, span.samples / 4)) return nan;
  const Eigen::VectorXcd X = fit_harmonics(span.t, raw, omega, K);
  return (raw - synthesise(span.t, X, omega)).squaredNorm() / dof;
}

// Leading periods of a sine record that are a transient (periodic.hpp's steady_periods), where
// its periods hold a whole number of samples; -1 when the record is left out (its reason in
// m.left_out and m.warnings).
int transient_periods(const Record& r, double frequency_hz, const MeasureOptions& o,
                      Measurement& m) {
  const double dt = r.dt(), per_period = 1.0 / (frequency_hz * dt);
  const auto per = static_cast<int>(std::lround(per_period));
  if (!o.average_periods || per < 2 || !(std::abs(per_period - per) <= 1e-6 * per_period)) return 0;
  const int periods = whole_period_samples(r.t, frequency_hz) / per;
  if (periods < 2) return 0;
  std::vector<const Channel*> all;
  for (const auto& c : r.channels)
    all.push_back(&c);
  const SteadyPeriods steady = steady_periods(all, per, periods, o.period_tolerance);
  if (!judge_periods(steady, r.source, o.period_tolerance, m)) return -1;
  return steady.first * per;
}

Measurement measure_sine(const Record& r, double frequency_hz, const MeasureOptions& o) {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(r.source + ": " + what); };
  const int K = o.harmonics;
  if (K < 1) throw std::invalid_argument("measure: need at least harmonic 1");
  Measurement m;
  m.source = r.source;
  m.harmonics = K;
  const auto forces = r.all(Quantity::force);
  // Worded for every format a record is read from (CSV columns, UFF58 datasets).
  if (forces.empty()) fail(no_force_channel(r));
  const std::vector<const Channel*> best = best_response_channels(r, m);
  if (best.empty()) fail(no_response_channel(r));

  // A force channel that is zero in every sample measured no force.
  std::vector<const Channel*> loaded;
  for (const Channel* c : forces) {
    if (c->samples.size() > 0 && c->samples.cwiseAbs().maxCoeff() == 0.0)
      m.warnings.push_back(r.source + ": channel " + c->name() +
                           ": zero in every sample (no force was measured there)");
    else
      loaded.push_back(c);
  }
  if (loaded.empty())
    fail("every force channel is zero in every sample (" + forces.front()->name() +
         "): no force was measured; a sine test needs its force");
  m.frequency_hz = frequency_hz;
  if (!(m.frequency_hz > 0.0)) fail("excitation frequency must be > 0 Hz");
  const double omega = two_pi * m.frequency_hz, dt = r.dt();
  const int n = whole_period_samples(r.t, m.frequency_hz);
  if (n == 0)
    fail("shorter than one period of the excitation (" + significant(m.frequency_hz) +
         " Hz): " + significant(static_cast<double>(r.t.size()) * dt) +
         " s recorded, a period lasts " + significant(1.0 / m.frequency_hz) + " s");
  const double nyquist = 0.5 / dt;
  if (K * m.frequency_hz >= nyquist)
    fail(fmt::format("harmonic {} ({:.6g} Hz) is at or above the Nyquist frequency of the "
                     "sampling ({:.6g} Hz): sample faster, or ask fewer harmonics",
                     K, K * m.frequency_hz, nyquist));
  if (n < 2 * K + 1)
    fail("its whole periods hold " + std::to_string(n) +
         " samples, too few to fit harmonics 0 to " + std::to_string(K) + " (at least " +
         std::to_string(2 * K + 1) + " needed: record more periods, or ask fewer harmonics)");

  // The span analysed: the synchronous average of the periods when a period holds a whole
  // number of samples, else the whole periods as they are.
  Span span;
  span.samples = n;
  const double per_period = 1.0 / (m.frequency_hz * dt);
  const int per = static_cast<int>(std::lround(per_period));
  const double periods = n * dt * m.frequency_hz;
  span.periods = static_cast<int>(std::lround(periods));
  span.averaged = o.average_periods && span.periods >= 2 &&
                  std::abs(per_period - per) <= 1e-6 * per_period &&
                  static_cast<long long>(per) * span.periods == n;
  if (span.averaged) {
    span.t = r.t.head(per);
    m.periods_averaged = span.periods;
    m.averaging = span.periods;
  } else {
    span.t = r.t.head(n);
    span.periods = 1;
  }
  m.t = span.t;
  span.dense_harmonics = std::min(64, (static_cast<int>(std::floor(per_period)) - 1) / 4);
  auto analysed = [&](const Eigen::VectorXd& raw) -> Eigen::VectorXd {
    const Eigen::VectorXd head = raw.head(n);
    return span.averaged ? average_periods(head, per, span.periods) : head;
  };
  if (periods < 2.0 - 1e-9)
    m.warnings.push_back(r.source + ": only " + std::to_string(static_cast<int>(periods)) +
                         " period; steady state cannot be checked (record at least 2)");

  for (const auto& c : r.channels) {
    const Channel* v =
        c.quantity == Quantity::displacement ? r.find(Quantity::velocity, c.at) : nullptr;
    const double clipped = clipped_fraction(c.samples, v ? &v->samples : nullptr);
    if (clipped > 0.01)
      m.warnings.push_back(r.source + ": channel " + c.name() + " looks clipped (" +
                           percent(clipped) + " of samples at its extremes)");
  }

  Eigen::MatrixXd f(span.t.size(), static_cast<Eigen::Index>(forces.size()));
  for (std::size_t i = 0; i < forces.size(); ++i) {
    m.force_at.push_back(forces[i]->at);
    f.col(static_cast<Eigen::Index>(i)) = analysed(forces[i]->samples);
  }
  m.F = fit_harmonics(span.t, f, omega, K);
  m.F_variance.resize(K + 1, f.cols());
  for (Eigen::Index i = 0; i < f.cols(); ++i) {
    const double variance = noise_variance(forces[i]->samples.head(n), span, omega);
    m.force_noise.push_back(std::sqrt(variance));
    for (int k = 0; k <= K; ++k)
      m.F_variance(k, i) = (k == 0 ? 1.0 : 4.0) * variance / n;
  }

  const auto nr = static_cast<Eigen::Index>(best.size());
  m.X.resize(K + 1, nr);
  m.X_variance.resize(K + 1, nr);
  m.x.resize(span.t.size(), nr);
  m.v.resize(span.t.size(), nr);
  const int dense = std::max(K, span.dense_harmonics);
  m.derived_harmonics = dense;
  for (Eigen::Index j = 0; j < nr; ++j) {
    const Channel& c = *best[j];
    const fem::NodeDof at = c.at;
    const Eigen::VectorXd samples = analysed(c.samples);
    const double variance = noise_variance(c.samples.head(n), span, omega);
    m.channel_noise.push_back(std::sqrt(variance));
    const int power = c.quantity == Quantity::displacement ? 0
                      : c.quantity == Quantity::velocity   ? 1
                                                           : 2;
    // Harmonics of the measured quantity, then of the displacement; many of them where a
    // signal is derived from another (a kink in a stick-slip velocity has slow-decaying ones).
    const bool derive = power != 0 || !r.find(Quantity::velocity, at);
    const Eigen::VectorXcd Q = fit_harmonics(span.t, samples, omega, derive ? dense : K);
    const Eigen::VectorXcd Xd = power == 0 ? Q : differentiate(Q, omega, -power);
    m.X.col(j) = Xd.head(K + 1);
    m.has_mean.push_back(power == 0);
    for (int k = 0; k <= K; ++k) {
      const double gain = k == 0 ? 1.0 : std::pow(k * omega, -2.0 * power);
      m.X_variance(k, j) = (k == 0 ? (power == 0 ? variance / n : nan) : 4.0 * variance / n) * gain;
    }
    // Displacement and velocity samples for the basis functions.
    m.velocity_noise.push_back(nan);
    if (power == 0) {
      m.x.col(j) = samples;
      if (const Channel* v = r.find(Quantity::velocity, at)) {
        m.v.col(j) = analysed(v->samples);
        m.velocity_noise.back() = std::sqrt(noise_variance(v->samples.head(n), span, omega));
      } else {
        m.v.col(j) = synthesise(span.t, differentiate(Q, omega, 1), omega);
        m.warnings.push_back(r.source + ": no velocity channel v@" + fem::to_string(at) +
                             "; velocity derived from displacement");
      }
    } else {
      m.x.col(j) = synthesise(span.t, Xd, omega);
      m.v.col(j) = power == 1 ? samples : synthesise(span.t, differentiate(Q, omega, -1), omega);
      m.warnings.push_back(r.source + ": no displacement channel x@" + fem::to_string(at) +
                           "; displacement derived from " +
                           (power == 1 ? "velocity" : "acceleration") +
                           " (its mean is unknown and taken as 0)");
    }
  }

  // Steady state: the fundamental over the first and the last half of the record, on the
  // largest response, allowing for the difference the noise alone would make.
  if (periods >= 2.0 - 1e-9) {
    Eigen::Index big = 0;
    m.X.row(1).cwiseAbs().maxCoeff(&big);
    const Eigen::VectorXd t = r.t.head(n), x = best[big]->samples.head(n);
    const int half = whole_period_samples(t.head(n / 2), m.frequency_hz);
    if (half > 0) {
      const Eigen::VectorXcd a =
          fit_harmonics(t.head(half), Eigen::VectorXd(x.head(half)), omega, 1);
      const Eigen::VectorXcd b =
          fit_harmonics(t.tail(half), Eigen::VectorXd(x.tail(half)), omega, 1);
      const double size = std::max(std::abs(b(1)), 1e-300);
      const double change = std::abs(a(1) - b(1)) / size;
      const double sigma = m.channel_noise[big];
      const double allowance =
          std::isfinite(sigma) ? 4.0 * 2.0 * sigma / std::sqrt(half) / size : 0.0;
      if (change > o.steady_tolerance + allowance)
        m.warnings.push_back(r.source + ": " + best[big]->name() +
                             ": not a steady state (the fundamental of the first and last half "
                             "differ by " +
                             percent(change) + "; limit " +
                             percent(o.steady_tolerance + allowance) + " with the noise)");
    }
  }
  return m;
}

// A sine record: its transient periods dropped (the record analysed from the first steady one)
// or the whole record left out, then measure_sine.
Measurement measure_record(const Record& original, double frequency_hz, const MeasureOptions& o) {
  Measurement transient;
  transient.source = original.source;
  int skip = 0;
  // A record without a force or a response is refused (by measure_sine), never left out.
  const bool measurable =
      !original.all(Quantity::force).empty() &&
      std::any_of(original.channels.begin(), original.channels.end(),
                  [](const Channel& c) { return c.quantity != Quantity::force; });
  if (measurable && frequency_hz > 0.0 && whole_period_samples(original.t, frequency_hz) > 0)
    skip = transient_periods(original, frequency_hz, o, transient);
  if (skip < 0) {
    transient.frequency_hz = frequency_hz;
    return transient;
  }
  Measurement m;
  if (skip == 0) {
    m = measure_sine(original, frequency_hz, o);
  } else {
    Record trimmed;
    trimmed.source = original.source;
    trimmed.excitation_hz = original.excitation_hz;
    trimmed.t = original.t.tail(original.t.size() - skip);
    for (const auto& c : original.channels)
      trimmed.channels.push_back({c.quantity, c.at, c.samples.tail(c.samples.size() - skip)});
    m = measure_sine(trimmed, frequency_hz, o);
  }
  m.warnings.insert(m.warnings.begin(), transient.warnings.begin(), transient.warnings.end());
  m.dropped_periods = transient.dropped_periods;
  return m;
}

Measurement measure_phasors(const Phasors& row, const MeasureOptions& o) {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument(row.source + ": " + what);
  };
  if (!(row.frequency_hz > 0.0)) fail("excitation frequency must be > 0 Hz");
  const int K = std::max(1, o.harmonics);
  Measurement m;
  m.source = row.source;
  m.frequency_hz = row.frequency_hz;
  m.harmonics = K;
  m.fundamental_only = true;
  const double omega = two_pi * row.frequency_hz;
  std::vector<Complex> forces, responses;
  for (const auto& c : row.channels) {
    if (c.quantity == Quantity::force) {
      m.force_at.push_back(c.at);
      forces.push_back(c.value);
      continue;
    }
    const int power = c.quantity == Quantity::displacement ? 0
                      : c.quantity == Quantity::velocity   ? 1
                                                           : 2;
    const Complex X = c.value * std::pow(Complex(0.0, omega), -power);
    const int i = m.response_index(c.at);
    if (i < 0) {
      m.response_at.push_back(c.at);
      m.measured_as.push_back(c.quantity);
      responses.push_back(X);
    } else if (static_cast<int>(c.quantity) < static_cast<int>(m.measured_as[i])) {
      m.measured_as[i] = c.quantity;
      responses[i] = X;
    }
  }
  if (forces.empty()) fail("no force channel (expected columns such as f@7:uy.re, f@7:uy.im)");
  if (responses.empty()) fail("no response channel (expected x, v or a columns)");
  // A zero force phasor measured no force, as a record's force channel zero in every sample:
  // one of several is said, every one is refused (the row would identify from nothing).
  std::string zero_forces;
  for (std::size_t i = 0; i < forces.size(); ++i)
    if (forces[i] == Complex(0.0, 0.0)) {
      const std::string name = "f@" + fem::to_string(m.force_at[i]);
      m.warnings.push_back(row.source + ": channel " + name +
                           ": zero (no force was measured there)");
      if (zero_forces.empty()) zero_forces = name;
    }
  if (std::all_of(forces.begin(), forces.end(), [](Complex f) { return f == Complex(0.0, 0.0); }))
    fail("every force channel is zero (" + zero_forces +
         "): no force was measured; a sine test needs its force");
  const auto nf = static_cast<Eigen::Index>(forces.size()),
             nr = static_cast<Eigen::Index>(responses.size());
  m.F = Eigen::MatrixXcd::Zero(K + 1, nf);
  m.F_variance = Eigen::MatrixXd::Constant(K + 1, nf, nan);
  m.X = Eigen::MatrixXcd::Zero(K + 1, nr);
  m.X_variance = Eigen::MatrixXd::Constant(K + 1, nr, nan);
  for (Eigen::Index i = 0; i < nf; ++i) {
    m.F(1, i) = forces[i];
    m.force_noise.push_back(nan);
  }
  // One period of the fundamental's sinusoid, finely sampled, for the basis functions.
  const int samples = 64 * (K + 1);
  m.t = Eigen::VectorXd::LinSpaced(samples, 0.0, (samples - 1.0) / (samples * row.frequency_hz));
  m.x.resize(samples, nr);
  m.v.resize(samples, nr);
  for (Eigen::Index j = 0; j < nr; ++j) {
    m.X(1, j) = responses[j];
    m.has_mean.push_back(false);
    m.channel_noise.push_back(nan);
    m.velocity_noise.push_back(nan);
    for (int i = 0; i < samples; ++i) {
      const Complex e = std::polar(1.0, omega * m.t(i));
      m.x(i, j) = (responses[j] * e).real();
      m.v(i, j) = (Complex(0.0, omega) * responses[j] * e).real();
    }
  }
  return m;
}

} // namespace

std::string PhasorChannel::name() const {
  return std::string(1, quantity_letter(quantity)) + "@" + fem::to_string(at);
}

const std::string& source_of(const SineTest& test) {
  return std::visit([](const auto& t) -> const std::string& { return t.source; }, test);
}

int Measurement::response_index(const fem::NodeDof& at) const {
  for (std::size_t i = 0; i < response_at.size(); ++i)
    if (response_at[i] == at) return static_cast<int>(i);
  return -1;
}

int Measurement::force_index(const fem::NodeDof& at) const {
  for (std::size_t i = 0; i < force_at.size(); ++i)
    if (force_at[i] == at) return static_cast<int>(i);
  return -1;
}

namespace {
Measurement measure_classified(const Record* record, const RecordClass& kind,
                               const MeasureOptions& options) {
  switch (kind.kind) {
  case RecordKind::sine:
    return measure_record(*record, kind.frequency_hz, options);
  case RecordKind::periodic:
    return measure_periodic(*record, kind, options);
  case RecordKind::sweep:
    break;
  }
  throw std::invalid_argument(record->source +
                              ": a sweep gives a stepped-sine row per window: measure the list of "
                              "tests (or identify::reduce_sweep) to get them");
}
} // namespace

Measurement measure(const SineTest& test, const MeasureOptions& options) {
  const auto* record = std::get_if<Record>(&test);
  if (!record) return measure_phasors(std::get<Phasors>(test), options);
  return measure_classified(record, classify(*record), options);
}

std::vector<Measurement> measure(const std::vector<SineTest>& tests,
                                 const MeasureOptions& options) {
  std::vector<Measurement> out;
  out.reserve(tests.size());
  for (const auto& t : tests) {
    const auto* record = std::get_if<Record>(&t);
    if (record) {
      const RecordClass kind = classify(*record);
      if (kind.kind == RecordKind::sweep) {
        for (auto& row : reduce_sweep(*record, kind, options))
          out.push_back(std::move(row));
      } else {
        out.push_back(measure_classified(record, kind, options));
      }
      continue;
    }
    out.push_back(measure(t, options));
  }
  return out;
}

std::vector<const Channel*> best_response_channels(const Record& r, Measurement& m) {
  std::vector<const Channel*> best;
  for (const auto& c : r.channels) {
    if (c.quantity == Quantity::force) continue;
    const int i = m.response_index(c.at);
    if (i < 0) {
      m.response_at.push_back(c.at);
      m.measured_as.push_back(c.quantity);
      best.push_back(&c);
    } else if (static_cast<int>(c.quantity) < static_cast<int>(m.measured_as[i])) {
      m.measured_as[i] = c.quantity;
      best[static_cast<std::size_t>(i)] = &c;
    }
  }
  return best;
}

std::vector<Measurement> usable(const std::vector<Measurement>& measurements,
                                std::vector<std::string>& notes) {
  std::vector<Measurement> out;
  for (const auto& m : measurements) {
    if (m.left_out.empty())
      out.push_back(m);
    else
      notes.push_back(m.left_out);
  }
  return out;
}

double force_level(const Measurement& m) {
  if (m.F.cols() == 0 || m.F.rows() < 2) return 0.0;
  if (m.kind != RecordKind::periodic) return m.F.row(1).cwiseAbs().maxCoeff();
  // A periodic test: the RMS of its largest force channel over its lines.
  double level = 0.0;
  for (Eigen::Index c = 0; c < m.F.cols(); ++c)
    level = std::max(level, std::sqrt(0.5 * m.F.col(c).tail(m.F.rows() - 1).squaredNorm()));
  return level;
}

} // namespace jointid::identify
