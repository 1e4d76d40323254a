// Periodic broadband candidates of the experiment design (identify/design.hpp,
// predict_periodic_candidates): each multisine integrated in time at the prior values, measured
// with the noise expected as identify measures a periodic record, and weighed by the
// information of its lines.
#include "fem/parallel.hpp"
#include "identify/design.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/parametric.hpp"
#include "identify/random_tests.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace jointid::identify {

namespace {

void check_plan(const PeriodicPlan& p, std::size_t i) {
  const auto refuse = [&](const std::string& what) {
    return std::invalid_argument(fmt::format("design: periodic candidate {}: {}", i + 1, what));
  };
  if (!(p.f0_hz >= 0.0 && p.f1_hz > p.f0_hz && std::isfinite(p.f1_hz)))
    throw refuse(fmt::format("expected a band 0 <= f0 < f1, got {} to {} Hz", p.f0_hz, p.f1_hz));
  if (!(p.rms > 0.0 && std::isfinite(p.rms)))
    throw refuse(fmt::format("expected an RMS force > 0, got {}", p.rms));
  if (!(p.period_s > 0.0 && std::isfinite(p.period_s)))
    throw refuse(fmt::format("expected a period > 0 s, got {}", p.period_s));
  if (!(p.sample_rate_hz > 2.0 * p.f1_hz && std::isfinite(p.sample_rate_hz)))
    throw refuse(fmt::format("expected a sample rate above twice the band's top ({} Hz), got {}",
                             2.0 * p.f1_hz, p.sample_rate_hz));
  const double n = p.period_s * p.sample_rate_hz;
  if (std::abs(n - std::round(n)) > 1e-6 * n)
    throw refuse(fmt::format("the period ({} s) must hold a whole number of samples at {} Hz "
                             "(it holds {})",
                             p.period_s, p.sample_rate_hz, n));
  if (p.f1_hz * p.period_s < 1.0)
    throw refuse(fmt::format("the band {} to {} Hz holds no line of the period's spacing "
                             "({} Hz)",
                             p.f0_hz, p.f1_hz, 1.0 / p.period_s));
}

} // namespace

double default_periodic_sample_rate(double f1_hz, int harmonics) {
  double rate = 1.0;
  while (rate < std::max(32.0 * f1_hz, 8.0 * (harmonics + 1) * f1_hz))
    rate *= 2.0;
  return rate;
}

std::vector<CandidateTest>
predict_periodic_candidates(const frf::Substructure& sub, const std::vector<joints::Joint>& joints,
                            const fem::NodeDof& force_at, const std::vector<PeriodicPlan>& plans,
                            const DesignOptions& o, int transient_periods) {
  if (o.harmonics.empty()) throw std::invalid_argument("design: no harmonics asked");
  if (!(o.noise > 0.0 && o.noise < 1.0))
    throw std::invalid_argument(
        fmt::format("design: noise: expected a fraction between 0 and 1, got {}", o.noise));
  if (o.periods < 2)
    throw std::invalid_argument(
        fmt::format("design: periods: expected at least 2 (the noise of a periodic test's "
                    "lines is their scatter over its periods), got {}",
                    o.periods));
  if (transient_periods < 0)
    throw std::invalid_argument("design: transient periods: expected 0 or more");
  if (plans.empty()) throw std::invalid_argument("design: no candidate tests");
  if (design_unknowns(joints).empty())
    throw std::invalid_argument("design: every joint term is fixed; nothing to identify");
  for (std::size_t i = 0; i < plans.size(); ++i)
    check_plan(plans[i], i);
  const int K = *std::max_element(o.harmonics.begin(), o.harmonics.end());

  // The receptance the fit will use, to the highest line its equations may take.
  const fem::DofMap& dofs = sub.dofs();
  std::vector<int> rows = joint_dof_set(joints, dofs);
  const int fe = dofs.equation(force_at);
  if (std::find(rows.begin(), rows.end(), fe) == rows.end()) rows.push_back(fe);
  double f_max = 0.0;
  for (const auto& p : plans)
    f_max = std::max(f_max, std::min(p.f1_hz * std::max(K, 1), 0.5 * p.sample_rate_hz));
  const frf::ModalSynthesis synthesis = sub.synthesis(rows, frf::synthesis_band_hz(f_max, 1));
  const ReceptanceFn H = [&synthesis](double omega, std::span<const int> r,
                                      std::span<const int> c) {
    return synthesis.receptance(omega, r, c);
  };

  std::mutex progress_lock;
  std::size_t done = 0;
  std::vector<std::function<CandidateTest()>> jobs;
  for (std::size_t i = 0; i < plans.size(); ++i)
    jobs.push_back([&, i]() -> CandidateTest {
      const PeriodicPlan& p = plans[i];
      CandidateTest c;
      c.periodic = p;
      c.plan = {1.0 / p.period_s, p.rms};
      const auto finish = [&](CandidateTest&& out) {
        if (o.progress) {
          const std::lock_guard<std::mutex> lock(progress_lock);
          o.progress(static_cast<double>(++done) / static_cast<double>(plans.size()));
        }
        return std::move(out);
      };
      if (!synthesis.status().ok()) {
        c.reason = synthesis.status().reason;
        return finish(std::move(c));
      }
      // 1. The multisine integrated in time, its transient cut off, the noise added.
      ExcitationSpec spec{Excitation::multisine,
                          p.f0_hz,
                          p.f1_hz,
                          p.rms,
                          1,
                          (transient_periods + o.periods) * p.period_s,
                          p.sample_rate_hz,
                          p.period_s};
      ForceInput force = generated_force(spec, force_at);
      ForcedOptions fo;
      fo.quantities = o.quantities;
      fo.fade_in_s = transient_periods > 0 ? p.period_s : 0.0;
      ForcedTest run = simulate_forced(sub, joints, force, fo);
      if (!run.status.ok()) {
        c.reason = run.status.reason;
        return finish(std::move(c));
      }
      Record& record = run.record;
      const auto cut = static_cast<Eigen::Index>(
          std::llround(transient_periods * p.period_s * p.sample_rate_hz));
      const Eigen::Index keep = record.t.size() - cut;
      record.t = Eigen::VectorXd(record.t.tail(keep));
      for (Channel& ch : record.channels)
        ch.samples = Eigen::VectorXd(ch.samples.tail(keep));
      record.period_s = p.period_s;
      add_noise(record, o.noise, 7919ULL * (i + 1));
      // 2. Measured as identify measures it, and weighed.
      MeasureOptions mo;
      mo.harmonics = std::max(K, 1);
      mo.band_from_hz = p.f0_hz;
      mo.band_to_hz = p.f1_hz;
      Measurement m;
      try {
        m = measure(SineTest(record), mo);
      } catch (const std::invalid_argument& e) {
        c.reason = e.what();
        return finish(std::move(c));
      }
      if (!m.left_out.empty()) {
        c.reason = m.left_out;
        return finish(std::move(c));
      }
      for (const joints::Joint& j : joints)
        c.joint_amplitude.push_back(joint_equivalent_sine(m, j).amplitude);
      std::vector<std::string> warnings;
      const TestSpectrum ts = spectrum(m, dofs, joints, warnings);
      TestInformation info = information(H, dofs, joints, ts, o.harmonics);
      c.information = std::move(info.information);
      // Its score holds this record's noise (about one standard deviation of the estimates), not
      // only the basis functions' miss: the bias is not predicted for periodic candidates (NaN).
      c.score =
          Eigen::VectorXd::Constant(info.score.size(), std::numeric_limits<double>::quiet_NaN());
      c.misfit = info.misfit;
      c.usable = c.information.allFinite();
      // A noisy record's equations miss by about 1 noise standard deviation at the true values
      // (their residual is the noise; its RMS over `rows` equations scatters by 1/√(2 rows)),
      // and the basis functions' miss adds to it in quadrature.
      const double limit =
          std::hypot(1.0, o.max_misfit) + 3.0 / std::sqrt(2.0 * std::max(1, info.rows));
      if (!c.usable) {
        c.reason = "its information is not finite";
      } else if (c.misfit > limit) {
        c.usable = false;
        c.reason = fmt::format(
            "at the prior values its equations miss by {:.3g} noise standard deviations (limit "
            "{:.3g}: the noise itself, its scatter and --max-misfit): the basis functions do not "
            "describe the joints' forces here{}",
            c.misfit, limit, warnings.empty() ? "" : " (" + warnings.front() + ")");
      }
      return finish(std::move(c));
    });
  return fem::parallel_map(jobs);
}

} // namespace jointid::identify
