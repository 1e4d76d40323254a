// Modal analysis at scale: builds a 3D frame lattice (bench/lattice.hpp), times assembly and
// the 20 lowest modes, checks the eigen-equation, reports peak memory, and prints one JSON line.
// Large cases run once, so this is a plain main, not Google Benchmark. Results and the scipy
// comparison: docs/benchmarks_modal.md, made by scripts/bench_modal_scale.sh.
//
//   bench_modal_scale SIZE [--export DIR] [--engine sparse|dense] [--modes N]
//                          [--ordering default|amd|metis|nesdis]
//                          [--tolerance T] [--analyze-only] [--shift-hz F]
//                          [--method block|spectra] [--block-size B] [--basis N]
//                          [--solve-widths B1,B2,...]
//
// SIZE is 1e4, 1e5, 1e6 or NXxNYxNZ (grid nodes per axis). Both engines are the library's
// fem::modal_analysis; the sparse engine's stages (ordering, factorisation, Lanczos) are timed
// by the library and printed under "sparse". `--method` picks the sparse engine's iteration
// (block Lanczos, the default, or Spectra's), `--block-size` and `--basis` its block and
// basis cap. `--analyze-only` stops after the symbolic analysis of K − σM and prints the
// predicted factor (size, flops, ordering). `--solve-widths` factorises K − σM (ordering on
// the nodes, as the engine does) and times block solves of each width instead of the modes
// (best of 3 per width), to see what a pass over the factor costs per right-hand side:
// CHOLMOD's solve (`solve_s`, what the engine uses) and our own (`own_solve_s`,
// fem/supernodal_solve.hpp) on the same factor, and how far their results differ.
#include "bench/lattice.hpp"
#include "bench/matrix_market.hpp"
#include "fem/assembly.hpp"
#include "fem/modal.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

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
  double tolerance = 1e-10;
  double shift_hz = 1.0; // the library's default
  bool analyze_only = false;
  bool node_ordering = false;
  std::string method = "block";
  int block_size = 8; // the library's default
  int basis = 0;      // automatic
  std::vector<int> solve_widths;
};

[[noreturn]] void usage_error(const std::string& why) {
  throw std::invalid_argument(
      why + "\nusage: bench_modal_scale SIZE [--export DIR] [--engine sparse|dense] "
            "[--modes N] [--ordering default|amd|metis|nesdis] "
            "[--tolerance T] [--analyze-only] "
            "[--shift-hz F] [--method block|spectra] [--block-size B] [--basis N] "
            "[--solve-widths B1,B2,...]   (SIZE: 1e4, 1e5, 1e6 or "
            "NXxNYxNZ)");
}

fem::CholeskyOrdering ordering(const std::string& name) {
  if (name == "default") return fem::CholeskyOrdering::automatic;
  if (name == "amd") return fem::CholeskyOrdering::amd;
  if (name == "metis") return fem::CholeskyOrdering::metis;
  if (name == "nesdis") return fem::CholeskyOrdering::nesdis;
  usage_error("--ordering must be default, amd, metis or nesdis, not " + name);
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
    else if (a == "--tolerance")
      o.tolerance = std::stod(value());
    else if (a == "--spacing")
      o.spacing = std::stod(value());
    else if (a == "--analyze-only")
      o.analyze_only = true;
    else if (a == "--node-ordering")
      o.node_ordering = true;
    else if (a == "--shift-hz")
      o.shift_hz = std::stod(value());
    else if (a == "--method")
      o.method = value();
    else if (a == "--block-size")
      o.block_size = std::stoi(value());
    else if (a == "--basis")
      o.basis = std::stoi(value());
    else if (a == "--solve-widths") {
      std::istringstream list(value());
      std::string item;
      while (std::getline(list, item, ','))
        o.solve_widths.push_back(std::stoi(item));
    } else if (!a.empty() && a[0] == '-')
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
  if (o.engine != "sparse" && o.engine != "dense")
    usage_error("--engine must be sparse or dense, not " + o.engine);
  ordering(o.ordering); // checks the name
  if (o.method != "block" && o.method != "spectra")
    usage_error("--method must be block or spectra, not " + o.method);
  for (int b : o.solve_widths)
    if (b < 1) usage_error("--solve-widths: every width must be >= 1");
  return o;
}

json analysis_json(const fem::CholeskyAnalysis& a) {
  return {{"ordering_used", a.ordering},
          {"lnz", a.factor_nonzeros},
          {"factor_entries", a.factor_entries},
          {"factor_gib", a.factor_bytes / (1024.0 * 1024.0 * 1024.0)},
          {"factor_flops", a.flops}};
}

// ---- the benchmark ---------------------------------------------------------------------------

// "success" (the raw records' word for ok), else the code's name.
std::string status_name(const fem::Status& s) {
  return s.ok() ? "success" : std::string(fem::code_name(s.code));
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
  // What is known so far, on stderr, so that a run that dies later still reports it.
  std::cerr << "partial: " << r.dump() << std::endl;

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
  start = std::chrono::steady_clock::now();
  if (o.analyze_only) {
    fem::CholeskyOptions co;
    co.ordering = ordering(o.ordering);
    fem::SparseCholesky llt(co);
    const fem::SparseMatrix A = K - sigma * M;
    r["analysis"] = analysis_json(o.node_ordering ? llt.analyze(A, system.dofs.equation_nodes())
                                                  : llt.analyze(A));
    r["analyze_s"] = seconds_since(start);
    r["peak_rss_modal_mib"] = proc_status_mib("VmHWM");
    std::cout << r.dump() << std::endl;
    return 0;
  }
  if (!o.solve_widths.empty()) {
    // The factor the engine would use, then block solves of each width on random blocks.
    fem::CholeskyOptions co;
    co.ordering = ordering(o.ordering);
    fem::SparseCholesky llt(co);
    const fem::SparseMatrix A = K - sigma * M;
    r["analysis"] = analysis_json(llt.analyze(A, system.dofs.equation_nodes()));
    auto stage = std::chrono::steady_clock::now();
    llt.factorize(A);
    r["factorize_s"] = seconds_since(stage);
    json widths = json::array();
    for (int b : o.solve_widths) {
      const Eigen::MatrixXd B = Eigen::MatrixXd::Random(K.rows(), b);
      // Our own block solve (fem/supernodal_solve.hpp), then CHOLMOD's, on the same factor.
      Eigen::MatrixXd X[2] = {Eigen::MatrixXd(K.rows(), b), Eigen::MatrixXd(K.rows(), b)};
      double best[2] = {1e300, 1e300};
      for (int path = 0; path < 2; ++path) {
        llt.set_own_solve_columns(path == 0 ? 1 : 0);
        for (int rep = 0; rep < 3; ++rep) {
          stage = std::chrono::steady_clock::now();
          llt.solve(B.data(), X[path].data(), b);
          best[path] = std::min(best[path], seconds_since(stage));
        }
      }
      llt.set_own_solve_columns(co.own_solve_columns);
      widths.push_back({{"width", b},
                        {"own_solve_s", best[0]},
                        {"solve_s", best[1]},
                        {"per_column_s", best[1] / b},
                        {"max_relative_difference",
                         (X[0] - X[1]).cwiseAbs().maxCoeff() / X[1].cwiseAbs().maxCoeff()}});
    }
    r["block_solves"] = widths;
    r["peak_rss_modal_mib"] = proc_status_mib("VmHWM");
    std::cout << r.dump() << std::endl;
    return 0;
  }
  fem::ModalOptions mo;
  mo.num_modes = o.modes;
  mo.sparse_method =
      o.method == "spectra" ? fem::SparseMethod::spectra : fem::SparseMethod::block_lanczos;
  mo.block_size = o.block_size;
  mo.basis_vectors = o.basis;
  mo.engine = o.engine == "dense" ? fem::ModalEngine::dense : fem::ModalEngine::sparse;
  mo.tolerance = o.tolerance;
  mo.shift_hz = o.shift_hz;
  mo.cholesky.ordering = ordering(o.ordering);
  modes = fem::modal_analysis(system, mo);
  r["modal_s"] = seconds_since(start);
  r["peak_rss_modal_mib"] = proc_status_mib("VmHWM");
  r["ru_maxrss_mib"] = ru_maxrss_mib();
  r["status"] = status_name(modes.status);
  if (modes.sparse) {
    const fem::SparseModalStats& st = *modes.sparse;
    json j = analysis_json(st.factor);
    j["analyze_s"] = st.analyze_s;
    j["factorize_s"] = st.factorize_s;
    j["cholmod_peak_mib"] = st.cholesky_peak_bytes / (1024.0 * 1024.0);
    j["method"] = st.method;
    j["block_size"] = st.block_size;
    j["ncv"] = st.ncv;
    j["restarts"] = st.restarts;
    j["solves"] = st.solves;
    j["right_hand_sides"] = st.right_hand_sides;
    j["solve_s"] = st.solve_s;
    j["lanczos_s"] = st.lanczos_s;
    r["sparse"] = j;
  }

  // 4. Checks: ‖KΦ − MΦΛ‖_F / ‖KΦ‖_F and max |ΦᵀMΦ − I|.
  if (modes.status.ok()) {
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
  return modes.status.ok() ? 0 : 1;
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
