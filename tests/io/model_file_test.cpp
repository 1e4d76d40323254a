#include "io/model_file.hpp"

#include "io/cantilever_toml.hpp"
#include "io/files.hpp"
#include "io/model_toml.hpp"
#include "io/test_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace jointid::io {
namespace {

using fem::Dof;

using test::cantilever_toml;
using test::length;

class ModelFileTest : public ::testing::Test {
protected:
  std::filesystem::path write(const std::string& text) {
    const auto path = dir / "cantilever.toml";
    test::write_text(path, text);
    return path;
  }
  // Expects read_model to fail with a message naming the file, `line` and every one of `parts`.
  void expect_error(const std::string& text, int line, std::initializer_list<std::string> parts) {
    ASSERT_GT(line, 0) << "bad test: line not found";
    const auto path = write(text);
    try {
      read_model(path);
      FAIL() << "expected io::Error";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("cantilever.toml:" + std::to_string(line) + ":"), std::string::npos)
          << message;
      for (const auto& p : parts)
        EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' not in: " << message;
    }
  }
  test::TempDir dir;
};

TEST_F(ModelFileTest, ReadsTheCantilever) {
  const auto path = write(cantilever_toml());
  const ModelFile file = read_model(path);
  const fem::Model& m = file.model;
  EXPECT_EQ(file.path, path);
  EXPECT_EQ(m.dimension, 2);
  ASSERT_EQ(m.nodes.size(), 7u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(m.nodes[i].id, i + 1);
    EXPECT_DOUBLE_EQ(m.nodes[i].x.x(), length * i / 6.0);
    EXPECT_EQ(m.nodes[i].x.y(), 0.0);
    EXPECT_EQ(m.nodes[i].x.z(), 0.0);
  }
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "steel");
  EXPECT_EQ(m.materials[0].E, 210e9);
  EXPECT_EQ(m.materials[0].rho, 7850.0);
  EXPECT_EQ(m.materials[0].nu, 0.3);
  ASSERT_EQ(m.sections.size(), 1u);
  EXPECT_DOUBLE_EQ(m.sections[0].A, 0.0036);
  EXPECT_DOUBLE_EQ(m.sections[0].Iz, 0.25 * std::pow(0.0144, 3) / 12.0);
  ASSERT_EQ(m.elements.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(m.elements[i].id, i + 1);
    EXPECT_EQ(m.elements[i].node_a, i + 1);
    EXPECT_EQ(m.elements[i].node_b, i + 2);
    EXPECT_EQ(m.elements[i].type, fem::ElementType::beam);
    EXPECT_EQ(m.elements[i].material, 0);
    EXPECT_EQ(m.elements[i].section, 0);
  }
  ASSERT_EQ(m.supports.size(), 1u);
  EXPECT_EQ(m.supports[0].node, 1);
  EXPECT_EQ(m.supports[0].fixed, (std::vector<Dof>{Dof::ux, Dof::uy, Dof::rz}));
  EXPECT_TRUE(m.masses.empty());
  EXPECT_TRUE(m.springs.empty());
  EXPECT_EQ(m.damping.kind, fem::Damping::Kind::modal);
  EXPECT_EQ(m.damping.modal_ratio, 0.01);
  EXPECT_FALSE(m.mass_options.lumped);

  ASSERT_EQ(file.joints.size(), 1u);
  const joints::Joint& j = file.joints[0];
  EXPECT_EQ(j.name, "tip");
  EXPECT_EQ(j.node, 7);
  EXPECT_TRUE(j.to_ground());
  EXPECT_EQ(j.dof, Dof::uy);
  EXPECT_EQ(j.terms,
            (std::vector<joints::Term>{joints::Term::k, joints::Term::c, joints::Term::k3}));
  EXPECT_EQ(j.values, (std::vector<double>{4800.0, 20.0, 1.6e8}));
  EXPECT_EQ(j.fixed, (std::vector<bool>{false, false, false}));
}

// The cantilever of cantilever_toml() built in memory, as Python's dicts give it (python/): no
// source positions anywhere.
toml::table built_cantilever(const std::string& joint_dof = "uy") {
  toml::array nodes, elements;
  for (int i = 0; i < 7; ++i)
    nodes.push_back(toml::array{i + 1, length * i / 6.0, 0.0});
  for (int e = 1; e <= 6; ++e)
    elements.push_back(toml::array{e, e, e + 1});
  return toml::table{
      {"model", toml::table{{"dimension", 2}}},
      {"materials",
       toml::array{toml::table{{"name", "steel"}, {"E", 210e9}, {"rho", 7850.0}, {"nu", 0.3}}}},
      {"sections", toml::array{toml::table{{"name", "bar"}, {"A", test::area}, {"Iz", test::Iz}}}},
      {"mesh", toml::table{{"nodes", nodes}, {"elements", elements}}},
      {"element_sets",
       toml::array{toml::table{
           {"elements", "all"}, {"type", "beam"}, {"material", "steel"}, {"section", "bar"}}}},
      {"supports", toml::array{toml::table{{"node", 1}, {"fix", toml::array{"ux", "uy", "rz"}}}}},
      {"damping", toml::table{{"modal", 0.01}}},
      {"joints", toml::array{toml::table{
                     {"name", "tip"},
                     {"node", 7},
                     {"dof", joint_dof},
                     {"terms", toml::array{"k", "c", "k3"}},
                     {"values", toml::table{{"k", 4800.0}, {"c", 20.0}, {"k3", 1.6e8}}}}}}};
}

TEST_F(ModelFileTest, ReadsADocumentBuiltInMemoryAsTheFile) {
  const ModelFile file = read_model(write(cantilever_toml()));
  const ModelFile built = read_model(built_cantilever(), dir / "<dict>");
  EXPECT_EQ(built.path, dir / "<dict>");
  ASSERT_EQ(built.model.nodes.size(), file.model.nodes.size());
  for (std::size_t i = 0; i < file.model.nodes.size(); ++i) {
    EXPECT_EQ(built.model.nodes[i].id, file.model.nodes[i].id);
    EXPECT_EQ(built.model.nodes[i].x, file.model.nodes[i].x);
  }
  EXPECT_EQ(built.model.elements.size(), 6u);
  EXPECT_EQ(built.model.damping.modal_ratio, 0.01);
  EXPECT_EQ(built.dof_map().num_equations(), file.dof_map().num_equations());
  ASSERT_EQ(built.joints.size(), 1u);
  EXPECT_EQ(built.joints[0].values, file.joints[0].values);
  EXPECT_EQ(built.joints[0].dof, Dof::uy);
}

TEST_F(ModelFileTest, ADocumentBuiltInMemoryIsCheckedWithoutLines) {
  try {
    read_model(built_cantilever("uw"), "<dict>");
    FAIL() << "expected io::Error";
  } catch (const Error& e) {
    // Named as given, no line (there is none); the key and what was expected as for a file.
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("<dict>: [[joints]] 'tip': ", 0), 0u) << message;
    EXPECT_NE(message.find("'dof'"), std::string::npos) << message;
    EXPECT_NE(message.find("\"uw\""), std::string::npos) << message;
  }
}

TEST_F(ModelFileTest, ReadsOptionalItemsAndExtensions) {
  std::string text = cantilever_toml();
  text = test::replaced(text, "modal = 0.01", "rayleigh = [0.5, 1e-4]");
  text = test::replaced(text, "values = { k = 4800.0, c = 20.0, k3 = 1.6e8 }",
                        "values = { k = 4800.0, k3 = 1.6e8 }\nfixed = [\"k\"]");
  text +=
      "\n[[joints]]\nname = \"link\"\nnode = 5\nnode_b = 6\ndof = \"rz\"\nterms = [\"k\", \"fc\"]\n"
      "values = { fc = 2 }\n"
      "\n[[masses]]\nnode = 7\nmass = 1.5\ninertia = [0.0, 0.0, 0.002]\n"
      "\n[[springs]]\nnode = 4\ndof = \"uy\"\nstiffness = 1000\n"
      "\n[[springs]]\nnode = 2\nnode_b = 3\ndof = \"rz\"\nstiffness = 50.0\n"
      "\n[options]\nlumped_mass = true\n";
  const ModelFile file = read_model(write(text));
  const fem::Model& m = file.model;
  EXPECT_EQ(m.damping.kind, fem::Damping::Kind::rayleigh);
  EXPECT_EQ(m.damping.alpha, 0.5);
  EXPECT_EQ(m.damping.beta, 1e-4);
  EXPECT_TRUE(m.mass_options.lumped);
  ASSERT_EQ(m.masses.size(), 1u);
  EXPECT_EQ(m.masses[0].node, 7);
  EXPECT_EQ(m.masses[0].mass, 1.5);
  EXPECT_EQ(m.masses[0].inertia, Eigen::Vector3d(0.0, 0.0, 0.002));
  ASSERT_EQ(m.springs.size(), 2u);
  EXPECT_EQ(m.springs[0].node, 4);
  EXPECT_EQ(m.springs[0].node_b, 0);
  EXPECT_EQ(m.springs[0].dof, Dof::uy);
  EXPECT_EQ(m.springs[0].stiffness, 1000.0);
  EXPECT_EQ(m.springs[1].node_b, 3);
  EXPECT_EQ(m.springs[1].dof, Dof::rz);

  ASSERT_EQ(file.joints.size(), 2u);
  const joints::Joint& tip = file.joints[0];
  EXPECT_EQ(tip.values, (std::vector<double>{4800.0, 0.0, 1.6e8})); // c has no value: starts at 0
  EXPECT_EQ(tip.fixed, (std::vector<bool>{true, false, false}));
  const joints::Joint& link = file.joints[1];
  EXPECT_EQ(link.node, 5);
  EXPECT_EQ(link.node_b, 6);
  EXPECT_EQ(link.dof, Dof::rz);
  EXPECT_EQ(link.terms, (std::vector<joints::Term>{joints::Term::k, joints::Term::fc}));
  EXPECT_EQ(link.values, (std::vector<double>{0.0, 2.0}));
}

TEST_F(ModelFileTest, ReadsASpatialFrame) {
  const std::string text =
      "[model]\ndimension = 3\n"
      "[[materials]]\nname = \"al\"\nE = 70e9\nrho = 2700\nnu = 0.33\n"
      "[[sections]]\nname = \"tube\"\nA = 1e-4\nIz = 2e-9\nIy = 3e-9\nJ = 4e-9\n"
      "[[sections]]\nname = \"post\"\nA = 2e-4\nIz = 5e-9\n"
      "[mesh]\nnodes = [[10, 0, 0, 0], [20, 0, 0, 1.5], [30, 1, 0, 1.5]]\n"
      "elements = [[100, 10, 20], [200, 20, 30]]\n"
      "[[element_sets]]\nelements = [100]\ntype = \"frame3d\"\nmaterial = \"al\"\n"
      "section = \"tube\"\nup = [1.0, 0.0, 0.0]\n"
      "[[element_sets]]\nelements = [200]\ntype = \"frame3d\"\nmaterial = \"al\"\n"
      "section = \"tube\"\n"
      "[[supports]]\nnode = 10\nfix = [\"ux\", \"uy\", \"uz\", \"rx\", \"ry\", \"rz\"]\n";
  const ModelFile file = read_model(write(text));
  const fem::Model& m = file.model;
  EXPECT_EQ(m.dimension, 3);
  EXPECT_EQ(m.nodes[1].x, Eigen::Vector3d(0.0, 0.0, 1.5));
  EXPECT_EQ(m.sections[0].Iy, 3e-9);
  EXPECT_EQ(m.sections[0].J, 4e-9);
  EXPECT_EQ(m.sections[1].Iy, 0.0); // optional
  ASSERT_EQ(m.elements.size(), 2u);
  EXPECT_EQ(m.elements[0].type, fem::ElementType::frame3d);
  EXPECT_EQ(m.elements[0].up, Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_FALSE(m.elements[1].up.has_value()); // not given: fem::frame3d_default_up
  EXPECT_TRUE(file.joints.empty());
}

TEST_F(ModelFileTest, UnknownKeyNamesKeyAndLine) {
  const std::string text = test::replaced(cantilever_toml(), "nu = 0.3", "nu = 0.3\nnuu = 0.3");
  expect_error(text, test::line_of(text, "nuu"), {"'nuu'", "[[materials]]", "unknown key"});
}

TEST_F(ModelFileTest, UnknownTableNamesKeyAndLine) {
  const std::string text = cantilever_toml() + "\n[dampnig]\nmodal = 0.02\n";
  expect_error(text, test::line_of(text, "[dampnig]"), {"'dampnig'", "unknown key"});
}

TEST_F(ModelFileTest, ElementOnAMissingNode) {
  const std::string text = test::replaced(cantilever_toml(), "[6, 6, 7]]", "[6, 6, 8]]");
  expect_error(text, test::line_of(text, "elements = [[1"),
               {"node 8 does not exist", "key 'elements', entry 6"});
}

TEST_F(ModelFileTest, SupportOnAMissingNode) {
  const std::string text = test::replaced(cantilever_toml(), "node = 1\n", "node = 11\n");
  expect_error(text, test::line_of(text, "node = 11"), {"node 11 does not exist", "key 'node'"});
}

TEST_F(ModelFileTest, JointOnAFixedDof) {
  const std::string text = test::replaced(cantilever_toml(), "node = 7\n", "node = 1\n");
  expect_error(text, test::line_of(text, "[[joints]]"),
               {"joint 'tip'", "1:uy", "fixed by a support"});
}

TEST_F(ModelFileTest, JointOnAnAbsentDof) {
  // Beam elements have no ux: the joint cannot act there.
  const std::string text = test::replaced(cantilever_toml(), "dof = \"uy\"", "dof = \"ux\"");
  expect_error(text, test::line_of(text, "[[joints]]"), {"joint 'tip'", "has no DOF ux"});
}

TEST_F(ModelFileTest, UnknownDofName) {
  const std::string text = test::replaced(cantilever_toml(), "dof = \"uy\"", "dof = \"uw\"");
  expect_error(
      text, test::line_of(text, "dof = \"uw\""),
      {"[[joints]] 'tip'", "key 'dof'", "expected one of ux, uy, uz, rx, ry, rz", "\"uw\""});
}

TEST_F(ModelFileTest, UnknownDofNameInASupport) {
  const std::string text = test::replaced(cantilever_toml(), "\"rz\"]", "\"rr\"]");
  expect_error(text, test::line_of(text, "fix ="), {"[[supports]] node 1", "key 'fix'", "\"rr\""});
}

TEST_F(ModelFileTest, SupportMayNameADofTheNodeLacks) {
  // ux is not a DOF of beam nodes: naming it is fine (DESIGN.md).
  const ModelFile file = read_model(write(cantilever_toml()));
  EXPECT_EQ(file.model.supports[0].fixed.front(), Dof::ux);
}

TEST_F(ModelFileTest, WrongTypeNamesExpectedType) {
  std::string text = test::replaced(cantilever_toml(), "E = 210e9", "E = \"210e9\"");
  expect_error(text, test::line_of(text, "E = "),
               {"[[materials]] 'steel'", "key 'E'", "expected a number"});
  text = test::replaced(cantilever_toml(), "dimension = 2", "dimension = 2.0");
  expect_error(text, test::line_of(text, "dimension"),
               {"[model]", "key 'dimension'", "expected an integer"});
}

TEST_F(ModelFileTest, MissingKeyIsNamed) {
  const std::string text = test::replaced(cantilever_toml(), "dof = \"uy\"\n", "");
  expect_error(text, test::line_of(text, "[[joints]]"), {"[[joints]] 'tip'", "missing key 'dof'"});
}

TEST_F(ModelFileTest, BothDampingKindsAreAnError) {
  const std::string text =
      test::replaced(cantilever_toml(), "modal = 0.01", "modal = 0.01\nrayleigh = [0.1, 0.0]");
  expect_error(text, test::line_of(text, "[damping]"), {"[damping]", "not both"});
}

TEST_F(ModelFileTest, NeitherDampingKindIsAnError) {
  const std::string text = test::replaced(cantilever_toml(), "modal = 0.01\n", "");
  expect_error(text, test::line_of(text, "[damping]"),
               {"[damping]: expected modal = ratio or rayleigh = [alpha, beta]"});
}

TEST_F(ModelFileTest, MissingTopLevelTablesAreNamed) {
  // The cantilever without the text from `begin` up to `end`.
  auto error_without = [&](std::string_view begin, std::string_view end) {
    std::string text = cantilever_toml();
    const auto a = text.find(begin), b = text.find(end);
    if (a == std::string::npos || b == std::string::npos || b < a) return std::string("bad test");
    text.erase(a, b - a);
    try {
      read_model(write(text));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string file = (dir / "cantilever.toml").string();
  EXPECT_EQ(error_without("[model]", "[[materials]]"),
            file + ": missing table [model] (expected [model] with dimension = 2 or 3)");
  EXPECT_EQ(error_without("[[materials]]", "[[sections]]"),
            file + ": missing [[materials]] (expected at least one, with name, E, rho, nu)");
  EXPECT_EQ(error_without("[[sections]]", "[mesh]"),
            file + ": missing [[sections]] (expected at least one, with name, A, Iz)");
  EXPECT_EQ(error_without("[mesh]", "[[element_sets]]"),
            file + ": missing table [mesh] (expected nodes = [[id, x, y], ...] and elements = "
                   "[[id, a, b], ...])");
}

TEST_F(ModelFileTest, ElementIdMaterialAndSectionNamesUsedTwice) {
  std::string text = test::replaced(cantilever_toml(), "[2, 2, 3]", "[1, 2, 3]");
  const int elements = test::line_of(text, "elements = [[1");
  expect_error(text, elements,
               {"key 'elements', entry 2",
                "element id 1 is already used at line " + std::to_string(elements)});
  text = cantilever_toml() +
         "\n[[materials]] # again\nname = \"steel\"\nE = 70e9\nrho = 2700.0\nnu = 0.33\n";
  expect_error(text, test::line_of(text, "# again"),
               {"[[materials]] 'steel'", "name 'steel' is used by another material"});
  text = cantilever_toml() + "\n[[sections]] # again\nname = \"bar\"\nA = 1e-3\nIz = 1e-8\n";
  expect_error(text, test::line_of(text, "# again"),
               {"[[sections]] 'bar'", "name 'bar' is used by another section"});
}

TEST_F(ModelFileTest, ElementsOutsideEverySetAreNamed) {
  const std::string text =
      test::replaced(cantilever_toml(), "elements = \"all\"", "elements = [1, 2, 3, 4]");
  expect_error(text, test::line_of(text, "elements = [[1"),
               {"elements 5, 6", "no [[element_sets]]"});
}

TEST_F(ModelFileTest, ElementsInTwoSetsAreNamed) {
  const std::string second =
      "\n[[element_sets]]\nelements = [2, 5]\ntype = \"beam\"\nmaterial = \"steel\"\n"
      "section = \"bar\"\n";
  const std::string text = cantilever_toml() + second;
  expect_error(
      text, test::line_of(text, "elements = [2, 5]"),
      {"[[element_sets]] #2", "elements 2, 5 are already in the element set at line " +
                                  std::to_string(test::line_of(text, "[[element_sets]]"))});
}

TEST_F(ModelFileTest, UnknownMaterialNameListsTheKnownOnes) {
  const std::string text =
      test::replaced(cantilever_toml(), "material = \"steel\"", "material = \"steal\"");
  expect_error(text, test::line_of(text, "material = "),
               {"key 'material'", "\"steel\"", "\"steal\""});
}

TEST_F(ModelFileTest, JointValuesAndFixedMustNameListedTerms) {
  std::string text = test::replaced(cantilever_toml(), "k3 = 1.6e8 }", "k3 = 1.6e8, c2 = 1.0 }");
  expect_error(text, test::line_of(text, "c2 = 1.0"),
               {"key 'values.c2'", "not among the joint's terms (k, c, k3)"});
  text = test::replaced(cantilever_toml(), "k3 = 1.6e8 }", "k3 = 1.6e8 }\nfixed = [\"c3\"]");
  expect_error(text, test::line_of(text, "fixed ="), {"key 'fixed'", "'c3'"});
  text = test::replaced(cantilever_toml(), "terms = [\"k\", \"c\", \"k3\"]",
                        "terms = [\"k\", \"c\", \"k4\"]");
  expect_error(text, test::line_of(text, "terms ="),
               {"key 'terms'", "\"k4\"", "expected one of k, c"});
}

TEST_F(ModelFileTest, GmshFileAndInlineMeshAreExclusive) {
  const std::string text =
      test::replaced(cantilever_toml(), "[mesh]\n", "[mesh]\nfile = \"frame.msh\"\n");
  expect_error(text, test::line_of(text, "frame.msh"), {"key 'file'", "not both"});
}

TEST_F(ModelFileTest, GroupNamesNeedAGmshMesh) {
  const std::string text =
      test::replaced(cantilever_toml(), "elements = \"all\"", "elements = \"columns\"");
  expect_error(text, test::line_of(text, "\"columns\""), {"key 'elements'", "Gmsh mesh"});
}

TEST_F(ModelFileTest, DuplicateNodeId) {
  const std::string text = test::replaced(cantilever_toml(), "[2, ", "[1, ");
  expect_error(text, test::line_of(text, "nodes ="), {"node id 1 is already used"});
}

TEST_F(ModelFileTest, InvalidPhysicalValue) {
  const std::string text = test::replaced(cantilever_toml(), "E = 210e9", "E = -210e9");
  expect_error(text, test::line_of(text, "E = "), {"key 'E'", "> 0 Pa"});
}

TEST_F(ModelFileTest, InclinedBeamElementIsReportedAtItsLine) {
  // A 'beam' must run along +x; the element's geometry is checked when reading.
  const std::string text = test::replaced(cantilever_toml(), "[7, 2, 0.0]", "[7, 2, 0.5]");
  expect_error(text, test::line_of(text, "elements = [[1"), {"element 6", "must run along +x"});
}

TEST_F(ModelFileTest, TomlSyntaxErrorGivesLineAndColumn) {
  const std::string text = test::replaced(cantilever_toml(), "rho = 7850.0", "rho = 7850.0 kg");
  const auto path = write(text);
  try {
    read_model(path);
    FAIL() << "expected io::Error";
  } catch (const Error& e) {
    const std::string expected =
        "cantilever.toml:" + std::to_string(test::line_of(text, "rho =")) + ":";
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST_F(ModelFileTest, MissingFileIsNamed) {
  try {
    read_model(dir / "nothing.toml");
    FAIL() << "expected io::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nothing.toml"), std::string::npos) << e.what();
  }
}

// A substructure given by its modes ([modal], DESIGN.md): two modes at three DOFs, a residual
// flexibility and a joint to ground at 4:uy.
std::string modal_toml() {
  return "# a substructure given by its modes\n"
         "[model]\n"
         "dimension = 2\n"
         "\n"
         "[modal]\n"
         "dofs = [\"1:uy\", \"4:uy\", \"4:rz\"]\n"
         "frequencies_hz = [80.3, 212.0]\n"
         "damping = [0.0012, 0.002]\n"
         "shapes = [[0.91, -0.40, 0.5],\n"
         "          [0.35, 0.88, -1.5]]\n"
         "residual_flexibility = [[1e-7, 0.0, 2e-9],\n"
         "                        [0.0, 2e-7, 0.0],\n"
         "                        [2e-9, 0.0, 3e-7]]\n"
         "\n"
         "[[joints]]\n"
         "name = \"tip\"\n"
         "node = 4\n"
         "dof = \"uy\"\n"
         "terms = [\"k\", \"c\"]\n"
         "values = { k = 4800.0, c = 20.0 }\n";
}

TEST_F(ModelFileTest, ReadsAModalSubstructure) {
  const ModelFile file = read_model(write(modal_toml()));
  ASSERT_TRUE(file.modal.has_value());
  const frf::ModalModel& m = *file.modal;
  EXPECT_EQ(m.dofs, (std::vector<fem::NodeDof>{{1, Dof::uy}, {4, Dof::uy}, {4, Dof::rz}}));
  ASSERT_EQ(m.frequencies_hz.size(), 2);
  EXPECT_EQ(m.frequencies_hz(0), 80.3);
  EXPECT_EQ(m.frequencies_hz(1), 212.0);
  ASSERT_EQ(m.damping.size(), 2);
  EXPECT_EQ(m.damping(0), 0.0012);
  EXPECT_EQ(m.damping(1), 0.002);
  ASSERT_EQ(m.shapes.rows(), 2); // one row per mode
  ASSERT_EQ(m.shapes.cols(), 3); // one column per DOF
  EXPECT_EQ(m.shapes(0, 1), -0.40);
  EXPECT_EQ(m.shapes(1, 2), -1.5);
  ASSERT_EQ(m.residual_flexibility.rows(), 3);
  ASSERT_EQ(m.residual_flexibility.cols(), 3);
  EXPECT_EQ(m.residual_flexibility(0, 2), 2e-9);
  EXPECT_EQ(m.residual_flexibility(2, 2), 3e-7);
  EXPECT_TRUE(file.model.nodes.empty()); // no finite element model
  EXPECT_FALSE(file.mesh.has_value());
  ASSERT_EQ(file.joints.size(), 1u);
  EXPECT_EQ(file.joints[0].node, 4);
  EXPECT_EQ(file.joints[0].dof, Dof::uy);
  EXPECT_EQ(file.joints[0].values, (std::vector<double>{4800.0, 20.0}));

  // The substructure is the modal one, its equations numbered as `dofs`.
  const frf::Substructure sub = file.substructure();
  ASSERT_NE(sub.modal(), nullptr);
  EXPECT_EQ(sub.system(), nullptr);
  EXPECT_EQ(sub.dofs().equation({4, Dof::rz}), 2);
  EXPECT_EQ(resolve_node_dof(file, "4:uy").node, 4);
}

TEST_F(ModelFileTest, ModalWithoutModelTableOrResidual) {
  // [model] is optional with [modal], and then any of the six DOFs may be listed.
  std::string text = test::replaced(modal_toml(), "[model]\ndimension = 2\n", "");
  text = test::replaced(text, "\"4:rz\"]", "\"4:uz\"]");
  const auto begin = text.find("residual_flexibility");
  text.erase(begin, text.find("\n\n[[joints]]") - begin);
  const ModelFile file = read_model(write(text));
  ASSERT_TRUE(file.modal.has_value());
  EXPECT_EQ(file.modal->dofs[2], (fem::NodeDof{4, Dof::uz}));
  EXPECT_EQ(file.modal->residual_flexibility.size(), 0);
  EXPECT_FALSE(file.substructure().synthesis({0, 1}, 0.0).has_residual());
}

TEST_F(ModelFileTest, FiniteElementModelFileHasNoModal) {
  const ModelFile file = read_model(write(cantilever_toml()));
  EXPECT_FALSE(file.modal.has_value());
  const frf::Substructure sub = file.substructure();
  ASSERT_NE(sub.system(), nullptr);
  EXPECT_EQ(sub.dofs().num_equations(), 12);
}

TEST_F(ModelFileTest, FiniteElementTablesAreErrorsWithModal) {
  const std::string why = "not used with [modal]: the substructure is given by its modes";
  const std::pair<std::string, std::string> tables[] = {
      {"[mesh]", "[mesh]\nnodes = [[1, 0.0, 0.0]]\n"},
      {"[[element_sets]]", "[[element_sets]]\nelements = \"all\"\n"},
      {"[[materials]]", "[[materials]]\nname = \"steel\"\n"},
      {"[[sections]]", "[[sections]]\nname = \"bar\"\n"},
      {"[[supports]]", "[[supports]]\nnode = 1\nfix = [\"uy\"]\n"},
      {"[[masses]]", "[[masses]]\nnode = 4\nmass = 1.0\n"},
      {"[[springs]]", "[[springs]]\nnode = 4\ndof = \"uy\"\nstiffness = 1.0\n"},
      {"[damping]", "[damping]\nmodal = 0.01\n"},
      {"[options]", "[options]\nlumped_mass = true\n"},
  };
  for (const auto& [header, table] : tables) {
    SCOPED_TRACE(header);
    const std::string key = header.substr(header.find_first_not_of('['),
                                          header.find(']') - header.find_first_not_of('['));
    // After the joints, and (a second time) before [modal].
    const std::string after = modal_toml() + "\n" + table;
    expect_error(after, test::line_of(after, header), {"key '" + key + "'", why});
    const std::string before = test::replaced(modal_toml(), "[modal]\n", table + "\n[modal]\n");
    expect_error(before, test::line_of(before, header), {"key '" + key + "'", why});
  }
}

TEST_F(ModelFileTest, ModalDofErrorsNameTheEntry) {
  const std::string dofs = "dofs = [\"1:uy\", \"4:uy\", \"4:rz\"]";
  auto with_dofs = [&](const std::string& replacement) {
    return test::replaced(modal_toml(), dofs, replacement);
  };
  std::string text = with_dofs("dofs = [\"1:uy\", \"4:uy\", \"4:uz\"]");
  expect_error(text, test::line_of(text, "dofs ="),
               {"[modal]", "key 'dofs', entry 3",
                "a planar model (dimension = 2) has only ux, uy and rz", "\"4:uz\""});
  text = with_dofs("dofs = [\"1:uy\", \"4:uw\", \"4:rz\"]");
  expect_error(text, test::line_of(text, "dofs ="),
               {"[modal]", "key 'dofs', entry 2", "expected \"<node>:<dof>\"", "\"4:uw\""});
  text = with_dofs("dofs = [\"1:uy\", \"0:uy\", \"4:rz\"]");
  expect_error(text, test::line_of(text, "dofs ="), {"key 'dofs', entry 2", "must be > 0"});
  text = with_dofs("dofs = [\"1:uy\", \"4:uy\", \"1:uy\"]");
  expect_error(text, test::line_of(text, "dofs ="),
               {"key 'dofs', entry 3", "\"1:uy\" is already entry 1"});
  text = with_dofs("dofs = [1, 4]");
  expect_error(text, test::line_of(text, "dofs ="), {"key 'dofs', entry 1", "expected a string"});
  text = with_dofs("dofs = []");
  expect_error(text, test::line_of(text, "dofs ="), {"key 'dofs'", "at least one DOF"});
  text = with_dofs("");
  expect_error(text, test::line_of(text, "[modal]"), {"[modal]", "missing key 'dofs'"});
  text = with_dofs(dofs + "\nfrequencies = [1.0]");
  expect_error(text, test::line_of(text, "frequencies = "),
               {"[modal]", "unknown key 'frequencies'", "frequencies_hz"});
}

TEST_F(ModelFileTest, ModalValueErrorsNameKeyAndLine) {
  std::string text =
      test::replaced(modal_toml(), "frequencies_hz = [80.3, 212.0]", "frequencies_hz = [80.3, -2]");
  expect_error(
      text, test::line_of(text, "frequencies_hz"),
      {"[modal]", "key 'frequencies_hz', entry 2", "expected a frequency >= 0 Hz, got -2"});
  text = test::replaced(modal_toml(), "frequencies_hz = [80.3, 212.0]", "frequencies_hz = []");
  expect_error(text, test::line_of(text, "frequencies_hz"),
               {"key 'frequencies_hz'", "at least one mode"});
  text = test::replaced(modal_toml(), "damping = [0.0012, 0.002]", "damping = [0.0012]");
  expect_error(text, test::line_of(text, "damping ="),
               {"[modal]", "key 'damping'", "expected 2 damping ratios", "got 1"});
  text = test::replaced(modal_toml(), "damping = [0.0012, 0.002]", "damping = [-0.1, 0.002]");
  expect_error(text, test::line_of(text, "damping ="),
               {"key 'damping', entry 1", "expected a damping ratio >= 0, got -0.1"});
  text = test::replaced(modal_toml(), "damping = [0.0012, 0.002]", "damping = [0.0012, \"1%\"]");
  expect_error(text, test::line_of(text, "damping ="),
               {"key 'damping', entry 2", "expected a number", "\"1%\""});
  text = test::replaced(modal_toml(), "[0.35, 0.88, -1.5]]", "[0.35, 0.88]]");
  expect_error(text, test::line_of(text, "[0.35, 0.88]]"),
               {"[modal]", "key 'shapes', row 2", "expected 3 numbers",
                "one column per entry of dofs", "got 2 numbers"});
  text = test::replaced(modal_toml(), ",\n          [0.35, 0.88, -1.5]]", "]");
  expect_error(text, test::line_of(text, "shapes ="),
               {"key 'shapes'", "expected 2 rows of 3 numbers", "got 1 rows"});
  text = test::replaced(modal_toml(), "[0.35, 0.88, -1.5]]", "[0.35, 0.88, inf]]");
  expect_error(text, test::line_of(text, "inf]]"), {"key 'shapes', row 2", "finite number"});
  text = test::replaced(modal_toml(), "[2e-9, 0.0, 3e-7]]", "[3e-9, 0.0, 3e-7]]");
  expect_error(text, test::line_of(text, "[3e-9"),
               {"[modal]", "key 'residual_flexibility', row 3", "expected a symmetric matrix",
                "entry 1 of row 3 is 3e-09, entry 3 of row 1 is 2e-09"});
  text = test::replaced(modal_toml(), ",\n                        [2e-9, 0.0, 3e-7]]", "]");
  expect_error(text, test::line_of(text, "residual_flexibility"),
               {"key 'residual_flexibility'", "expected 3 rows of 3 numbers", "got 2 rows"});
}

TEST_F(ModelFileTest, ModalJointsMustBeOnListedDofs) {
  std::string text = test::replaced(modal_toml(), "node = 4\n", "node = 7\n");
  expect_error(text, test::line_of(text, "node = 7"),
               {"[[joints]] 'tip'", "key 'node'", "node 7 is not among the [modal] dofs"});
  text = test::replaced(modal_toml(), "dof = \"uy\"", "dof = \"ux\"");
  expect_error(text, test::line_of(text, "[[joints]]"),
               {"joint 'tip'", "node 4 has no DOF ux", "not among the substructure's DOFs"});
  text = test::replaced(modal_toml(), "node = 4\n", "node = 4\nnode_b = 9\n");
  expect_error(text, test::line_of(text, "node_b = 9"),
               {"key 'node_b'", "node 9 is not among the [modal] dofs"});
  text = test::replaced(modal_toml(), "node = 4\n", "node = \"tip\"\n");
  expect_error(text, test::line_of(text, "node = \"tip\""),
               {"key 'node'", "expected a node id", "[modal]"});
  // A joint between two listed DOFs is fine.
  text = test::replaced(modal_toml(), "node = 4\n", "node = 4\nnode_b = 1\n");
  EXPECT_EQ(read_model(write(text)).joints[0].node_b, 1);
}

// Gmsh meshes: the shipped portal-frame example, and errors on a copy of it.
class GmshModelTest : public ::testing::Test {
protected:
  std::string portal_toml() const { return read_file(source / "portal.toml"); }
  std::filesystem::path write(const std::string& text) {
    std::filesystem::copy_file(source / "portal.msh", dir / "portal.msh",
                               std::filesystem::copy_options::overwrite_existing);
    const auto path = dir / "portal.toml";
    test::write_text(path, text);
    return path;
  }
  void expect_error(const std::string& text, int line, std::initializer_list<std::string> parts) {
    ASSERT_GT(line, 0) << "bad test: line not found";
    try {
      read_model(write(text));
      FAIL() << "expected io::Error";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("portal.toml:" + std::to_string(line) + ":"), std::string::npos)
          << message;
      for (const auto& p : parts)
        EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' not in: " << message;
    }
  }
  const std::filesystem::path source =
      std::filesystem::path(JOINTID_SOURCE_DIR) / "examples/portal_frame";
  test::TempDir dir;
};

TEST_F(GmshModelTest, ReadsThePortalFrame) {
  const ModelFile file = read_model(source / "portal.toml");
  const fem::Model& m = file.model;
  // portal.geo: 3 m columns and a 4 m beam meshed at 0.25 m: 12 + 16 + 12 elements.
  EXPECT_EQ(m.elements.size(), 40u);
  EXPECT_EQ(m.nodes.size(), 41u);
  for (const auto& e : m.elements)
    EXPECT_EQ(e.type, fem::ElementType::frame2d);
  ASSERT_EQ(m.supports.size(), 2u); // "base": both feet, nodes 1 and 4 of the mesh
  EXPECT_EQ(m.supports[0].node, 1);
  EXPECT_EQ(m.supports[1].node, 4);
  ASSERT_EQ(file.joints.size(), 1u);
  EXPECT_EQ(file.joints[0].node, 2); // "corner": the top of the left column
  EXPECT_EQ(file.joints[0].dof, Dof::ux);
  double length = 0.0;
  for (const auto& e : m.elements)
    length += (m.nodes[m.node_index(e.node_b)].x - m.nodes[m.node_index(e.node_a)].x).norm();
  EXPECT_NEAR(length, 10.0, 1e-9);
}

TEST_F(GmshModelTest, NodeDofTextAcceptsIdsAndOneNodeGroups) {
  const ModelFile file = read_model(source / "portal.toml");
  EXPECT_EQ(resolve_node_dof(file, "corner:uy").node, 2); // Physical Point("corner") = node 2
  EXPECT_EQ(resolve_node_dof(file, "corner:uy").dof, Dof::uy);
  EXPECT_EQ(resolve_node_dof(file, "7:rz").node, 7);
  auto error = [&](std::string_view text) {
    try {
      resolve_node_dof(file, text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("base:ux").find("holds 2 nodes"), std::string::npos) << error("base:ux");
  EXPECT_NE(error("roof:ux").find("\"corner\""), std::string::npos) << error("roof:ux");
  EXPECT_NE(error("corner:uz3").find("uz3"), std::string::npos) << error("corner:uz3");
  EXPECT_NE(error("corner").find("NODE:DOF"), std::string::npos) << error("corner");
  // Without a mesh a name cannot be resolved.
  ModelFile no_mesh = file;
  no_mesh.mesh.reset();
  EXPECT_EQ(resolve_node_dof(no_mesh, "7:ux").node, 7); // ids still work
  try {
    resolve_node_dof(no_mesh, "corner:ux");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no Gmsh mesh"), std::string::npos) << e.what();
  }
}

TEST_F(GmshModelTest, ReadsTheTableFrame) {
  const ModelFile file = read_model(source.parent_path() / "table_frame/table.toml");
  int legs = 0;
  for (const auto& e : file.model.elements) {
    EXPECT_EQ(e.type, fem::ElementType::frame3d);
    if (e.up && *e.up == Eigen::Vector3d::UnitX()) ++legs;
  }
  EXPECT_EQ(legs, 4 * 8); // four 0.75 m legs meshed at 0.1 m
  EXPECT_EQ(file.model.supports.size(), 4u);
}

TEST_F(GmshModelTest, AGroupWithoutElementSetIsNamed) {
  std::string text = portal_toml();
  const auto begin = text.find("[[element_sets]]\nelements = \"beam\"");
  ASSERT_NE(begin, std::string::npos);
  text.erase(begin, text.find("[[supports]]") - begin);
  expect_error(text, test::line_of(text, "file = "), {"in no [[element_sets]]", "'beam'"});
}

TEST_F(GmshModelTest, MeshNodesOffThePlaneOrWithIdZeroAreRefused) {
  const std::string mesh = read_file(source / "portal.msh");
  auto error_with_mesh = [&](const std::string& msh) {
    const auto path = write(portal_toml());
    test::write_text(dir / "portal.msh", msh);
    try {
      read_model(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string msh = (dir / "portal.msh").string(), toml = (dir / "portal.toml").string();
  EXPECT_EQ(error_with_mesh(test::replaced(mesh, "\n5 0 0.249999999998938 0\n",
                                           "\n5 0 0.249999999998938 0.125\n")),
            msh + ": node 5 has z = 0.125, but " + toml +
                " declares a planar model (dimension = 2)");
  // An extra node 0, on no element (Gmsh itself accepts it): 0 means ground in jointid.
  EXPECT_EQ(error_with_mesh(test::replaced(mesh, "$Nodes\n41\n", "$Nodes\n42\n0 9 9 0\n")),
            msh + ": node ids must be > 0 (0 means ground), got 0");
}

TEST_F(GmshModelTest, UnknownGroupsAndAmbiguousNodesAreErrors) {
  const std::string roof =
      test::replaced(portal_toml(), "elements = \"beam\"", "elements = \"roof\"");
  expect_error(roof, test::line_of(roof, "\"roof\""), {"key 'elements'", "'roof'"});
  const std::string two = test::replaced(portal_toml(), "node = \"corner\"", "node = \"base\"");
  expect_error(two, test::line_of(two, "node = \"base\""), {"key 'node'", "holds 2 nodes"});
  const std::string missing =
      test::replaced(portal_toml(), "file = \"portal.msh\"", "file = \"nowhere.msh\"");
  try {
    read_model(write(missing));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nowhere.msh"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace jointid::io
