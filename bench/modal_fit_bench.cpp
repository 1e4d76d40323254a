// The modal fit of a 4-channel low-level record (plain main): a ground-vibration-test-like
// periodic multisine record, force and three accelerations, 400 Hz, 8192 samples a period, 9
// periods (73 728 samples), 2–15 Hz, three modes, 1 % noise. Times the FRF estimate (period by
// period, and Welch's method) and the fit (LSCF diagram to order 40, selection, LSFD), median
// of 5 runs each; with a file name, also writes the record (CSV, `# period_s`) for timing
// `jointid modal-fit` on it. See docs/benchmarks.md.
//   bench_modal_fit [record.csv]
#include "fem/fft.hpp"
#include "frf/receptance.hpp"
#include "identify/measured_frfs.hpp"
#include "identify/modal_fit.hpp"
#include "io/record_csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

using namespace jointid;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;
constexpr double fs = 400.0;
constexpr int period = 8192, periods = 9;

frf::ModalModel structure() {
  frf::ModalModel m;
  m.dofs = {{1, fem::Dof::uy}, {2, fem::Dof::uy}, {3, fem::Dof::uy}};
  m.frequencies_hz = Eigen::Vector3d(3.1, 7.3, 11.8);
  m.damping = Eigen::Vector3d(0.015, 0.02, 0.012);
  m.shapes.resize(3, 3);
  m.shapes << 0.02, 0.035, 0.045, //
      -0.03, -0.01, 0.025,        //
      0.04, -0.03, 0.02;
  return m;
}

identify::Record record(const frf::ModalModel& model) {
  const frf::ModalSynthesis s(model, {0, 1, 2});
  const int bins = period / 2 + 1;
  Eigen::MatrixXcd spectra = Eigen::MatrixXcd::Zero(bins, 4); // f, a1, a2, a3
  int lines = 0;
  for (int k = 1; k < bins; ++k) {
    const double f = k * fs / period;
    if (f < 2.0 || f > 15.0) continue;
    ++lines;
  }
  int n = 0;
  const std::vector<int> rows{0, 1, 2}, drive{0};
  for (int k = 1; k < bins; ++k) {
    const double f = k * fs / period;
    if (f < 2.0 || f > 15.0) continue;
    const std::complex<double> F =
        std::polar(0.5 * period, -std::numbers::pi * n * (n + 1) / lines); // Schroeder
    ++n;
    const double w = two_pi * f;
    spectra(k, 0) = F;
    const Eigen::MatrixXcd h = s.receptance(w, rows, drive);
    for (int c = 0; c < 3; ++c)
      spectra(k, c + 1) = -w * w * h(c, 0) * F;
  }
  fem::RealFft fft(period);
  identify::Record r;
  r.source = "gvt_multisine.csv";
  const Eigen::Index N = static_cast<Eigen::Index>(period) * periods;
  r.t = Eigen::VectorXd::LinSpaced(N, 0.0, static_cast<double>(N - 1) / fs);
  std::mt19937_64 random(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  const char* names[] = {"f@1:uy", "a@1:uy", "a@2:uy", "a@3:uy"};
  for (int c = 0; c < 4; ++c) {
    const Eigen::VectorXd one = fft.inverse(spectra.col(c)) / period;
    const double rms = std::sqrt(one.squaredNorm() / period);
    identify::Channel ch = identify::parse_channel_name(names[c]);
    ch.samples.resize(N);
    for (Eigen::Index i = 0; i < N; ++i)
      ch.samples(i) = one(i % period) + 0.01 * rms * normal(random);
    r.channels.push_back(std::move(ch));
  }
  r.period_s = period / fs;
  return r;
}

// Median wall time of `runs` calls, ms.
double median_ms(int runs, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

} // namespace

int main(int argc, char** argv) {
  const frf::ModalModel model = structure();
  const identify::Record r = record(model);
  if (argc > 1) {
    io::write_record(argv[1], r,
                     {"bench_modal_fit: 3 modes (3.1, 7.3, 11.8 Hz), multisine "
                      "2-15 Hz, 1 % noise"});
    fmt::print("wrote {}\n", argv[1]);
  }
  identify::FrfEstimateOptions periodic{.f0_hz = 2.0, .f1_hz = 15.0};
  identify::FrfEstimateOptions welch = periodic;
  welch.method = identify::SpectraMethod::welch;
  identify::MeasuredFrfs by_periods, by_welch;
  identify::ModalFit fit, fit3;
  const double t_periods =
      median_ms(5, [&] { by_periods = identify::frfs_from_records({r}, periodic); });
  const double t_welch = median_ms(5, [&] { by_welch = identify::frfs_from_records({r}, welch); });
  const double t_fit = median_ms(5, [&] { fit = identify::modal_fit(by_periods); });
  const double t_fit3 = median_ms(5, [&] { fit3 = identify::modal_fit(by_periods, {.modes = 3}); });
  fmt::print("record: 4 channels x {} samples at {} Hz, period {} samples x {}\n", r.t.size(), fs,
             period, periods);
  fmt::print("FRFs period by period ({} lines, {} blocks): {:.1f} ms\n", by_periods.num_lines(),
             by_periods.blocks[0], t_periods);
  fmt::print("FRFs by Welch (segment {}, {} lines, {} blocks): {:.1f} ms\n", by_welch.block_samples,
             by_welch.num_lines(), by_welch.blocks[0], t_welch);
  fmt::print("modal fit, automatic (orders to {}): {:.1f} ms\n", fit.max_order, t_fit);
  fmt::print("modal fit, --modes 3 (orders to {}): {:.1f} ms\n", fit3.max_order, t_fit3);
  for (std::size_t k = 0; k < fit.modes.size(); ++k)
    fmt::print("  mode {}: {:.5f} Hz (true {:.5f}), damping {:.5f} (true {:.5f})\n", k + 1,
               fit.modes[k].frequency_hz,
               k < 3 ? model.frequencies_hz(static_cast<Eigen::Index>(k)) : 0.0,
               fit.modes[k].damping, k < 3 ? model.damping(static_cast<Eigen::Index>(k)) : 0.0);
  return 0;
}
