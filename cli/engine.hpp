#pragma once
/// The modal engine chosen with `--engine`, and the MPI session the distributed (SLEPc) one
/// runs in. Under `mpirun -np N` every rank runs the whole command; the modal analysis is
/// shared between them and only rank 0 prints and writes.
#include "fem/modal.hpp"
#include "frf/substructure.hpp"

#include <memory>
#include <string>

namespace jointid::cli {

enum class Engine { automatic, dense, sparse, slepc };

/// "auto", "dense", "sparse" or "slepc"; io::Error otherwise.
Engine parse_engine(const std::string& text);

/// Starts MPI, PETSc and SLEPc for the slepc engine, for the life of the object (nothing for
/// the others). Throws io::Error when this build has no SLEPc engine. On ranks other than 0
/// the standard output and error are silenced (rank 0 reports for all).
class EngineSession {
public:
  explicit EngineSession(Engine engine);
  ~EngineSession();
  EngineSession(const EngineSession&) = delete;
  EngineSession& operator=(const EngineSession&) = delete;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// True on the process that prints and writes the outputs: rank 0, or the only process.
bool output_rank();

/// Modes of a finite element model by `engine`: slepc assembles K and M distributed by rows
/// and returns every row of φ on rank 0 (none elsewhere; ω everywhere); the others use
/// `system` (the model assembled; assembled here when null).
fem::Modes compute_modes(const fem::Model& model, const fem::Assembled* system,
                         fem::ModalOptions options, Engine engine);

/// Makes `sub` compute the band of modes of a large model with `engine` (slepc: only the rows
/// the synthesis needs, sent to every rank); automatic leaves the default.
void use_engine(frf::Substructure& sub, Engine engine);

} // namespace jointid::cli
