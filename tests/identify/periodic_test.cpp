// Periodic broadband tests: the steadiness of periods, the noise off the lines, the reduction to
// lines with their noise, and identification round trips from multisine virtual tests (time
// integration: an independent method, the identification never sees the joints' equations).
#include "identify/periodic.hpp"

#include "fem/excitation.hpp"
#include "identify/fit.hpp"
#include "identify/random_tests.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

using namespace jointid;
using namespace jointid::identify;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;
const fem::NodeDof tip{7, fem::Dof::uy};

joints::Joint model_one() {
  joints::Joint j{"tip",
                  7,
                  0,
                  fem::Dof::uy,
                  {joints::Term::k, joints::Term::c, joints::Term::c2, joints::Term::k3},
                  {4800.0, 20.0, 500.0, 1.6e8},
                  {},
                  {}};
  j.fixed.assign(4, false);
  return j;
}

const frf::Substructure& cantilever() {
  static const frf::Substructure s(test::paper_cantilever());
  return s;
}

// A multisine virtual test of the cantilever (force at the tip, 1–8 Hz, period 4 s, 256 Hz),
// from rest with a fade-in, by time integration in modal coordinates.
int g_substeps = 4;
double g_rate = 256.0;
Record multisine_test(const std::vector<joints::Joint>& joints, double rms, int periods,
                      double noise, std::uint64_t seed,
                      std::vector<Quantity> quantities = {Quantity::displacement,
                                                          Quantity::velocity}) {
  ExcitationSpec spec{Excitation::multisine, 1.0, 8.0, rms, seed, 4.0 * periods, g_rate, 4.0};
  ForceInput input = generated_force(spec, tip);
  ForcedOptions o;
  o.fade_in_s = 1.0;
  o.substeps = g_substeps;
  o.quantities = std::move(quantities);
  ForcedTest test = simulate_forced(cantilever(), joints, input, o);
  add_noise(test, noise, seed);
  test.record.source = "multisine_" + std::to_string(static_cast<int>(rms)) + "N.csv";
  return std::move(test.record);
}

} // namespace

TEST(PeriodicExperiment, Bias) {
  g_substeps = 8;
  const std::vector<joints::Joint> truth{model_one()};
  for (double noise : {0.003, 0.01}) {
  const bool propagate = true;
    std::vector<double> c, c2, k3, k;
    for (int rep = 0; rep < 4; ++rep) {
      std::vector<SineTest> tests;
      for (double rms : {10.0, 40.0, 80.0}) {
        Record r = multisine_test(truth, rms, 20, noise, 100 * rep + static_cast<int>(rms));
        const int skip = 10 * 1024;
        r.t = Eigen::VectorXd(r.t.tail(r.t.size() - skip));
        for (auto& c : r.channels)
          c.samples = Eigen::VectorXd(c.samples.tail(c.samples.size() - skip));
        tests.push_back(r);
      }
      FitOptions fo;
      fo.propagate_noise = propagate;
      MeasureOptions mo = measure_options(fo);
      mo.band_from_hz = 0.9;
      const auto m = measure(tests, mo);
      if (rep == 0) for (int k : m[2].lines) std::printf("%g ", k * m[2].frequency_hz);
      const FitResult r = fit(cantilever(), truth, m, fo);
      k.push_back(r.joints[0].terms[0].value / 4800 - 1);
      c.push_back(r.joints[0].terms[1].value / 20 - 1);
      c2.push_back(r.joints[0].terms[2].value / 500 - 1);
      k3.push_back(r.joints[0].terms[3].value / 1.6e8 - 1);
      std::printf("%d prop %d: k %.5f c %.5f (std %.5f) c2 %.5f (std %.5f) k3 %.5f chi2 %.3f\n", rep,
                  propagate, k.back(), c.back(), r.joints[0].terms[1].std / 20, c2.back(),
                  r.joints[0].terms[2].std / 500, k3.back(), r.chi2_per_dof);
    }
  }
}

TEST(PeriodicExperiment, Residual) {
  for (auto [sub_steps, rate] : {std::pair{4, 256.0}, std::pair{16, 256.0}, std::pair{4, 1024.0}}) {
  g_substeps = sub_steps; g_rate = rate;
  std::printf("substeps %d rate %g\n", sub_steps, rate);
  std::vector<joints::Joint> truth{model_one()};
  Record r = multisine_test(truth, 80.0, 20, 0.0, 1);
  const int skip = static_cast<int>(10 * 4 * rate);
  r.t = Eigen::VectorXd(r.t.tail(r.t.size() - skip));
  for (auto& c : r.channels)
    c.samples = Eigen::VectorXd(c.samples.tail(c.samples.size() - skip));
  MeasureOptions mo;
  mo.harmonics = 3;
  const Measurement m = measure(SineTest(r), mo);
  std::vector<std::string> w;
  const auto& sub = cantilever();
  const TestSpectrum ts = spectrum(m, sub.dofs(), truth, w);
  const int e = sub.dofs().equation(tip);
  std::vector<int> dofs{e};
  const auto syn = sub.synthesis(dofs, 100.0);
  for (int k : m.lines) {
    const double om = two_pi * k * m.frequency_hz;
    const std::complex<double> H = syn.receptance(om, dofs, dofs)(0, 0);
    std::complex<double> g = 0;
    for (int t = 0; t < 4; ++t) g += truth[0].values[t] * ts.G[0](k, t);
    const std::complex<double> res = ts.X2(k, 0) - H * (ts.F(k, 0) - g);
    if (k % 4 == 0 && k < 80) std::printf("%6.2f Hz |X| %.3e rel %.2e  phase %.2e\n", k * m.frequency_hz, std::abs(ts.X2(k, 0)),
                std::abs(res) / std::abs(ts.X2(k, 0)), std::arg(res / ts.X2(k, 0)));
  }
  }
}
