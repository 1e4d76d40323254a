#pragma once
/// Internal to jointid_io_vtk: the X display connection that VTK's render window draws on.
#include <string>

namespace jointid::report::detail {

/// Debian's VTK 9.1 renders through GLX and aborts the process when it cannot open the X
/// display itself. So the library opens the display first, retrying briefly (an Xvfb whose last
/// client has just left resets and refuses connections for a moment), and hands the
/// connection to the render window, which then opens none of its own. Where VTK needs no X
/// display, id() is null and problem() empty.
class RenderDisplay {
public:
  RenderDisplay();
  ~RenderDisplay();
  RenderDisplay(const RenderDisplay&) = delete;
  RenderDisplay& operator=(const RenderDisplay&) = delete;
  /// The X `Display*` for vtkRenderWindow::SetDisplayId, or null.
  void* id() const { return id_; }
  /// Why rendering is impossible here; empty if it is possible.
  const std::string& problem() const { return problem_; }

private:
  void* id_ = nullptr;
  std::string problem_;
};

} // namespace jointid::report::detail
