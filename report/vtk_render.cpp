#include "report/vtk_render.hpp"

#include "io/files.hpp"

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkWindowToImageFilter.h>

#include <memory>
#include <random>
#include <stdexcept>

namespace jointid::report::detail {

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
  // A hidden temporary name beside the picture, registered so that an interrupt removes it,
  // then renamed over the picture: an old picture is replaced whole or kept.
  io::check_not_an_input(png);
  std::error_code ec;
  fs::path tmp;
  std::unique_ptr<io::InFlight> registration;
  std::random_device seed;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = ".";
    name += png.filename().string();
    name += ".tmp." + std::to_string(seed() % 1000000000) + ".png";
    tmp = png.parent_path() / name;
    if (!fs::exists(tmp, ec)) break;
  }
  registration = std::make_unique<io::InFlight>(tmp, io::InFlight::Kind::file);
  vtkNew<vtkPNGWriter> writer;
  vtkNew<ErrorCatcher> write_errors;
  writer->AddObserver(vtkCommand::ErrorEvent, write_errors);
  writer->SetFileName(tmp.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  if (!write_errors->message.empty() || !fs::is_regular_file(tmp, ec)) {
    fs::remove(tmp, ec);
    throw std::runtime_error(
        "cannot write " + png.string() + ": " +
        (write_errors->message.empty() ? "PNG writer failed" : vtk_message(write_errors->message)));
  }
  {
    const io::CommitSection section;
    fs::rename(tmp, png, ec);
  }
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw std::runtime_error("cannot write " + png.string() + ": " + ec.message());
  }
}

} // namespace jointid::report::detail
