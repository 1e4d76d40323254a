#include "report/vtk_output.hpp"

#include "fem/constants.hpp"
#include "io/files.hpp"
#include "report/vtk_display.hpp"
#include "report/vtk_render.hpp"

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkCoordinate.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace jointid::report {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// Checks and nodal mode shapes

void check_modes(const fem::Model& model, const fem::DofMap& dofs, const fem::Modes& modes) {
  const auto& ids = dofs.node_ids();
  bool same_nodes = ids.size() == model.nodes.size();
  for (std::size_t i = 0; same_nodes && i < ids.size(); ++i)
    same_nodes = ids[i] == model.nodes[i].id;
  if (!same_nodes)
    throw std::invalid_argument("VTK output: the DOF map was built for a different model (its "
                                "node ids differ from the model's)");
  if (modes.phi.rows() != dofs.num_equations() || modes.phi.cols() != modes.omega.size())
    throw std::invalid_argument("VTK output: phi is " + std::to_string(modes.phi.rows()) + " × " +
                                std::to_string(modes.phi.cols()) + " but the DOF map has " +
                                std::to_string(dofs.num_equations()) + " equations and there are " +
                                std::to_string(modes.omega.size()) + " frequencies");
}

/// Node positions, 3 × n_nodes in model order.
Eigen::Matrix3Xd node_positions(const fem::Model& model) {
  Eigen::Matrix3Xd x(3, model.nodes.size());
  for (std::size_t i = 0; i < model.nodes.size(); ++i)
    x.col(i) = model.nodes[i].x;
  return x;
}

/// Mode r at the nodes: 6 × n_nodes (ux uy uz rx ry rz), 0 where a DOF is absent or fixed.
Eigen::Matrix<double, 6, Eigen::Dynamic>
nodal_shape(const fem::Model& model, const fem::DofMap& dofs, const fem::Modes& modes, int r) {
  Eigen::Matrix<double, 6, Eigen::Dynamic> u =
      Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, model.nodes.size());
  for (std::size_t i = 0; i < model.nodes.size(); ++i) {
    const auto eq = dofs.node_equations(model.nodes[i].id);
    for (int d = 0; d < 6; ++d)
      if (eq[d] >= 0) u(d, i) = modes.phi(eq[d], r);
  }
  return u;
}

/// Diagonal of the model's bounding box, m (1 for a model of a single point).
double model_size(const Eigen::Matrix3Xd& x) {
  if (x.cols() == 0) return 1.0;
  const double size = (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).norm();
  return size > 0.0 ? size : 1.0;
}

/// Factor on a nodal shape that makes its largest translation `fraction` · size. A mode that
/// does not translate any node is scaled so that its largest rotation is `fraction` rad.
double shape_scale(const Eigen::Matrix<double, 6, Eigen::Dynamic>& u, double size,
                   double fraction) {
  if (u.cols() == 0) return 0.0;
  const double max_translation = u.topRows<3>().colwise().norm().maxCoeff();
  const double max_rotation = u.bottomRows<3>().colwise().norm().maxCoeff();
  if (max_translation > 1e-12 * max_rotation * size && max_translation > 0.0)
    return fraction * size / max_translation;
  return max_rotation > 0.0 ? fraction / max_rotation : 0.0;
}

std::string frequency_text(double f_hz) {
  // Four significant digits, trailing zeros kept: 3.000, 18.80, 123.4, 1234.
  const double a = std::abs(f_hz);
  const int decimals =
      a > 0.0 ? std::clamp(3 - static_cast<int>(std::floor(std::log10(a))), 0, 6) : 3;
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, f_hz);
  return buffer;
}

// ---------------------------------------------------------------------------------------------
// VTK data sets and writers

/// Records the last error a VTK object reports, instead of VTK printing it.

vtkSmartPointer<vtkPoints> make_points(const Eigen::Matrix3Xd& x) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(x.cols());
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    points->SetPoint(i, x(0, i), x(1, i), x(2, i));
  return points;
}

/// The undeformed mesh: one VTK_LINE per element, point data node_id, cell data element_id.
vtkSmartPointer<vtkUnstructuredGrid> mesh_grid(const fem::Model& model, const Eigen::Matrix3Xd& x) {
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(make_points(x));
  grid->Allocate(static_cast<vtkIdType>(model.elements.size()));
  vtkNew<vtkIntArray> element_ids;
  element_ids->SetName("element_id");
  for (const auto& e : model.elements) {
    const vtkIdType ends[2] = {model.node_index(e.node_a), model.node_index(e.node_b)};
    grid->InsertNextCell(VTK_LINE, 2, ends);
    element_ids->InsertNextValue(e.id);
  }
  grid->GetCellData()->AddArray(element_ids);
  vtkNew<vtkIntArray> node_ids;
  node_ids->SetName("node_id");
  node_ids->SetNumberOfValues(static_cast<vtkIdType>(model.nodes.size()));
  for (std::size_t i = 0; i < model.nodes.size(); ++i)
    node_ids->SetValue(static_cast<vtkIdType>(i), model.nodes[i].id);
  grid->GetPointData()->AddArray(node_ids);
  return grid;
}

vtkSmartPointer<vtkDoubleArray> vector_array(const std::string& name,
                                             const Eigen::Ref<const Eigen::Matrix3Xd>& v) {
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name.c_str());
  array->SetNumberOfComponents(3);
  array->SetNumberOfTuples(v.cols());
  for (Eigen::Index i = 0; i < v.cols(); ++i)
    array->SetTuple3(i, v(0, i), v(1, i), v(2, i));
  return array;
}

void write_grid(vtkUnstructuredGrid* grid, const fs::path& path, bool binary) {
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  vtkNew<detail::ErrorCatcher> errors;
  writer->AddObserver(vtkCommand::ErrorEvent, errors);
  writer->SetFileName(path.c_str());
  writer->SetInputData(grid);
  if (binary) {
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    writer->SetCompressorTypeToNone(); // zlib costs more time than it saves on small files
    writer->SetHeaderTypeToUInt64();   // arrays over 4 GiB
  } else {
    writer->SetDataModeToAscii();
  }
  if (writer->Write() != 1 || !errors->message.empty())
    throw std::runtime_error(
        "cannot write " + path.string() + ": " +
        (errors->message.empty() ? "VTK writer failed" : detail::vtk_message(errors->message)));
}

void write_pvd(const fs::path& path, const std::vector<std::pair<double, std::string>>& frames) {
  std::ofstream out(path);
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  char time[32];
  for (const auto& [t, file] : frames) {
    std::snprintf(time, sizeof time, "%.6g", t);
    out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file
        << "\"/>\n";
  }
  out << "  </Collection>\n</VTKFile>\n";
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

// ---------------------------------------------------------------------------------------------
// Atomic output: everything goes into a staging directory inside the target directory and is
// renamed into place at the end; whatever it replaces is moved into the staging directory,
// which is removed in every case.

class Staging {
public:
  explicit Staging(const fs::path& dir) : dir_(dir) {
    std::error_code ec;
    fs::create_directories(dir_, ec);
    if (ec || !fs::is_directory(dir_))
      throw std::runtime_error("cannot create directory " + dir_.string() + ": " +
                               (ec ? ec.message() : "a file of that name exists"));
    std::random_device seed;
    std::mt19937_64 random(seed());
    for (int attempt = 0; attempt < 100; ++attempt) {
      path_ = dir_ / (".jointid-vtk-" + std::to_string(random() % 1000000000));
      // Registered before it exists: an interrupt removes it with whatever it holds.
      registration_ = std::make_unique<io::InFlight>(path_, io::InFlight::Kind::directory);
      if (fs::create_directory(path_, ec)) return;
    }
    registration_.reset();
    throw std::runtime_error("cannot create a temporary directory in " + dir_.string() + ": " +
                             ec.message());
  }
  Staging(const Staging&) = delete;
  Staging& operator=(const Staging&) = delete;
  ~Staging() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

  /// Moves staged entries (file or directory names, in this order) into the target directory.
  void commit(const std::vector<std::string>& names) {
    for (const auto& name : names)
      io::check_not_an_input(dir_ / name);
    // An interrupt waits for the renames: an old directory moved aside is always replaced.
    const io::CommitSection section;
    std::error_code ec;
    for (const auto& name : names) {
      const fs::path target = dir_ / name;
      if (fs::is_directory(target)) { // rename() does not replace a non-empty directory
        fs::rename(target, path_ / (".replaced-" + name), ec);
        if (ec) throw std::runtime_error("cannot replace " + target.string() + ": " + ec.message());
      }
      fs::rename(path_ / name, target, ec);
      if (ec) throw std::runtime_error("cannot write " + target.string() + ": " + ec.message());
    }
  }

private:
  fs::path dir_;
  fs::path path_;
  std::unique_ptr<io::InFlight> registration_;
};

// ---------------------------------------------------------------------------------------------
// Pictures

/// Deformed members as cubic beam curves: per element, the axial displacement is linear and
/// the transverse displacement is the Hermite cubic through the end translations with end
/// slopes θ × e (a small rotation θ turns the member's unit tangent e by θ × e).
vtkSmartPointer<vtkPolyData> deformed_members(const fem::Model& model, const Eigen::Matrix3Xd& x,
                                              const Eigen::Matrix<double, 6, Eigen::Dynamic>& u,
                                              double scale) {
  constexpr int segments = 16;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  for (const auto& element : model.elements) {
    const int a = model.node_index(element.node_a), b = model.node_index(element.node_b);
    const Eigen::Vector3d xa = x.col(a), xb = x.col(b);
    const double length = (xb - xa).norm();
    const Eigen::Vector3d ua = scale * u.col(a).head<3>(), ub = scale * u.col(b).head<3>();
    const Eigen::Vector3d ta = scale * u.col(a).tail<3>(), tb = scale * u.col(b).tail<3>();
    if (length <= 0.0) continue;
    std::vector<vtkIdType> ids;
    const Eigen::Vector3d e = (xb - xa) / length;
    const Eigen::Vector3d wa = ua - ua.dot(e) * e, wb = ub - ub.dot(e) * e;
    const Eigen::Vector3d sa = ta.cross(e), sb = tb.cross(e);
    for (int k = 0; k <= segments; ++k) {
      const double s = static_cast<double>(k) / segments;
      const double h1 = 1 - 3 * s * s + 2 * s * s * s, h2 = s - 2 * s * s + s * s * s;
      const double h3 = 3 * s * s - 2 * s * s * s, h4 = -s * s + s * s * s;
      const Eigen::Vector3d p = xa + s * (xb - xa) + ((1 - s) * ua.dot(e) + s * ub.dot(e)) * e +
                                h1 * wa + h2 * length * sa + h3 * wb + h4 * length * sb;
      ids.push_back(points->InsertNextPoint(p.data()));
    }
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetLines(lines);
  return poly;
}

/// Points (as vertices) joined by straight lines along the elements.
vtkSmartPointer<vtkPolyData> straight_members(const fem::Model& model, const Eigen::Matrix3Xd& x) {
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkCellArray> vertices;
  for (const auto& e : model.elements) {
    const vtkIdType ends[2] = {model.node_index(e.node_a), model.node_index(e.node_b)};
    lines->InsertNextCell(2, ends);
  }
  for (vtkIdType i = 0; i < x.cols(); ++i)
    vertices->InsertNextCell(1, &i);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(make_points(x));
  poly->SetLines(lines);
  poly->SetVerts(vertices);
  return poly;
}

vtkSmartPointer<vtkPolyData> node_points(const Eigen::Matrix3Xd& x) {
  vtkNew<vtkCellArray> vertices;
  for (vtkIdType i = 0; i < x.cols(); ++i)
    vertices->InsertNextCell(1, &i);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(make_points(x));
  poly->SetVerts(vertices);
  return poly;
}

vtkSmartPointer<vtkActor> actor_of(vtkPolyData* poly, const double rgb[3], double line_width,
                                   double point_size) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(poly);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  vtkProperty* p = actor->GetProperty();
  p->SetColor(rgb[0], rgb[1], rgb[2]);
  p->SetLineWidth(static_cast<float>(line_width));
  p->SetPointSize(static_cast<float>(point_size));
  p->SetRenderPointsAsSpheres(true);
  p->LightingOff(); // flat colours: lines have no meaningful normals
  return actor;
}

vtkSmartPointer<vtkTextActor> text_actor(const std::string& text, int font_size,
                                         const double rgb[3], double x, double y) {
  auto actor = vtkSmartPointer<vtkTextActor>::New();
  actor->SetInput(text.c_str());
  vtkTextProperty* tp = actor->GetTextProperty();
  tp->SetFontSize(font_size);
  tp->SetColor(rgb[0], rgb[1], rgb[2]);
  tp->SetFontFamilyToArial();
  tp->SetJustificationToCentered();
  tp->SetVerticalJustificationToCentered();
  actor->SetPosition(x, y); // viewport pixels
  return actor;
}

/// Parallel view looking along −direction, `up` drawn vertical: 2D models are drawn in the
/// x–y plane with y up, 3D models isometrically from the (+h1, −h2, +v) octant, v vertical.
struct View {
  Eigen::Vector3d direction; ///< from the focal point towards the camera, unit
  Eigen::Vector3d right;     ///< screen x, unit
  Eigen::Vector3d up;        ///< screen y, unit
};

View view_of(const fem::Model& model, int vertical_axis) {
  Eigen::Vector3d direction, up;
  if (model.dimension == 2) {
    direction = Eigen::Vector3d::UnitZ();
    up = Eigen::Vector3d::UnitY();
  } else {
    const int v = vertical_axis, h1 = (v + 1) % 3, h2 = (v + 2) % 3;
    direction = Eigen::Vector3d::Unit(h1) - Eigen::Vector3d::Unit(h2) + Eigen::Vector3d::Unit(v);
    up = Eigen::Vector3d::Unit(v);
  }
  View view;
  view.direction = direction.normalized();
  view.right = up.cross(view.direction).normalized();
  view.up = view.direction.cross(view.right);
  return view;
}

/// What the view sees of some points: their box on the screen (m) and in space.
struct Extent {
  double u_lo = INFINITY, u_hi = -INFINITY, v_lo = INFINITY, v_hi = -INFINITY;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-INFINITY);
  void add(vtkPolyData* poly, const View& view) {
    for (vtkIdType i = 0; i < poly->GetNumberOfPoints(); ++i) {
      Eigen::Vector3d p;
      poly->GetPoint(i, p.data());
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      u_lo = std::min(u_lo, p.dot(view.right));
      u_hi = std::max(u_hi, p.dot(view.right));
      v_lo = std::min(v_lo, p.dot(view.up));
      v_hi = std::max(v_hi, p.dot(view.up));
    }
  }
  /// Screen width and height, m, at least `floor` each (a straight beam has no height).
  double width(double floor) const { return std::max(u_hi - u_lo, floor); }
  double height(double floor) const { return std::max(v_hi - v_lo, floor); }
};

/// Fits the camera to `extent` in a viewport of w × h pixels, leaving `pad` pixels plus 4 % of
/// the viewport each side.
void fit_camera(vtkRenderer* renderer, const View& view, const Extent& extent, double floor,
                double w, double h, double pad) {
  const Eigen::Vector3d centre = 0.5 * (extent.lo + extent.hi);
  // The focal point goes to the middle of the screen box.
  const Eigen::Vector3d focal =
      centre + (0.5 * (extent.u_lo + extent.u_hi) - centre.dot(view.right)) * view.right +
      (0.5 * (extent.v_lo + extent.v_hi) - centre.dot(view.up)) * view.up;
  const double usable_w = std::max(0.92 * w - 2.0 * pad, 0.5 * w),
               usable_h = std::max(0.92 * h - 2.0 * pad, 0.5 * h);
  const double metres_per_pixel =
      std::max(extent.width(floor) / usable_w, extent.height(floor) / usable_h);
  const double size = (extent.hi - extent.lo).norm() + floor;
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->ParallelProjectionOn();
  camera->SetFocalPoint(focal.data());
  const Eigen::Vector3d position = focal + 4.0 * size * view.direction;
  camera->SetPosition(position.data());
  camera->SetViewUp(view.up.data());
  camera->SetParallelScale(0.5 * h * metres_per_pixel); // half the viewport height, m
  renderer->ResetCameraClippingRange();
}

/// Small x/y/z axes in the lower left corner of a 3D panel, in the view's orientation.
void add_axes(vtkRenderer* renderer, const View& view, double length, int font_size) {
  const double colours[3][3] = {{0.80, 0.15, 0.15}, {0.15, 0.60, 0.20}, {0.15, 0.15, 0.80}};
  const char* names[3] = {"x", "y", "z"};
  const Eigen::Vector2d origin(0.9 * length, 1.3 * length);
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
    const Eigen::Vector2d tip =
        origin + length * Eigen::Vector2d(e.dot(view.right), e.dot(view.up));
    vtkNew<vtkPoints> points;
    points->InsertNextPoint(origin.x(), origin.y(), 0.0);
    points->InsertNextPoint(tip.x(), tip.y(), 0.0);
    vtkNew<vtkCellArray> line;
    const vtkIdType ends[2] = {0, 1};
    line->InsertNextCell(2, ends);
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->SetLines(line);
    vtkNew<vtkCoordinate> pixels;
    pixels->SetCoordinateSystemToViewport();
    vtkNew<vtkPolyDataMapper2D> mapper;
    mapper->SetInputData(poly);
    mapper->SetTransformCoordinate(pixels);
    vtkNew<vtkActor2D> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(colours[a][0], colours[a][1], colours[a][2]);
    actor->GetProperty()->SetLineWidth(2.0f);
    renderer->AddActor2D(actor);
    const Eigen::Vector2d label =
        origin + (length + 0.6 * font_size) * Eigen::Vector2d(e.dot(view.right), e.dot(view.up));
    renderer->AddActor2D(text_actor(names[a], font_size, colours[a], label.x(), label.y()));
  }
}

} // namespace

// -------------------------------------------------------------------------------------------------

bool vtk_available() {
  return true;
}

void write_modes_vtk(const fs::path& dir, const fem::Model& model, const fem::DofMap& dofs,
                     const fem::Modes& modes, const VtkOptions& options) {
  check_modes(model, dofs, modes);
  if (options.frames < 1)
    throw std::invalid_argument("VTK output: frames = " + std::to_string(options.frames) +
                                " (need at least 1)");
  if (!(options.amplitude > 0.0) || !std::isfinite(options.amplitude))
    throw std::invalid_argument("VTK output: amplitude = " + std::to_string(options.amplitude) +
                                " (need a positive fraction, e.g. 0.1)");

  Staging staging(dir);
  const fs::path& tmp = staging.path();
  const Eigen::Matrix3Xd x = node_positions(model);
  const double size = model_size(x);
  const int n_modes = modes.num_modes();

  const vtkSmartPointer<vtkUnstructuredGrid> mesh = mesh_grid(model, x);
  write_grid(mesh, tmp / "mesh.vtu", options.binary);

  vtkNew<vtkUnstructuredGrid> all_modes;
  all_modes->ShallowCopy(mesh);
  vtkNew<vtkDoubleArray> frequencies;
  frequencies->SetName("frequency_hz");
  frequencies->SetNumberOfValues(n_modes);
  std::vector<std::string> names; // staged entries, directories first
  for (int r = 0; r < n_modes; ++r) {
    const auto u = nodal_shape(model, dofs, modes, r);
    const std::string mode = "mode_" + std::to_string(r + 1);
    all_modes->GetPointData()->AddArray(vector_array(mode + "_translation", u.topRows<3>()));
    all_modes->GetPointData()->AddArray(vector_array(mode + "_rotation", u.bottomRows<3>()));
    frequencies->SetValue(r, modes.frequency_hz(r));

    // Animation: frame k displaced by scale · sin(2πk / frames) · φ_r.
    const double scale = shape_scale(u, size, options.amplitude);
    const fs::path frame_dir = tmp / mode;
    std::error_code ec;
    if (!fs::create_directory(frame_dir, ec))
      throw std::runtime_error("cannot create directory " + frame_dir.string() + ": " +
                               ec.message());
    vtkNew<vtkDoubleArray> frame_frequency;
    frame_frequency->SetName("frequency_hz");
    frame_frequency->InsertNextValue(modes.frequency_hz(r));
    std::vector<std::pair<double, std::string>> frames;
    for (int k = 0; k < options.frames; ++k) {
      const double phase = std::sin(two_pi * k / options.frames);
      const Eigen::Matrix3Xd displacement = scale * phase * u.topRows<3>();
      vtkNew<vtkUnstructuredGrid> frame;
      frame->ShallowCopy(mesh);
      frame->SetPoints(make_points(x + displacement));
      frame->GetPointData()->AddArray(vector_array("displacement", displacement));
      frame->GetFieldData()->AddArray(frame_frequency);
      const std::string file = "frame_" + std::to_string(k) + ".vtu";
      write_grid(frame, frame_dir / file, options.binary);
      frames.emplace_back(static_cast<double>(k) / options.frames, mode + "/" + file);
    }
    write_pvd(tmp / (mode + ".pvd"), frames);
    names.insert(names.begin(), mode); // directories before the .pvd files that use them
    names.push_back(mode + ".pvd");
  }
  all_modes->GetFieldData()->AddArray(frequencies);
  write_grid(all_modes, tmp / "modes.vtu", options.binary);
  names.push_back("modes.vtu");
  names.push_back("mesh.vtu");
  staging.commit(names);
}

void render_modes_png(const fs::path& png, const fem::Model& model, const fem::DofMap& dofs,
                      const fem::Modes& modes, int count, const PngOptions& options) {
  check_modes(model, dofs, modes);
  if (count < 1)
    throw std::invalid_argument("mode picture: count = " + std::to_string(count) +
                                " (need at least 1)");
  if (modes.num_modes() == 0)
    throw std::invalid_argument("mode picture: there are no modes to draw");
  if (options.width < 16 || options.height < 16 || options.width > 16384 || options.height > 16384)
    throw std::invalid_argument("mode picture: size " + std::to_string(options.width) + " × " +
                                std::to_string(options.height) +
                                " pixels (need 16 … 16384 each way)");
  if (options.columns < 0)
    throw std::invalid_argument("mode picture: columns = " + std::to_string(options.columns));
  if (!(options.amplitude > 0.0) || !std::isfinite(options.amplitude))
    throw std::invalid_argument("mode picture: amplitude = " + std::to_string(options.amplitude) +
                                " (need a positive fraction, e.g. 0.1)");
  if (options.vertical_axis < 0 || options.vertical_axis > 2)
    throw std::invalid_argument("mode picture: vertical_axis = " +
                                std::to_string(options.vertical_axis) + " (0 x, 1 y or 2 z)");
  count = std::min(count, modes.num_modes());
  const fs::path folder = png.parent_path().empty() ? fs::path(".") : png.parent_path();
  if (!fs::is_directory(folder))
    throw std::runtime_error("cannot write " + png.string() + ": the directory " + folder.string() +
                             " does not exist");

  // Debian's VTK aborts the process if it cannot open the X display: open it first. Declared
  // before every VTK object, so that it is closed after all of them.
  const detail::RenderDisplay display;
  if (!display.problem().empty())
    throw std::runtime_error("cannot render " + png.string() + ": " + display.problem() +
                             "; run the program under `xvfb-run -a`");
  vtkNew<vtkRenderWindow> window;
  if (display.id() != nullptr) window->SetDisplayId(display.id());

  // 1. The shapes, and the screen box that holds all of them (every panel uses the same
  //    framing, so the undeformed structure looks the same in each).
  const Eigen::Matrix3Xd x = node_positions(model);
  const double size = model_size(x);
  const View view = view_of(model, options.vertical_axis);
  const vtkSmartPointer<vtkPolyData> undeformed = straight_members(model, x);
  Extent extent;
  extent.add(undeformed, view);
  std::vector<vtkSmartPointer<vtkPolyData>> deformed, deformed_nodes;
  for (int r = 0; r < count; ++r) {
    const auto u = nodal_shape(model, dofs, modes, r);
    const double scale = shape_scale(u, size, options.amplitude);
    deformed.push_back(deformed_members(model, x, u, scale));
    deformed_nodes.push_back(node_points(x + scale * u.topRows<3>()));
    extent.add(deformed.back(), view);
    extent.add(deformed_nodes.back(), view);
  }
  const double floor = 0.05 * size; // a straight beam still gets some height

  // 2. Layout: the grid that draws the structure largest, below a title line per panel, among
  //    those whose titles come out at least 16 px high (if any do).
  const double W = options.width, H = options.height;
  auto font_size_of = [](double panel_w, double panel_h) {
    return 0.05 * std::min(panel_w, 1.6 * panel_h);
  };
  auto pixels_per_metre = [&](int c) {
    const int rows = (count + c - 1) / c;
    const double panel_w = W / c, panel_h = H / rows;
    const double font = font_size_of(panel_w, panel_h);
    const double scene_h = panel_h - 2.0 * std::clamp(font, 12.0, 44.0);
    const double ppm = std::min(panel_w / extent.width(floor), scene_h / extent.height(floor));
    return font >= 16.0 ? ppm : 1e-6 * ppm; // small titles only as a last resort
  };
  int columns = std::min(options.columns, count);
  if (columns == 0) {
    columns = 1;
    for (int c = 2; c <= count; ++c)
      if (pixels_per_metre(c) > 1.02 * pixels_per_metre(columns)) columns = c;
  }
  const int rows = (count + columns - 1) / columns;
  const double panel_w = W / columns, panel_h = H / rows;
  const int font_size = static_cast<int>(std::clamp(font_size_of(panel_w, panel_h), 12.0, 44.0));
  const double title_h = std::min(2.0 * font_size, 0.4 * panel_h); // pixels
  const double scene_h = panel_h - title_h;
  const double px = std::clamp(std::min(panel_w, panel_h) / 350.0, 1.0, 4.0); // line scale

  // 3. The scene: white background, one scene and one title viewport per mode.
  window->SetOffScreenRendering(1);
  window->SetSize(options.width, options.height);
  window->SetMultiSamples(0);
  vtkNew<vtkRenderer> background; // white behind everything, also where the grid has no panel
  background->SetBackground(1.0, 1.0, 1.0);
  window->AddRenderer(background);

  const double grey[3] = {0.62, 0.62, 0.62};
  const double blue[3] = {0.10, 0.34, 0.75};
  const double black[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < count; ++r) {
    const int column = r % columns, row = r / columns;
    const double x0 = column * panel_w / W, x1 = (column + 1) * panel_w / W;
    const double y_top = 1.0 - row * panel_h / H, y0 = 1.0 - (row + 1) * panel_h / H;
    const double y_title = y_top - title_h / H;

    vtkNew<vtkRenderer> scene;
    scene->SetViewport(x0, y0, x1, y_title);
    scene->SetBackground(1.0, 1.0, 1.0);
    scene->UseFXAAOn();
    scene->AddActor(actor_of(undeformed, grey, 1.5 * px, 4.0 * px));
    scene->AddActor(actor_of(deformed[r], blue, 3.0 * px, 0.0));
    scene->AddActor(actor_of(deformed_nodes[r], blue, 0.0, 6.5 * px));
    fit_camera(scene, view, extent, floor, panel_w, scene_h, 5.0 * px);
    if (model.dimension == 3)
      add_axes(scene, view, std::clamp(0.07 * std::min(panel_w, scene_h), 18.0, 60.0),
               std::max(10, font_size * 2 / 3));
    window->AddRenderer(scene);

    vtkNew<vtkRenderer> title;
    title->SetViewport(x0, y_title, x1, y_top);
    title->SetBackground(1.0, 1.0, 1.0);
    const std::string text =
        "Mode " + std::to_string(r + 1) + ": " + frequency_text(modes.frequency_hz(r)) + " Hz";
    title->AddActor2D(text_actor(text, font_size, black, 0.5 * panel_w, 0.45 * title_h));
    window->AddRenderer(title);
  }

  detail::render_to_png(window, png);
}

} // namespace jointid::report
