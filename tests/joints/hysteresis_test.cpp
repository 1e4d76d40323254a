// The parametric terms' forces: the Jenkins loop against its area 4 fs (a − fs/kt), the discrete
// Iwan against Segalman's closed-form dissipation in microslip, the steady loop's exact
// derivative against finite differences, and the clearance's force and slope.
#include "joints/hysteresis.hpp"

#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace jointid::joints;

namespace {

using jointid::test::pi;

// y = a sin θ at N samples θ_n = 2πn/N (N a multiple of 4: the peaks ±a are samples).
std::vector<double> sine(double a, int N) {
  std::vector<double> y(static_cast<std::size_t>(N));
  for (int n = 0; n < N; ++n)
    y[static_cast<std::size_t>(n)] = a * std::sin(2.0 * pi * n / N);
  return y;
}

// ∮ g dy over the closed polygon of samples (trapezoidal rule): the loop's area, J.
double loop_area(const std::vector<double>& y, const std::vector<double>& g) {
  double area = 0.0;
  const std::size_t N = y.size();
  for (std::size_t n = 0; n < N; ++n) {
    const std::size_t m = (n + 1) % N;
    area += 0.5 * (g[n] + g[m]) * (y[m] - y[n]);
  }
  return area;
}

} // namespace

TEST(Jenkins, LoopAreaIsFourTimesSlipForceTimesSlidingTravel) {
  // Under y = a sin θ a Jenkins element sticks while |y − x| < fs/kt and slides the rest of the
  // way: its loop is a parallelogram of height 2 fs and width 2 (a − fs/kt), area
  // 4 fs (a − fs/kt). The samples' trapezoidal rule is exact on the stick and slide stretches and
  // off by at most ½ kt Δy² at each of the two stick→slide corners (the chord across the kink
  // of one segment), Δy ≤ a 2π/N.
  const double kt = 1.0e4, fs = 3.0;
  const Sliders s = jenkins_sliders(kt, fs);
  ASSERT_EQ(s.size(), 1);
  LoopWork work;
  for (double a : {4e-4, 1e-3, 5e-2}) {
    const int N = 4096;
    const std::vector<double> y = sine(a, N);
    std::vector<double> g(y.size());
    ASSERT_TRUE(steady_loop(s, y, false, g, nullptr, work));
    const double expected = 4.0 * fs * (a - fs / kt);
    const double dy = a * 2.0 * pi / N;
    EXPECT_NEAR(loop_area(y, g), expected, kt * dy * dy) << a;
    // the force never exceeds the slip force, and reaches it while sliding
    double largest = 0.0;
    for (double v : g)
      largest = std::max(largest, std::abs(v));
    EXPECT_NEAR(largest, fs, 1e-12 * fs) << a;
  }
  // Below the slip stretch it never slides: a line of slope kt, no area.
  const std::vector<double> y = sine(0.5 * fs / kt, 64);
  std::vector<double> g(y.size());
  ASSERT_TRUE(steady_loop(s, y, false, g, nullptr, work));
  for (std::size_t n = 0; n < y.size(); ++n)
    EXPECT_NEAR(g[n], kt * y[n], 1e-12 * fs);
}

TEST(Jenkins, ReturnMapSticksUpToTheSlipForceAndSlidesBeyond) {
  // From rest, a deformation rising in steps: force kt y while kt y ≤ fs, then fs; back down,
  // it sticks again at once (the force falls with slope kt from fs).
  const double kt = 2.0e3, fs = 5.0;
  const Sliders s = jenkins_sliders(kt, fs);
  std::vector<double> x(1, 0.0);
  double tangent = 0.0;
  EXPECT_DOUBLE_EQ(slide(s, x, 1e-3, &tangent), 2.0); // stuck: kt y
  EXPECT_EQ(tangent, kt);
  EXPECT_DOUBLE_EQ(slide(s, x, 2.5e-3, &tangent), 5.0); // exactly at the slip stretch
  EXPECT_EQ(tangent, kt);
  EXPECT_DOUBLE_EQ(slide(s, x, 4e-3, &tangent), 5.0); // beyond: slides
  EXPECT_EQ(tangent, 0.0);
  EXPECT_DOUBLE_EQ(x[0], 4e-3 - fs / kt);
  EXPECT_DOUBLE_EQ(slide_trial(s, x, 3e-3, &tangent), 5.0 - kt * 1e-3); // back: stuck
  EXPECT_EQ(tangent, kt);
  EXPECT_DOUBLE_EQ(x[0], 4e-3 - fs / kt); // the trial does not move it
}

TEST(Iwan, QuadratureKeepsTheStiffnessAndTheMacroslipForce) {
  // K_T = Σ k_i and F_S = Σ k_i φ_i hold exactly (each interval's share of ∫ρ and ∫φρ), for any
  // number of sliders, with and without the Dirac.
  for (double beta : {0.0, 0.1, 2.0})
    for (double chi : {-0.9, -0.5, 0.0})
      for (int n : {2, 10, 100}) {
        const Sliders s = iwan_sliders(3.0, 1.0e4, chi, beta, n);
        EXPECT_EQ(s.size(), n);
        EXPECT_NEAR(s.stiffness_sum(), 1.0e4, 1e-12 * 1.0e4) << beta << " " << chi << " " << n;
        EXPECT_NEAR(s.slip_force_sum(), 3.0, 1e-12 * 3.0) << beta << " " << chi << " " << n;
        for (int i = 0; i < n; ++i)
          EXPECT_GT(s.stiffness[static_cast<std::size_t>(i)], 0.0);
      }
  // The density's own consistency: K_T = R φ_max^{χ+1}/(χ+1) + S, F_S = R φ_max^{χ+2}/(χ+2) + S
  // φ_max.
  const IwanDensity d = iwan_density(3.0, 1.0e4, -0.5, 0.1);
  EXPECT_NEAR(d.R * std::pow(d.phi_max, 0.5) / 0.5 + d.S, 1.0e4, 1e-9);
  EXPECT_NEAR(d.R * std::pow(d.phi_max, 1.5) / 1.5 + d.S * d.phi_max, 3.0, 1e-12);
  EXPECT_THROW(iwan_density(3.0, 1.0e4, -1.0, 0.1), std::invalid_argument);
  EXPECT_THROW(iwan_density(3.0, 1.0e4, 0.1, 0.1), std::invalid_argument);
  EXPECT_THROW(iwan_density(0.0, 1.0e4, -0.5, 0.1), std::invalid_argument);
  EXPECT_THROW(iwan_density(3.0, -1.0, -0.5, 0.1), std::invalid_argument);
  EXPECT_THROW(iwan_density(3.0, 1.0e4, -0.5, -0.1), std::invalid_argument);
}

TEST(Iwan, MicroslipDissipationFollowsSegalmansClosedForm) {
  // Segalman (2005): for a cycle ±a below φ_max, D = 4R a^{χ+3}/((χ+2)(χ+3)) — a power χ + 3 of
  // the amplitude. The 100-slider quadrature (geometric cuts φ_max r^{i−M}, r = 1e4^{1/(M−1)})
  // differs from it by at most Σ_{intervals below a} w_i Δφ_i² + 4 w φ Δφ of the interval holding
  // a (hysteresis.hpp), computed here from the density; the loop's area from the samples is off
  // by at most ½ k_i Δy² per element and corner (two a cycle).
  const double fs = 3.0, kt = 1.0e4, beta = 0.1;
  for (double chi : {-0.7, -0.5, -0.2}) {
    const IwanDensity d = iwan_density(fs, kt, chi, beta);
    const Sliders s = iwan_sliders(fs, kt, chi, beta, 100);
    const int M = 99; // the continuum's elements (one more is the Dirac's)
    const double r = std::pow(1e4, 1.0 / (M - 1));
    auto mass = [&](double u) { return d.R * std::pow(u, chi + 1.0) / (chi + 1.0); };
    std::vector<double> dissipation;
    // Amplitudes at cuts of the grid (no interval straddles a; 3.5e-3, 0.037 and 0.39 φ_max).
    std::vector<double> amplitudes;
    for (int back : {60, 35, 10})
      amplitudes.push_back(d.phi_max * std::pow(r, -back));
    for (double a : amplitudes) {
      const int N = 8192;
      const std::vector<double> y = sine(a, N);
      std::vector<double> g(y.size());
      LoopWork work;
      ASSERT_TRUE(steady_loop(s, y, false, g, nullptr, work));
      const double area = loop_area(y, g);
      const double dy = a * 2.0 * pi / N;
      const double sampling = s.stiffness_sum() * dy * dy;
      double quadrature = 0.0, below = 0.0;
      for (int i = 1; i <= M; ++i) {
        const double cut = d.phi_max * std::pow(r, i - M); // as the amplitudes: equal at a
        const double w = mass(cut) - mass(below), width = cut - below;
        if (cut <= a)
          quadrature += w * width * width;
        else if (below < a)
          quadrature += 4.0 * w * cut * width;
        below = cut;
      }
      const double exact = iwan_dissipation(d, a);
      EXPECT_NEAR(area, exact, quadrature + sampling) << "chi " << chi << " a " << a;
      // and the bound is meaningful: below 1 %
      EXPECT_LT(quadrature + sampling, 0.01 * exact) << "chi " << chi << " a " << a;
      dissipation.push_back(area);
    }
    // The slope on log axes is χ + 3 (microslip), not 2 (a linear damper) or 1 (sliding).
    for (std::size_t i = 1; i < dissipation.size(); ++i) {
      const double slope = std::log(dissipation[i] / dissipation[i - 1]) /
                           std::log(amplitudes[i] / amplitudes[i - 1]);
      EXPECT_NEAR(slope, chi + 3.0, 0.02) << chi;
    }
  }
}

TEST(Iwan, MacroslipForceIsTheSlipForce) {
  // Beyond φ_max every element slides: the force is ±F_S whatever the amplitude.
  const double fs = 3.0, kt = 1.0e4;
  const IwanDensity d = iwan_density(fs, kt, -0.5, 0.1);
  const Sliders s = iwan_sliders(fs, kt, -0.5, 0.1);
  const std::vector<double> y = sine(2.0 * d.phi_max, 400);
  std::vector<double> g(y.size());
  LoopWork work;
  ASSERT_TRUE(steady_loop(s, y, false, g, nullptr, work));
  EXPECT_NEAR(g[100], fs, 1e-12 * fs); // at +2 φ_max
  EXPECT_NEAR(g[300], -fs, 1e-12 * fs);
}

TEST(SteadyLoop, DerivativeMatchesFiniteDifferences) {
  // ∂g_n/∂y_m of the steady loop, exact for the samples, against central differences of the
  // loop itself. The deformation (two harmonics: a loop with inner reversals) keeps every
  // sample away from a stick–slide switch by more than the step, so the differences are exact
  // but for rounding (g is piecewise linear in the samples).
  const Sliders s = iwan_sliders(3.0, 1.0e4, -0.5, 0.1, 20);
  for (bool antisymmetric : {false, true}) {
    const int N = antisymmetric ? 24 : 48; // the period has 48 samples either way
    std::vector<double> y(static_cast<std::size_t>(N));
    for (int n = 0; n < N; ++n) {
      const double th = 2.0 * pi * n / 48.0;
      y[static_cast<std::size_t>(n)] =
          4e-4 * std::sin(th + 0.3) + 1.5e-4 * std::sin(3.0 * th + 1.1) + 2e-5 * std::cos(th);
    }
    if (!antisymmetric) // a mean (in the full form only): the loop is not symmetric
      for (double& v : y)
        v += 5e-5;
    std::vector<double> g(y.size());
    std::vector<LoopEntry> entries;
    LoopWork work;
    ASSERT_TRUE(steady_loop(s, y, antisymmetric, g, &entries, work));
    std::vector<double> J(static_cast<std::size_t>(N * N), 0.0);
    for (const LoopEntry& e : entries) {
      ASSERT_GE(e.m, 0);
      ASSERT_LT(e.m, N);
      J[static_cast<std::size_t>(e.n * N + e.m)] += e.value;
    }
    const double h = 1e-10;
    for (int m = 0; m < N; ++m) {
      std::vector<double> up = y, down = y, gu(y.size()), gd(y.size());
      up[static_cast<std::size_t>(m)] += h;
      down[static_cast<std::size_t>(m)] -= h;
      steady_loop(s, up, antisymmetric, gu, nullptr, work);
      steady_loop(s, down, antisymmetric, gd, nullptr, work);
      for (int n = 0; n < N; ++n) {
        const double fd =
            (gu[static_cast<std::size_t>(n)] - gd[static_cast<std::size_t>(n)]) / (2.0 * h);
        EXPECT_NEAR(J[static_cast<std::size_t>(n * N + m)], fd, 1e-4 * 1.0e4)
            << "n " << n << " m " << m << (antisymmetric ? " antisymmetric" : "");
      }
    }
  }
}

TEST(SteadyLoop, IsTheReturnMapOfEveryElementPassAfterPass) {
  // steady_loop follows runs of elements that share a state; the definition is the return map
  // x_i ← clamp(x_i, y − φ_i, y + φ_i) of every element at every sample, from rest, pass after
  // pass until the positions repeat. Both against each other on deformations with inner loops
  // (three harmonics, a mean), for a Jenkins element and an iwan appended out of order of φ,
  // in the full and the antisymmetric form: the forces, the closing and the derivative's
  // entries (summed per (n, m)) agree to rounding.
  Sliders s = jenkins_sliders(4.0e3, 0.5);
  s.append(iwan_sliders(3.0, 1.0e4, -0.5, 0.1, 40));
  s.append(jenkins_sliders(1.0e3, 4.0)); // φ = 4 mm: sticks at the smaller amplitudes
  for (bool antisymmetric : {false, true})
    for (double a : {5e-5, 4e-4, 3e-3}) {
      const int N = antisymmetric ? 32 : 64;
      std::vector<double> y(static_cast<std::size_t>(N));
      for (int n = 0; n < N; ++n) {
        const double th = 2.0 * pi * n / 64.0;
        y[static_cast<std::size_t>(n)] =
            a * (std::sin(th + 0.2) + 0.45 * std::sin(3.0 * th + 1.3) + 0.2 * std::cos(5.0 * th)) +
            (antisymmetric ? 0.0 : 0.3 * a);
      }
      // The definition, element by element.
      const int full = antisymmetric ? 2 * N : N;
      const std::size_t n_el = s.stiffness.size();
      std::vector<double> x(n_el, 0.0), x0;
      std::vector<int> anchor(n_el, -1);
      std::vector<double> g_ref(y.size());
      std::vector<double> J_ref(static_cast<std::size_t>(N * N), 0.0);
      bool closed_ref = false;
      for (int pass = 0; pass < 8 && !closed_ref; ++pass) {
        x0 = x;
        std::fill(J_ref.begin(), J_ref.end(), 0.0);
        for (int t = 0; t < full; ++t) {
          const double yt =
              t < N ? y[static_cast<std::size_t>(t)] : -y[static_cast<std::size_t>(t - N)];
          double f = 0.0;
          for (std::size_t i = 0; i < n_el; ++i) {
            const double phi = s.reach[i], k = s.stiffness[i], d = yt - x[i];
            const bool slides = d > phi || d < -phi;
            if (d > phi) x[i] = yt - phi;
            if (d < -phi) x[i] = yt + phi;
            if (slides) anchor[i] = t;
            f += k * (yt - x[i]);
            if (t >= N || slides) continue;
            J_ref[static_cast<std::size_t>(t * N + t)] += k;
            const int m = anchor[i];
            if (m >= 0)
              J_ref[static_cast<std::size_t>(t * N + (m < N ? m : m - N))] += m < N ? -k : k;
          }
          if (t < N) g_ref[static_cast<std::size_t>(t)] = f;
        }
        closed_ref = x == x0;
      }
      std::vector<double> g(y.size());
      std::vector<LoopEntry> entries;
      LoopWork work;
      EXPECT_EQ(steady_loop(s, y, antisymmetric, g, &entries, work), closed_ref);
      std::vector<double> J(static_cast<std::size_t>(N * N), 0.0);
      for (const LoopEntry& e : entries)
        J[static_cast<std::size_t>(e.n * N + e.m)] += e.value;
      const double K = s.stiffness_sum(), scale = K * 2.0 * a;
      for (int n = 0; n < N; ++n) {
        EXPECT_NEAR(g[static_cast<std::size_t>(n)], g_ref[static_cast<std::size_t>(n)],
                    1e-12 * scale)
            << "a " << a << " n " << n;
        for (int m = 0; m < N; ++m)
          EXPECT_NEAR(J[static_cast<std::size_t>(n * N + m)],
                      J_ref[static_cast<std::size_t>(n * N + m)], 1e-12 * K)
              << "a " << a << " n " << n << " m " << m;
      }
    }
}

TEST(Gap, NoForceInsideTheClearanceContactStiffnessBeyond) {
  const double delta = 1e-3, kg = 5e5;
  double slope = -1.0;
  EXPECT_EQ(gap_force(delta, kg, 0.0, &slope), 0.0);
  EXPECT_EQ(slope, 0.0);
  EXPECT_EQ(gap_force(delta, kg, 0.999e-3, &slope), 0.0);
  EXPECT_EQ(gap_force(delta, kg, -1e-3, &slope), 0.0);
  EXPECT_DOUBLE_EQ(gap_force(delta, kg, 3e-3, &slope), kg * 2e-3);
  EXPECT_EQ(slope, kg);
  EXPECT_DOUBLE_EQ(gap_force(delta, kg, -4e-3, &slope), -kg * 3e-3);
  EXPECT_EQ(slope, kg);
  // the slope is the derivative away from ±δ (central differences of a linear piece: exact
  // to rounding)
  for (double y : {-5e-3, -2e-3, -5e-4, 0.0, 7e-4, 1.5e-3, 4e-3}) {
    const double h = 1e-7;
    gap_force(delta, kg, y, &slope);
    const double fd = (gap_force(delta, kg, y + h) - gap_force(delta, kg, y - h)) / (2 * h);
    EXPECT_NEAR(slope, fd, 1e-6 * kg) << y;
  }
  // no clearance: a linear spring
  EXPECT_DOUBLE_EQ(gap_force(0.0, kg, 2e-3), kg * 2e-3);
}

TEST(SteadyLoop, AWorkReusedForOtherSlidersGivesTheirOwnLoop) {
  // LoopWork keeps the sliders' order and prefix sums from its last call: a call with other
  // sliders — the same number, only one value changed, or appended out of order — must give
  // exactly what a fresh work gives.
  const std::vector<double> y = sine(2e-3, 128);
  const std::vector<Sliders> sets{iwan_sliders(3.0, 1.0e4, -0.5, 0.1, 20),
                                  iwan_sliders(3.0, 1.0e4, -0.5, 0.2, 20),
                                  iwan_sliders(3.0, 1.1e4, -0.5, 0.2, 20),
                                  jenkins_sliders(1.0e4, 3.0),
                                  [] {
                                    Sliders s = jenkins_sliders(
                                        2.0e4, 40.0); // reach 2e-3, then smaller ones
                                    s.append(iwan_sliders(3.0, 1.0e4, -0.5, 0.1, 20));
                                    return s;
                                  }(),
                                  iwan_sliders(3.0, 1.0e4, -0.5, 0.1, 20)};
  LoopWork reused;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    std::vector<double> g(y.size()), fresh(y.size());
    std::vector<LoopEntry> d, fresh_d;
    ASSERT_TRUE(steady_loop(sets[i], y, false, g, &d, reused));
    LoopWork own;
    ASSERT_TRUE(steady_loop(sets[i], y, false, fresh, &fresh_d, own));
    EXPECT_EQ(g, fresh) << "set " << i;
    ASSERT_EQ(d.size(), fresh_d.size()) << "set " << i;
    for (std::size_t e = 0; e < d.size(); ++e)
      EXPECT_TRUE(d[e].n == fresh_d[e].n && d[e].m == fresh_d[e].m &&
                  d[e].value == fresh_d[e].value)
          << "set " << i << " entry " << e;
  }
}
