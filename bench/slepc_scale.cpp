// The distributed (SLEPc) modal engine at scale, on the 3D frame lattices of bench_modal_scale
// (same grids, 1 m spacing):
// the 20 lowest modes, only a few rows of φ gathered (as a synthesis would), every stage timed
// and the peak memory of every rank. Run under mpirun; rank 0 prints one JSON line. Results:
// docs/benchmarks.md.
//
//   mpirun -np N bench_slepc_scale SIZE [--modes M]
//
// SIZE is 1e4, 1e5 or NXxNYxNZ (grid nodes per axis). The 1e6 case (55×55×56) is accepted but
// needs ~20 GiB (see docs/scaling.md): do not run it on a shared machine.
#include "bench/lattice.hpp"
#include "fem/slepc_modal.hpp"

#include <mpi.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace jointid;

namespace {

/// A field of /proc/self/status in MiB (VmHWM: peak resident set, VmRSS: current).
double proc_status_mib(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) {
      std::istringstream s(line.substr(field.size() + 1));
      double kib = 0.0;
      s >> kib;
      return kib / 1024.0;
    }
  return -1.0;
}

// One value per rank, on rank 0.
std::vector<double> gathered(double value, int size) {
  std::vector<double> all(size);
  MPI_Gather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return all;
}

int run(int argc, char** argv) {
  std::string size = argc > 1 ? argv[1] : "1e4";
  int modes = 20;
  for (int i = 2; i + 1 < argc; i += 2)
    if (std::string(argv[i]) == "--modes") modes = std::stoi(argv[i + 1]);
  int nx = 0, ny = 0, nz = 0;
  if (size == "1e4")
    nx = 12, ny = 12, nz = 13;
  else if (size == "1e5")
    nx = 26, ny = 26, nz = 26;
  else if (size == "1e6")
    nx = 55, ny = 55, nz = 56;
  else if (std::sscanf(size.c_str(), "%dx%dx%d", &nx, &ny, &nz) != 3)
    throw std::invalid_argument("SIZE: expected 1e4, 1e5, 1e6 or NXxNYxNZ, got " + size);

  const fem::SlepcSession mpi;
  const auto start = std::chrono::steady_clock::now();
  const fem::Model model = bench::frame_lattice(nx, ny, nz, 1.0);
  const double model_mib = proc_status_mib("VmRSS");
  fem::ModalOptions options;
  options.num_modes = modes;
  // Rows a synthesis of a few drive points and joints would gather.
  const fem::Modes result = fem::slepc_modal_analysis(model, options, {.rows = {0, 1, 2, 3}});
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<double> peak = gathered(proc_status_mib("VmHWM"), mpi.size());
  const std::vector<double> after_model = gathered(model_mib, mpi.size());
  if (mpi.rank() != 0) return result.status.ok() ? 0 : 1;

  const fem::DistributedModalStats& s = *result.distributed;
  nlohmann::json j;
  j["size"] = size;
  j["grid"] = std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz);
  j["free_dofs"] = bench::lattice_size(nx, ny, nz).free_dofs;
  j["ranks"] = s.ranks;
  j["status"] = result.status.ok() ? "success" : "failed";
  j["modes"] = result.num_modes();
  j["assemble_s"] = s.assemble_s;
  j["factorize_s"] = s.factorize_s;
  j["solve_s"] = s.solve_s;
  j["restarts"] = s.restarts;
  j["total_s"] = total_s; // model built, assembled, solved, rows gathered
  j["factor_entries"] = s.factor_entries;
  j["factor_flops"] = s.factor_flops;
  j["mumps_max_rank_mb"] = s.factor_max_bytes / 1e6;
  j["mumps_sum_mb"] = s.factor_sum_bytes / 1e6;
  j["peak_rss_mib_per_rank"] = peak;
  j["rss_after_model_mib_per_rank"] = after_model;
  std::vector<double> hz, lambda;
  for (int r = 0; r < result.num_modes(); ++r) {
    if (r < 5) hz.push_back(result.frequency_hz(r));
    lambda.push_back(result.omega(r) * result.omega(r));
  }
  j["first_hz"] = hz;
  j["eigenvalues"] = lambda; // ω², rad²/s², as bench_modal_scale prints them
  std::cout << j.dump() << std::endl;
  return result.status.ok() ? 0 : 1;
}

} // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "bench_slepc_scale: " << e.what() << "\n";
    return 1;
  }
}
