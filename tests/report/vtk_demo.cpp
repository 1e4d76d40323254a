// Writes mode pictures and ParaView files of two small frames, to look at:
//   xvfb-run -a io_vtk_demo OUTDIR
// OUTDIR/cantilever_modes.png, OUTDIR/portal_modes.png, OUTDIR/cantilever/, OUTDIR/portal/.
#include "fem/assembly.hpp"
#include "fem/modal.hpp"
#include "report/vtk_models.hpp"
#include "report/vtk_output.hpp"

#include <exception>
#include <filesystem>
#include <iostream>

using namespace jointid;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: io_vtk_demo OUTDIR (run under xvfb-run -a without a display)\n";
    return 2;
  }
  try {
    const std::filesystem::path out = argv[1];
    std::filesystem::create_directories(out);

    // 1. A 2D cantilever of 10 beam elements: the first six bending modes.
    const fem::Model cantilever = test::beam_cantilever(10);
    const fem::Assembled beam = fem::assemble(cantilever);
    const fem::Modes beam_modes = fem::modal_analysis(beam, {.num_modes = 6});
    report::write_modes_vtk(out / "cantilever", cantilever, beam.dofs, beam_modes);
    report::render_modes_png(out / "cantilever_modes.png", cantilever, beam.dofs, beam_modes, 6);

    // 2. A 3D portal frame, 4 elements per member: the first six modes, in and out of plane.
    const fem::Model portal = test::portal_frame(4);
    const fem::Assembled frame = fem::assemble(portal);
    const fem::Modes frame_modes = fem::modal_analysis(frame, {.num_modes = 6});
    report::write_modes_vtk(out / "portal", portal, frame.dofs, frame_modes);
    report::render_modes_png(out / "portal_modes.png", portal, frame.dofs, frame_modes, 6);

    std::cout << "wrote " << (out / "cantilever_modes.png").string() << " and "
              << (out / "portal_modes.png").string() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "io_vtk_demo: " << e.what() << "\n";
    return 1;
  }
}
