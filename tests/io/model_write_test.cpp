// A model file written from another with new joints (io/model_write.hpp): read back from
// another directory, it is the starting model (the same receptance) with the joints given.
#include "io/model_write.hpp"

#include "io/cantilever_toml.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "io/test_files.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"

#include <gtest/gtest.h>

using namespace jointid;
using test::error_of;
namespace fs = std::filesystem;

namespace {

// The tip joint as discovery might end it: k and c refitted, a cubic stiffness and a Jenkins
// element added (values that no decimal text rounds to).
joints::Joint discovered_tip(const joints::Joint& start) {
  joints::Joint j = start;
  j.terms = {joints::Term::k, joints::Term::c, joints::Term::k3, joints::Term::jenkins};
  j.values = {4800.0 / 3.0, 20.0 * std::numbers::sqrt2, -1.6e8 / 7.0, 1.0};
  j.fixed.assign(4, false);
  j.given.assign(4, true);
  j.parameters.assign(4, {});
  j.parameters[3] = {{std::numbers::pi * 1e4, false, true}, {std::numbers::e, true, true}};
  return j;
}

void expect_same_joint(const joints::Joint& a, const joints::Joint& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.node, b.node);
  EXPECT_EQ(a.node_b, b.node_b);
  EXPECT_EQ(a.dof, b.dof);
  ASSERT_EQ(a.terms, b.terms);
  for (std::size_t k = 0; k < a.terms.size(); ++k) {
    if (joints::has_parameters(a.terms[k])) {
      ASSERT_EQ(a.parameters_of(k).size(), b.parameters_of(k).size());
      for (std::size_t p = 0; p < a.parameters_of(k).size(); ++p) {
        EXPECT_EQ(a.parameters_of(k)[p].value, b.parameters_of(k)[p].value) << k << "." << p;
        EXPECT_EQ(a.parameters_of(k)[p].fixed, b.parameters_of(k)[p].fixed) << k << "." << p;
      }
    } else {
      EXPECT_EQ(a.values[k], b.values[k]) << k; // exactly: the text round-trips
      EXPECT_EQ(a.fixed[k], b.fixed[k]) << k;
    }
  }
}

// The receptance at the tip over a few frequencies (m/N).
std::vector<std::complex<double>> tip_receptance(const io::ModelFile& m, int node) {
  const frf::Substructure s = m.substructure();
  const std::vector<int> at{s.dofs().equation({node, fem::Dof::uy})};
  const frf::ModalSynthesis H = s.synthesis(at, 200.0);
  std::vector<std::complex<double>> out;
  for (double f : {0.7, 2.9, 13.0})
    out.push_back(H.receptance(test::two_pi * f, at, at)(0, 0));
  return out;
}

} // namespace

TEST(ModelWrite, TheStartingModelWithTheDiscoveredJointReadFromAnotherDirectory) {
  const test::TempDir dir;
  fs::create_directories(dir / "start");
  fs::create_directories(dir / "out/deeper");
  // The beam's mesh in a Gmsh-free form is inline; a part-less model with a relative path is
  // the [[substructures]] case below.
  test::write_text(dir / "start/model.toml", test::cantilever_toml());
  const io::ModelFile start = io::read_model(dir / "start/model.toml");
  const joints::Joint tip = discovered_tip(start.joints[0]);
  const fs::path target = dir / "out/deeper/model.toml";
  const std::string text = io::model_with_joints(dir / "start/model.toml", {tip}, 1.0, target,
                                                 "written by a test\nsecond line");
  EXPECT_EQ(text.rfind("# written by a test\n# second line\n", 0), 0u) << text;
  test::write_text(target, text);
  const io::ModelFile back = io::read_model(target);
  ASSERT_EQ(back.joints.size(), 1u);
  expect_same_joint(back.joints[0], tip);
  // "jenkins.fs" held fixed, kt not.
  EXPECT_NE(text.find("fixed = [ \"jenkins.fs\" ]"), std::string::npos) << text;
  // The substructure is the starting one: the same receptance to the last bit.
  EXPECT_EQ(tip_receptance(back, 7), tip_receptance(start, 7));
  EXPECT_EQ(back.model.damping.modal_ratio, 0.01);
}

TEST(ModelWrite, TheDampingScaleIsWrittenIntoTheDampingTheModelHas) {
  const test::TempDir dir;
  test::write_text(dir / "a.toml", test::cantilever_toml());
  const io::ModelFile start = io::read_model(dir / "a.toml");
  test::write_text(dir / "b.toml", io::model_with_joints(dir / "a.toml", start.joints, 1.5,
                                                         dir / "b.toml", "scaled"));
  EXPECT_DOUBLE_EQ(io::read_model(dir / "b.toml").model.damping.modal_ratio, 0.015);
  // Rayleigh: both coefficients (each mode's ratio α/2ω + βω/2 scales with them).
  test::write_text(dir / "r.toml", test::replaced(test::cantilever_toml(), "modal = 0.01",
                                                  "rayleigh = [0.2, 4e-5]"));
  test::write_text(dir / "rs.toml", io::model_with_joints(dir / "r.toml", start.joints, 0.5,
                                                          dir / "rs.toml", "scaled"));
  const fem::Damping d = io::read_model(dir / "rs.toml").model.damping;
  EXPECT_DOUBLE_EQ(d.alpha, 0.1);
  EXPECT_DOUBLE_EQ(d.beta, 2e-5);
}

TEST(ModelWrite, PartsAreFoundFromTheNewDirectoryAndAPartsJointMustBeUnchanged) {
  const test::TempDir dir;
  fs::create_directories(dir / "parts");
  fs::create_directories(dir / "result");
  // Part a.toml holds the tip joint; the whole adds a joint 'mount' between node 4 and ground.
  test::write_text(dir / "parts/a.toml", test::cantilever_toml());
  const std::string whole = "[model]\ndimension = 2\n\n[[substructures]]\nfile = \"a.toml\"\n\n"
                            "[[joints]]\nname = \"mount\"\nnode = 4\ndof = \"uy\"\n"
                            "terms = [\"k\"]\nvalues = { k = 1000.0 }\n";
  test::write_text(dir / "parts/whole.toml", whole);
  const io::ModelFile start = io::read_model(dir / "parts/whole.toml");
  ASSERT_EQ(start.joints.size(), 2u);
  std::vector<joints::Joint> found = start.joints;
  const auto mount = static_cast<std::size_t>(found[0].name == "mount" ? 0 : 1);
  found[mount].terms.push_back(joints::Term::c3);
  found[mount].values.push_back(1.0 / 3.0);
  found[mount].fixed.push_back(false);
  found[mount].given.assign(found[mount].terms.size(), true);
  const fs::path target = dir / "result/model.toml";
  test::write_text(target,
                   io::model_with_joints(dir / "parts/whole.toml", found, 1.0, target, "x"));
  EXPECT_NE(test::read_text(target).find("file = \"../parts/a.toml\""), std::string::npos);
  const io::ModelFile back = io::read_model(target);
  ASSERT_EQ(back.joints.size(), 2u);
  for (const joints::Joint& j : back.joints)
    expect_same_joint(j, found[j.name == "mount" ? mount : 1 - mount]);
  EXPECT_EQ(tip_receptance(back, 7), tip_receptance(start, 7));

  // The part's joint changed: it lives in parts/a.toml, which is not rewritten.
  std::vector<joints::Joint> changed = start.joints;
  changed[1 - mount].values[0] *= 2.0;
  EXPECT_EQ(error_of([&] {
              (void)io::model_with_joints(dir / "parts/whole.toml", changed, 1.0, target, "x");
            }),
            (dir / "parts/whole.toml").string() +
                ": joint 'tip' is given by one of the model's parts ([[substructures]]), whose "
                "file would have to be rewritten: give the joint in the model file itself to "
                "have it written");
  // A damping scale on parts: each part has its own damping.
  EXPECT_EQ(error_of([&] {
              (void)io::model_with_joints(dir / "parts/whole.toml", start.joints, 1.2, target, "x");
            }),
            (dir / "parts/whole.toml").string() +
                ": the substructure's damping scaled by 1.2 cannot be written into a model of "
                "several parts ([[substructures]]): scale the damping in its own files");
}
