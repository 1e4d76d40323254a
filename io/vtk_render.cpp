#include "io/vtk_render.hpp"

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkWindowToImageFilter.h>

#include <random>
#include <stdexcept>

namespace jointid::io::detail {

namespace fs = std::filesystem;

std::string vtk_message(const std::string& text) {
  std::string s = text;
  const std::size_t start = s.find("): ");
  if (start != std::string::npos) s = s.substr(start + 3);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
    s.pop_back();
  return s;
}

void render_to_png(vtkRenderWindow* window, const fs::path& png) {
  vtkNew<ErrorCatcher> render_errors;
  window->AddObserver(vtkCommand::ErrorEvent, render_errors);
  window->Render();
  if (!render_errors->message.empty())
    throw std::runtime_error("cannot render " + png.string() + ": " +
                             vtk_message(render_errors->message));

  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->SetInputBufferTypeToRGB();
  capture->ReadFrontBufferOff();
  capture->Update();
  const fs::path tmp =
      png.string() + ".tmp-" + std::to_string(std::random_device{}() % 1000000) + ".png";
  vtkNew<vtkPNGWriter> writer;
  vtkNew<ErrorCatcher> write_errors;
  writer->AddObserver(vtkCommand::ErrorEvent, write_errors);
  writer->SetFileName(tmp.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  std::error_code ec;
  if (!write_errors->message.empty() || !fs::is_regular_file(tmp, ec)) {
    fs::remove(tmp, ec);
    throw std::runtime_error(
        "cannot write " + png.string() + ": " +
        (write_errors->message.empty() ? "PNG writer failed" : vtk_message(write_errors->message)));
  }
  fs::rename(tmp, png, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw std::runtime_error("cannot write " + png.string() + ": " + ec.message());
  }
}

} // namespace jointid::io::detail
