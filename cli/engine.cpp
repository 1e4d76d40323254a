#include "cli/engine.hpp"

#include "fem/assembly.hpp"
#include "io/files.hpp"

#if JOINTID_WITH_SLEPC
#include "fem/slepc_modal.hpp"
#endif

#include <cstdio>

namespace jointid::cli {

namespace {

int this_rank = 0;

} // namespace

Engine parse_engine(const std::string& text) {
  if (text == "auto") return Engine::automatic;
  if (text == "dense") return Engine::dense;
  if (text == "sparse") return Engine::sparse;
  if (text == "slepc") return Engine::slepc;
  throw io::Error("--engine: expected auto, dense, sparse or slepc, got \"" + text + "\"");
}

#if JOINTID_WITH_SLEPC
struct EngineSession::Impl {
  fem::SlepcSession mpi;
};
#else
struct EngineSession::Impl {};
#endif

EngineSession::EngineSession(Engine engine) {
  if (engine != Engine::slepc) return;
#if JOINTID_WITH_SLEPC
  impl_ = std::make_unique<Impl>();
  this_rank = impl_->mpi.rank();
  if (this_rank != 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
  }
#else
  throw io::Error("--engine slepc: this build has no SLEPc engine: install PETSc and SLEPc "
                  "(Debian: petsc-dev libslepc-real-dev) and rebuild jointid");
#endif
}

EngineSession::~EngineSession() = default;

bool output_rank() {
  return this_rank == 0;
}

fem::Modes compute_modes(const fem::Model& model, const fem::Assembled* system,
                         fem::ModalOptions options, Engine engine) {
#if JOINTID_WITH_SLEPC
  if (engine == Engine::slepc) return fem::slepc_modal_analysis(model, options);
#endif
  options.engine = engine == Engine::dense    ? fem::ModalEngine::dense
                   : engine == Engine::sparse ? fem::ModalEngine::sparse
                                              : fem::ModalEngine::automatic;
  return system != nullptr ? fem::modal_analysis(*system, options)
                           : fem::modal_analysis(fem::assemble(model), options);
}

void use_engine(frf::Substructure& sub, Engine engine) {
#if JOINTID_WITH_SLEPC
  if (engine == Engine::slepc)
    sub.set_band_solver([](const fem::Model& model, const fem::Assembled&,
                           const fem::ModalOptions& options, const std::vector<int>& rows) {
      return fem::slepc_modal_analysis(model, options, {.rows = rows, .every_rank = true});
    });
#else
  (void)sub;
  (void)engine;
#endif
}

} // namespace jointid::cli
