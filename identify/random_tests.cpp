#include "identify/random_tests.hpp"

#include "identify/sine_tests.hpp"
#include "identify/spectra.hpp"

#include "fem/excitation.hpp"
#include "fem/transient.hpp"
#include "frf/time_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::identify {

namespace {

void add_output(std::vector<int>& list, int value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

// "1: full model, 36 equations; 2: 5 modes of its [modal] model, …"
std::string substructure_list(const std::vector<std::string>& parts) {
  std::string text;
  for (std::size_t p = 0; p < parts.size(); ++p)
    text += fmt::format("{}{}: {}", p ? "; " : "", p + 1, parts[p]);
  return text;
}

} // namespace

ForceInput force_input(const Record& record) {
  ForceInput in;
  const auto forces = record.all(Quantity::force);
  if (forces.empty())
    throw std::invalid_argument(
        fmt::format("{}: no force channel (expected a column f@NODE:DOF)", record.source));
  const double dt = record.dt();
  if (!(dt > 0.0))
    throw std::invalid_argument(fmt::format("{}: expected at least 2 samples", record.source));
  in.sample_rate_hz = 1.0 / dt;
  in.samples.resize(record.t.size(), static_cast<Eigen::Index>(forces.size()));
  for (std::size_t j = 0; j < forces.size(); ++j) {
    in.at.push_back(forces[j]->at);
    in.samples.col(static_cast<Eigen::Index>(j)) = forces[j]->samples;
  }
  // A force zero in every sample drives nothing: the response would be zero, and a comparison
  // with it a comparison with the arithmetic's floor.
  if (in.samples.size() > 0 && in.samples.cwiseAbs().maxCoeff() == 0.0)
    throw std::invalid_argument(fmt::format(
        "{}: every force channel is zero in every sample ({}): no force to drive the model",
        record.source, [&] {
          std::string names;
          for (const Channel* c : forces)
            names += (names.empty() ? "" : ", ") + c->name();
          return names;
        }()));
  in.period_s = record.period_s;
  in.sweep = record.sweep;
  in.description = fmt::format(
      "force: the channels {} of {}",
      [&] {
        std::string names;
        for (const Channel* c : forces)
          names += (names.empty() ? "" : ", ") + c->name();
        return names;
      }(),
      record.source);
  return in;
}

namespace {
// The frequency below which `fraction` of the force's power lies (all its channels, a Welch
// spectrum of up to 4096-sample segments); 0 for fewer than 16 samples.
double power_band_hz(const ForceInput& in, double fraction) {
  const Eigen::Index n = in.samples.rows();
  if (n < 16) return 0.0;
  int segment = 16;
  while (2 * segment <= std::min<Eigen::Index>(n, 4096))
    segment *= 2;
  const WelchSpectra s = welch(in.samples, in.sample_rate_hz, {segment, 0.5});
  Eigen::VectorXd power = Eigen::VectorXd::Zero(s.frequency_hz.size());
  for (Eigen::Index j = 0; j < in.samples.cols(); ++j)
    power += s.psd(static_cast<int>(j));
  const double total = power.sum();
  if (!(total > 0.0)) return 0.0;
  double sum = 0.0;
  for (Eigen::Index k = 0; k < power.size(); ++k) {
    sum += power(k);
    if (sum >= fraction * total) return s.frequency_hz(k);
  }
  return s.frequency_hz(power.size() - 1);
}
} // namespace

ForcedTest simulate_forced(const frf::Substructure& sub, const std::vector<joints::Joint>& joints,
                           const ForceInput& in, const ForcedOptions& o) {
  // 1. Checks.
  if (!(std::isfinite(in.sample_rate_hz) && in.sample_rate_hz > 0.0))
    throw std::invalid_argument(
        fmt::format("force history: expected a sample rate > 0 Hz, got {}", in.sample_rate_hz));
  if (in.at.empty() || static_cast<Eigen::Index>(in.at.size()) != in.samples.cols())
    throw std::invalid_argument("force history: expected one column of samples per force DOF");
  if (in.samples.rows() < 2)
    throw std::invalid_argument("force history: expected at least 2 samples");
  if (o.substeps < 1)
    throw std::invalid_argument(fmt::format("substeps: expected at least 1, got {}", o.substeps));
  if (!(o.modal_cutoff_hz >= 0.0))
    throw std::invalid_argument(
        fmt::format("modal cutoff: expected >= 0 Hz, got {}", o.modal_cutoff_hz));
  if (o.quantities.empty()) throw std::invalid_argument("no response quantity asked (x, v or a)");
  for (Quantity q : o.quantities)
    if (q == Quantity::force)
      throw std::invalid_argument("force is always written; responses are x, v or a");
  const fem::DofMap& dofs = sub.dofs();
  joints::validate_joints(joints, dofs);

  // 2. Where the forces act and what is recorded.
  fem::ForceHistory history;
  history.dt = 1.0 / in.sample_rate_hz;
  history.samples = in.samples;
  for (const auto& at : in.at)
    history.equations.push_back(dofs.equation(at));
  std::vector<int> outputs = joints::joint_dof_set(joints, dofs);
  for (int e : history.equations)
    add_output(outputs, e);
  for (const auto& at : o.extra_outputs)
    add_output(outputs, dofs.equation(at));
  const joints::JointForces forces(joints, dofs);
  const fem::LocalForces* local = joints.empty() ? nullptr : &forces;
  fem::TransientOptions options;
  options.substeps = o.substeps;
  options.fade_in_s = o.fade_in_s;
  options.progress = o.progress;

  // 3. Simulate: the substructure in its time model's coordinates (frf/time_model.hpp).
  ForcedTest test;
  frf::TimeModelOptions to;
  to.modal_coordinates = o.route == TransientRoute::modal;
  to.modal_cutoff_hz = o.modal_cutoff_hz > 0.0 ? o.modal_cutoff_hz : 0.5 * in.sample_rate_hz;
  to.static_correction = o.static_correction;
  to.loaded = history.equations;
  for (int e : joints::joint_dof_set(joints, dofs))
    add_output(to.loaded, e);
  // The frequency below which 99 % of the force's power lies: a mode left out below it is
  // driven at its resonance, which the static correction does not hold (a warning).
  if (to.modal_coordinates) to.force_band_hz = power_band_hz(in, 0.99);
  const frf::TimeDomainModel model = frf::time_domain_model(sub, to);
  if (!model.status.ok()) {
    test.status = model.status.within("time simulation: ");
    return test;
  }
  test.modes_kept = model.modes_kept;
  test.static_columns = model.static_columns;
  test.warnings.insert(test.warnings.end(), model.warnings.begin(), model.warnings.end());
  const fem::TransientResponse r =
      fem::transient_response(model.model, local, history, outputs, options);
  std::string method;
  if (sub.system() && o.route == TransientRoute::full)
    method = fmt::format("method: time, full model (Newmark, average acceleration, {} equations, "
                         "{} steps per sample)",
                         dofs.num_equations(), o.substeps);
  else if (sub.parts().empty()) // in modal coordinates: a finite element model's, or [modal]
    method = fmt::format("method: time, modal coordinates (Newmark, average acceleration, {}, {} "
                         "steps per sample)",
                         model.parts.front(), o.substeps);
  else
    method = fmt::format("method: time, each substructure in its own coordinates (Newmark, "
                         "average acceleration; {}; {} steps per sample)",
                         substructure_list(model.parts), o.substeps);
  if (!r.status.ok()) {
    test.status = r.status.within("time simulation: ");
    return test;
  }

  // 4. The record.
  Record& rec = test.record;
  rec.t = r.t;
  rec.period_s = in.period_s;
  rec.sweep = in.sweep;
  for (std::size_t j = 0; j < in.at.size(); ++j) {
    Eigen::VectorXd applied = in.samples.col(static_cast<Eigen::Index>(j));
    for (Eigen::Index i = 0; i < applied.size(); ++i) {
      const double t = r.t(i);
      if (t < o.fade_in_s) // + 0.0: no "-0" in the record
        applied(i) = applied(i) * 0.5 * (1.0 - std::cos(std::numbers::pi * t / o.fade_in_s)) + 0.0;
    }
    rec.channels.push_back({Quantity::force, in.at[j], applied});
  }
  for (std::size_t j = 0; j < outputs.size(); ++j) {
    const auto c = static_cast<Eigen::Index>(j);
    const fem::NodeDof at = dofs.node_dof(outputs[j]);
    for (Quantity q : o.quantities) {
      if (q == Quantity::displacement) rec.channels.push_back({q, at, r.u.col(c)});
      if (q == Quantity::velocity) rec.channels.push_back({q, at, r.v.col(c)});
      if (q == Quantity::acceleration) rec.channels.push_back({q, at, r.a.col(c)});
    }
  }
  if (!in.description.empty()) test.comments.push_back(in.description);
  if (o.fade_in_s > 0.0)
    test.comments.push_back(
        fmt::format("force faded in over the first {} s (half-cosine); from rest", o.fade_in_s));
  else
    test.comments.push_back("from rest");
  for (const auto& j : joints)
    test.comments.push_back(joint_comment(j));
  test.comments.push_back(method);
  return test;
}

namespace {
const char* excitation_name(Excitation kind) {
  switch (kind) {
  case Excitation::random:
    return "random";
  case Excitation::sweep:
    return "sweep";
  case Excitation::multisine:
    return "multisine";
  }
  return "";
}
} // namespace

ForceInput generated_force(const ExcitationSpec& s, const fem::NodeDof& at) {
  ForceInput input;
  input.at = {at};
  input.sample_rate_hz = s.sample_rate_hz;
  const fem::Sampling sampling{s.duration_s, s.sample_rate_hz};
  switch (s.kind) {
  case Excitation::random:
    input.samples = fem::band_limited_random({s.f0_hz, s.f1_hz, s.level, s.seed}, sampling);
    input.description =
        fmt::format("excitation: band-limited Gaussian random, flat {}-{} Hz, RMS {} N, seed {}",
                    s.f0_hz, s.f1_hz, s.level, s.seed);
    break;
  case Excitation::sweep:
    input.samples = fem::sine_sweep({s.f0_hz, s.f1_hz, s.level, false}, sampling);
    input.sweep = true;
    input.description = fmt::format("excitation: linear sine sweep {}-{} Hz, amplitude {} N (peak)",
                                    s.f0_hz, s.f1_hz, s.level);
    break;
  case Excitation::multisine:
    input.samples = fem::multisine({s.f0_hz, s.f1_hz, s.level, s.period_s}, sampling);
    // The period as sampled: a whole number of samples (the record's comment says it).
    input.period_s = (s.period_s > 0.0 ? std::round(s.period_s * s.sample_rate_hz)
                                       : static_cast<double>(input.samples.rows())) /
                     s.sample_rate_hz;
    input.description =
        fmt::format("excitation: multisine, lines k/T in {}-{} Hz, Schroeder phases, RMS {} N",
                    s.f0_hz, s.f1_hz, s.level);
    break;
  }
  input.description += fmt::format("; {} s at {} Hz", s.duration_s, s.sample_rate_hz);
  return input;
}

std::string excitation_record_name(const ExcitationSpec& s) {
  return fmt::format("{}_{}-{}Hz_{}N{}.csv", excitation_name(s.kind), s.f0_hz, s.f1_hz, s.level,
                     s.kind == Excitation::random ? fmt::format("_seed{}", s.seed) : "");
}

double default_fade_in_s(const ExcitationSpec& spec) {
  return 0.05 * spec.duration_s;
}

double default_fade_in_s(const ForceInput& measured) {
  if (measured.samples.size() == 0 || !(measured.sample_rate_hz > 0.0)) return 0.0;
  const bool starts_at_zero = measured.samples.row(0).cwiseAbs().maxCoeff() <=
                              1e-9 * measured.samples.cwiseAbs().maxCoeff();
  const double duration = static_cast<double>(measured.samples.rows()) / measured.sample_rate_hz;
  return starts_at_zero ? 0.0 : 0.05 * duration;
}

void add_noise(ForcedTest& test, double level, std::uint64_t force_seed) {
  if (level == 0.0) return;
  const std::uint64_t seed = force_seed + 1000003ULL;
  add_noise(test.record, level, seed);
  test.comments.push_back(
      fmt::format("noise: white Gaussian, RMS {} of each channel's RMS, on every channel (seed {})",
                  level, seed));
}

} // namespace jointid::identify
