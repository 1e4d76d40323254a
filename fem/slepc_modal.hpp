#pragma once
/// The distributed modal engine: SLEPc's Krylov–Schur on PETSc matrices, K and M distributed
/// by rows over MPI processes, shift-and-invert with a MUMPS factorisation of K − σM
/// (σ below the first mode). Target `jointid_fem_slepc`, built only when PETSc and SLEPc are
/// found (pkg-config `PETSc`, `slepc`); this header includes neither, nor MPI.
///
/// Run under `mpirun -np N`: every rank reads the same model, assembles only the rows of K and
/// M it owns (an even split of the equations), and the eigenvectors stay distributed; only the
/// rows asked for are gathered (to rank 0, or to every rank). Same result and status
/// conventions as fem::modal_analysis: ascending ω, mass-normalised φ (φᵀMφ = 1), caller
/// mistakes std::invalid_argument, a solver that does not converge Status::Code::not_converging.
#include "fem/modal.hpp"
#include "fem/model.hpp"

#include <vector>

namespace jointid::fem {

/// MPI, PETSc and SLEPc, started for the life of the object: make one per process before the
/// first slepc_modal_analysis and keep it until the last (MPI cannot be restarted). PETSc
/// options come from the environment (PETSC_OPTIONS), never from the command line. Throws
/// std::runtime_error when MPI or PETSc cannot start.
class SlepcSession {
public:
  SlepcSession();
  ~SlepcSession();
  SlepcSession(const SlepcSession&) = delete;
  SlepcSession& operator=(const SlepcSession&) = delete;

  int rank() const { return rank_; } ///< this process, 0 … size() − 1
  int size() const { return size_; } ///< MPI processes

private:
  int rank_ = 0;
  int size_ = 1;
  bool finalize_ = false; // started here (not by an enclosing session)
};

struct SlepcModalOptions {
  /// Equations whose rows of φ are gathered, in this order (Modes::rows); empty: every row,
  /// in equation order (Modes::rows empty). A synthesis needs only its set 1 and set 2 DOFs.
  std::vector<int> rows;
  /// false: only rank 0 receives the rows (the others get φ with 0 rows); true: every rank
  /// does, so that all ranks can carry on with the same computation.
  bool every_rank = false;
};

/// The lowest `options.num_modes` modes (≥ 1, fewer than the equations), or every mode below
/// `options.max_frequency_hz` when that is > 0. Uses options.shift_hz (σ = −(2π·shift_hz)²),
/// options.tolerance (SLEPc's relative residual) and options.max_iterations (restarts);
/// options.engine and the CHOLMOD settings are ignored. Collective: every rank of
/// MPI_COMM_WORLD calls it with the same model and options, inside a SlepcSession. Fills
/// Modes::distributed. Throws std::invalid_argument for bad options or an invalid model,
/// std::logic_error without a session, std::runtime_error when PETSc, SLEPc or MUMPS fail
/// (e.g. K − σM singular: a DOF with neither stiffness nor mass).
Modes slepc_modal_analysis(const Model& model, const ModalOptions& options = {},
                           const SlepcModalOptions& slepc = {});

} // namespace jointid::fem
