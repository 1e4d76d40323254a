// FRF sweeps of the substructure: a single-DOF oscillator against its closed form, a cantilever
// against the direct solve, and the checks of the arguments.
#include "frf/sweep.hpp"

#include "support/beam_models.hpp"
#include "support/failing_substructure.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <vector>

using namespace jointid;
using fem::Dof;

namespace {

using jointid::test::two_pi;

TEST(FrfSweep, OscillatorReceptanceMobilityAndAccelerance) {
  // m ẍ + c ẋ + k x = F e^{iωt} with c = α m (Rayleigh): H = 1 / (k − ω² m + iω c).
  const double m = 2.0, k = 8.0e4, alpha = 3.0;
  fem::Model model = test::oscillator(m, k);
  model.damping.kind = fem::Damping::Kind::rayleigh;
  model.damping.alpha = alpha;
  const frf::Substructure sub(model);
  const int e = sub.dofs().equation({1, Dof::ux});
  const std::vector<double> freq{0.0, 5.0, 31.830988618379067, 100.0};
  for (const frf::FrfKind kind :
       {frf::FrfKind::receptance, frf::FrfKind::mobility, frf::FrfKind::accelerance}) {
    const frf::FrfSweep s = frf::frf_sweep(sub, e, {e}, freq, kind);
    ASSERT_EQ(s.values.rows(), 4);
    ASSERT_EQ(s.values.cols(), 1);
    for (std::size_t i = 0; i < freq.size(); ++i) {
      const double w = two_pi * freq[i];
      const std::complex<double> H = 1.0 / std::complex<double>(k - w * w * m, w * alpha * m);
      const std::complex<double> expected = kind == frf::FrfKind::receptance ? H
                                            : kind == frf::FrfKind::mobility
                                                ? std::complex<double>(0.0, w) * H
                                                : -w * w * H;
      const std::complex<double> got = s.values(static_cast<Eigen::Index>(i), 0);
      EXPECT_LE(std::abs(got - expected), 1e-12 * std::abs(H) * std::max(1.0, w * w))
          << frf::frf_kind_name(kind) << " at " << freq[i] << " Hz";
    }
  }
  EXPECT_EQ(frf::parse_frf_kind("mobility"), frf::FrfKind::mobility);
  EXPECT_THROW(frf::parse_frf_kind("inertance"), std::invalid_argument);
}

TEST(FrfSweep, CantileverEqualsTheDirectSolve) {
  fem::Model model = test::cantilever(10, {});
  model.damping.kind = fem::Damping::Kind::modal;
  model.damping.modal_ratio = 0.02;
  const frf::Substructure sub(model);
  const int tip = sub.dofs().equation({11, Dof::uy}), mid = sub.dofs().equation({6, Dof::uy}),
            slope = sub.dofs().equation({11, Dof::rz});
  const std::vector<double> freq{0.0, 2.0, 3.0, 18.0, 60.0};
  const frf::FrfSweep s = frf::frf_sweep(sub, tip, {mid, tip, slope}, freq);
  const fem::SparseMatrix C = sub.damping_matrix().value;
  const std::vector<int> rows{mid, tip, slope}, cols{tip};
  for (std::size_t i = 0; i < freq.size(); ++i) {
    const frf::CMatrix direct =
        frf::direct_receptance(*sub.system(), C, two_pi * freq[i], rows, cols).value;
    const Eigen::VectorXcd got = s.values.row(static_cast<Eigen::Index>(i)).transpose();
    EXPECT_LE((got - direct.col(0)).norm(), 1e-9 * direct.norm()) << freq[i] << " Hz";
  }
}

// The frequency lines of a sweep: evenly spaced from the first to the last, both exact.
TEST(FrfSweep, EvenlySpacedLinesEndExactly) {
  const std::vector<double> f = frf::evenly_spaced_hz(1.1, 5.3, 7);
  ASSERT_EQ(f.size(), 7u);
  EXPECT_EQ(f.front(), 1.1);
  EXPECT_EQ(f.back(), 5.3); // 1.1 + (5.3 - 1.1) * 6 / 6 rounds to 5.299999999999999
  for (std::size_t i = 0; i < f.size(); ++i)
    EXPECT_NEAR(f[i], 1.1 + 0.7 * static_cast<double>(i), 4e-15 * 5.3) << i;
  const std::vector<double> g = frf::evenly_spaced_hz(0.0, 100.0, 1001);
  EXPECT_EQ(g[500], 50.0);
  EXPECT_EQ(g.back(), 100.0);
  EXPECT_THROW(frf::evenly_spaced_hz(0.0, 10.0, 1), std::invalid_argument);
  EXPECT_THROW(frf::evenly_spaced_hz(0.0, std::nan(""), 10), std::invalid_argument);
}

TEST(FrfSweep, BadArgumentsAreRefused) {
  const frf::Substructure sub(test::cantilever(4, {}));
  const int tip = sub.dofs().equation({5, Dof::uy});
  EXPECT_THROW(frf::frf_sweep(sub, tip, {}, {1.0}), std::invalid_argument);
  EXPECT_THROW(frf::frf_sweep(sub, tip, {tip, tip}, {1.0}), std::invalid_argument);
  EXPECT_THROW(frf::frf_sweep(sub, tip, {tip}, {}), std::invalid_argument);
  EXPECT_THROW(frf::frf_sweep(sub, tip, {tip}, {-1.0}), std::invalid_argument);
  EXPECT_THROW(frf::frf_sweep(sub, tip, {tip}, {std::nan("")}), std::invalid_argument);
  EXPECT_THROW(frf::frf_sweep(sub, 999, {tip}, {1.0}), std::invalid_argument);
}

} // namespace

TEST(FrfSweep, AModalAnalysisThatFailsIsTheSweepStatus) {
  // tests/support/failing_substructure.hpp: its dense modal analysis fails.
  const frf::FrfSweep s = frf::frf_sweep(test::failing_substructure(), 0, {1, 2}, {1.0, 2.0});
  EXPECT_EQ(s.status.code, fem::Status::Code::numerical_issue);
  EXPECT_EQ(s.status.reason, "the modal analysis failed: " + test::failing_modes_reason);
  EXPECT_EQ(s.values.size(), 0);
}
