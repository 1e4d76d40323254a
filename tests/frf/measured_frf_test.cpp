// A substructure given by measured FRFs: the interpolation between lines against the analytic
// receptance it samples (and the error bound of a cubic), reciprocity, the band, and what
// MeasuredFrf::validate refuses.
#include "frf/measured_frf.hpp"

#include "frf/continuation.hpp"
#include "frf/harmonic_balance.hpp"

#include "frf/receptance.hpp"
#include "frf/substructure.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>

using namespace jointid;
using fem::Dof;
using test::error_of;

namespace {

using jointid::test::two_pi;

// Two modes (10 Hz, ζ 1 %; 31 Hz, ζ 2 %) at two DOFs, mass-normalised shapes: the analytic
// receptance the "measurement" samples.
frf::ModalModel two_modes() {
  frf::ModalModel m;
  m.dofs = {{3, Dof::uy}, {7, Dof::uy}};
  m.frequencies_hz = Eigen::Vector2d(10.0, 31.0);
  m.damping = Eigen::Vector2d(0.01, 0.02);
  m.shapes.resize(2, 2);
  m.shapes << 0.4, 0.9, -0.7, 0.5;
  return m;
}

// The FRFs of two_modes() from 7:uy to both DOFs (and 3:uy to itself) at lines f0, f0 + h, …
frf::MeasuredFrf sampled(double f0, double h, int lines, bool with_33 = true) {
  const frf::ModalModel m = two_modes();
  const frf::ModalSynthesis H(m, {0, 1});
  frf::MeasuredFrf out;
  out.dofs = m.dofs;
  const auto function = [&](int response, int drive) {
    frf::MeasuredFunction f;
    f.response = m.dofs[static_cast<std::size_t>(response)];
    f.drive = m.dofs[static_cast<std::size_t>(drive)];
    for (int i = 0; i < lines; ++i) {
      const double freq = f0 + h * i;
      const int r[] = {response}, c[] = {drive};
      f.frequencies_hz.push_back(freq);
      f.receptance.push_back(H.receptance(two_pi * freq, r, c)(0, 0));
    }
    f.source = "sampled";
    out.functions.push_back(f);
  };
  function(1, 1);
  function(0, 1);
  if (with_33) function(0, 0);
  return out;
}

} // namespace

TEST(MeasuredFrf, OnTheLinesTheMeasurementIsReturnedExactly) {
  const frf::MeasuredFrf data = sampled(0.0, 0.05, 1201);
  const frf::MeasuredReceptance H(data);
  for (int i : {0, 1, 200, 617, 1200}) {
    const int r[] = {1}, c[] = {1};
    const double f = data.functions[0].frequencies_hz[static_cast<std::size_t>(i)];
    EXPECT_EQ(H.receptance(two_pi * f, r, c)(0, 0),
              data.functions[0].receptance[static_cast<std::size_t>(i)])
        << f;
  }
}

TEST(MeasuredFrf, BetweenLinesTheCubicHoldsItsErrorBound) {
  // Near a resonance of half-power half-width b = ζ f_r, H(f) ≈ P b / (b + i (f − f_r)): its
  // fourth derivative is at most 24 P / b⁴, and the cubic through four equally spaced lines h
  // apart errs by at most (3/128) h⁴ max|H⁗| in the middle interval, (9/16)(h/b)⁴ of the peak.
  // Each halving of h divides the error by about 16. Measured between every pair of lines
  // around the 10 Hz mode (b = 0.1 Hz), against the analytic receptance.
  const frf::ModalModel m = two_modes();
  const frf::ModalSynthesis exact(m, {0, 1});
  const double b = 0.01 * 10.0;
  double previous = 0.0;
  for (const double h : {b / 2.0, b / 4.0, b / 8.0}) {
    const int lines = static_cast<int>(std::lround(40.0 / h)) + 1;
    const frf::MeasuredReceptance H(sampled(0.0, h, lines));
    const int r[] = {1}, c[] = {1};
    double peak = 0.0, worst = 0.0;
    for (double f = 9.0; f < 11.0; f += h / 7.3) {
      const std::complex<double> truth = exact.receptance(two_pi * f, r, c)(0, 0);
      peak = std::max(peak, std::abs(truth));
      worst = std::max(worst, std::abs(H.receptance(two_pi * f, r, c)(0, 0) - truth));
    }
    const double relative = worst / peak, bound = 9.0 / 16.0 * std::pow(h / b, 4);
    EXPECT_LE(relative, bound) << "h = " << h;
    EXPECT_GT(relative, bound / 100.0) << "h = " << h << ": the bound should be near, not vacuous";
    if (previous > 0.0) {
      EXPECT_GT(previous / relative, 8.0) << "h = " << h;
      EXPECT_LT(previous / relative, 32.0) << "h = " << h;
    }
    previous = relative;
    // The estimate from the data alone is of the same order as the true error.
    const int equations[] = {0, 1};
    const double estimate = H.interpolation_error(equations);
    EXPECT_GT(estimate, relative / 2.0) << "h = " << h;
    EXPECT_LT(estimate, relative * 2.0) << "h = " << h;
    std::printf("h = b/%.0f: error %.3g of the peak (bound %.3g), estimate %.3g\n", b / h, relative,
                bound, estimate);
  }
}

TEST(MeasuredFrf, ReciprocityFillsTheEntryNotMeasured) {
  // 7:uy → 3:uy was measured; 3:uy → 7:uy is the same by Maxwell–Betti.
  const frf::MeasuredReceptance H(sampled(0.0, 0.05, 801));
  const int a[] = {0}, b[] = {1};
  const double w = two_pi * 12.345;
  EXPECT_EQ(H.receptance(w, a, b)(0, 0), H.receptance(w, b, a)(0, 0));
  // Not measured either way: named.
  frf::MeasuredFrf only_77 = sampled(0.0, 0.05, 801, false);
  only_77.functions.erase(only_77.functions.begin() + 1); // drop 7:uy → 3:uy
  const frf::MeasuredReceptance G(only_77);
  EXPECT_EQ(error_of([&] { (void)G.receptance(w, a, b); }),
            "measured FRFs: neither the FRF from 7:uy to 3:uy nor the one from 3:uy to 7:uy was "
            "measured (drive to response), and the analysis needs it: add one of them");
}

TEST(MeasuredFrf, OutsideTheBandIsRefusedAndZeroHertzIsQuasiStatic) {
  const frf::MeasuredFrf data = sampled(1.0, 0.05, 781); // 1 … 40 Hz
  const frf::MeasuredReceptance H(data);
  const int r[] = {1}, c[] = {1};
  EXPECT_EQ(error_of([&] { (void)H.receptance(two_pi * 45.0, r, c); }),
            "FRF 7:uy/7:uy (sampled): 45 Hz is outside the measured band 1–40 Hz: measure a wider "
            "band, or ask for fewer harmonics or other test frequencies");
  EXPECT_NE(error_of([&] { (void)H.receptance(two_pi * 0.5, r, c); }).find("outside"),
            std::string::npos);
  // Harmonic 0 takes the first line: the quasi-static flexibility, here within 1 % of the
  // static one (the first line is a tenth of the first resonance).
  EXPECT_EQ(H.receptance(0.0, r, c)(0, 0), data.functions[0].receptance[0]);
  const frf::ModalSynthesis exact(two_modes(), {0, 1});
  EXPECT_NEAR(std::abs(H.receptance(0.0, r, c)(0, 0)), std::abs(exact.receptance(0.0, r, c)(0, 0)),
              0.01 * std::abs(exact.receptance(0.0, r, c)(0, 0)));
  const int equations[] = {0, 1};
  EXPECT_EQ(H.band_top_hz(equations), data.functions[0].frequencies_hz.back());
}

TEST(MeasuredFrf, ValidateNamesTheFunctionAndTheFault) {
  const auto fault = [](const std::function<void(frf::MeasuredFrf&)>& change) {
    frf::MeasuredFrf d = sampled(0.0, 0.5, 11);
    change(d);
    return error_of([&] { d.validate(); });
  };
  EXPECT_EQ(fault([](frf::MeasuredFrf&) {}), "(no error)");
  EXPECT_EQ(fault([](frf::MeasuredFrf& d) { d.functions[1].frequencies_hz[4] = 1.5; }),
            "FRF 3:uy/7:uy (sampled): line 5 (1.5 Hz) is not above line 4 (1.5 Hz): the "
            "frequencies must increase");
  EXPECT_EQ(fault([](frf::MeasuredFrf& d) {
              d.functions[0].receptance[2] = {NAN, 0.0};
            }),
            "FRF 7:uy/7:uy (sampled): the value at line 3 (1 Hz) is not finite");
  EXPECT_EQ(fault([](frf::MeasuredFrf& d) {
              d.functions[2].drive = {9, Dof::uy};
            }),
            "FRF 3:uy/9:uy (sampled): 9:uy is not among the substructure's DOFs");
  EXPECT_EQ(fault([](frf::MeasuredFrf& d) { d.functions.push_back(d.functions[0]); }),
            "FRF 7:uy/7:uy (sampled): the same response and drive as FRF 7:uy/7:uy (sampled)");
  EXPECT_EQ(fault([](frf::MeasuredFrf& d) {
              d.functions[0].frequencies_hz.resize(1);
              d.functions[0].receptance.resize(1);
            }),
            "FRF 7:uy/7:uy (sampled): 1 line(s); an FRF needs at least 2 to be interpolated");
}

TEST(MeasuredFrf, TheSubstructureHasNoModesToScaleOrIntegrate) {
  const frf::Substructure sub(sampled(0.0, 0.05, 801));
  ASSERT_NE(sub.measured(), nullptr);
  EXPECT_EQ(sub.dofs().num_equations(), 2);
  const frf::ModalSynthesis H = sub.synthesis({0, 1}, 40.0);
  EXPECT_EQ(H.num_modes(), 0);
  EXPECT_NE(H.measured(), nullptr);
  EXPECT_THROW((void)H.with_damping_scale(2.0), std::logic_error);
  EXPECT_EQ(error_of([&] { (void)sub.damping_matrix(); }),
            "time integration needs a finite element model; this substructure is given by "
            "measured FRFs ([frf])");
  // An equation the synthesis was not built for is refused, as from modes.
  const frf::ModalSynthesis only_7 = sub.synthesis({1}, 40.0);
  const int r[] = {0}, c[] = {1};
  EXPECT_THROW((void)only_7.receptance(two_pi * 5.0, r, c), std::invalid_argument);
}

TEST(MeasuredFrf, AResponseCurveSaysOnceThatItsStabilityCannotBeDetermined) {
  // Floquet's method needs modes, which measured FRFs do not have: a response curve of a
  // non-linear joint on them has no point with a verdict, and its notes say so once, with the
  // number of points tried and the first one's reason.
  const frf::Substructure sub(sampled(0.0, 0.05, 801));
  const frf::ModalSynthesis H = sub.synthesis({1}, 40.0);
  joints::Joint j{"tip", 7, 0, Dof::uy, {joints::Term::k, joints::Term::k3}, {1000.0, 1e7}, {}, {}};
  j.fixed.assign(2, true);
  frf::ContinuationOptions o;
  o.hb.harmonics = 3; // 3 × 12 Hz within the measured 40 Hz
  const frf::ResponseBranch b =
      frf::trace_response(H, {j}, sub.dofs(), {1}, frf::sine_force(1.0), {1}, 8.0, 12.0, o);
  ASSERT_TRUE(b.complete);
  ASSERT_FALSE(b.points.empty());
  std::size_t computed = 0;
  for (const auto& p : b.points) {
    EXPECT_FALSE(p.stable.has_value());
    computed += p.stability_checked ? 1 : 0;
  }
  EXPECT_GT(computed, 1u);
  std::size_t said = 0;
  for (const auto& n : b.notes)
    if (n.find("could not be determined") != std::string::npos) {
      ++said;
      EXPECT_NE(n.find("the stability of " + std::to_string(computed) + " of the " +
                       std::to_string(computed) + " points"),
                std::string::npos)
          << n;
      EXPECT_NE(n.find("measured FRFs have no modes"), std::string::npos) << n;
    }
  EXPECT_EQ(said, 1u);
}
