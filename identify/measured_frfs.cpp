#include "identify/measured_frfs.hpp"

#include "fem/constants.hpp"
#include "fem/fft.hpp"
#include "identify/record_messages.hpp"
#include "identify/spectra.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace jointid::identify {

namespace {

using cd = std::complex<double>;

// The force has power at a line when its auto spectrum is at least this fraction of its largest
// value in the band (40 dB below: a multisine's lines that are not excited, or the edges of a
// sweep's range, hold only noise there).
constexpr double force_power_floor = 1e-4;

// Sums over blocks at one response DOF: Σ G_ff, Σ G_fx, Σ G_xx (receptance terms) per line.
struct Sums {
  fem::NodeDof at;
  std::string name;
  Quantity quantity = Quantity::displacement;
  Eigen::VectorXd ff, xx;
  Eigen::VectorXcd fx;
  int blocks = 0;
};

// The response channel used at each DOF of a record: x before v before a.
std::vector<const Channel*> responses_of(const Record& r, std::vector<std::string>& notes) {
  std::vector<const Channel*> used;
  for (const Channel& c : r.channels) {
    if (c.quantity == Quantity::force) continue;
    auto same =
        std::find_if(used.begin(), used.end(), [&](const Channel* u) { return u->at == c.at; });
    if (same == used.end()) {
      used.push_back(&c);
      continue;
    }
    // Quantity's order is force, displacement, velocity, acceleration: the lower one is kept.
    const Channel* keep = c.quantity < (*same)->quantity ? &c : *same;
    const Channel* drop = keep == &c ? *same : &c;
    notes.push_back(fmt::format("{}: {} is not used ({} at the same DOF is)", r.source,
                                drop->name(), keep->name()));
    *same = keep;
  }
  return used;
}

// (iω)^p for the quantity: the factor from receptance to what was measured.
cd derivative_factor(Quantity q, double omega) {
  switch (q) {
  case Quantity::velocity:
    return {0.0, omega};
  case Quantity::acceleration:
    return {-omega * omega, 0.0};
  default:
    return {1.0, 0.0};
  }
}

} // namespace

const char* spectra_method_name(SpectraMethod method) {
  switch (method) {
  case SpectraMethod::automatic:
    return "automatic";
  case SpectraMethod::welch:
    return "welch";
  case SpectraMethod::periods:
    return "periods";
  case SpectraMethod::whole:
    return "whole";
  case SpectraMethod::measured:
    return "measured";
  }
  return "?";
}

int MeasuredFrfs::drive_column() const {
  for (std::size_t i = 0; i < responses.size(); ++i)
    if (responses[i] == drive) return static_cast<int>(i);
  return -1;
}

MeasuredFrfs frfs_from_records(const std::vector<Record>& records,
                               const FrfEstimateOptions& options) {
  if (records.empty()) throw std::invalid_argument("no records to estimate FRFs from");
  const double f0 = options.f0_hz, f1 = options.f1_hz;
  if (!(std::isfinite(f0) && std::isfinite(f1) && f0 >= 0.0 && f1 > f0))
    throw std::invalid_argument(
        fmt::format("the band {} to {} Hz: expected 0 <= F0 < F1 (Hz)", f0, f1));

  MeasuredFrfs out;
  // 1. Sampling, the force and the responses of every record.
  const Record& first = records.front();
  const double fs = 1.0 / first.dt();
  std::vector<std::vector<const Channel*>> used(records.size());
  const Channel* first_force = nullptr;
  Eigen::Index shortest = std::numeric_limits<Eigen::Index>::max(), longest = 0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const Record& r = records[i];
    if (r.t.size() < 8)
      throw std::invalid_argument(
          fmt::format("{}: {} samples, expected at least 8", r.source, r.t.size()));
    const double rate = 1.0 / r.dt();
    if (!(std::isfinite(rate) && rate > 0.0))
      throw std::invalid_argument(fmt::format("{}: the time step is not > 0", r.source));
    if (std::abs(rate - fs) > 1e-6 * fs)
      throw std::invalid_argument(fmt::format(
          "{} is sampled at {} Hz but {} at {} Hz: the records of one fit need one sample rate",
          r.source, rate, first.source, fs));
    const auto forces = r.all(Quantity::force);
    if (forces.empty())
      throw std::invalid_argument(fmt::format(
          "{}: no force channel (expected f@<node>:<dof> at the driving point beside the "
          "responses; the channels are {})",
          r.source, channel_list(r)));
    if (forces.size() > 1)
      throw std::invalid_argument(
          fmt::format("{}: {} force channels ({} and {}): a modal fit takes one driving point (one "
                      "reference); give the records of each driving point separately",
                      r.source, forces.size(), forces[0]->name(), forces[1]->name()));
    if (!first_force) first_force = forces[0];
    if (forces[0]->at != first_force->at)
      throw std::invalid_argument(fmt::format(
          "{} is driven at {} but {} at {}: a modal fit takes one driving point (one reference)",
          r.source, forces[0]->name(), first.source, first_force->name()));
    used[i] = responses_of(r, out.notes);
    if (used[i].empty())
      throw std::invalid_argument(
          fmt::format("{}: no response channel (expected x, v or a channels beside {})", r.source,
                      forces[0]->name()));
    shortest = std::min(shortest, r.t.size());
    longest = std::max(longest, r.t.size());
    out.sources.push_back(r.source);
  }
  out.drive = first_force->at;
  out.drive_name = first_force->name();
  out.sample_rate_hz = fs;
  if (f1 > 0.5 * fs * (1.0 + 1e-12))
    throw std::invalid_argument(fmt::format(
        "the band {} to {} Hz reaches above the records' Nyquist frequency, {} Hz (sampled at "
        "{} Hz): lower F1",
        f0, f1, 0.5 * fs, fs));

  // 2. The method and its block length.
  SpectraMethod method = options.method;
  std::vector<double> periods(records.size(), options.period_s);
  if (!(options.period_s >= 0.0 && std::isfinite(options.period_s)))
    throw std::invalid_argument(
        fmt::format("the period: expected seconds > 0, got {}", options.period_s));
  if (options.period_s == 0.0)
    for (std::size_t i = 0; i < records.size(); ++i)
      periods[i] = records[i].period_s.value_or(0.0);
  const bool all_periodic =
      std::all_of(periods.begin(), periods.end(), [](double p) { return p > 0.0; });
  int block = 0;
  auto period_samples = [&](std::size_t i) -> std::optional<int> {
    const double samples = periods[i] * fs;
    const double whole = std::round(samples);
    if (whole < 8 || std::abs(samples - whole) > 1e-6 * whole) return std::nullopt;
    return static_cast<int>(whole);
  };
  if (method == SpectraMethod::automatic || method == SpectraMethod::periods) {
    std::string why; // why the periods cannot be used
    if (!all_periodic) {
      for (std::size_t i = 0; i < records.size() && why.empty(); ++i)
        if (!(periods[i] > 0.0))
          why = fmt::format("{} states no period (# period_s = T)", records[i].source);
    } else {
      for (std::size_t i = 0; i < records.size() && why.empty(); ++i) {
        const auto P = period_samples(i);
        if (!P)
          why = fmt::format("{}: its period, {} s, holds {} samples, not a whole number (to "
                            "1e-6) of at least 8",
                            records[i].source, periods[i], periods[i] * fs);
        else if (block != 0 && *P != block)
          why = fmt::format("{} has a period of {} samples but {} of {}: their lines differ",
                            records[i].source, *P, records.front().source, block);
        else if (records[i].t.size() < *P)
          why = fmt::format("{} holds {} samples, less than one period ({})", records[i].source,
                            records[i].t.size(), *P);
        else
          block = *P;
      }
    }
    if (!why.empty()) {
      if (method == SpectraMethod::periods)
        throw std::invalid_argument("averaging period by period: " + why);
      if (all_periodic)
        out.notes.push_back("not averaged period by period (" + why +
                            "): Welch's method with a Hann window instead");
      method = SpectraMethod::welch;
      block = 0;
    } else {
      method = SpectraMethod::periods;
    }
  }
  if (method == SpectraMethod::welch) {
    if (options.segment != 0) {
      if (options.segment < 8)
        throw std::invalid_argument(
            fmt::format("the Welch segment: expected at least 8 samples, got {}", options.segment));
      if (options.segment > shortest)
        throw std::invalid_argument(fmt::format(
            "the Welch segment of {} samples is longer than the shortest record ({} samples)",
            options.segment, shortest));
      block = options.segment;
    } else {
      // 50 % overlap: n samples hold 2n/N − 1 segments of N; at least 8 of them.
      block = 8;
      while (2 * block <= 2 * shortest / 9)
        block *= 2;
      if (2 * shortest / block - 1 < 2)
        throw std::invalid_argument(
            fmt::format("the records are too short for Welch's method ({} samples)", shortest));
    }
  } else if (method == SpectraMethod::whole) {
    block = static_cast<int>(longest);
  }
  out.method = method;
  out.block_samples = block;
  out.resolution_hz = fs / block;

  // 3. The lines of the band (never 0 Hz).
  const int bins = block / 2 + 1;
  std::vector<int> lines;
  for (int k = 1; k < bins; ++k) {
    const double f = k * fs / block;
    if (f >= f0 * (1.0 - 1e-12) && f <= f1 * (1.0 + 1e-12)) lines.push_back(k);
  }
  if (lines.empty())
    throw std::invalid_argument(fmt::format(
        "the band {} to {} Hz holds no line of the spectra (lines every {} Hz): widen it", f0, f1,
        out.resolution_hz));
  const auto L = static_cast<Eigen::Index>(lines.size());

  // 4. Sums over the blocks of every record, as receptance.
  std::vector<Sums> sums;
  Eigen::VectorXd force_power = Eigen::VectorXd::Zero(L);
  auto sums_at = [&](const Channel& c) -> Sums& {
    for (Sums& s : sums)
      if (s.at == c.at) return s;
    Sums s;
    s.at = c.at;
    s.name = c.name();
    s.quantity = c.quantity;
    s.ff = s.xx = Eigen::VectorXd::Zero(L);
    s.fx = Eigen::VectorXcd::Zero(L);
    sums.push_back(std::move(s));
    return sums.back();
  };
  // Adds one record's spectra: Gff, Gfx[c], Gxx[c] at the bins, from `blocks` blocks.
  auto add = [&](const std::vector<const Channel*>& channels, const Eigen::VectorXd& Gff,
                 const std::vector<Eigen::VectorXcd>& Gfx, const std::vector<Eigen::VectorXd>& Gxx,
                 int blocks, const std::string& source) {
    for (Eigen::Index l = 0; l < L; ++l)
      force_power(l) += Gff(lines[static_cast<std::size_t>(l)]);
    for (std::size_t c = 0; c < channels.size(); ++c) {
      Sums& s = sums_at(*channels[c]);
      if (s.quantity != channels[c]->quantity)
        out.notes.push_back(fmt::format("{}: {} is measured as {} there, as {} in another record",
                                        source, fem::to_string(s.at), channels[c]->name(), s.name));
      for (Eigen::Index l = 0; l < L; ++l) {
        const int k = lines[static_cast<std::size_t>(l)];
        const cd d = derivative_factor(channels[c]->quantity, two_pi * k * fs / block);
        s.ff(l) += Gff(k);
        s.fx(l) += Gfx[c](k) / d;
        s.xx(l) += Gxx[c](k) / std::norm(d);
      }
      s.blocks += blocks;
    }
  };
  for (std::size_t i = 0; i < records.size(); ++i) {
    const Record& r = records[i];
    const Channel& force = *r.all(Quantity::force).front();
    const auto& channels = used[i];
    const auto m = static_cast<Eigen::Index>(channels.size());
    std::vector<Eigen::VectorXcd> Gfx(channels.size());
    std::vector<Eigen::VectorXd> Gxx(channels.size());
    if (method == SpectraMethod::welch) {
      Eigen::MatrixXd signals(r.t.size(), m + 1);
      signals.col(0) = force.samples;
      for (Eigen::Index c = 0; c < m; ++c)
        signals.col(c + 1) = channels[static_cast<std::size_t>(c)]->samples;
      const WelchSpectra s = welch(signals, fs, {block, 0.5});
      // Sums, not averages: records with more segments weigh more.
      for (Eigen::Index c = 0; c < m; ++c) {
        Gfx[static_cast<std::size_t>(c)] = s.averages * s.G[0].col(c + 1);
        Gxx[static_cast<std::size_t>(c)] = s.averages * s.psd(static_cast<int>(c + 1));
      }
      add(channels, s.averages * s.psd(0), Gfx, Gxx, s.averages, r.source);
      continue;
    }
    // Rectangular blocks: the last whole periods, or the record zero-padded to `block`.
    fem::RealFft fft(block);
    const Eigen::Index n = r.t.size();
    const Eigen::Index count = method == SpectraMethod::periods ? n / block : 1;
    const Eigen::Index start = method == SpectraMethod::periods ? n - count * block : 0;
    Eigen::VectorXd Gff = Eigen::VectorXd::Zero(bins);
    for (std::size_t c = 0; c < channels.size(); ++c) {
      Gfx[c] = Eigen::VectorXcd::Zero(bins);
      Gxx[c] = Eigen::VectorXd::Zero(bins);
    }
    Eigen::VectorXd x = Eigen::VectorXd::Zero(block);
    auto transform = [&](const Eigen::VectorXd& samples, Eigen::Index from) {
      if (method == SpectraMethod::periods) {
        x = samples.segment(from, block);
      } else {
        x.setZero();
        x.head(n) = samples;
      }
      return fft.forward(x);
    };
    for (Eigen::Index b = 0; b < count; ++b) {
      const Eigen::Index from = start + b * block;
      const Eigen::VectorXcd F = transform(force.samples, from);
      Gff += F.cwiseAbs2();
      for (std::size_t c = 0; c < channels.size(); ++c) {
        const Eigen::VectorXcd X = transform(channels[c]->samples, from);
        Gfx[c] += F.conjugate().cwiseProduct(X);
        Gxx[c] += X.cwiseAbs2();
      }
    }
    add(channels, Gff, Gfx, Gxx, static_cast<int>(count), r.source);
  }

  // 5. The lines where the force has power.
  const double floor = force_power_floor * force_power.maxCoeff();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index l = 0; l < L; ++l)
    if (force_power(l) >= floor && force_power(l) > 0.0) kept.push_back(l);
  if (kept.size() < lines.size())
    out.notes.push_back(fmt::format(
        "{} of the band's {} lines left out: the force has no power there (its auto spectrum is "
        "more than 40 dB below its largest value in the band)",
        lines.size() - kept.size(), lines.size()));
  const auto K = static_cast<Eigen::Index>(kept.size());
  out.frequency_hz.resize(K);
  for (Eigen::Index j = 0; j < K; ++j)
    out.frequency_hz(j) = lines[static_cast<std::size_t>(kept[j])] * fs / block;
  const auto R = static_cast<Eigen::Index>(sums.size());
  out.H.resize(K, R);
  out.coherence.resize(K, R);
  for (Eigen::Index c = 0; c < R; ++c) {
    const Sums& s = sums[static_cast<std::size_t>(c)];
    out.responses.push_back(s.at);
    out.response_names.push_back(s.name);
    out.measured_as.push_back(s.quantity);
    out.blocks.push_back(s.blocks);
    for (Eigen::Index j = 0; j < K; ++j) {
      const Eigen::Index l = kept[j];
      out.H(j, c) = s.ff(l) > 0.0 ? s.fx(l) / s.ff(l) : cd(0.0, 0.0);
      out.coherence(j, c) = s.blocks < 2 ? std::numeric_limits<double>::quiet_NaN()
                            : s.ff(l) > 0.0 && s.xx(l) > 0.0
                                ? std::norm(s.fx(l)) / (s.ff(l) * s.xx(l))
                                : 0.0;
    }
  }
  return out;
}

MeasuredFrfs frfs_from_measured(const frf::MeasuredFrf& frf, double f0, double f1) {
  if (frf.functions.empty()) throw std::invalid_argument("no measured FRFs");
  if (!(std::isfinite(f0) && std::isfinite(f1) && f0 >= 0.0 && f1 > f0))
    throw std::invalid_argument(
        fmt::format("the band {} to {} Hz: expected 0 <= F0 < F1 (Hz)", f0, f1));
  const frf::MeasuredFunction& first = frf.functions.front();
  MeasuredFrfs out;
  out.method = SpectraMethod::measured;
  out.drive = first.drive;
  out.drive_name = fem::to_string(first.drive);
  const std::vector<double>& lines = first.frequencies_hz;
  const double top = lines.back();
  for (const frf::MeasuredFunction& f : frf.functions) {
    if (f.drive != first.drive)
      throw std::invalid_argument(fmt::format(
          "{} is driven at {} but {} at {}: a modal fit takes one driving point (one reference)",
          f.source, fem::to_string(f.drive), first.source, fem::to_string(first.drive)));
    bool same = f.frequencies_hz.size() == lines.size();
    for (std::size_t k = 0; same && k < lines.size(); ++k)
      same = std::abs(f.frequencies_hz[k] - lines[k]) <= 1e-9 * top;
    if (!same)
      throw std::invalid_argument(fmt::format(
          "{} is measured at other frequency lines than {} ({} lines from {} to {} Hz against {} "
          "from {} to {} Hz): the FRFs of one fit need the same lines",
          f.source, first.source, f.frequencies_hz.size(), f.frequencies_hz.front(),
          f.frequencies_hz.back(), lines.size(), lines.front(), top));
    out.sources.push_back(f.source);
  }
  if (f1 > top * (1.0 + 1e-9) || f0 >= top)
    throw std::invalid_argument(fmt::format(
        "the band {} to {} Hz reaches outside the measured FRFs ({} lines from {} to {} Hz): "
        "choose a band inside them",
        f0, f1, lines.size(), lines.front(), top));
  std::vector<std::size_t> kept;
  for (std::size_t k = 0; k < lines.size(); ++k)
    if (lines[k] > 0.0 && lines[k] >= f0 * (1.0 - 1e-12) && lines[k] <= f1 * (1.0 + 1e-12))
      kept.push_back(k);
  const auto K = static_cast<Eigen::Index>(kept.size());
  const auto R = static_cast<Eigen::Index>(frf.functions.size());
  out.frequency_hz.resize(K);
  out.H.resize(K, R);
  out.coherence = Eigen::MatrixXd::Constant(K, R, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index j = 0; j < K; ++j)
    out.frequency_hz(j) = lines[kept[static_cast<std::size_t>(j)]];
  for (Eigen::Index c = 0; c < R; ++c) {
    const frf::MeasuredFunction& f = frf.functions[static_cast<std::size_t>(c)];
    out.responses.push_back(f.response);
    out.response_names.push_back(fem::to_string(f.response));
    out.measured_as.push_back(Quantity::displacement);
    out.blocks.push_back(0);
    for (Eigen::Index j = 0; j < K; ++j)
      out.H(j, c) = f.receptance[kept[static_cast<std::size_t>(j)]];
  }
  out.resolution_hz = lines.size() > 1 ? (top - lines.front()) / (lines.size() - 1) : 0.0;
  return out;
}

} // namespace jointid::identify
