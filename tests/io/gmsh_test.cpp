#include "io/gmsh.hpp"

#include "io/files.hpp"
#include "io/test_files.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace jointid;

namespace {

// A directory of this process's own: ctest runs the tests of this file in parallel processes,
// and a shared directory let one test read another's half-written file.
std::filesystem::path write_temp(const std::string& name, const std::string& text) {
  static const test::TempDir dir;
  const auto path = dir / name;
  test::write_text(path, text);
  return path;
}

// An L-shaped frame: column 1–2–3 (group "column"), beam 3–4 (group "beam"), base point 1
// ("base"), tip point 4 ("tip"). The same mesh in both formats.
const char* msh22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
4
0 10 "base"
0 11 "tip"
1 20 "column"
1 21 "beam"
$EndPhysicalNames
$Nodes
4
1 0 0 0
2 0 1.5 0
3 0 3 0
4 2 3 0
$EndNodes
$Elements
5
1 15 2 10 1 1
2 15 2 11 2 4
3 1 2 20 1 1 2
4 1 2 20 1 2 3
5 1 2 21 2 3 4
$EndElements
)";

const char* msh41 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
4
0 10 "base"
0 11 "tip"
1 20 "column"
1 21 "beam"
$EndPhysicalNames
$Entities
2 2 0 0
1 0 0 0 1 10
2 2 3 0 1 11
1 0 0 0 0 3 0 1 20 2 1 -3
2 0 3 0 2 3 0 1 21 2 3 -2
$EndEntities
$Nodes
4 4 1 4
0 1 0 1
1
0 0 0
0 2 0 1
4
2 3 0
1 1 0 2
2
3
0 1.5 0
0 3 0
1 2 0 0
$EndNodes
$Elements
4 5 1 5
0 1 15 1
1 1
0 2 15 1
2 4
1 1 1 2
3 1 2
4 2 3
1 2 1 1
5 3 4
$EndElements
)";

void expect_l_frame(const io::GmshMesh& m) {
  ASSERT_EQ(m.nodes.size(), 4u);
  ASSERT_EQ(m.lines.size(), 3u);
  EXPECT_EQ(m.elements_in("column"), (std::vector<int>{3, 4}));
  EXPECT_EQ(m.elements_in("beam"), (std::vector<int>{5}));
  EXPECT_EQ(m.nodes_in("base"), (std::vector<int>{1}));
  EXPECT_EQ(m.nodes_in("tip"), (std::vector<int>{4}));
  EXPECT_EQ(m.nodes_in("column"), (std::vector<int>{1, 2, 3})); // a line group as a node set
  for (const auto& n : m.nodes) {
    if (n.id == 2) {
      EXPECT_DOUBLE_EQ(n.x.y(), 1.5);
    }
  }
}

void expect_error(const std::string& text, const std::string& fragment, const std::string& line) {
  const auto path = write_temp("bad.msh", text);
  try {
    io::read_gmsh(path);
    FAIL() << "accepted a mesh that should fail with: " << fragment;
  } catch (const io::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string() + ":" + line + ": "), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

} // namespace

TEST(Gmsh, ReadsFormat22) {
  expect_l_frame(io::read_gmsh(write_temp("l22.msh", msh22)));
}

TEST(Gmsh, ReadsFormat41WithEntityPhysicalGroups) {
  expect_l_frame(io::read_gmsh(write_temp("l41.msh", msh41)));
}

TEST(Gmsh, UnknownGroupIsAnError) {
  const auto path = write_temp("l22.msh", msh22);
  const io::GmshMesh m = io::read_gmsh(path);
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const io::Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(message([&] { m.elements_in("roof"); }),
            path.string() + ": no physical group of lines named 'roof'");
  EXPECT_EQ(message([&] { m.nodes_in("roof"); }),
            path.string() + ": no physical group of points or lines named 'roof'");
  // "tip" is a group of points: not a group of lines.
  EXPECT_EQ(message([&] { m.elements_in("tip"); }),
            path.string() + ": no physical group of lines named 'tip'");
}

TEST(Gmsh, TruncatedFilesAndUnclosedSectionsNameTheLine) {
  const std::string text = msh22;
  // Cut inside $Nodes (after node 2, line 14), and right after the last node (line 16).
  expect_error(text.substr(0, text.find("3 0 3 0")), "unexpected end of file, expected a node",
               "14");
  expect_error(text.substr(0, text.find("$EndNodes")), "unexpected end of file, expected $EndNodes",
               "16");
  // One node more than announced: the fifth stands where $EndNodes should.
  expect_error(replace(msh22, "4 2 3 0\n", "4 2 3 0\n5 2 4 0\n"),
               "expected $EndNodes, got '5 2 4 0'", "17");
  // A section jointid skips, never closed: the end of the file is where it was looked for.
  expect_error(text + "$Comments\nmeshed by hand\n", "section $Comments has no $EndComments", "27");
  expect_error(text.substr(0, text.find("$EndMeshFormat")),
               "unexpected end of file, expected $EndMeshFormat", "2");
}

TEST(Gmsh, MalformedLinesNameWhatWasExpected) {
  // Format 2.2: a node, an element's tags and nodes, a physical name.
  expect_error(replace(msh22, "2 0 1.5 0", "2 0 1.5"), "expected a node: id x y z", "14");
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "5 1 2 21"), "element 5: expected 2 tags", "24");
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "5 1 2 21 2 3"), "element 5: expected 2 node ids",
               "24");
  expect_error(replace(msh22, "1 21 \"beam\"", "1 21"),
               "expected a physical name: dim tag \"name\"", "9");
  // Format 4.1: node coordinates, an entity, an element.
  expect_error(replace(msh41, "0 1.5 0", "0 x 0"), "expected node coordinates x y z", "29");
  expect_error(replace(msh41, "2 0 3 0 2 3 0 1 21 2 3 -2", "2 0 3 0 2 3 0"),
               "expected an entity: tag, coordinates, number of physical tags", "16");
  expect_error(replace(msh41, "5 3 4", "5 3"), "element 5: expected 2 node ids", "43");
}

TEST(Gmsh, MeshWithoutLinesIsAnError) {
  // Only the two points of the L-frame: nothing to build beams from.
  std::string points = replace(msh22, "5\n1 15", "2\n1 15");
  points = replace(points, "3 1 2 20 1 1 2\n4 1 2 20 1 2 3\n5 1 2 21 2 3 4\n", "");
  const auto path = write_temp("points.msh", points);
  try {
    io::read_gmsh(path);
    FAIL() << "accepted a mesh without lines";
  } catch (const io::Error& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": the mesh has no 2-node line elements");
  }
}

TEST(Gmsh, ErrorsNameFileLineAndProblem) {
  // Element 5 stands on line 24 of the file, node 4 on line 16.
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "5 2 2 21 2 2 3 4"), "triangle", "24");
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "5 8 2 21 2 3 4 2"), "second-order", "24");
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "5 1 2 21 2 3 9"), "node 9", "24");
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "4 1 2 21 2 3 4"), "duplicate element 4", "24");
  expect_error(replace(msh22, "4 2 3 0", "3 2 3 0"), "duplicate node 3", "16");
  expect_error(replace(msh22, "4 2 3 0", "4 0 3 0"), "zero length", "24");
  expect_error(replace(msh22, "2.2 0 8", "3.0 0 8"), "unsupported .msh format 3.0", "2");
  expect_error(replace(msh22, "2.2 0 8", "2.2 1 8"), "binary", "2");
}

// Fuzzing regressions (docs/fuzzing.md): counts read from the file (tags of an element,
// physical tags of an entity, nodes of a block) sized vectors before their values were read, so a
// short file asked for gigabytes; now the values are read one by one and the file's end says.
TEST(Gmsh, CountsBeyondTheFileAreErrorsNotAllocations) {
  expect_error(replace(msh22, "5 1 2 21 2 3 4", "5 1 2000000000 21 2 3 4"),
               "element 5: expected 2000000000 tags", "24");
  expect_error(replace(msh41, "1 0 0 0 1 10", "1 0 0 0 99999999999 10"),
               "entity 1: expected 99999999999 physical tags", "13");
  expect_error(replace(msh41, "0 1 0 1\n", "0 1 0 99999999999\n"), "expected a node tag", "32");
  // The input fuzz_gmsh found in 6 s on the old reader (std::length_error): a point entity whose
  // number of physical tags is -3, read into an unsigned count.
  expect_error(replace(msh41, "2 2 3 0 1 11", "2 2 3  1 -3"),
               "entity 2: expected a number of physical tags >= 0, got -3", "14");
}
