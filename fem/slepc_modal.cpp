#include "fem/slepc_modal.hpp"

#include "fem/assembly.hpp"
#include "fem/constants.hpp"
#include "fem/dof_map.hpp"

#include <Eigen/SparseCore>
#include <petscmat.h>
#include <slepceps.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

namespace jointid::fem {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// PETSc returns error codes (the session installs PetscReturnErrorHandler, so nothing is
// printed): turn them into exceptions naming the step.
void check(PetscErrorCode code, const char* step) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string("SLEPc modal analysis: ") + step + " failed (PETSc error " +
                           std::to_string(static_cast<int>(code)) +
                           (text != nullptr ? std::string(": ") + text : std::string()) + ")");
}

// A PETSc object destroyed with its owner's XxxDestroy(&object).
template <class T, PetscErrorCode (*destroy)(T*)> class Owned {
public:
  Owned() = default;
  ~Owned() {
    if (object_ != nullptr) destroy(&object_);
  }
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;
  T get() const { return object_; }
  T* out() { return &object_; } // for PETSc's XxxCreate(…, &object)

private:
  T object_ = nullptr;
};
using OwnedMat = Owned<Mat, MatDestroy>;
using OwnedVec = Owned<Vec, VecDestroy>;
using OwnedEps = Owned<EPS, EPSDestroy>;
using OwnedIs = Owned<IS, ISDestroy>;
using OwnedScatter = Owned<VecScatter, VecScatterDestroy>;

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, PetscInt>;

// Rows first … last − 1 of the matrix given by global triplets, as a distributed AIJ matrix
// (the local block in compressed rows, columns sorted, as PETSc wants it).
void distributed_matrix(const std::vector<Eigen::Triplet<double>>& entries, PetscInt first,
                        PetscInt last, PetscInt n, Mat* out) {
  std::vector<Eigen::Triplet<double, PetscInt>> local;
  local.reserve(entries.size());
  for (const auto& t : entries)
    local.emplace_back(t.row() - first, t.col(), t.value());
  RowMatrix rows(last - first, n);
  rows.setFromTriplets(local.begin(), local.end());
  rows.makeCompressed();
  check(MatCreateMPIAIJWithArrays(PETSC_COMM_WORLD, last - first, last - first, n, n,
                                  rows.outerIndexPtr(), rows.innerIndexPtr(), rows.valuePtr(), out),
        "creating the distributed matrix");
  check(MatSetOption(*out, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
  check(MatSetOption(*out, MAT_SYMMETRY_ETERNAL, PETSC_TRUE), "MatSetOption");
}

// MUMPS reports counts above 2³¹ as minus millions.
double mumps_count(PetscInt value) {
  return value < 0 ? -1e6 * static_cast<double>(value) : static_cast<double>(value);
}

// b when every node with free DOFs has b of them, numbered consecutively node after node (a
// 3D frame: 6), else 1. MUMPS then orders the graph of the nodes, not of the DOFs
// (ICNTL(15) = −b): on a 10⁴-DOF frame lattice 30 % fewer factor entries and half the flops.
int uniform_node_block(const DofMap& dofs) {
  int block = 0, next = 0;
  for (int id : dofs.node_ids()) {
    std::vector<int> eq;
    for (int e : dofs.node_equations(id))
      if (e >= 0) eq.push_back(e);
    if (eq.empty()) continue;
    std::sort(eq.begin(), eq.end());
    if (block == 0) block = static_cast<int>(eq.size());
    if (static_cast<int>(eq.size()) != block || eq.front() != next || eq.back() != next + block - 1)
      return 1;
    next += block;
  }
  return next == dofs.num_equations() && block > 0 ? block : 1;
}

void check_options(int n, const ModalOptions& o) {
  if (o.num_modes < 0) throw std::invalid_argument("num_modes must be >= 0");
  if (o.max_frequency_hz <= 0.0 && (o.num_modes == 0 || o.num_modes >= n))
    throw std::invalid_argument(
        "the SLEPc engine finds fewer modes than DOFs (" + std::to_string(n) + "), asked for " +
        (o.num_modes == 0 ? std::string("all") : std::to_string(o.num_modes)) +
        "; ask for fewer modes or use the dense engine");
  if (n < 3)
    throw std::invalid_argument("the SLEPc engine needs at least 3 equations, the model has " +
                                std::to_string(n) + "; use the dense engine");
  if (!(o.shift_hz > 0.0) || !std::isfinite(o.shift_hz))
    throw std::invalid_argument("shift_hz must be > 0, got " + std::to_string(o.shift_hz));
  if (!(o.tolerance > 0.0) || o.max_iterations < 1)
    throw std::invalid_argument("tolerance must be > 0 and max_iterations >= 1");
}

} // namespace

SlepcSession::SlepcSession() {
  PetscBool started = PETSC_FALSE;
  check(SlepcInitialized(&started), "SlepcInitialized");
  if (!started) {
    check(SlepcInitialize(nullptr, nullptr, nullptr, nullptr), "starting MPI, PETSc and SLEPc");
    finalize_ = true;
    check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
  }
  PetscMPIInt rank = 0, size = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  rank_ = rank;
  size_ = size;
}

SlepcSession::~SlepcSession() {
  if (finalize_) SlepcFinalize();
}

Modes slepc_modal_analysis(const Model& model, const ModalOptions& o, const SlepcModalOptions& so) {
  PetscBool started = PETSC_FALSE;
  SlepcInitialized(&started);
  if (!started)
    throw std::logic_error("slepc_modal_analysis: no SlepcSession (make one in main())");
  auto start = std::chrono::steady_clock::now();
  model.validate();
  const DofMap dofs(model);
  const int n = dofs.num_equations();
  check_options(n, o);
  for (int e : so.rows)
    if (e < 0 || e >= n)
      throw std::invalid_argument("SLEPc modal analysis: row " + std::to_string(e) +
                                  " is not an equation of the model (0 … " + std::to_string(n - 1) +
                                  ")");
  PetscMPIInt rank = 0, size = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  DistributedModalStats stats;
  stats.ranks = size;

  // 1. This rank's rows of K and M: an even split of the equations.
  const auto first = static_cast<PetscInt>(static_cast<long long>(n) * rank / size);
  const auto last = static_cast<PetscInt>(static_cast<long long>(n) * (rank + 1) / size);
  OwnedMat K, M;
  {
    const Entries entries = assemble_rows(model, dofs, first, last);
    distributed_matrix(entries.K, first, last, n, K.out());
    distributed_matrix(entries.M, first, last, n, M.out());
  }
  stats.assemble_s = seconds_since(start);

  // 2. K φ = λ M φ, Hermitian generalised; shift-and-invert about σ below every λ (rigid modes
  //    included), (K − σM)⁻¹ by a MUMPS Cholesky (LDLᵀ) factorisation; the λ nearest σ first.
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  OwnedEps eps;
  check(EPSCreate(PETSC_COMM_WORLD, eps.out()), "EPSCreate");
  Mat operators[2] = {K.get(), M.get()};
  check(EPSSetOperators(eps.get(), operators[0], operators[1]), "EPSSetOperators");
  check(EPSSetProblemType(eps.get(), EPS_GHEP), "EPSSetProblemType");
  check(EPSSetType(eps.get(), EPSKRYLOVSCHUR), "EPSSetType");
  check(EPSSetTarget(eps.get(), sigma), "EPSSetTarget");
  check(EPSSetWhichEigenpairs(eps.get(), EPS_TARGET_MAGNITUDE), "EPSSetWhichEigenpairs");
  ST st = nullptr;
  KSP ksp = nullptr;
  PC pc = nullptr;
  check(EPSGetST(eps.get(), &st), "EPSGetST");
  check(STSetType(st, STSINVERT), "STSetType");
  check(STGetKSP(st, &ksp), "STGetKSP");
  check(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  check(PCSetType(pc, PCCHOLESKY), "PCSetType");
  check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType (MUMPS)");
  // MUMPS reads its ICNTL settings from the options database when the factor is made; a value
  // the user gave (PETSC_OPTIONS) wins. Removed again after the factorisation.
  const char* block_option = "-st_mat_mumps_icntl_15";
  PetscBool user_block = PETSC_FALSE;
  check(PetscOptionsHasName(nullptr, nullptr, block_option, &user_block), "PetscOptionsHasName");
  const int block = user_block ? 1 : uniform_node_block(dofs);
  if (block > 1)
    check(PetscOptionsSetValue(nullptr, block_option, std::to_string(-block).c_str()),
          "PetscOptionsSetValue");
  check(EPSSetTolerances(eps.get(), o.tolerance, o.max_iterations), "EPSSetTolerances");
  const bool band = o.max_frequency_hz > 0.0;
  int nev = band ? std::max(o.num_modes, 8) : o.num_modes;
  nev = std::min(nev, n - 1);
  // Krylov–Schur works with one vector at a time: of a repeated eigenvalue (a symmetric
  // structure's pairs) it finds the second copy only through rounding, late. Asked for exactly
  // nev modes it returned one copy of the double 19th/20th mode of a square 12 × 12 × 13 lattice
  // and the 21st as the 20th (the block Lanczos of the CHOLMOD engine found both, and so did
  // Spectra asked for 30). So it is asked for half as many again and the lowest are kept.
  const auto with_margin = [n](int count) {
    return std::min(count + std::max(6, count / 2), n - 1);
  };
  const int wanted_modes = nev;
  nev = with_margin(nev);
  check(EPSSetDimensions(eps.get(), nev, PETSC_DEFAULT, PETSC_DEFAULT), "EPSSetDimensions");
  check(EPSSetFromOptions(eps.get()), "EPSSetFromOptions"); // PETSC_OPTIONS may refine

  start = std::chrono::steady_clock::now();
  const PetscErrorCode set_up = EPSSetUp(eps.get());
  const PetscErrorCode factorised = set_up != 0 ? set_up : KSPSetUp(ksp);
  if (block > 1) PetscOptionsClearValue(nullptr, block_option);
  // A factorisation that breaks down (a zero or negative pivot) makes EPSSetUp fail with
  // PETSc's "error in external library": say what that means before the generic error. MUMPS'
  // INFOG(1) < 0 is its own verdict (-10: numerically singular) when PETSc records no reason.
  PCFailedReason failed = PC_NOERROR;
  const bool reason_known = PCGetFailedReason(pc, &failed) == 0;
  PetscInt mumps_status = 0;
  if (set_up != 0 || factorised != 0) {
    Mat factor = nullptr;
    if (PCFactorGetMatrix(pc, &factor) == 0 && factor != nullptr)
      MatMumpsGetInfog(factor, 1, &mumps_status);
  }
  if ((reason_known && failed != PC_NOERROR) || mumps_status < 0)
    throw std::invalid_argument(
        "SLEPc modal analysis: K + (2 pi " + std::to_string(o.shift_hz) +
        " Hz)^2 M could not be factorised (" +
        (reason_known && failed != PC_NOERROR
             ? std::string(PCFailedReasons[failed])
             : "MUMPS INFOG(1) = " + std::to_string(mumps_status) +
                   (mumps_status == -10 ? ", numerically singular" : "")) +
        "); look for a DOF with neither stiffness nor mass (e.g. a rotation no element or "
        "spring holds), or a negative mass or stiffness");
  check(set_up, "EPSSetUp");
  check(factorised, "factorising K - sigma M with MUMPS");
  stats.factorize_s = seconds_since(start);
  Mat factor = nullptr;
  if (PCFactorGetMatrix(pc, &factor) == 0 && factor != nullptr) {
    PetscInt entries = 0, max_mb = 0, sum_mb = 0;
    PetscReal flops = 0.0;
    if (MatMumpsGetInfog(factor, 29, &entries) == 0) stats.factor_entries = mumps_count(entries);
    if (MatMumpsGetInfog(factor, 21, &max_mb) == 0) stats.factor_max_bytes = 1e6 * max_mb;
    if (MatMumpsGetInfog(factor, 22, &sum_mb) == 0) stats.factor_sum_bytes = 1e6 * sum_mb;
    if (MatMumpsGetRinfog(factor, 3, &flops) == 0) stats.factor_flops = flops;
  }

  // 3. Solve; for a band, grow the count until the highest mode found lies above f_max (the
  //    factorisation is kept: only the Krylov–Schur iteration is repeated).
  const double lambda_max = std::pow(two_pi * o.max_frequency_hz, 2);
  std::vector<double> lambda;
  Modes out;
  start = std::chrono::steady_clock::now();
  while (true) {
    check(EPSSolve(eps.get()), "EPSSolve");
    PetscInt converged = 0, iterations = 0;
    check(EPSGetConverged(eps.get(), &converged), "EPSGetConverged");
    check(EPSGetIterationNumber(eps.get(), &iterations), "EPSGetIterationNumber");
    stats.restarts = static_cast<int>(iterations);
    if (converged < nev) {
      stats.solve_s = seconds_since(start);
      out.status = Status::failure(Status::Code::not_converging,
                                   "Krylov-Schur (SLEPc) converged " + std::to_string(converged) +
                                       " of " + std::to_string(nev) + " modes in " +
                                       std::to_string(iterations) + " restarts");
      out.distributed = stats;
      return out;
    }
    lambda.resize(nev);
    for (int i = 0; i < nev; ++i) {
      PetscScalar re = 0.0, im = 0.0;
      check(EPSGetEigenvalue(eps.get(), i, &re, &im), "EPSGetEigenvalue");
      lambda[i] = re;
    }
    if (!band || *std::max_element(lambda.begin(), lambda.end()) >= lambda_max || nev == n - 1)
      break;
    nev = with_margin(std::min(2 * nev, n - 1));
    check(EPSSetDimensions(eps.get(), nev, PETSC_DEFAULT, PETSC_DEFAULT), "EPSSetDimensions");
  }
  stats.solve_s = seconds_since(start);

  // 4. Ascending λ; a band keeps those below f_max, a count the first num_modes.
  std::vector<int> order(nev);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return lambda[a] < lambda[b]; });
  int count = std::min(wanted_modes, nev);
  if (band) {
    count = 0;
    while (count < nev && lambda[order[count]] < lambda_max)
      ++count;
  }
  out.omega.resize(count);
  for (int r = 0; r < count; ++r)
    out.omega(r) = std::sqrt(std::max(lambda[order[r]], 0.0));

  // 5. Mass-normalise each eigenvector and gather the rows asked for.
  const bool receive = rank == 0 || so.every_rank;
  std::vector<PetscInt> wanted;
  if (receive) {
    if (so.rows.empty()) {
      wanted.resize(n);
      std::iota(wanted.begin(), wanted.end(), 0);
    } else {
      wanted.assign(so.rows.begin(), so.rows.end());
    }
  }
  const auto k = static_cast<PetscInt>(wanted.size());
  OwnedVec x, mx, gathered;
  OwnedIs from;
  OwnedScatter scatter;
  check(MatCreateVecs(K.get(), x.out(), mx.out()), "MatCreateVecs");
  check(VecCreateSeq(PETSC_COMM_SELF, k, gathered.out()), "VecCreateSeq");
  check(ISCreateGeneral(PETSC_COMM_SELF, k, wanted.data(), PETSC_COPY_VALUES, from.out()),
        "ISCreateGeneral");
  check(VecScatterCreate(x.get(), from.get(), gathered.get(), nullptr, scatter.out()),
        "VecScatterCreate");
  out.phi.resize(k, count);
  for (int r = 0; r < count; ++r) {
    check(EPSGetEigenvector(eps.get(), order[r], x.get(), nullptr), "EPSGetEigenvector");
    check(MatMult(M.get(), x.get(), mx.get()), "MatMult");
    PetscScalar mass = 0.0;
    check(VecDot(mx.get(), x.get(), &mass), "VecDot");
    if (!(mass > 0.0)) {
      out.status = Status::failure(Status::Code::numerical_issue,
                                   "mode " + std::to_string(r + 1) +
                                       " has no positive modal mass (M is not positive definite "
                                       "on it)");
      out.phi.resize(0, 0);
      out.omega.resize(0);
      out.distributed = stats;
      return out;
    }
    check(VecScale(x.get(), 1.0 / std::sqrt(mass)), "VecScale");
    check(VecScatterBegin(scatter.get(), x.get(), gathered.get(), INSERT_VALUES, SCATTER_FORWARD),
          "VecScatterBegin");
    check(VecScatterEnd(scatter.get(), x.get(), gathered.get(), INSERT_VALUES, SCATTER_FORWARD),
          "VecScatterEnd");
    const PetscScalar* values = nullptr;
    check(VecGetArrayRead(gathered.get(), &values), "VecGetArrayRead");
    for (PetscInt i = 0; i < k; ++i)
      out.phi(i, r) = values[i];
    check(VecRestoreArrayRead(gathered.get(), &values), "VecRestoreArrayRead");
  }
  if (receive && !so.rows.empty()) out.rows = so.rows;
  out.distributed = stats;
  return out;
}

} // namespace jointid::fem
