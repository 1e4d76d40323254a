#include "identify/sweep.hpp"

#include "fem/constants.hpp"
#include "identify/harmonics.hpp"

#include "fem/fft.hpp"
#include "identify/record_messages.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace jointid::identify {

namespace {

using Complex = std::complex<double>;

// The unwrapped phase and the amplitude of x's analytic signal x + i H(x).
void analytic(const Eigen::VectorXd& signal, Eigen::VectorXd& phase, Eigen::VectorXd& amplitude) {
  const auto n = static_cast<int>(signal.size());
  const Eigen::VectorXd x = signal.array() - signal.mean();
  fem::RealFft fft(n);
  Eigen::VectorXcd X = fft.forward(x);
  // H(x): −i sign(k) X_k; DC and Nyquist have none.
  X(0) = 0.0;
  if (n % 2 == 0) X(n / 2) = 0.0;
  for (Eigen::Index k = 1; k < X.size(); ++k)
    X(k) *= Complex(0.0, -1.0);
  const Eigen::VectorXd h = fft.inverse(X) / n;
  phase.resize(n);
  amplitude.resize(n);
  double previous = 0.0, unwrapped = 0.0;
  for (int i = 0; i < n; ++i) {
    const double wrapped = std::atan2(h(i), x(i));
    if (i == 0) {
      unwrapped = wrapped;
    } else {
      double step = wrapped - previous;
      step -= two_pi * std::round(step / two_pi);
      unwrapped += step;
    }
    previous = wrapped;
    phase(i) = unwrapped;
    amplitude(i) = std::hypot(x(i), h(i));
  }
}

// φ ≈ a + b τ + c τ² over samples [i, i + L) with τ = t − t_centre: (a, b, c).
Eigen::Vector3d phase_fit(const Eigen::VectorXd& t, const Eigen::VectorXd& phase, Eigen::Index i,
                          Eigen::Index L, double centre) {
  Eigen::MatrixXd D(L, 3);
  for (Eigen::Index j = 0; j < L; ++j) {
    const double tau = t(i + j) - centre;
    D(j, 0) = 1.0, D(j, 1) = tau, D(j, 2) = tau * tau;
  }
  return D.colPivHouseholderQr().solve(phase.segment(i, L));
}

} // namespace

std::vector<Measurement> reduce_sweep(const Record& r, const RecordClass& kind,
                                      const MeasureOptions& o) {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(r.source + ": " + what); };
  (void)kind;
  const int K = o.harmonics;
  if (K < 1) throw std::invalid_argument("measure: need at least harmonic 1");
  if (o.sweep_window_periods < 2)
    throw std::invalid_argument("measure: a sweep's windows need at least 2 periods");
  const Channel& drive = driving_force(r);
  const auto forces = r.all(Quantity::force);
  // Response DOFs in order of first appearance, each with its best channel (x, then v, then a).
  std::vector<fem::NodeDof> response_at;
  std::vector<const Channel*> best;
  for (const auto& c : r.channels) {
    if (c.quantity == Quantity::force) continue;
    const auto it = std::find(response_at.begin(), response_at.end(), c.at);
    if (it == response_at.end()) {
      response_at.push_back(c.at);
      best.push_back(&c);
    } else {
      const auto i = static_cast<std::size_t>(it - response_at.begin());
      if (static_cast<int>(c.quantity) < static_cast<int>(best[i]->quantity)) best[i] = &c;
    }
  }
  if (best.empty()) fail(no_response_channel(r));
  const auto n = r.t.size();
  const double dt = r.dt(), nyquist = 0.5 / dt;

  // 1. The force's phase.
  Eigen::VectorXd phase, amplitude;
  analytic(drive.samples, phase, amplitude);
  std::vector<double> sorted(amplitude.data(), amplitude.data() + n);
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median_amplitude = sorted[static_cast<std::size_t>(n / 2)];

  // Every channel the rows need: forces, the best responses, separately measured velocities.
  std::vector<const Channel*> fitted(forces.begin(), forces.end());
  std::vector<int> velocity_of(best.size(), -1);
  for (std::size_t j = 0; j < best.size(); ++j) {
    fitted.push_back(best[j]);
    if (best[j]->quantity == Quantity::displacement)
      if (const Channel* v = r.find(Quantity::velocity, best[j]->at)) {
        velocity_of[j] = static_cast<int>(fitted.size());
        fitted.push_back(v);
      }
  }
  Eigen::MatrixXd samples(n, static_cast<Eigen::Index>(fitted.size()));
  for (std::size_t c = 0; c < fitted.size(); ++c)
    samples.col(static_cast<Eigen::Index>(c)) = fitted[c]->samples;

  // 2. and 3. The windows and their harmonics.
  std::vector<Measurement> rows;
  std::vector<double> window_s;
  int skipped_above_nyquist = 0;
  Eigen::Index i = 0;
  while (i < n) {
    // The window's length from its frequency and rate, found from a first guess.
    Eigen::Index L = std::min<Eigen::Index>(n - i, std::max<Eigen::Index>(64, n / 200));
    double omega = 0.0, rate = 0.0;
    for (int pass = 0; pass < 3; ++pass) {
      const double centre = r.t(i) + 0.5 * static_cast<double>(L - 1) * dt;
      const Eigen::Vector3d c = phase_fit(r.t, phase, i, L, centre);
      omega = std::abs(c(1));
      rate = 2.0 * c(2) * (c(1) < 0.0 ? -1.0 : 1.0);
      if (!(omega > 0.0)) break;
      double length = o.sweep_window_periods * two_pi / omega;
      if (rate != 0.0) length = std::min(length, std::sqrt(1.2 / std::abs(rate)));
      length = std::max(length, 2.0 * two_pi / omega);
      L = std::min<Eigen::Index>(n - i, static_cast<Eigen::Index>(std::ceil(length / dt)));
    }
    const double f = omega / two_pi;
    if (!(omega > 0.0) || static_cast<double>(L) * dt * f < 2.0 - 1e-9) break; // the end
    const Eigen::Index start = i;
    i += L;
    const double window_amplitude = amplitude.segment(start, L).mean();
    if (window_amplitude < 0.1 * median_amplitude) continue;
    if (K * f >= nyquist) {
      ++skipped_above_nyquist;
      continue;
    }
    // The harmonics of the window's phase, and more of them for the noise and the derived
    // signals (within a quarter of the samples a period holds).
    const double per_period = 1.0 / (f * dt);
    const int dense = std::max(K, std::min(std::max(2 * K, 8), static_cast<int>(per_period / 4)));
    const double centre = r.t(start) + 0.5 * static_cast<double>(L - 1) * dt;
    const Eigen::Vector3d pc = phase_fit(r.t, phase, start, L, centre);
    Eigen::MatrixXd D(L, 2 * dense + 1);
    for (Eigen::Index j = 0; j < L; ++j) {
      const double tau = r.t(start + j) - centre;
      const double phi = pc(0) + pc(1) * tau + pc(2) * tau * tau;
      D(j, 0) = 1.0;
      for (int k = 1; k <= dense; ++k) {
        D(j, 2 * k - 1) = std::cos(k * phi);
        D(j, 2 * k) = std::sin(k * phi);
      }
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(D);
    const Eigen::MatrixXd block = samples.middleRows(start, L);
    const Eigen::MatrixXd coef = qr.solve(block);
    const Eigen::MatrixXd residual = block - D * coef;
    const int dof = static_cast<int>(L) - (2 * dense + 1);
    auto harmonics = [&](Eigen::Index c) { // X_k = A_k − i B_k, relative to the phase φ
      Eigen::VectorXcd X(dense + 1);
      X(0) = coef(0, c);
      for (int k = 1; k <= dense; ++k)
        X(k) = Complex(coef(2 * k - 1, c), -coef(2 * k, c));
      return X;
    };
    auto variance = [&](Eigen::Index c) {
      return dof >= 20 ? residual.col(c).squaredNorm() / dof : nan;
    };

    Measurement m;
    m.kind = RecordKind::sweep;
    m.source = fmt::format("{} at {:.6g} Hz", r.source, f);
    m.frequency_hz = f;
    m.harmonics = K;
    m.sweep_rate_hz_per_s = rate / two_pi;
    m.response_at = response_at;
    const double w = omega, samples_in = static_cast<double>(L);
    const auto nf = static_cast<Eigen::Index>(forces.size());
    m.F.resize(K + 1, nf);
    m.F_variance.resize(K + 1, nf);
    for (Eigen::Index c = 0; c < nf; ++c) {
      m.force_at.push_back(forces[static_cast<std::size_t>(c)]->at);
      m.F.col(c) = harmonics(c).head(K + 1);
      const double var = variance(c);
      m.force_noise.push_back(std::sqrt(var));
      for (int k = 0; k <= K; ++k)
        m.F_variance(k, c) = (k == 0 ? 1.0 : 4.0) * var / samples_in;
    }
    // One period of the window's harmonics, finely sampled, for the basis functions: each
    // synthesised sample stands for L / M of the record's (its noise variance is σ² M / L).
    const int M = std::max(64, 8 * (dense + 1));
    m.t = Eigen::VectorXd::LinSpaced(M, 0.0, (M - 1.0) / (M * f));
    m.averaging = samples_in / M;
    m.derived_harmonics = dense;
    const auto nr = static_cast<Eigen::Index>(best.size());
    m.X.resize(K + 1, nr);
    m.X_variance.resize(K + 1, nr);
    m.x.resize(M, nr);
    m.v.resize(M, nr);
    for (Eigen::Index j = 0; j < nr; ++j) {
      const Channel& c = *best[static_cast<std::size_t>(j)];
      const Eigen::Index column = nf + j + [&] { // the velocity columns before it
        Eigen::Index before = 0;
        for (Eigen::Index jj = 0; jj < j; ++jj)
          before += velocity_of[static_cast<std::size_t>(jj)] >= 0 ? 1 : 0;
        return before;
      }();
      const int power = c.quantity == Quantity::displacement ? 0
                        : c.quantity == Quantity::velocity   ? 1
                                                             : 2;
      m.measured_as.push_back(c.quantity);
      m.has_mean.push_back(power == 0);
      const Eigen::VectorXcd Q = harmonics(column);
      const Eigen::VectorXcd Xd = power == 0 ? Q : differentiate(Q, w, -power);
      m.X.col(j) = Xd.head(K + 1);
      const double var = variance(column);
      m.channel_noise.push_back(std::sqrt(var));
      for (int k = 0; k <= K; ++k) {
        const double gain = k == 0 ? 1.0 : std::pow(k * w, -2.0 * power);
        m.X_variance(k, j) =
            (k == 0 ? (power == 0 ? var / samples_in : nan) : 4.0 * var / samples_in) * gain;
      }
      m.x.col(j) = synthesise(m.t, Xd, w);
      const int v_column = velocity_of[static_cast<std::size_t>(j)];
      if (v_column >= 0) {
        m.v.col(j) = synthesise(m.t, harmonics(v_column), w);
        m.velocity_noise.push_back(std::sqrt(variance(v_column)));
      } else {
        m.v.col(j) = synthesise(m.t, differentiate(Xd, w, 1), w);
        m.velocity_noise.push_back(nan);
      }
    }
    rows.push_back(std::move(m));
    window_s.push_back(samples_in * dt);
  }
  if (rows.empty())
    fail(skipped_above_nyquist > 0
             ? fmt::format("every window of the sweep has harmonic {} above the Nyquist frequency "
                           "({} Hz): sample faster, or ask fewer harmonics",
                           K, nyquist)
             : std::string("too short for a window of two periods of its frequency"));

  // 4. The sweep rate's bias per row, from the measured FRF's curvature over the rows.
  Eigen::Index big = 0;
  {
    double largest = -1.0;
    for (Eigen::Index j = 0; j < rows.front().X.cols(); ++j) {
      double sum = 0.0;
      for (const auto& row : rows)
        sum += std::abs(row.X(1, j));
      if (sum > largest) largest = sum, big = j;
    }
  }
  const auto count = static_cast<Eigen::Index>(rows.size());
  auto frf = [&](Eigen::Index q) {
    const Measurement& row = rows[static_cast<std::size_t>(q)];
    const Complex F = row.F.row(1).cwiseAbs().maxCoeff() > 0.0 ? row.F(1, 0) : Complex(1.0);
    return row.X(1, big) / F;
  };
  double worst = 0.0, worst_f = 0.0;
  for (Eigen::Index q = 0; q < count; ++q) {
    Measurement& row = rows[static_cast<std::size_t>(q)];
    const Eigen::Index lo = std::max<Eigen::Index>(0, std::min(q - 2, count - 5)),
                       hi = std::min(count, lo + 5);
    if (hi - lo < 3) continue;
    const double w0 = two_pi * row.frequency_hz;
    Eigen::MatrixXd A(hi - lo, 3);
    Eigen::VectorXcd h(hi - lo);
    for (Eigen::Index p = lo; p < hi; ++p) {
      const double dw = two_pi * rows[static_cast<std::size_t>(p)].frequency_hz - w0;
      A(p - lo, 0) = 1.0, A(p - lo, 1) = dw, A(p - lo, 2) = dw * dw;
      h(p - lo) = frf(p);
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    const Eigen::VectorXd re = qr.solve(Eigen::VectorXd(h.real())),
                          im = qr.solve(Eigen::VectorXd(h.imag()));
    const double curvature = 2.0 * std::hypot(re(2), im(2)); // |H''|
    const double H = std::abs(frf(q));
    if (!(H > 0.0)) continue;
    const double rate = two_pi * std::abs(row.sweep_rate_hz_per_s),
                 L = window_s[static_cast<std::size_t>(q)];
    row.sweep_bias = (0.5 * rate + rate * rate * L * L / 24.0) * curvature / H;
    if (row.sweep_bias > worst) worst = row.sweep_bias, worst_f = row.frequency_hz;
  }
  Measurement& first = rows.front();
  first.warnings.push_back(fmt::format(
      "{}: a sweep, reduced to {} stepped-sine rows of {:.4g} to {:.4g} Hz ({}); the sweep rate "
      "biases their response by up to {:.3g} % (at {:.4g} Hz, where it changes fastest with "
      "frequency; the bias grows with the rate: sweep slower there, or test in steps)",
      r.source, rows.size(), rows.front().frequency_hz, rows.back().frequency_hz, kind.evidence,
      100.0 * worst, worst_f));
  if (skipped_above_nyquist > 0)
    first.warnings.push_back(
        fmt::format("{}: {} windows left out: harmonic {} above the Nyquist frequency ({} Hz)",
                    r.source, skipped_above_nyquist, K, nyquist));
  for (std::size_t j = 0; j < best.size(); ++j) {
    if (best[j]->quantity != Quantity::displacement)
      first.warnings.push_back(
          r.source + ": no displacement channel x@" + fem::to_string(best[j]->at) +
          "; displacement derived from " +
          (best[j]->quantity == Quantity::velocity ? "velocity" : "acceleration") +
          " (its mean is unknown and taken as 0)");
    else if (velocity_of[j] < 0)
      first.warnings.push_back(r.source + ": no velocity channel v@" + fem::to_string(best[j]->at) +
                               "; velocity derived from displacement");
  }
  return rows;
}

} // namespace jointid::identify
