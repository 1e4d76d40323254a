#pragma once
/// Internal to jointid_io_vtk: what the mode pictures and the charts share to turn a VTK render
/// window into a PNG file, and VTK's error reports turned into exceptions.
#include <vtkCommand.h>
#include <vtkRenderWindow.h>

#include <filesystem>
#include <string>

namespace jointid::report::detail {

/// Keeps the last error a VTK object reports (attach with AddObserver(vtkCommand::ErrorEvent)).
class ErrorCatcher : public vtkCommand {
public:
  static ErrorCatcher* New() { return new ErrorCatcher; }
  void Execute(vtkObject*, unsigned long, void* data) override {
    message = data != nullptr ? static_cast<const char*>(data) : "unknown VTK error";
  }
  std::string message;
};

/// The message of a VTK error without its "ERROR: In file, line n" header and object address.
std::string vtk_message(const std::string& text);

/// Renders `window` and writes what it shows to `png`: into a temporary file next to it, then
/// renamed into place, so that a failure never leaves half a file. Throws std::runtime_error
/// naming the path when rendering or writing fails.
void render_to_png(vtkRenderWindow* window, const std::filesystem::path& png);

} // namespace jointid::report::detail
