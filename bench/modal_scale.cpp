// Modal analysis at scale: builds a 3D frame lattice (bench/lattice.hpp), times assembly and
// the 20 lowest modes, checks the eigen-equation, reports peak memory, and prints one JSON line.
// Large cases run once, so this is a plain main, not Google Benchmark. Results and the scipy
// comparison: docs/benchmarks_modal.md, made by scripts/bench_modal_scale.sh.
//
//   bench_modal_scale SIZE [--export DIR] [--engine sparse|dense|proto] [--modes N]
//                          [--ordering default|amd|metis|nesdis|natural] [--ncv N]
//                          [--tolerance T] [--index int|long] [--analyze-only]
//                          [--shift-hz F]
//
// SIZE is 1e4, 1e5, 1e6 or NXxNYxNZ (grid nodes per axis). `--engine sparse` (default) and
// `dense` call fem::modal_analysis; `proto` runs a copy of the library's shift-invert operator
// with the CHOLMOD ordering, Spectra ncv and index type exposed, and times its stages, to
// measure proposals for fem/modal.cpp (scripts/bench_modal_proposals.sh).
#include "bench/lattice.hpp"
#include "bench/matrix_market.hpp"
#include "fem/assembly.hpp"
#include "fem/modal.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Core>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <nlohmann/json.hpp>

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

using namespace jointid;
using json = nlohmann::json;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

// ---- memory and time -------------------------------------------------------------------------

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// A field of /proc/self/status in MiB (VmHWM: peak resident set, VmRSS: current), -1 if absent.
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

double ru_maxrss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0; // Linux: KiB
}

/// Resets the kernel's peak-RSS mark (VmHWM and ru_maxrss) to the current RSS, so that the
/// next reading is the peak of the stage that follows. Linux >= 4.0.
bool reset_peak_rss() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  return static_cast<bool>(out);
}

// ---- arguments -------------------------------------------------------------------------------

struct Options {
  std::string size = "1e4";
  int nx = 0, ny = 0, nz = 0;
  double spacing = 1.0;
  std::string export_dir;
  std::string engine = "sparse";
  int modes = 20;
  std::string ordering = "default";
  int ncv = 0; // 0: the library's rule
  double tolerance = 1e-10;
  double shift_hz = 1.0; // the library's default
  std::string index = "int";
  bool analyze_only = false;
};

[[noreturn]] void usage_error(const std::string& why) {
  throw std::invalid_argument(
      why + "\nusage: bench_modal_scale SIZE [--export DIR] [--engine sparse|dense|proto] "
            "[--modes N] [--ordering default|amd|metis|nesdis|natural] [--ncv N] "
            "[--tolerance T] [--index int|long] [--analyze-only] "
            "[--shift-hz F]   (SIZE: 1e4, 1e5, 1e6 or "
            "NXxNYxNZ)");
}

Options parse(int argc, char** argv) {
  Options o;
  bool have_size = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--export")
      o.export_dir = value();
    else if (a == "--engine")
      o.engine = value();
    else if (a == "--modes")
      o.modes = std::stoi(value());
    else if (a == "--ordering")
      o.ordering = value();
    else if (a == "--ncv")
      o.ncv = std::stoi(value());
    else if (a == "--tolerance")
      o.tolerance = std::stod(value());
    else if (a == "--index")
      o.index = value();
    else if (a == "--spacing")
      o.spacing = std::stod(value());
    else if (a == "--analyze-only")
      o.analyze_only = true;
    else if (a == "--shift-hz")
      o.shift_hz = std::stod(value());
    else if (!a.empty() && a[0] == '-')
      usage_error("unknown option " + a);
    else if (!have_size) {
      o.size = a;
      have_size = true;
    } else
      usage_error("unexpected argument " + a);
  }
  // Grid nodes per axis; base layer fixed: free DOFs = 6 nx ny (nz - 1).
  if (o.size == "1e4")
    o.nx = 12, o.ny = 12, o.nz = 13; // 10 368 DOFs
  else if (o.size == "1e5")
    o.nx = 26, o.ny = 26, o.nz = 26; // 101 400 DOFs
  else if (o.size == "1e6")
    o.nx = 55, o.ny = 55, o.nz = 56; // 998 250 DOFs
  else if (std::sscanf(o.size.c_str(), "%dx%dx%d", &o.nx, &o.ny, &o.nz) != 3)
    usage_error("SIZE '" + o.size + "' is not 1e4, 1e5, 1e6 or NXxNYxNZ");
  if (o.engine != "sparse" && o.engine != "dense" && o.engine != "proto")
    usage_error("--engine must be sparse, dense or proto, not " + o.engine);
  if (o.index != "int" && o.index != "long") usage_error("--index must be int or long");
  return o;
}

// ---- the prototype: the library's shift-invert operator with its settings exposed ------------

struct ProtoStats {
  std::string ordering_used;
  double lnz = 0.0, flops = 0.0;
  double analyze_s = 0.0, factor_s = 0.0, solve_s = 0.0;
  long long solves = 0;
  double cholmod_peak_mib = 0.0;
};

int cholmod_ordering(const std::string& name) {
  if (name == "amd") return CHOLMOD_AMD;
  if (name == "metis") return CHOLMOD_METIS;
  if (name == "nesdis") return CHOLMOD_NESDIS;
  if (name == "natural") return CHOLMOD_NATURAL;
  throw std::invalid_argument("--ordering must be default, amd, metis, nesdis or natural");
}

std::string ordering_name(int ordering) {
  switch (ordering) {
  case CHOLMOD_NATURAL:
    return "natural";
  case CHOLMOD_GIVEN:
    return "given";
  case CHOLMOD_AMD:
    return "amd";
  case CHOLMOD_METIS:
    return "metis";
  case CHOLMOD_NESDIS:
    return "nesdis";
  case CHOLMOD_COLAMD:
    return "colamd";
  case CHOLMOD_POSTORDERED:
    return "postordered";
  default:
    return "unknown";
  }
}

// Copy of fem/modal.cpp's CholmodShiftInvert, plus: lower triangle only handed to CHOLMOD,
// analysis and factorisation timed apart, a choice of ordering, a check of CHOLMOD's status
// after the analysis (Eigen would dereference a null factor if the analysis failed), solves
// counted.
template <typename Sparse> class ProtoShiftInvert {
public:
  using Scalar = double;
  ProtoShiftInvert(const Sparse& K, const Sparse& M, const Options& o, ProtoStats& stats)
      : K_(K), M_(M), options_(o), stats_(stats) {}
  Eigen::Index rows() const { return K_.rows(); }
  Eigen::Index cols() const { return K_.cols(); }
  void set_shift(double sigma) {
    const Sparse A = (K_ - sigma * M_).template triangularView<Eigen::Lower>();
    cholmod_common& cm = llt_.cholmod();
    if (options_.ordering != "default") {
      cm.nmethods = 1;
      cm.method[0].ordering = cholmod_ordering(options_.ordering);
    }
    auto start = std::chrono::steady_clock::now();
    llt_.analyzePattern(A);
    stats_.analyze_s = seconds_since(start);
    if (cm.status < 0)
      throw std::runtime_error("CHOLMOD analysis failed, status " + std::to_string(cm.status));
    stats_.ordering_used = ordering_name(cm.method[cm.selected].ordering);
    stats_.lnz = cm.lnz;
    stats_.flops = cm.fl;
    if (options_.analyze_only) return;
    start = std::chrono::steady_clock::now();
    llt_.factorize(A);
    stats_.factor_s = seconds_since(start);
    if (cm.status < 0)
      throw std::runtime_error("CHOLMOD factorisation failed, status " + std::to_string(cm.status));
    if (llt_.info() != Eigen::Success)
      throw std::runtime_error("K - sigma*M is not positive definite");
    stats_.cholmod_peak_mib = static_cast<double>(cm.memory_usage) / (1024.0 * 1024.0);
  }
  void perform_op(const double* x_in, double* y_out) const {
    const auto start = std::chrono::steady_clock::now();
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = llt_.solve(x);
    ++stats_.solves;
    stats_.solve_s += seconds_since(start);
  }

private:
  const Sparse& K_;
  const Sparse& M_;
  const Options& options_;
  ProtoStats& stats_;
  Eigen::CholmodSupernodalLLT<Sparse, Eigen::Lower> llt_;
};

template <typename Sparse>
fem::Modes proto_modes(const Sparse& K, const Sparse& M, const Options& o, double sigma,
                       ProtoStats& stats, json& extra) {
  const int n = static_cast<int>(K.rows());
  const int nev = o.modes;
  const int ncv = o.ncv > 0 ? o.ncv : std::min(n, std::max(2 * nev + 1, nev + 20));
  ProtoShiftInvert<Sparse> op(K, M, o, stats);
  Spectra::SparseSymMatProd<double, Eigen::Lower, Eigen::ColMajor, typename Sparse::StorageIndex>
      bop(M);
  Spectra::SymGEigsShiftSolver<ProtoShiftInvert<Sparse>, decltype(bop),
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, bop, nev, ncv, sigma);
  fem::Modes out;
  extra["ncv"] = ncv;
  extra["ordering_used"] = stats.ordering_used;
  extra["lnz"] = stats.lnz;
  extra["factor_flops"] = stats.flops;
  extra["analyze_s"] = stats.analyze_s;
  if (o.analyze_only) {
    out.status = fem::ModalStatus::not_converging;
    return out;
  }
  extra["factor_s"] = stats.factor_s;
  extra["cholmod_peak_mib"] = stats.cholmod_peak_mib;
  const auto start = std::chrono::steady_clock::now();
  solver.init();
  solver.compute(Spectra::SortRule::LargestMagn, 1000, o.tolerance,
                 Spectra::SortRule::SmallestAlge);
  extra["lanczos_s"] = seconds_since(start);
  extra["solves"] = stats.solves;
  extra["solve_s"] = stats.solve_s;
  extra["restarts"] = solver.num_iterations();
  if (solver.info() != Spectra::CompInfo::Successful) {
    out.status = fem::ModalStatus::not_converging;
    return out;
  }
  out.omega = solver.eigenvalues().unaryExpr([](double l) { return std::sqrt(std::max(l, 0.0)); });
  out.phi = solver.eigenvectors();
  return out;
}

// ---- the benchmark ---------------------------------------------------------------------------

std::string status_name(fem::ModalStatus s) {
  switch (s) {
  case fem::ModalStatus::success:
    return "success";
  case fem::ModalStatus::not_converging:
    return "not_converging";
  case fem::ModalStatus::numerical_issue:
    return "numerical_issue";
  }
  return "unknown";
}

int run(const Options& o) {
  json r;
  r["size"] = o.size;
  r["grid"] = {o.nx, o.ny, o.nz};
  r["engine"] = o.engine;

  // 1. The lattice.
  auto start = std::chrono::steady_clock::now();
  const fem::Model model = bench::frame_lattice(o.nx, o.ny, o.nz, o.spacing);
  r["lattice_s"] = seconds_since(start);
  r["nodes"] = model.nodes.size();
  r["elements"] = model.elements.size();

  // 2. Assembly.
  start = std::chrono::steady_clock::now();
  const fem::Assembled system = fem::assemble(model);
  r["assembly_s"] = seconds_since(start);
  const fem::SparseMatrix& K = system.K;
  const fem::SparseMatrix& M = system.M;
  r["dofs"] = system.dofs.num_equations();
  r["nnz_K"] = K.nonZeros();
  r["nnz_M"] = M.nonZeros();
  r["peak_rss_to_assembly_mib"] = proc_status_mib("VmHWM");

  if (!o.export_dir.empty()) {
    start = std::chrono::steady_clock::now();
    bench::write_matrix_market_symmetric(o.export_dir + "/K.mtx", K);
    bench::write_matrix_market_symmetric(o.export_dir + "/M.mtx", M);
    r["export_s"] = seconds_since(start);
  }

  // 3. Modes. The peak mark is reset so that the modal stage's own peak is seen.
  const double sigma = -std::pow(two_pi * o.shift_hz, 2);
  r["sigma"] = sigma;
  r["rss_before_modal_mib"] = proc_status_mib("VmRSS");
  r["peak_reset"] = reset_peak_rss();
  fem::Modes modes;
  json extra;
  start = std::chrono::steady_clock::now();
  if (o.engine == "proto") {
    ProtoStats stats;
    if (o.index == "long") {
      using LongSparse = Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long>;
      const LongSparse K_long = K, M_long = M;
      modes = proto_modes(K_long, M_long, o, sigma, stats, extra);
    } else {
      modes = proto_modes(K, M, o, sigma, stats, extra);
    }
    r["proto"] = extra;
  } else {
    fem::ModalOptions mo;
    mo.num_modes = o.modes;
    mo.engine = o.engine == "dense" ? fem::ModalEngine::dense : fem::ModalEngine::sparse;
    mo.tolerance = o.tolerance;
    mo.shift_hz = o.shift_hz;
    modes = fem::modal_analysis(system, mo);
  }
  r["modal_s"] = seconds_since(start);
  r["peak_rss_modal_mib"] = proc_status_mib("VmHWM");
  r["ru_maxrss_mib"] = ru_maxrss_mib();
  r["status"] = status_name(modes.status);

  // 4. Checks: ‖KΦ − MΦΛ‖_F / ‖KΦ‖_F and max |ΦᵀMΦ − I|.
  if (modes.status == fem::ModalStatus::success) {
    const Eigen::VectorXd lambda = modes.omega.array().square();
    const Eigen::MatrixXd KPhi = K * modes.phi;
    const Eigen::MatrixXd MPhi = M * modes.phi;
    r["residual"] = (KPhi - MPhi * lambda.asDiagonal()).norm() / KPhi.norm();
    const Eigen::MatrixXd gram = modes.phi.transpose() * MPhi;
    const int m = modes.num_modes();
    r["orthonormality"] = (gram - Eigen::MatrixXd::Identity(m, m)).cwiseAbs().maxCoeff();
    r["eigenvalues"] = std::vector<double>(lambda.data(), lambda.data() + lambda.size());
    std::vector<double> hz(m);
    for (int i = 0; i < m; ++i)
      hz[i] = modes.frequency_hz(i);
    r["frequencies_hz"] = hz;
  }
  std::cout << r.dump() << std::endl;
  return modes.status == fem::ModalStatus::success || o.analyze_only ? 0 : 1;
}

} // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::cerr << "bench_modal_scale: " << e.what() << "\n";
    return 2;
  }
}
