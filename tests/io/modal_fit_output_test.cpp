// The fitted substructure as a model file: it reads back bit-exactly with io::read_model, alone
// and as a part of a model with joints ([[substructures]] file = ...); and modal_fit.json.
#include "io/modal_fit_output.hpp"

#include "frf/receptance.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "io/test_files.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <numbers>

namespace jointid {
namespace {

using jointid::test::two_pi;

// FRFs of a modal model of three DOFs (uy at nodes 1, 2, 3; modes at 8, 12.5 and 21 Hz) from
// the driving point 3:uy, measured as acceleration at node 2, and the fit of them.
struct Fitted {
  frf::ModalModel truth;
  identify::MeasuredFrfs data;
  identify::ModalFit fit;
  Fitted() {
    truth.dofs = {{1, fem::Dof::uy}, {2, fem::Dof::uy}, {3, fem::Dof::uy}};
    truth.frequencies_hz = Eigen::Vector3d(8.0, 12.5, 21.0);
    truth.damping = Eigen::Vector3d(0.01, 0.015, 0.02);
    truth.shapes.resize(3, 3);
    truth.shapes << 0.2, 0.35, 0.45, -0.3, -0.1, 0.25, 0.4, -0.3, 0.2;
    truth.residual_flexibility = 1e-7 * Eigen::Matrix3d::Identity();
    const frf::ModalSynthesis s(truth, {0, 1, 2});
    data.drive = {3, fem::Dof::uy};
    data.drive_name = "f@3:uy";
    data.responses = truth.dofs;
    data.response_names = {"x@1:uy", "a@2:uy", "x@3:uy"};
    data.measured_as = {identify::Quantity::displacement, identify::Quantity::acceleration,
                        identify::Quantity::displacement};
    data.method = identify::SpectraMethod::periods;
    data.frequency_hz = Eigen::VectorXd::LinSpaced(1001, 5.0, 25.0);
    data.H.resize(1001, 3);
    const std::vector<int> rows{0, 1, 2}, drive{2};
    for (Eigen::Index j = 0; j < 1001; ++j)
      data.H.row(j) = s.receptance(two_pi * data.frequency_hz(j), rows, drive).transpose();
    data.coherence = Eigen::MatrixXd::Constant(1001, 3, 0.99);
    data.coherence.col(2).setConstant(std::numeric_limits<double>::quiet_NaN());
    data.blocks = {4, 4, 4};
    data.resolution_hz = 0.02;
    fit = identify::modal_fit(data, {.modes = 3});
  }
};

TEST(ModalFitOutput, TheModelFileReadsBackAloneAndAsAPartWithJoints) {
  const Fitted f;
  ASSERT_TRUE(f.fit.status.ok()) << f.fit.status.reason;
  ASSERT_EQ(f.fit.substructure.num_modes(), 3);
  const test::TempDir dir;
  std::filesystem::create_directories(dir / "fit");
  const std::string text = io::modal_fit_toml(f.fit, f.data, {"made by a test"});
  EXPECT_EQ(text.rfind("# made by a test\n", 0), 0u);
  test::write_text(dir / "fit" / "substructure.toml", text);

  // Alone: the [modal] model, every number bit-exact.
  const io::ModelFile alone = io::read_model(dir / "fit" / "substructure.toml");
  ASSERT_TRUE(alone.modal.has_value());
  const frf::ModalModel& back = *alone.modal;
  const frf::ModalModel& m = f.fit.substructure;
  EXPECT_EQ(back.dofs, m.dofs);
  EXPECT_EQ(back.frequencies_hz, m.frequencies_hz);
  EXPECT_EQ(back.damping, m.damping);
  EXPECT_EQ(back.shapes, m.shapes);
  EXPECT_EQ(back.residual_flexibility, m.residual_flexibility);
  EXPECT_TRUE(alone.joints.empty());
  // ...and close to the truth it was fitted to (exact FRFs: no noise).
  for (int r = 0; r < 3; ++r)
    EXPECT_NEAR(back.frequencies_hz(r), f.truth.frequencies_hz(r),
                1e-6 * f.truth.frequencies_hz(r));

  // A part of a model with a joint to ground at 2:uy and one between node 1 of the fitted part
  // and node 1 of a second copy (node_offset 100): the parts' DOFs, the joints on them, and the
  // receptance of the composite block by block.
  test::write_text(
      dir / "parent.toml",
      "[[substructures]]\nfile = \"fit/substructure.toml\"\n\n"
      "[[substructures]]\nfile = \"fit/substructure.toml\"\nnode_offset = 100\n\n"
      "[[joints]]\nname = \"ground\"\nnode = 2\ndof = \"uy\"\nterms = [\"k\", \"k3\"]\n"
      "values = { k = 1000.0, k3 = 1e7 }\n\n"
      "[[joints]]\nname = \"link\"\nnode = 1\nnode_b = 101\ndof = \"uy\"\n"
      "terms = [\"k\", \"c\"]\nvalues = { k = 500.0, c = 2.0 }\n");
  const io::ModelFile parent = io::read_model(dir / "parent.toml");
  ASSERT_EQ(parent.parts.size(), 2u);
  ASSERT_EQ(parent.joints.size(), 2u);
  EXPECT_EQ(parent.joints[1].node_b, 101);
  const frf::Substructure sub = parent.substructure();
  EXPECT_EQ(sub.dofs().num_equations(), 6);
  const int e2 = sub.dofs().equation({2, fem::Dof::uy}),
            e3 = sub.dofs().equation({3, fem::Dof::uy});
  const int e103 = sub.dofs().equation({103, fem::Dof::uy});
  const frf::ModalSynthesis composite = sub.synthesis({e2, e3, e103}, 30.0);
  const frf::ModalSynthesis part(m, {1, 2});
  const double omega = two_pi * 12.0;
  const std::vector<int> r2{e2}, c3{e3}, c103{e103}, p2{1}, p3{2};
  const auto h = composite.receptance(omega, r2, c3)(0, 0);
  const auto expected = part.receptance(omega, p2, p3)(0, 0);
  EXPECT_LT(std::abs(h - expected), 1e-12 * std::abs(expected));
  EXPECT_EQ(composite.receptance(omega, r2, c103)(0, 0), std::complex<double>(0.0, 0.0));
}

TEST(ModalFitOutput, TheJsonSaysWhatWasFitted) {
  const Fitted f;
  const nlohmann::json j = nlohmann::json::parse(
      io::modal_fit_json(f.fit, f.data, {.f0_hz = 5.0, .f1_hz = 25.0, .inputs = {"a.csv"}}));
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["driving_point"], "3:uy");
  EXPECT_EQ(j["force_channel"], "f@3:uy");
  EXPECT_EQ(j["substructure"], "substructure.toml");
  EXPECT_EQ(j["inputs"][0], "a.csv");
  EXPECT_EQ(j["lines"], 1001);
  EXPECT_EQ(j["spectra"]["method"], "periods");
  EXPECT_NE(j["fitted_as"].get<std::string>().find("(iω)² = −ω²"), std::string::npos);
  ASSERT_EQ(j["modes"].size(), 3u);
  for (std::size_t r = 0; r < 3; ++r) {
    EXPECT_EQ(j["modes"][r]["frequency_hz"].get<double>(), f.fit.modes[r].frequency_hz);
    EXPECT_EQ(j["modes"][r]["damping"].get<double>(), f.fit.modes[r].damping);
    EXPECT_EQ(j["modes"][r]["shape"]["3:uy"].get<double>(), f.fit.modes[r].shape(2));
  }
  for (const char* dof : {"1:uy", "2:uy", "3:uy"}) {
    ASSERT_TRUE(j["fit_error"][dof].is_number()) << dof;
    EXPECT_LT(j["fit_error"][dof].get<double>(), 1e-6) << dof; // exact FRFs
  }
  EXPECT_NEAR(j["coherence"]["2:uy"].get<double>(), 0.99, 1e-12);
  EXPECT_TRUE(j["coherence"]["3:uy"].is_null()); // not estimated
  EXPECT_EQ(j["channels"][1]["measured_as"], "acceleration");
  EXPECT_EQ(j["estimator"]["max_order"], f.fit.max_order);
  EXPECT_EQ(j["diagram"].size(), f.fit.diagram.size());
}

TEST(ModalFitOutput, NoModelWithoutModes) {
  Fitted f;
  f.fit.substructure.frequencies_hz.resize(0);
  f.fit.substructure.damping.resize(0);
  f.fit.substructure.shapes.resize(0, 3);
  EXPECT_THROW(io::modal_fit_toml(f.fit, f.data), io::Error);
}

} // namespace
} // namespace jointid
