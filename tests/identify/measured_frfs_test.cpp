// FRFs from time records: periodic records averaged period by period give the exact FRF at
// their lines (responses built from the known FRF line by line), Welch's estimate is
// identify::h1_estimate's, velocity and acceleration become receptance; and the refusals.
#include "identify/measured_frfs.hpp"

#include "fem/excitation.hpp"
#include "fem/fft.hpp"
#include "frf/receptance.hpp"
#include "identify/spectra.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace jointid::identify {
namespace {

using cd = std::complex<double>;
using jointid::test::two_pi;
using test::error_of;
constexpr double fs = 256.0;

// Three DOFs (uy at nodes 1, 2, 3), modes at 10, 14 and 25 Hz.
frf::ModalModel three_modes() {
  frf::ModalModel m;
  m.dofs = {{1, fem::Dof::uy}, {2, fem::Dof::uy}, {3, fem::Dof::uy}};
  m.frequencies_hz = Eigen::Vector3d(10.0, 14.0, 25.0);
  m.damping = Eigen::Vector3d(0.02, 0.02, 0.02);
  m.shapes.resize(3, 3);
  m.shapes << 1.0, 0.5, -0.8, 0.7, -1.0, 0.4, 0.5, 0.9, 0.6;
  return m;
}

// H(f) from the force at DOF 1 to DOF `response` (0-based).
cd receptance(const frf::ModalSynthesis& s, int response, double f) {
  const std::vector<int> rows{response}, cols{0};
  return s.receptance(two_pi * f, rows, cols)(0, 0);
}

// A channel whose spectrum is `bins` (FFT bins of one period of `n` samples, x(t) = Re Σ X e^{iωt}
// with bin k holding n/2 X_k), repeated `periods` times.
Eigen::VectorXd periodic(const Eigen::VectorXcd& bins, int n, int periods) {
  fem::RealFft fft(n);
  const Eigen::VectorXd one = fft.inverse(bins) / n;
  Eigen::VectorXd out(static_cast<Eigen::Index>(n) * periods);
  for (int p = 0; p < periods; ++p)
    out.segment(static_cast<Eigen::Index>(p) * n, n) = one;
  return out;
}

// A periodic record: force f@1:uy with equal lines at every second bin from 2 to 40 Hz, and
// the steady-state responses x@1:uy, a@2:uy, v@3:uy computed line by line from the FRFs.
Record periodic_record(const frf::ModalSynthesis& s, int n, int periods) {
  const int bins = n / 2 + 1;
  Eigen::VectorXcd F = Eigen::VectorXcd::Zero(bins), X = F, A = F, V = F;
  for (int k = 1; k < bins; ++k) {
    const double f = k * fs / n;
    if (f < 2.0 || f > 40.0 || k % 2 != 0) continue;
    F(k) = std::polar(0.5 * n, -std::numbers::pi * k * k / 80.0); // Schroeder-like phases
    const double w = two_pi * f;
    X(k) = receptance(s, 0, f) * F(k);
    A(k) = -w * w * receptance(s, 1, f) * F(k);
    V(k) = cd(0.0, w) * receptance(s, 2, f) * F(k);
  }
  Record r;
  r.source = "periodic.csv";
  r.t = Eigen::VectorXd::LinSpaced(static_cast<Eigen::Index>(n) * periods, 0.0,
                                   (static_cast<double>(n) * periods - 1.0) / fs);
  r.channels = {{Quantity::force, {1, fem::Dof::uy}, periodic(F, n, periods)},
                {Quantity::displacement, {1, fem::Dof::uy}, periodic(X, n, periods)},
                {Quantity::acceleration, {2, fem::Dof::uy}, periodic(A, n, periods)},
                {Quantity::velocity, {3, fem::Dof::uy}, periodic(V, n, periods)}};
  r.period_s = n / fs;
  return r;
}

TEST(MeasuredFrfs, PeriodicRecordGivesTheExactReceptanceAtItsExcitedLines) {
  const frf::ModalModel model = three_modes();
  const frf::ModalSynthesis s(model, {0, 1, 2});
  const int n = 1024; // 4 s a period: lines 0.25 Hz apart
  Record r = periodic_record(s, n, 4);
  // Half a period of something else before the periods: a transient, left over at the start.
  const Eigen::Index extra = n / 2;
  Record longer = r;
  longer.t = Eigen::VectorXd::LinSpaced(r.t.size() + extra, 0.0,
                                        static_cast<double>(r.t.size() + extra - 1) / fs);
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    Eigen::VectorXd x(r.t.size() + extra);
    x << Eigen::VectorXd::Constant(extra, 3.0 * (c + 1)), r.channels[c].samples;
    longer.channels[c].samples = x;
  }
  const MeasuredFrfs d = frfs_from_records({longer}, {.f0_hz = 5.0, .f1_hz = 30.0});
  EXPECT_EQ(d.method, SpectraMethod::periods);
  EXPECT_EQ(d.block_samples, n);
  EXPECT_DOUBLE_EQ(d.resolution_hz, 0.25);
  EXPECT_EQ(d.drive_name, "f@1:uy");
  ASSERT_EQ(d.num_responses(), 3);
  EXPECT_EQ(d.response_names, (std::vector<std::string>{"x@1:uy", "a@2:uy", "v@3:uy"}));
  EXPECT_EQ(d.blocks, (std::vector<int>{4, 4, 4}));
  EXPECT_EQ(d.drive_column(), 0);
  // The excited lines only: 5, 5.5, … 30 Hz (51 lines); the 50 between them have no force.
  ASSERT_EQ(d.num_lines(), 51);
  EXPECT_DOUBLE_EQ(d.frequency_hz(0), 5.0);
  EXPECT_DOUBLE_EQ(d.frequency_hz(50), 30.0);
  ASSERT_FALSE(d.notes.empty());
  EXPECT_NE(d.notes.back().find("50 of the band's 101 lines left out"), std::string::npos)
      << d.notes.back();
  for (Eigen::Index j = 0; j < d.num_lines(); ++j)
    for (int c = 0; c < 3; ++c) {
      const cd h = receptance(s, c, d.frequency_hz(j));
      EXPECT_LT(std::abs(d.H(j, c) - h), 1e-9 * std::abs(h)) << d.frequency_hz(j) << " Hz, " << c;
      EXPECT_NEAR(d.coherence(j, c), 1.0, 1e-9);
    }

  // One period: no coherence (one block gives 1 whatever the noise).
  const MeasuredFrfs one =
      frfs_from_records({periodic_record(s, n, 1)}, {.f0_hz = 5.0, .f1_hz = 30.0});
  EXPECT_TRUE(std::isnan(one.coherence(0, 0)));
  // Without the period: Welch's method (automatic), with the period given: the periods.
  Record plain = r;
  plain.period_s.reset();
  EXPECT_EQ(frfs_from_records({plain}, {.f0_hz = 5.0, .f1_hz = 30.0}).method, SpectraMethod::welch);
  EXPECT_EQ(frfs_from_records({plain}, {.f0_hz = 5.0, .f1_hz = 30.0, .period_s = n / fs}).method,
            SpectraMethod::periods);
  // A period that is not a whole number of samples: Welch, with a note.
  const MeasuredFrfs fallback =
      frfs_from_records({plain}, {.f0_hz = 5.0, .f1_hz = 30.0, .period_s = 4.001});
  EXPECT_EQ(fallback.method, SpectraMethod::welch);
  EXPECT_NE(fallback.notes.front().find("not a whole number"), std::string::npos);
  EXPECT_NE(error_of([&] {
              frfs_from_records({plain},
                                {.f0_hz = 5.0, .f1_hz = 30.0, .method = SpectraMethod::periods});
            }).find("periodic.csv states no period"),
            std::string::npos);
}

TEST(MeasuredFrfs, RecordsOfARovingSensorAreAveragedPerResponse) {
  // Two periodic records, the sensors at 1 and 2 in the first (4 periods), 1 and 3 in the second
  // (3 periods): every response from the periods that measured it.
  const frf::ModalModel model = three_modes();
  const frf::ModalSynthesis s(model, {0, 1, 2});
  Record a = periodic_record(s, 512, 4), b = periodic_record(s, 512, 3);
  a.source = "a.csv";
  b.source = "b.csv";
  a.channels.pop_back();                    // v@3:uy
  b.channels.erase(b.channels.begin() + 2); // a@2:uy
  const MeasuredFrfs d = frfs_from_records({a, b}, {.f0_hz = 5.0, .f1_hz = 30.0});
  EXPECT_EQ(d.response_names, (std::vector<std::string>{"x@1:uy", "a@2:uy", "v@3:uy"}));
  EXPECT_EQ(d.blocks, (std::vector<int>{7, 4, 3}));
  for (Eigen::Index j = 0; j < d.num_lines(); ++j)
    for (int c = 0; c < 3; ++c) {
      const cd h = receptance(s, c, d.frequency_hz(j));
      EXPECT_LT(std::abs(d.H(j, c) - h), 1e-9 * std::abs(h));
    }
}

TEST(MeasuredFrfs, WelchIsH1OfSpectraWithTheResponseTurnedIntoReceptance) {
  // A random force and arbitrary responses: frfs_from_records' Welch estimate is
  // identify::h1_estimate's line by line, divided by iω for a velocity.
  const double duration = 32.0;
  const Eigen::VectorXd force = fem::band_limited_random({2.0, 60.0, 10.0, 3}, {duration, fs});
  const Eigen::VectorXd x =
      fem::band_limited_random({1.0, 70.0, 1e-3, 4}, {duration, fs}) + 0.3e-4 * force;
  const Eigen::VectorXd v =
      fem::band_limited_random({1.0, 70.0, 1e-2, 5}, {duration, fs}) + 2e-4 * force;
  Record r;
  r.source = "random.csv";
  r.t = Eigen::VectorXd::LinSpaced(force.size(), 0.0, static_cast<double>(force.size() - 1) / fs);
  r.channels = {{Quantity::force, {7, fem::Dof::uy}, force},
                {Quantity::displacement, {7, fem::Dof::uy}, x},
                {Quantity::velocity, {4, fem::Dof::uy}, v},
                {Quantity::acceleration, {7, fem::Dof::uy}, v}}; // not used: x is there
  const MeasuredFrfs d = frfs_from_records({r}, {.f0_hz = 3.0, .f1_hz = 50.0, .segment = 512});
  EXPECT_EQ(d.method, SpectraMethod::welch);
  EXPECT_EQ(d.response_names, (std::vector<std::string>{"x@7:uy", "v@4:uy"}));
  ASSERT_FALSE(d.notes.empty());
  EXPECT_EQ(d.notes.front(), "random.csv: a@7:uy is not used (x@7:uy at the same DOF is)");
  const FrfEstimate hx = h1_estimate(force, x, fs, {512}), hv = h1_estimate(force, v, fs, {512});
  EXPECT_EQ(d.blocks[0], hx.averages);
  ASSERT_GT(d.num_lines(), 90);
  for (Eigen::Index j = 0; j < d.num_lines(); ++j) {
    const auto k = static_cast<Eigen::Index>(std::lround(d.frequency_hz(j) / (fs / 512)));
    ASSERT_DOUBLE_EQ(hx.frequency_hz(k), d.frequency_hz(j));
    EXPECT_LT(std::abs(d.H(j, 0) - hx.H(k)), 1e-12 * std::abs(hx.H(k)));
    const cd iw(0.0, two_pi * d.frequency_hz(j));
    EXPECT_LT(std::abs(d.H(j, 1) - hv.H(k) / iw), 1e-12 * std::abs(hv.H(k) / iw));
    EXPECT_NEAR(d.coherence(j, 0), hx.coherence(k), 1e-12);
    EXPECT_NEAR(d.coherence(j, 1), hv.coherence(k), 1e-12);
  }
  // The automatic segment: the largest power of two giving at least 8 averages at 50 % overlap
  // (8192 samples: 1024 gives 15, 2048 gives 7).
  EXPECT_EQ(frfs_from_records({r}, {.f0_hz = 3.0, .f1_hz = 50.0}).block_samples, 1024);
}

TEST(MeasuredFrfs, RefusesRecordsItCannotUse) {
  const frf::ModalModel model = three_modes();
  const frf::ModalSynthesis s(model, {0, 1, 2});
  const Record good = periodic_record(s, 256, 2);
  const FrfEstimateOptions band{.f0_hz = 5.0, .f1_hz = 30.0};
  Record no_force = good;
  no_force.channels.erase(no_force.channels.begin());
  EXPECT_EQ(error_of([&] { frfs_from_records({no_force}, band); }),
            "periodic.csv: no force channel (expected f@<node>:<dof> at the driving point beside "
            "the responses; the channels are x@1:uy, a@2:uy, v@3:uy)");
  Record two_forces = good;
  two_forces.channels.push_back({Quantity::force, {3, fem::Dof::uy}, good.channels[0].samples});
  EXPECT_NE(error_of([&] {
              frfs_from_records({two_forces}, band);
            }).find("2 force channels (f@1:uy and f@3:uy): a modal fit takes one driving point"),
            std::string::npos);
  Record elsewhere = good;
  elsewhere.source = "b.csv";
  elsewhere.channels[0].at = {2, fem::Dof::uy};
  EXPECT_EQ(error_of([&] {
              frfs_from_records({good, elsewhere}, band);
            }),
            "b.csv is driven at f@2:uy but periodic.csv at f@1:uy: a modal fit takes one driving "
            "point (one reference)");
  Record only_force = good;
  only_force.channels.resize(1);
  EXPECT_NE(error_of([&] { frfs_from_records({only_force}, band); }).find("no response channel"),
            std::string::npos);
  EXPECT_EQ(error_of([&] { frfs_from_records({good}, {.f0_hz = 5.0, .f1_hz = 200.0}); }),
            "the band 5 to 200 Hz reaches above the records' Nyquist frequency, 128 Hz (sampled "
            "at 256 Hz): lower F1");
  Record faster = good;
  faster.source = "fast.csv";
  faster.t *= 0.5;
  EXPECT_NE(error_of([&] {
              frfs_from_records({good, faster}, band);
            }).find("fast.csv is sampled at 512 Hz but periodic.csv at 256 Hz"),
            std::string::npos);
  EXPECT_NE(error_of([&] { frfs_from_records({}, band); }).find("no records"), std::string::npos);
}

frf::MeasuredFunction function(fem::NodeDof response, fem::NodeDof drive, double f0, double f1,
                               int n, const std::string& source) {
  frf::MeasuredFunction f;
  f.response = response;
  f.drive = drive;
  f.source = source;
  for (int k = 0; k < n; ++k) {
    f.frequencies_hz.push_back(f0 + (f1 - f0) * k / (n - 1));
    f.receptance.emplace_back(1.0 / (1.0 + k), 0.1 * k);
  }
  return f;
}

TEST(MeasuredFrfs, MeasuredFunctionsFromOneDriveOnTheSameLines) {
  frf::MeasuredFrf m;
  m.dofs = {{7, fem::Dof::uy}, {4, fem::Dof::uy}};
  m.functions = {function({7, fem::Dof::uy}, {7, fem::Dof::uy}, 0.0, 100.0, 401, "a.uff"),
                 function({4, fem::Dof::uy}, {7, fem::Dof::uy}, 0.0, 100.0, 401, "b.uff")};
  const MeasuredFrfs d = frfs_from_measured(m, 10.0, 20.0);
  EXPECT_EQ(d.method, SpectraMethod::measured);
  EXPECT_EQ(d.drive_name, "7:uy");
  EXPECT_EQ(d.response_names, (std::vector<std::string>{"7:uy", "4:uy"}));
  ASSERT_EQ(d.num_lines(), 41); // 10, 10.25, … 20 Hz
  EXPECT_DOUBLE_EQ(d.frequency_hz(0), 10.0);
  EXPECT_EQ(d.H(0, 1), m.functions[1].receptance[40]);
  EXPECT_TRUE(std::isnan(d.coherence(3, 1)));
  // A band from 0 Hz leaves out the 0 Hz line.
  EXPECT_DOUBLE_EQ(frfs_from_measured(m, 0.0, 20.0).frequency_hz(0), 0.25);

  EXPECT_EQ(error_of([&] { frfs_from_measured(m, 10.0, 120.0); }),
            "the band 10 to 120 Hz reaches outside the measured FRFs (401 lines from 0 to 100 Hz): "
            "choose a band inside them");
  frf::MeasuredFrf other = m;
  other.functions[1].drive = {4, fem::Dof::uy};
  EXPECT_EQ(error_of([&] { frfs_from_measured(other, 10.0, 20.0); }),
            "b.uff is driven at 4:uy but a.uff at 7:uy: a modal fit takes one driving point (one "
            "reference)");
  other = m;
  other.functions[1] = function({4, fem::Dof::uy}, {7, fem::Dof::uy}, 0.0, 100.0, 201, "b.uff");
  EXPECT_NE(error_of([&] {
              frfs_from_measured(other, 10.0, 20.0);
            }).find("b.uff is measured at other frequency lines than a.uff"),
            std::string::npos);
}

} // namespace
} // namespace jointid::identify
