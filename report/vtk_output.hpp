#pragma once
/// VTK output of a model's mesh and mode shapes (for ParaView) and PNG pictures of modes.
/// Target `jointid_io_vtk`: the only target that links VTK; this header includes no VTK.
/// Units: positions and translations in m, rotations in rad, frequencies in Hz.
#include "fem/dof_map.hpp"
#include "fem/modal.hpp"
#include "fem/model.hpp"

#include <filesystem>

namespace jointid::report {

/// What a build without VTK (-DJOINTID_WITH_VTK=OFF) says when asked for VTK files, pictures or
/// charts.
inline constexpr const char* no_vtk_message =
    "this build has no VTK: rebuild with -DJOINTID_WITH_VTK=ON";

/// False in a build without VTK: then the functions below, write_chart_png (chart.hpp) and
/// can_render_charts report `no_vtk_message` (std::runtime_error; false with that reason).
bool vtk_available();

struct VtkOptions {
  /// Frames per mode period in the `mode_<r>.pvd` animations (frame k is displaced by
  /// scale · sin(2πk / frames) · φ_r).
  int frames = 24;
  /// Largest nodal translation of an animated mode, as a fraction of the diagonal of the
  /// model's bounding box.
  double amplitude = 0.1;
  bool binary = true; ///< appended raw binary (false: ASCII, human-readable)
};

/// Writes, for the modes of `modes` (phi: n_eq × n_modes over `dofs`' equations):
/// - `dir/mesh.vtu`: the undeformed mesh, one line cell per element; point data `node_id`,
///   cell data `element_id`;
/// - `dir/modes.vtu`: the mesh with point data `node_id` and, for every mode r = 1 … n_modes,
///   `mode_<r>_translation` (ux, uy, uz) and `mode_<r>_rotation` (rx, ry, rz), the
///   mass-normalised φ entries (0 where a DOF is absent or fixed); field data `frequency_hz`
///   (n_modes values, mode 1 first);
/// - `dir/mode_<r>.pvd` and `dir/mode_<r>/frame_<k>.vtu`, k = 0 … frames − 1: the mesh
///   displaced by the scaled mode at phase 2πk / frames (time values are fractions of a
///   period), so that ParaView animates the mode.
/// Creates `dir` if needed. The files are written into a temporary directory inside `dir` and
/// then renamed into place, so a failure leaves earlier output intact. Throws
/// std::invalid_argument if `modes` does not match `dofs`, std::runtime_error naming the path
/// if a file cannot be written.
void write_modes_vtk(const std::filesystem::path& dir, const fem::Model& model,
                     const fem::DofMap& dofs, const fem::Modes& modes,
                     const VtkOptions& options = {});

struct PngOptions {
  int width = 1200; ///< pixels, whole picture
  int height = 800; ///< pixels, whole picture
  int columns = 0;  ///< panels per row; 0: chosen to make the panels as large as possible
  /// Largest nodal translation of the drawn mode, as a fraction of the bounding-box diagonal.
  double amplitude = 0.1;
  /// 3D models: the axis drawn vertical in the isometric view (0 x, 1 y, 2 z). 2D models are
  /// always drawn in the x–y plane with y up.
  int vertical_axis = 2;
};

/// Renders the first `count` modes (or all, if fewer) side by side into one PNG: in every
/// panel the undeformed mesh (thin grey) and the deformed shape (thick blue, members drawn as
/// cubic beam curves through the nodal translations and rotations), titled "Mode r: f Hz".
/// Renders off screen. Debian's VTK 9.1 renders through GLX and so needs an X server: without
/// one (DISPLAY unset) this throws std::runtime_error saying to run under `xvfb-run -a`.
/// Throws std::invalid_argument for count < 1, a bad size or modes that do not match `dofs`,
/// std::runtime_error naming the path if the picture cannot be written.
void render_modes_png(const std::filesystem::path& png, const fem::Model& model,
                      const fem::DofMap& dofs, const fem::Modes& modes, int count,
                      const PngOptions& options = {});

} // namespace jointid::report
