// Several substructures in one model ([[substructures]]): H block diagonal, parts from any
// source, joined by joints. Checked against one finite element model holding both beams (its K
// and M are block diagonal by construction): the same receptance, and the same identification
// of a joint to ground and a joint between the beams, with the second beam given by its finite
// elements or by its measured FRF.
#include "frf/sweep.hpp"

#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/sine_tests.hpp"
#include "io/cantilever_toml.hpp"
#include "io/files.hpp"
#include "io/frf_output.hpp"
#include "io/model_file.hpp"
#include "io/test_files.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

using namespace jointid;
using fem::Dof;
namespace fs = std::filesystem;
using test::error_of;

namespace {

using jointid::test::two_pi;

// A steel cantilever along x at height y (m), `length` m in 6 beam elements, nodes first …
// first + 6, fixed at the first node, 1 % modal damping; the finite element tables only.
std::string beam(int first, double length, double y) {
  std::string nodes, elements;
  for (int i = 0; i <= 6; ++i)
    nodes += fmt::format("{}[{}, {}, {}]", i ? ", " : "", first + i, length * i / 6.0, y);
  for (int i = 0; i < 6; ++i)
    elements += fmt::format("{}[{}, {}, {}]", i ? ", " : "", first + i, first + i, first + i + 1);
  return fmt::format(
      "[[materials]]\nname = \"steel\"\nE = 210e9\nrho = 7850.0\nnu = 0.3\n\n"
      "[[sections]]\nname = \"bar\"\nA = {}\nIz = {}\n\n"
      "[mesh]\nnodes = [{}]\nelements = [{}]\n\n"
      "[[element_sets]]\nelements = \"all\"\ntype = \"beam\"\nmaterial = \"steel\"\n"
      "section = \"bar\"\n\n[[supports]]\nnode = {}\nfix = [\"ux\", \"uy\", \"rz\"]\n",
      test::area, test::Iz, nodes, elements, first);
}

const std::string tip_joint = "[[joints]]\nname = \"tip\"\nnode = 7\ndof = \"uy\"\n"
                              "terms = [\"k\", \"c\", \"k3\"]\n"
                              "values = { k = 4800.0, c = 20.0, k3 = 1.6e8 }\n";
const std::string link_joint = "[[joints]]\nname = \"link\"\nnode = 4\nnode_b = 107\ndof = \"uy\"\n"
                               "terms = [\"k\", \"c2\"]\nvalues = { k = 3000.0, c2 = 400.0 }\n";

struct TwoBeams {
  test::TempDir dir;
  TwoBeams() {
    // One model with both beams (B: 1.5 m long, nodes 101–107, 1 m above A).
    std::string both = beam(1, 2.0, 0.0);
    std::string b = beam(101, 1.5, 1.0);
    // One [[materials]]/[[sections]]/[mesh] for both: merge B's nodes and elements into A's.
    const auto between = [](const std::string& s, const std::string& from, const std::string& to) {
      const std::size_t a = s.find(from) + from.size();
      return s.substr(a, s.find(to, a) - a);
    };
    both.insert(both.find("]\nelements = ["), ", " + between(b, "nodes = [", "]\nelements"));
    both.insert(both.find("]\n\n[[element_sets]]"), ", " + between(b, "elements = [", "]\n\n[["));
    both += "\n[[supports]]\nnode = 101\nfix = [\"ux\", \"uy\", \"rz\"]\n";
    test::write_text(dir / "both.toml", "[model]\ndimension = 2\n\n" + both +
                                            "\n[damping]\nmodal = 0.01\n\n" + tip_joint + "\n" +
                                            link_joint);
    // The same as two files: A with its tip joint, B alone (its own numbering, 1–7).
    test::write_text(dir / "a.toml", "[model]\ndimension = 2\n\n" + beam(1, 2.0, 0.0) +
                                         "\n[damping]\nmodal = 0.01\n\n" + tip_joint);
    test::write_text(dir / "b.toml", "[model]\ndimension = 2\n\n" + beam(1, 1.5, 1.0) +
                                         "\n[damping]\nmodal = 0.01\n");
    test::write_text(dir / "parts.toml", composite("b.toml"));
  }
  static std::string composite(const std::string& b) {
    return "[model]\ndimension = 2\n\n[[substructures]]\nfile = \"a.toml\"\n\n"
           "[[substructures]]\nfile = \"" +
           b + "\"\nnode_offset = 100\n\n" + link_joint;
  }
};

} // namespace

TEST(Substructures, TwoFilesGiveTheReceptanceOfOneModelHoldingBoth) {
  const TwoBeams x;
  const io::ModelFile one = io::read_model(x.dir / "both.toml"),
                      two = io::read_model(x.dir / "parts.toml");
  ASSERT_EQ(two.parts.size(), 2u);
  ASSERT_EQ(two.joints.size(), 2u); // link, then A's tip
  const frf::Substructure a = one.substructure(), b = two.substructure();
  ASSERT_EQ(a.dofs().num_equations(), b.dofs().num_equations());
  std::vector<int> ea, eb;
  for (const fem::NodeDof nd : {fem::NodeDof{7, Dof::uy}, fem::NodeDof{4, Dof::uy},
                                fem::NodeDof{107, Dof::uy}, fem::NodeDof{104, Dof::rz}})
    ea.push_back(a.dofs().equation(nd)), eb.push_back(b.dofs().equation(nd));
  const frf::ModalSynthesis Ha = a.synthesis(ea, 200.0), Hb = b.synthesis(eb, 200.0);
  EXPECT_EQ(Hb.num_modes(), Ha.num_modes()); // every mode of each beam, side by side
  for (double f : {0.5, 3.0, 5.6, 19.0, 47.0}) {
    const Eigen::MatrixXcd ra = Ha.receptance(two_pi * f, ea, ea),
                           rb = Hb.receptance(two_pi * f, eb, eb);
    // The two eigenproblems round differently (~1e-13 on ω_r); near a resonance H magnifies a
    // relative error of ω_r by about 1/ζ = 100.
    EXPECT_LE((ra - rb).norm(), 1e-9 * ra.norm()) << f;
    EXPECT_EQ(rb(0, 2), std::complex<double>(0.0)) << "A and B are joined by joints only";
  }
  // The parts have no one damping matrix, but each is integrated in time in its own
  // coordinates (here both in full), the joints coupling them: the steady state of the one
  // model, to rounding (its K, M and modal damping are block diagonal, the same blocks; the
  // steady states converge to a period-to-period change of 1e-10).
  EXPECT_EQ(error_of([&] { (void)b.damping_matrix(); }),
            "time integration needs a finite element model; this substructure is given by "
            "several substructures ([[substructures]])");
  identify::SimulationOptions o;
  o.periods = 1;
  o.steps_per_period = 256;
  o.extra_outputs = {{107, Dof::uy}};
  const auto ta = identify::simulate_sine_tests(a, one.joints, {7, Dof::uy}, {{5.0, 10.0}}, o);
  const auto tb = identify::simulate_sine_tests(b, two.joints, {7, Dof::uy}, {{5.0, 10.0}}, o);
  ASSERT_TRUE(ta[0].status.ok()) << ta[0].status.reason;
  ASSERT_TRUE(tb[0].status.ok()) << tb[0].status.reason;
  for (const fem::NodeDof at : {fem::NodeDof{7, Dof::uy}, fem::NodeDof{107, Dof::uy}}) {
    const Eigen::VectorXd& xa = ta[0].record.find(identify::Quantity::displacement, at)->samples;
    const Eigen::VectorXd& xb = tb[0].record.find(identify::Quantity::displacement, at)->samples;
    EXPECT_LE((xa - xb).cwiseAbs().maxCoeff(), 1e-8 * xa.cwiseAbs().maxCoeff())
        << fem::to_string(at);
  }
}

TEST(Substructures, IdentificationThroughPartsFromAnySource) {
  // Tests simulated on the one model (harmonic balance, force at A's tip, harmonics 1 and 3),
  // both joints identified through: the one model; A and B as finite element files; A's file
  // and B's FRF measured at its tip (universal file, 0.01 Hz lines to 80 Hz: the tests and their
  // harmonics lie on lines). The same values to rounding (1e-8).
  const TwoBeams x;
  const io::ModelFile one = io::read_model(x.dir / "both.toml");
  {
    test::write_text(x.dir / "b_tip.toml", "[model]\ndimension = 2\n\n" + beam(1, 1.5, 1.0) +
                                               "\n[damping]\nmodal = 0.01\n");
    const frf::Substructure b(io::read_model(x.dir / "b_tip.toml").substructure());
    const int tip = b.dofs().equation({7, Dof::uy});
    std::vector<double> f;
    for (int i = 0; i <= 8000; ++i)
      f.push_back(0.01 * i);
    io::write_uff58(x.dir / "b_tip.uff", io::frf_uff58(frf::frf_sweep(b, tip, {tip}, f), b.dofs()));
    test::write_text(x.dir / "b_measured.toml",
                     "[model]\ndimension = 2\n\n[frf]\nfiles = [\"b_tip.uff\"]\n");
    test::write_text(x.dir / "parts_measured.toml", TwoBeams::composite("b_measured.toml"));
  }
  std::vector<identify::SineTestPlan> plans;
  for (double f : {3.0, 4.0, 5.0, 15.0, 18.0, 21.0})
    for (double a : {20.0, 60.0})
      plans.push_back({f, a});
  identify::SimulationOptions so;
  so.method = identify::SimulationMethod::harmonic_balance;
  so.periods = 2;
  so.steps_per_period = 256;
  std::vector<identify::Measurement> tests;
  for (const auto& t :
       identify::simulate_sine_tests(one.substructure(), one.joints, {7, Dof::uy}, plans, so))
    tests.push_back(identify::measure(t.record, {.harmonics = 3}));
  const auto identified = [&](const io::ModelFile& file) {
    std::vector<joints::Joint> start = file.joints;
    for (auto& j : start)
      j.fixed.assign(j.terms.size(), false);
    const identify::FitResult r =
        identify::fit(file.substructure(), start, tests, {.harmonics = {1, 3}});
    std::map<std::string, double> values;
    for (const auto& j : r.joints)
      for (const auto& t : j.terms)
        values[j.name + "." + std::string(joints::term_name(t.term))] = t.value;
    return values;
  };
  const auto reference = identified(one);
  ASSERT_EQ(reference.size(), 5u);
  EXPECT_NEAR(reference.at("link.k"), 3000.0, 1e-5 * 3000.0); // c2's harmonics above 3: 1.4e-6
  for (const char* name : {"parts.toml", "parts_measured.toml"}) {
    const auto values = identified(io::read_model(x.dir / name));
    for (const auto& [term, value] : reference)
      EXPECT_NEAR(values.at(term), value, 1e-8 * std::abs(value)) << name << " " << term;
  }
}

TEST(Substructures, ErrorsNameTheFileAndTheParts) {
  const TwoBeams x;
  const auto model = [&](const std::string& text) {
    test::write_text(x.dir / "m.toml", text);
    return error_of([&] { (void)io::read_model(x.dir / "m.toml"); });
  };
  const std::string m = (x.dir / "m.toml").string();
  std::string no_offset = TwoBeams::composite("b.toml");
  no_offset.erase(no_offset.find("node_offset = 100\n"), 18);
  EXPECT_EQ(model(no_offset),
            m + ":8: [[substructures]] entry 2: key 'file': node 2 of b.toml (node 2 + node_offset "
                "0) is also a node of substructure 1 (a.toml): give one of them a node_offset");
  EXPECT_EQ(model(TwoBeams::composite("b.toml") + "\n[damping]\nmodal = 0.02\n"),
            m + ":19: key 'damping': not used with [[substructures]]: the substructure is made of "
                "the files it lists");
  const std::string nested = (x.dir / "parts.toml").string() +
                             ":4: [[substructures]]: this file is a part of a model made of "
                             "substructures and may not list substructures itself: list its "
                             "parts in that model instead";
  EXPECT_EQ(model("[model]\ndimension = 2\n\n[[substructures]]\nfile = \"parts.toml\"\n"), nested);
  // A file that lists itself is refused the same way, not read forever.
  EXPECT_EQ(model("[[substructures]]\nfile = \"m.toml\"\n"),
            m + ":1: [[substructures]]: this file is a part of a model made of substructures and "
                "may not list substructures itself: list its parts in that model instead");
  std::string far = TwoBeams::composite("b.toml");
  far.replace(far.find("node_b = 107"), 12, "node_b = 108");
  EXPECT_EQ(model(far).find(m + ":"), 0u);
  EXPECT_NE(model(far).find("node 108"), std::string::npos) << model(far);
  std::string twice = TwoBeams::composite("b.toml");
  twice.replace(twice.find("name = \"link\""), 13, "name = \"tip\"");
  EXPECT_EQ(model(twice), m + ":4: [[substructures]] entry 1: joint 'tip' of a.toml has the name "
                              "of another joint; rename one of them");
}

// Every part checked against the whole (issue 31): its dimension, its DOFs, its node ids.
TEST(Substructures, EveryPartIsCheckedAgainstTheWhole) {
  const TwoBeams x;
  const auto model = [&](const std::string& text) {
    test::write_text(x.dir / "m.toml", text);
    return error_of([&] { (void)io::read_model(x.dir / "m.toml"); });
  };
  const std::string m = (x.dir / "m.toml").string();
  // A spatial whole of planar parts.
  std::string spatial = TwoBeams::composite("b.toml");
  spatial.replace(spatial.find("dimension = 2"), 13, "dimension = 3");
  EXPECT_EQ(model(spatial), m + ":5: [[substructures]] entry 1: key 'file': a.toml is a planar "
                                "model (dimension = 2), but the whole ([model]) is spatial "
                                "(dimension = 3): the parts of a model share its dimension");
  // A [modal] part with a DOF the planar whole lacks (listed after the finite element parts,
  // and without [model] of its own, where any of the six DOFs may be listed).
  test::write_text(x.dir / "c.toml", "[modal]\ndofs = [\"1:uz\"]\nfrequencies_hz = [10.0]\n"
                                     "damping = [0.01]\nshapes = [[1.0]]\n");
  const std::string with_c =
      TwoBeams::composite("b.toml") + "\n[[substructures]]\nfile = \"c.toml\"\nnode_offset = 200\n";
  EXPECT_EQ(model(with_c),
            m + ":19: [[substructures]] entry 3: c.toml has the DOF 201:uz (node 1 + "
                "node_offset 200), but the model is planar (dimension = 2: its "
                "[model]), which has only ux, uy and rz");
  // Without the whole's [model], the planar finite element parts set the dimension.
  std::string no_model = with_c;
  no_model.erase(0, no_model.find("[[substructures]]"));
  EXPECT_NE(model(no_model).find("c.toml has the DOF 201:uz (node 1 + node_offset 200), but the "
                                 "model is planar (dimension = 2: substructure 1)"),
            std::string::npos)
      << model(no_model);
  // A node offset that carries a node id past the largest integer.
  std::string far = TwoBeams::composite("b.toml");
  far.replace(far.find("node_offset = 100"), 17, "node_offset = 2147483647");
  EXPECT_NE(model(far).find("[[substructures]] entry 2: key 'file': node "), std::string::npos)
      << model(far);
  EXPECT_NE(model(far).find("of b.toml + node_offset 2147483647 is above the largest node id "
                            "(2147483647)"),
            std::string::npos)
      << model(far);
}
