#include "identify/compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace jointid::identify {

Comparison compare_spectra(const frf::Substructure& sub, const std::vector<joints::Joint>& joints,
                           const Record& measured, const CompareOptions& o) {
  // 1. The record and the options.
  const std::string& name = measured.source;
  ForceInput input = force_input(measured);
  std::vector<const Channel*> responses;
  for (const auto& c : measured.channels)
    if (c.quantity != Quantity::force) responses.push_back(&c);
  if (responses.empty())
    throw std::invalid_argument(
        fmt::format("{}: no response channel (expected x@, v@ or a@NODE:DOF columns)", name));
  for (const auto& c : measured.channels) // the record's channel is at fault, not the model
    if (const std::string why = sub.dofs().why_not_free(c.at); !why.empty())
      throw std::invalid_argument(
          fmt::format("{}: {} {}: {}", name,
                      c.quantity == Quantity::force ? "force channel" : "channel", c.name(), why));
  const double fs = input.sample_rate_hz, nyquist = 0.5 * fs;
  const Eigen::Index n = measured.t.size();
  const double duration = static_cast<double>(n) / fs;
  const double skip = o.skip_s < 0.0 ? 0.1 * duration : o.skip_s;
  if (!(skip < duration))
    throw std::invalid_argument(
        fmt::format("{}: skip {} s: expected less than the record's {} s", name, skip, duration));
  const auto first = static_cast<Eigen::Index>(std::ceil(skip * fs - 1e-9));
  const Eigen::Index kept = n - first;
  int segment = o.segment;
  if (segment == 0 && kept < 64)
    throw std::invalid_argument(fmt::format(
        "{}: {} samples after the first {} s, fewer than the smallest automatic segment (64): "
        "ask for a shorter segment, or give a longer record",
        name, kept, skip));
  if (segment == 0) {
    segment = 64;
    while (2 * segment <= kept / 8) // 50 % overlap: about 2 kept / segment − 1 averages
      segment *= 2;
  }
  if (segment < 8 || segment > kept)
    throw std::invalid_argument(
        fmt::format("{}: segment {}: expected 8 to {} samples (the record after the first {} s)",
                    name, segment, kept, skip));
  double f0 = o.f0_hz, f1 = o.f1_hz;
  if (f0 == 0.0 && f1 == 0.0) {
    f0 = fs / segment;
    f1 = nyquist;
  }
  if (!(std::isfinite(f0) && std::isfinite(f1) && f0 >= 0.0 && f1 > f0 && f1 <= nyquist))
    throw std::invalid_argument(
        fmt::format("{}: band {}:{} Hz: expected 0 <= F0 < F1 <= the Nyquist frequency {} Hz", name,
                    f0, f1, nyquist));

  // 2. The prediction, with the same quantities at the measured DOFs.
  ForcedOptions sim = o.simulation;
  sim.quantities.clear();
  sim.extra_outputs.clear();
  for (const Channel* c : responses) {
    if (std::find(sim.quantities.begin(), sim.quantities.end(), c->quantity) ==
        sim.quantities.end())
      sim.quantities.push_back(c->quantity);
    sim.extra_outputs.push_back(c->at);
  }
  // A force that starts at zero (a record made from rest, faded in) is used as it is; any other
  // is faded in over the first half of the skipped part, so that the start from rest is smooth.
  const double peak = input.samples.cwiseAbs().maxCoeff();
  const bool from_zero = input.samples.row(0).cwiseAbs().maxCoeff() <= 1e-9 * peak;
  sim.fade_in_s = from_zero ? 0.0 : 0.5 * skip;
  input.description = "force: the measured force channels of " + name;
  Comparison out;
  try {
    out.prediction = simulate_forced(sub, joints, input, sim);
  } catch (const std::invalid_argument& e) { // e.g. a channel at a DOF the model lacks
    throw std::invalid_argument(fmt::format("{}: {}", name, e.what()));
  }
  if (!out.prediction.status.ok()) {
    out.source = name;
    out.status = out.prediction.status.within(name + ": ");
    return out;
  }

  // 3. Spectra of both over the kept part.
  out.source = name;
  out.sample_rate_hz = fs;
  out.segment = segment;
  out.skip_s = static_cast<double>(first) / fs;
  const WelchOptions welch_options{segment, 0.5};
  for (const Channel* c : responses) {
    const Channel* p = out.prediction.record.find(c->quantity, c->at);
    if (!p) throw std::logic_error("compare: a predicted channel is missing");
    if (!(c->samples.tail(kept).cwiseAbs().maxCoeff() > 0.0))
      throw std::invalid_argument(fmt::format(
          "{}: channel {}: zero in every sample after the first {} s: nothing was measured there "
          "to compare",
          name, c->name(), static_cast<double>(first) / fs));
    // A model that is unstable under this force (a joint whose net stiffness is negative: a
    // slipping joint that takes away more than the stiffness beside it) gives a prediction that
    // grows without bound: said so, not compared as a spectrum far above the measured one.
    const auto rms = [&](const Eigen::VectorXd& v) {
      return std::sqrt(v.tail(kept).squaredNorm() / static_cast<double>(kept));
    };
    const double measured_rms = rms(c->samples), predicted_rms = rms(p->samples);
    if (!std::isfinite(predicted_rms) || predicted_rms > 1e6 * measured_rms)
      throw std::invalid_argument(fmt::format(
          "{}: channel {}: the predicted response grows without bound (RMS {:.3g} against the "
          "measured {:.3g}{}): the model is unstable under this force — e.g. a joint whose net "
          "stiffness is negative, where a slipping joint's kt exceeds the stiffness beside it",
          name, c->name(), predicted_rms, measured_rms,
          std::isfinite(predicted_rms) ? "" : ", not finite"));
    Eigen::MatrixXd both(kept, 2);
    both << c->samples.tail(kept), p->samples.tail(kept);
    const WelchSpectra s = welch(both, fs, welch_options);
    out.averages = s.averages;
    out.resolution_hz = s.resolution_hz;
    ChannelComparison cc;
    cc.channel = c->name();
    std::vector<Eigen::Index> bins;
    for (Eigen::Index k = 0; k < s.frequency_hz.size(); ++k)
      if (s.frequency_hz(k) >= f0 - 1e-9 * fs && s.frequency_hz(k) <= f1 + 1e-9 * fs &&
          s.frequency_hz(k) > 0.0)
        bins.push_back(k);
    if (bins.empty())
      throw std::invalid_argument(
          fmt::format("{}: band {}:{} Hz holds no frequency line of the spectra (spacing {} Hz)",
                      name, f0, f1, s.resolution_hz));
    const auto m = static_cast<Eigen::Index>(bins.size());
    cc.frequency_hz.resize(m);
    cc.measured.resize(m);
    cc.predicted.resize(m);
    cc.difference_db.resize(m);
    const Eigen::VectorXd gm = s.psd(0), gp = s.psd(1);
    // A line where either spectrum is below 1e-20 (-200 dB) of the larger peak of the two in
    // the band holds the arithmetic's floor, not a measurement (a 24-bit converter spans 144 dB):
    // its difference is no difference (NaN, written null) and is left out of the RMS and the
    // maximum.
    double peak = 0.0;
    for (const Eigen::Index k : bins)
      peak = std::max({peak, gm(k), gp(k)});
    const double floor = 1e-20 * peak;
    int at_floor = 0;
    double sum = 0.0, largest = 0.0;
    for (Eigen::Index i = 0; i < m; ++i) {
      const Eigen::Index k = bins[static_cast<std::size_t>(i)];
      cc.frequency_hz(i) = s.frequency_hz(k);
      cc.measured(i) = gm(k);
      cc.predicted(i) = gp(k);
      if (!(gm(k) > floor && gp(k) > floor)) {
        cc.difference_db(i) = std::numeric_limits<double>::quiet_NaN();
        ++at_floor;
        continue;
      }
      cc.difference_db(i) = 10.0 * std::log10(gp(k) / gm(k));
      sum += cc.difference_db(i) * cc.difference_db(i);
      largest = std::max(largest, std::abs(cc.difference_db(i)));
    }
    if (at_floor == m)
      throw std::invalid_argument(fmt::format(
          "{}: channel {}: the {} spectrum is below -200 dB of the other's peak on every line "
          "of the band {}:{} Hz: nothing to compare",
          name, cc.channel, gm.maxCoeff() <= floor ? "measured" : "predicted", f0, f1));
    cc.rms_db = std::sqrt(sum / static_cast<double>(m - at_floor));
    cc.max_db = largest;
    if (at_floor > 0)
      out.notes.push_back(fmt::format(
          "channel {}: {} of {} lines below -200 dB of the spectra's peak (the arithmetic's "
          "floor) left out of the differences (null in difference_db)",
          cc.channel, at_floor, m));
    out.channels.push_back(std::move(cc));
  }
  out.f0_hz = f0;
  out.f1_hz = f1;
  out.statistical_db = 10.0 * std::log10(std::exp(1.0)) * std::sqrt(2.0 / out.averages);
  out.notes.push_back(fmt::format(
      "Welch: Hann window, 50 % overlap, segment {} samples ({} Hz resolution), {} averages over "
      "the record after its first {} s",
      segment, out.resolution_hz, out.averages, out.skip_s));
  for (const auto& c : out.prediction.comments)
    if (c.rfind("method", 0) == 0) out.notes.push_back("prediction " + c);
  return out;
}

} // namespace jointid::identify
