#pragma once
// Whether VTK can draw here: Debian's VTK renders through GLX, so pictures need an X display.
#include <cstdlib>

namespace jointid::test {

inline bool have_display() {
  const char* display = std::getenv("DISPLAY");
  return display != nullptr && *display != '\0';
}

inline constexpr const char* no_display = "no X display: Debian's VTK renders through GLX; ctest "
                                          "runs these tests as report_vtk_png under xvfb-run -a";

} // namespace jointid::test
