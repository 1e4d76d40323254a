// jointid_io_novtk: a build without VTK (-DJOINTID_WITH_VTK=OFF, for headless cluster nodes).
// The functions that need VTK say so; the discovery report is written without its plots.
#include "report/chart.hpp"
#include "report/vtk_output.hpp"

#include <stdexcept>

namespace jointid::report {

bool vtk_available() {
  return false;
}

void write_modes_vtk(const std::filesystem::path&, const fem::Model&, const fem::DofMap&,
                     const fem::Modes&, const VtkOptions&) {
  throw std::runtime_error(no_vtk_message);
}

void render_modes_png(const std::filesystem::path&, const fem::Model&, const fem::DofMap&,
                      const fem::Modes&, int, const PngOptions&) {
  throw std::runtime_error(no_vtk_message);
}

void write_chart_png(const std::filesystem::path&, const Figure&) {
  throw std::runtime_error(no_vtk_message);
}

bool can_render_charts(std::string* why) {
  if (why != nullptr) *why = no_vtk_message;
  return false;
}

} // namespace jointid::report
