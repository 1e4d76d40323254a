// VTK files and PNG pictures of mode shapes, read back with VTK's own readers and checked
// against the modal analysis they were written from.
#include "report/vtk_output.hpp"

#include "fem/assembly.hpp"
#include "io/test_files.hpp"
#include "report/vtk_models.hpp"
#include "support/display.hpp"

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <regex>
#include <set>
#include <string>

namespace jointid::report {
namespace {

namespace fs = std::filesystem;

struct Analysed {
  fem::Model model;
  fem::Assembled system;
  fem::Modes modes;
};

Analysed analyse(const fem::Model& model, int num_modes) {
  Analysed a{model, fem::assemble(model), {}};
  a.modes = fem::modal_analysis(a.system, {.num_modes = num_modes});
  EXPECT_TRUE(a.modes.status.ok());
  return a;
}

vtkSmartPointer<vtkUnstructuredGrid> read_vtu(const fs::path& path) {
  EXPECT_TRUE(fs::is_regular_file(path)) << path;
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkSmartPointer<vtkUnstructuredGrid> grid = reader->GetOutput();
  return grid;
}

/// φ of mode r at (node, dof), looked up through DofMap::state / equation; 0 unless free.
double phi_at(const Analysed& a, int node, fem::Dof dof, int r) {
  const fem::NodeDof nd{node, dof};
  if (a.system.dofs.state(nd) != fem::DofMap::State::free) return 0.0;
  return a.modes.phi(a.system.dofs.equation(nd), r);
}

/// Checks that `modes.vtu` holds φ of every mode at every node, and the frequencies.
void expect_mode_arrays(const Analysed& a, vtkUnstructuredGrid* grid) {
  const int n_modes = a.modes.num_modes();
  for (int r = 0; r < n_modes; ++r) {
    const std::string mode = "mode_" + std::to_string(r + 1);
    vtkDataArray* translation = grid->GetPointData()->GetArray((mode + "_translation").c_str());
    vtkDataArray* rotation = grid->GetPointData()->GetArray((mode + "_rotation").c_str());
    ASSERT_NE(translation, nullptr) << mode;
    ASSERT_NE(rotation, nullptr) << mode;
    ASSERT_EQ(translation->GetNumberOfComponents(), 3);
    ASSERT_EQ(rotation->GetNumberOfComponents(), 3);
    ASSERT_EQ(translation->GetNumberOfTuples(), static_cast<vtkIdType>(a.model.nodes.size()));
    for (std::size_t i = 0; i < a.model.nodes.size(); ++i) {
      const int node = a.model.nodes[i].id;
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(translation->GetComponent(i, c), phi_at(a, node, fem::all_dofs[c], r))
            << mode << " node " << node << " component " << c;
        EXPECT_EQ(rotation->GetComponent(i, c), phi_at(a, node, fem::all_dofs[3 + c], r))
            << mode << " node " << node << " component " << c;
      }
    }
  }
  EXPECT_EQ(grid->GetPointData()->GetArray(
                ("mode_" + std::to_string(n_modes + 1) + "_translation").c_str()),
            nullptr);
  vtkDataArray* f = grid->GetFieldData()->GetArray("frequency_hz");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(f->GetNumberOfTuples(), n_modes);
  for (int r = 0; r < n_modes; ++r)
    EXPECT_DOUBLE_EQ(f->GetComponent(r, 0), a.modes.frequency_hz(r)) << "mode " << r + 1;
}

/// The files a .pvd collection lists, in order.
std::vector<std::string> pvd_files(const fs::path& pvd) {
  const std::string text = test::read_text(pvd);
  const std::regex dataset(R"re(<DataSet[^>]*file="([^"]+)")re");
  std::vector<std::string> files;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), dataset);
       it != std::sregex_iterator(); ++it)
    files.push_back((*it)[1]);
  return files;
}

using jointid::test::have_display;
using jointid::test::no_display;

// ----- mesh.vtu and modes.vtu -----------------------------------------------------------------

TEST(VtkOutput, MeshHasTheNodesElementsAndNodeIds) {
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes);

  const auto mesh = read_vtu(dir / "mesh.vtu");
  ASSERT_EQ(mesh->GetNumberOfPoints(), 4);
  ASSERT_EQ(mesh->GetNumberOfCells(), 3);
  vtkDataArray* ids = mesh->GetPointData()->GetArray("node_id");
  ASSERT_NE(ids, nullptr);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(ids->GetComponent(i, 0), 10.0 * (i + 1));
    double p[3];
    mesh->GetPoint(i, p);
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(p[c], a.model.nodes[i].x(c)) << "node " << i;
  }
  vtkDataArray* element_ids = mesh->GetCellData()->GetArray("element_id");
  ASSERT_NE(element_ids, nullptr);
  for (int e = 0; e < 3; ++e) {
    EXPECT_EQ(mesh->GetCellType(e), VTK_LINE);
    EXPECT_EQ(element_ids->GetComponent(e, 0), e + 1.0);
    // Element e joins nodes e and e + 1 of the portal (feet, corners, feet).
    EXPECT_EQ(mesh->GetCell(e)->GetPointId(0), e);
    EXPECT_EQ(mesh->GetCell(e)->GetPointId(1), e + 1);
  }
}

TEST(VtkOutput, ModeArraysHoldPhiAtTheRightNodes3dFrame) {
  const Analysed a = analyse(test::portal_frame(), 4);
  ASSERT_EQ(a.modes.num_modes(), 4);
  test::TempDir dir;
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes);

  const auto grid = read_vtu(dir / "modes.vtu");
  ASSERT_EQ(grid->GetNumberOfPoints(), 4);
  ASSERT_EQ(grid->GetNumberOfCells(), 3);
  ASSERT_NE(grid->GetPointData()->GetArray("node_id"), nullptr);
  expect_mode_arrays(a, grid);
  // The clamped feet do not move; the corners do.
  vtkDataArray* t1 = grid->GetPointData()->GetArray("mode_1_translation");
  EXPECT_EQ(t1->GetComponent(0, 0), 0.0);
  EXPECT_EQ(t1->GetComponent(3, 2), 0.0);
  EXPECT_GT(std::abs(t1->GetComponent(1, 0)) + std::abs(t1->GetComponent(1, 1)), 0.0);
}

TEST(VtkOutput, AbsentDofsAreZero2dBeam) {
  // Beam elements have uy and rz only: ux, uz, rx and ry are absent everywhere.
  const Analysed a = analyse(test::beam_cantilever(5), 3);
  test::TempDir dir;
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes, {.frames = 4, .binary = false});
  const auto grid = read_vtu(dir / "modes.vtu");
  ASSERT_EQ(grid->GetNumberOfPoints(), 6);
  ASSERT_EQ(grid->GetNumberOfCells(), 5);
  expect_mode_arrays(a, grid);
  vtkDataArray* t = grid->GetPointData()->GetArray("mode_2_translation");
  vtkDataArray* rot = grid->GetPointData()->GetArray("mode_2_rotation");
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(t->GetComponent(i, 0), 0.0);
    EXPECT_EQ(t->GetComponent(i, 2), 0.0);
    EXPECT_EQ(rot->GetComponent(i, 0), 0.0);
    EXPECT_EQ(rot->GetComponent(i, 1), 0.0);
  }
  EXPECT_NE(t->GetComponent(5, 1), 0.0);   // tip uy
  EXPECT_NE(rot->GetComponent(5, 2), 0.0); // tip rz
}

// ----- animations -----------------------------------------------------------------------------

TEST(VtkOutput, PvdListsFramesOfTheScaledSineMotion) {
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  const int frames = 24;
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes, {.frames = frames});
  const double diagonal = std::hypot(4.0, 3.0); // bounding box 4 m × 0 × 3 m

  for (int r = 0; r < 4; ++r) {
    const std::string mode = "mode_" + std::to_string(r + 1);
    const std::vector<std::string> files = pvd_files(dir / (mode + ".pvd"));
    ASSERT_EQ(files.size(), static_cast<std::size_t>(frames)) << mode;
    // Largest nodal translation of the mode, for the expected scale.
    double max_translation = 0.0;
    for (const auto& node : a.model.nodes) {
      Eigen::Vector3d u;
      for (int c = 0; c < 3; ++c)
        u(c) = phi_at(a, node.id, fem::all_dofs[c], r);
      max_translation = std::max(max_translation, u.norm());
    }
    const double scale = 0.1 * diagonal / max_translation;
    for (int k = 0; k < frames; ++k) {
      EXPECT_EQ(files[k], mode + "/frame_" + std::to_string(k) + ".vtu");
      const auto frame = read_vtu(dir / files[k]);
      ASSERT_EQ(frame->GetNumberOfPoints(), 4);
      ASSERT_EQ(frame->GetNumberOfCells(), 3);
      const double s = scale * std::sin(2.0 * std::numbers::pi * k / frames);
      for (int i = 0; i < 4; ++i) {
        double p[3];
        frame->GetPoint(i, p);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(
              p[c], a.model.nodes[i].x(c) + s * phi_at(a, a.model.nodes[i].id, fem::all_dofs[c], r),
              1e-12 * diagonal)
              << mode << " frame " << k << " node " << i;
      }
    }
  }
}

TEST(VtkOutput, RewritingReplacesOldOutputAndLeavesNoTemporaries) {
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  test::write_text(dir / "modes.json", "{}\n"); // someone else's file in the same directory
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes, {.frames = 24});
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes, {.frames = 6});

  EXPECT_EQ(pvd_files(dir / "mode_1.pvd").size(), 6u);
  int frame_files = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(dir / "mode_1"))
    ++frame_files;
  EXPECT_EQ(frame_files, 6);
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir.path()))
    names.insert(entry.path().filename().string());
  const std::set<std::string> expected = {"mesh.vtu",   "modes.vtu",  "modes.json", "mode_1",
                                          "mode_2",     "mode_3",     "mode_4",     "mode_1.pvd",
                                          "mode_2.pvd", "mode_3.pvd", "mode_4.pvd"};
  EXPECT_EQ(names, expected);
  EXPECT_EQ(test::read_text(dir / "modes.json"), "{}\n");
}

TEST(VtkOutput, ErrorsNameThePathAndKeepEarlierOutput) {
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  const fs::path file = dir / "not_a_directory";
  test::write_text(file, "x");
  try {
    write_modes_vtk(file, a.model, a.system.dofs, a.modes);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(test::read_text(file), "x");

  // Modes that do not belong to the DOF map are refused before anything is written.
  write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes);
  const std::string before = test::read_text(dir / "modes.vtu");
  fem::Modes wrong = a.modes;
  wrong.phi.conservativeResize(wrong.phi.rows() - 1, Eigen::NoChange);
  EXPECT_THROW(write_modes_vtk(dir.path(), a.model, a.system.dofs, wrong), std::invalid_argument);
  EXPECT_THROW(write_modes_vtk(dir.path(), a.model, a.system.dofs, a.modes, {.frames = 0}),
               std::invalid_argument);
  EXPECT_EQ(test::read_text(dir / "modes.vtu"), before);
}

// ----- pictures -------------------------------------------------------------------------------

TEST(VtkPng, PortalFramePictureHasTheSizeAndIsNotBlank) {
  if (!have_display()) GTEST_SKIP() << no_display;
  const Analysed a = analyse(test::portal_frame(4), 6);
  test::TempDir dir;
  const fs::path png = dir / "portal.png";
  render_modes_png(png, a.model, a.system.dofs, a.modes, 4, {.width = 640, .height = 480});

  vtkNew<vtkPNGReader> reader;
  ASSERT_TRUE(reader->CanReadFile(png.c_str())) << png;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  EXPECT_EQ(dims[0], 640);
  EXPECT_EQ(dims[1], 480);
  ASSERT_GE(image->GetNumberOfScalarComponents(), 3);
  // Mostly white background, with grey (undeformed) and blue (mode shape) lines in every panel.
  int white = 0, blue = 0, other = 0;
  int blue_in_quadrant[4] = {0, 0, 0, 0};
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const auto* rgb = static_cast<unsigned char*>(image->GetScalarPointer(x, y, 0));
      if (rgb[0] > 245 && rgb[1] > 245 && rgb[2] > 245)
        ++white;
      else if (rgb[2] > rgb[0] + 60)
        ++blue, ++blue_in_quadrant[(x < dims[0] / 2 ? 0 : 1) + (y < dims[1] / 2 ? 2 : 0)];
      else
        ++other;
    }
  const int total = dims[0] * dims[1];
  EXPECT_GT(white, total / 2);
  EXPECT_GT(blue, total / 200);
  EXPECT_GT(other, total / 500); // grey lines and black titles
  for (int q = 0; q < 4; ++q)
    EXPECT_GT(blue_in_quadrant[q], 100) << "panel " << q;

  // No temporary files are left next to the picture.
  int files = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 1);
}

TEST(VtkPng, CantileverPictureHasTheRequestedSize) {
  if (!have_display()) GTEST_SKIP() << no_display;
  const Analysed a = analyse(test::beam_cantilever(10), 3);
  test::TempDir dir;
  const fs::path png = dir / "cantilever.png";
  render_modes_png(png, a.model, a.system.dofs, a.modes, 5, {.width = 900, .height = 300});
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  int dims[3];
  reader->GetOutput()->GetDimensions(dims);
  EXPECT_EQ(dims[0], 900);
  EXPECT_EQ(dims[1], 300);
  double range[2];
  reader->GetOutput()->GetPointData()->GetScalars()->GetRange(range, 0);
  EXPECT_LT(range[0], 100.0);
  EXPECT_EQ(range[1], 255.0);
}

TEST(VtkPng, UnwritablePathThrowsNamingIt) {
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  const fs::path png = dir / "missing_dir" / "x.png";
  try {
    render_modes_png(png, a.model, a.system.dofs, a.modes, 2, {.width = 200, .height = 150});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(png.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "missing_dir"));
}

TEST(VtkPng, BadArgumentsAreRefused) {
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  EXPECT_THROW(render_modes_png(dir / "x.png", a.model, a.system.dofs, a.modes, 0),
               std::invalid_argument);
  EXPECT_THROW(render_modes_png(dir / "x.png", a.model, a.system.dofs, a.modes, 2, {.width = 0}),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(VtkPng, WithoutDisplayTheErrorSaysToUseXvfbRun) {
  // Debian's VTK renders through GLX and would abort the process without an X server; the
  // library checks first and throws instead, whether DISPLAY is unset or names no server.
  const Analysed a = analyse(test::portal_frame(), 4);
  test::TempDir dir;
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display != nullptr ? display : "";
  const bool had_display = display != nullptr;
  for (const char* value : {static_cast<const char*>(nullptr), ":4242"}) {
    if (value == nullptr)
      ::unsetenv("DISPLAY");
    else
      ::setenv("DISPLAY", value, 1);
    try {
      render_modes_png(dir / "x.png", a.model, a.system.dofs, a.modes, 2);
      ADD_FAILURE() << "expected std::runtime_error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("xvfb-run"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find((dir / "x.png").string()), std::string::npos);
    }
  }
  if (had_display)
    ::setenv("DISPLAY", saved.c_str(), 1);
  else
    ::unsetenv("DISPLAY");
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

} // namespace
} // namespace jointid::report
