// A substructure given by its modes: what ModalModel::validate accepts and refuses.
#include "frf/modal_model.hpp"
#include "frf/receptance.hpp"

#include <gtest/gtest.h>

#include <complex>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

using namespace jointid;
using fem::Dof;

namespace {

// Two modes at three DOFs, with a symmetric residual flexibility.
frf::ModalModel valid() {
  frf::ModalModel m;
  m.dofs = {{1, Dof::uy}, {4, Dof::uy}, {4, Dof::rz}};
  m.frequencies_hz = Eigen::Vector2d(80.3, 212.0);
  m.damping = Eigen::Vector2d(0.0012, 0.002);
  m.shapes.resize(2, 3);
  m.shapes << 0.91, -0.40, 0.1, 0.35, 0.88, -0.2;
  m.residual_flexibility.resize(3, 3);
  m.residual_flexibility << 1e-7, 2e-8, 0.0, 2e-8, 2e-7, 1e-9, 0.0, 1e-9, 3e-7;
  return m;
}

// The message of validate() on valid() changed by `change`, or "" if it passes.
std::string error(const std::function<void(frf::ModalModel&)>& change) {
  frf::ModalModel m = valid();
  change(m);
  try {
    m.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();

} // namespace

TEST(ModalModel, AValidModelPasses) {
  EXPECT_NO_THROW(valid().validate());
  EXPECT_EQ(valid().num_modes(), 2);
  EXPECT_EQ(valid().num_dofs(), 3);
  // The residual is optional; a rigid-body mode (0 Hz) and an undamped mode are allowed.
  EXPECT_EQ(error([](auto& m) { m.residual_flexibility.resize(0, 0); }), "");
  EXPECT_EQ(error([](auto& m) { m.frequencies_hz(0) = 0.0; }), "");
  EXPECT_EQ(error([](auto& m) { m.damping(1) = 0.0; }), "");
  // Asymmetry below 1e-9 of the largest entry (3e-7 m/N) is rounding.
  EXPECT_EQ(error([](auto& m) { m.residual_flexibility(0, 1) += 2e-16; }), "");
  EXPECT_NE(error([](auto& m) { m.residual_flexibility(0, 1) += 4e-16; }), "");
}

TEST(ModalModel, EachProblemIsNamed) {
  struct Case {
    std::function<void(frf::ModalModel&)> change;
    std::string expected;
  };
  const Case cases[] = {
      {[](auto& m) { m.dofs.clear(); }, "no DOFs"},
      {[](auto& m) { m.frequencies_hz.resize(0); }, "no modes"},
      {[](auto& m) {
         m.dofs[2] = {1, Dof::uy};
       },
       "1:uy is listed twice"},
      {[](auto& m) { m.dofs[0].node = 0; }, "node ids must be > 0"},
      {[](auto& m) { m.damping.resize(1); }, "1 damping ratios for 2 frequencies"},
      {[](auto& m) { m.shapes.transposeInPlace(); }, "shapes are 3 × 2, expected 2 × 3"},
      {[](auto& m) { m.frequencies_hz(1) = -5.0; }, "mode 2: expected a frequency >= 0 Hz, got -5"},
      {[](auto& m) { m.frequencies_hz(0) = not_a_number; }, "mode 1: expected a frequency"},
      {[](auto& m) { m.damping(0) = -0.01; }, "mode 1: expected a damping ratio >= 0, got -0.01"},
      {[](auto& m) { m.shapes(1, 2) = not_a_number; }, "mode 2: the shape at 4:rz is not finite"},
      {[](auto& m) { m.residual_flexibility.resize(2, 2); }, "residual flexibility is 2 × 2"},
      {[](auto& m) { m.residual_flexibility(2, 2) = not_a_number; }, "non-finite"},
      {[](auto& m) { m.residual_flexibility(1, 0) = 3e-8; },
       "not symmetric: (1:uy, 4:uy) = 2e-08 but (4:uy, 1:uy) = 3e-08"},
  };
  for (const Case& c : cases) {
    const std::string message = error(c.change);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "expected '" << c.expected << "' in: '" << message << "'";
    EXPECT_EQ(message.rfind("modal model: ", 0), 0u) << message;
  }
}

// A 0 Hz mode (issue 31): its receptance at 0 Hz (harmonic 0) is infinite, and that is named,
// not left to surface as a term "without effect"; at any other frequency it is the mass line
// −φ_iφ_j / ω² of a rigid-body motion, plus the flexible mode's term.
TEST(ModalModel, AZeroHertzModeIsNamedAtZeroHertzAndAMassLineElsewhere) {
  frf::ModalModel m = valid();
  m.frequencies_hz(0) = 0.0;
  m.residual_flexibility.resize(0, 0);
  const frf::ModalSynthesis H(m, {0, 1, 2});
  const std::vector<int> at{1};
  try {
    H.receptance(0.0, at, at);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "receptance: mode 1 is at 0 Hz (a rigid-body motion), so the receptance at 0 Hz "
              "(harmonic 0, the static mean) is infinite: support the substructure, or leave "
              "harmonic 0 out");
  }
  const double w = 2.0 * std::numbers::pi * 5.0, w2 = 2.0 * std::numbers::pi * 212.0;
  const std::complex<double> flexible =
      0.88 * 0.88 / std::complex<double>(w2 * w2 - w * w, 2.0 * 0.002 * w2 * w);
  const std::complex<double> expected = -0.40 * -0.40 / (-w * w) + flexible;
  EXPECT_LE(std::abs(H.receptance(w, at, at)(0, 0) - expected), 1e-14 * std::abs(expected));
}
