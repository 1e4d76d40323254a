#include "report/vtk_display.hpp"

#include <vtkRenderingOpenGLConfigure.h> // VTK_USE_X

#include <chrono>
#include <cstdlib>
#include <thread>

#ifdef VTK_USE_X
// In its own file: Xlib defines macros (Success, Status, None, …) that clash with Eigen.
#include <X11/Xlib.h>
#endif

namespace jointid::report::detail {

RenderDisplay::RenderDisplay() {
#ifdef VTK_USE_X
  const char* name = std::getenv("DISPLAY");
  if (name == nullptr || *name == '\0') {
    problem_ = "VTK needs an X display and DISPLAY is not set";
    return;
  }
  for (int attempt = 0; attempt < 10 && id_ == nullptr; ++attempt) {
    if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    id_ = XOpenDisplay(nullptr);
  }
  if (id_ == nullptr)
    problem_ = std::string("VTK needs an X display and cannot open DISPLAY=") + name;
#endif
}

RenderDisplay::~RenderDisplay() {
#ifdef VTK_USE_X
  if (id_ != nullptr) XCloseDisplay(static_cast<Display*>(id_));
#endif
}

} // namespace jointid::report::detail
