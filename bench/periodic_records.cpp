// Periodic broadband records at the size of a ground-vibration test (issue 30): a multisine of
// 2–15 Hz at 400 Hz, 8192 samples a period, 9 periods (73 728 samples), a force and three
// accelerations. Times (a) classifying and measuring one such record (identify::measure: the
// period found from the force, the periods checked, the lines and their noise) and (b) identify
// on ten of them (measure + fit), the paper's cantilever with a linear joint (k, c) at its tip.
// Plain main: single timed runs, the median of five; see docs/benchmarks.md.
//
// The records are made in the frequency domain — the cantilever's receptance with the joint
// added by the Sherman–Morrison formula, line by line, then an inverse FFT of one period — so
// that building them takes no time integration; 1 % white noise on every channel.
#include "fem/fft.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "support/cantilever.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

using namespace jointid;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;
constexpr int N = 8192, P = 9;
constexpr double rate = 400.0, k_joint = 4800.0, c_joint = 20.0;

// `eq`: the equations of 7:uy (the joint and the force), 5:uy and 3:uy.
identify::Record gvt_record(const frf::ModalSynthesis& H, const std::vector<int>& eq, double rms,
                            std::uint64_t seed) {
  const double df = rate / N;
  const int from = static_cast<int>(std::ceil(2.0 / df)), to = static_cast<int>(15.0 / df);
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> phase(0.0, two_pi);
  const int tip[1] = {eq[0]};
  Eigen::MatrixXcd spectrum = Eigen::MatrixXcd::Zero(N / 2 + 1, 4); // f, a@7, a@5, a@3
  const double amplitude = rms * std::sqrt(2.0 / (to - from + 1));
  for (int k = from; k <= to; ++k) {
    const double w = two_pi * k * df;
    const std::complex<double> F = std::polar(amplitude, phase(gen));
    const Eigen::MatrixXcd h = H.receptance(w, eq, tip); // 3 × 1: column of the tip
    const std::complex<double> z(k_joint, w * c_joint);  // the grounded joint at the tip
    const Eigen::VectorXcd x = h.col(0) * F / (1.0 + z * h(0, 0));
    spectrum(k, 0) = F;
    spectrum.row(k).tail(3) = (-w * w * x).transpose();
  }
  fem::RealFft fft(N);
  identify::Record r;
  r.source = "gvt_seed" + std::to_string(seed) + ".csv";
  r.t = Eigen::VectorXd::LinSpaced(N * P, 0.0, (N * P - 1) / rate);
  const fem::NodeDof at[4] = {
      {7, fem::Dof::uy}, {7, fem::Dof::uy}, {5, fem::Dof::uy}, {3, fem::Dof::uy}};
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int c = 0; c < 4; ++c) {
    // x(t) = Re Σ X_k e^{ikω₀t}: bin k holds X_k N / 2 for the unnormalised inverse.
    const Eigen::VectorXd one = fft.inverse(spectrum.col(c) * (0.5 * N)) / N;
    const double noise = 0.01 * std::sqrt(one.squaredNorm() / N);
    Eigen::VectorXd samples(N * P);
    for (int p = 0; p < P; ++p)
      samples.segment(p * N, N) = one;
    for (Eigen::Index i = 0; i < samples.size(); ++i)
      samples(i) += noise * normal(gen);
    r.channels.push_back(
        {c == 0 ? identify::Quantity::force : identify::Quantity::acceleration, at[c], samples});
  }
  return r;
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

} // namespace

int main() {
  const frf::Substructure sub(test::paper_cantilever());
  const fem::DofMap& dofs = sub.dofs();
  const std::vector<int> eq{dofs.equation({7, fem::Dof::uy}), dofs.equation({5, fem::Dof::uy}),
                            dofs.equation({3, fem::Dof::uy})};
  const frf::ModalSynthesis H = sub.synthesis(eq, 100.0);
  std::vector<identify::SineTest> tests;
  for (int i = 0; i < 10; ++i)
    tests.push_back(gvt_record(H, eq, 10.0 + 10.0 * i, static_cast<std::uint64_t>(i + 1)));

  joints::Joint joint{"tip",      7,  0, fem::Dof::uy, {joints::Term::k, joints::Term::c},
                      {1.0, 1.0}, {}, {}};
  joint.fixed.assign(2, false);
  const identify::FitOptions fo{.harmonics = {1}};
  const identify::MeasureOptions mo = identify::measure_options(fo);

  std::vector<double> one, ten;
  identify::FitResult result;
  for (int repeat = 0; repeat < 5; ++repeat) {
    auto start = Clock::now();
    const identify::Measurement m = identify::measure(tests.front(), mo);
    one.push_back(seconds_since(start));
    if (repeat == 0)
      std::printf("one record: %s, %zu lines (%zu excited), %d periods averaged\n",
                  identify::to_string(m.kind), m.lines.size(), m.excited_lines.size(),
                  m.periods_averaged);
    start = Clock::now();
    result = identify::fit(sub, {joint}, identify::measure(tests, mo), fo);
    ten.push_back(seconds_since(start));
  }
  std::printf("measure one 73728-sample 4-channel multisine record: median %.3f s (of 5: %.3f "
              "to %.3f)\n",
              median(one), *std::min_element(one.begin(), one.end()),
              *std::max_element(one.begin(), one.end()));
  std::printf("identify (measure + fit) on ten such records: median %.3f s (of 5: %.3f to %.3f)\n",
              median(ten), *std::min_element(ten.begin(), ten.end()),
              *std::max_element(ten.begin(), ten.end()));
  if (!result.status.ok()) {
    std::printf("identification failed: %s\n", result.status.reason.c_str());
    return 1;
  }
  std::printf("identified k = %.6g (truth %g, std %.3g), c = %.6g (truth %g, std %.3g); %d "
              "equations\n",
              result.joints[0].terms[0].value, k_joint, result.joints[0].terms[0].std,
              result.joints[0].terms[1].value, c_joint, result.joints[0].terms[1].std,
              result.equations);
  return 0;
}
