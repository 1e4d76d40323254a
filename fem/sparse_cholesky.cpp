#include "fem/sparse_cholesky.hpp"

#include "fem/supernodal_solve.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace jointid::fem {

namespace {

using Long = SuiteSparse_long;

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

int cholmod_ordering(CholeskyOrdering o) {
  switch (o) {
  case CholeskyOrdering::amd:
    return CHOLMOD_AMD;
  case CholeskyOrdering::metis:
    return CHOLMOD_METIS;
  case CholeskyOrdering::nesdis:
    return CHOLMOD_NESDIS;
  case CholeskyOrdering::automatic:
    break;
  }
  return CHOLMOD_METIS;
}

std::string gib(double bytes) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(bytes < 10.0 * (1 << 30) ? 2 : 1);
  s << bytes / (1024.0 * 1024.0 * 1024.0) << " GiB";
  return s.str();
}

std::string status_text(int status) {
  switch (status) {
  case CHOLMOD_OUT_OF_MEMORY:
    return "out of memory";
  case CHOLMOD_TOO_LARGE:
    return "integer overflow (problem too large)";
  case CHOLMOD_INVALID:
    return "invalid input";
  case CHOLMOD_GPU_PROBLEM:
    return "GPU problem";
  case CHOLMOD_NOT_INSTALLED:
    return "method not installed";
  default:
    return "status " + std::to_string(status);
  }
}

} // namespace

double available_memory_bytes() {
  double available = -1.0;
  {
    std::ifstream in("/proc/meminfo");
    std::string key, unit;
    double value = 0.0;
    while (in >> key >> value >> unit)
      if (key == "MemAvailable:") {
        available = value * 1024.0; // kB
        break;
      }
  }
  // A cgroup (v2) limit, as in containers and batch jobs, can be tighter than the machine.
  std::ifstream max_in("/sys/fs/cgroup/memory.max"), current_in("/sys/fs/cgroup/memory.current");
  std::string max_text;
  double current = 0.0;
  if (max_in >> max_text && max_text != "max" && current_in >> current) {
    const double room = std::max(0.0, std::stod(max_text) - current);
    available = available < 0.0 ? room : std::min(available, room);
  }
  return available;
}

// Owners of CHOLMOD objects, so that no exception path leaks one.
struct FreeSparse {
  cholmod_common* common;
  void operator()(cholmod_sparse* p) const { cholmod_l_free_sparse(&p, common); }
};
struct FreeFactor {
  cholmod_common* common;
  void operator()(cholmod_factor* p) const { cholmod_l_free_factor(&p, common); }
};
using SparsePtr = std::unique_ptr<cholmod_sparse, FreeSparse>;
using FactorPtr = std::unique_ptr<cholmod_factor, FreeFactor>;

// The pattern of a lower triangle: its size and a hash (FNV-1a) of its column pointers and
// row indices, to check that factorize gets the pattern that was analysed.
struct Pattern {
  Long nonzeros = -1;
  std::uint64_t hash = 0;
  bool operator==(const Pattern&) const = default;
};

Pattern pattern_of(const cholmod_sparse& L) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](Long v) {
    h ^= static_cast<std::uint64_t>(v);
    h *= 1099511628211ull;
  };
  const auto* p = static_cast<const Long*>(L.p);
  const auto* i = static_cast<const Long*>(L.i);
  const Long n = static_cast<Long>(L.ncol);
  for (Long j = 0; j <= n; ++j)
    mix(p[j]);
  for (Long k = 0; k < p[n]; ++k)
    mix(i[k]);
  return {p[n], h};
}

struct SparseCholesky::Impl {
  CholeskyOptions options;
  CholeskyAnalysis analysis;
  mutable cholmod_common common{};
  cholmod_factor* factor = nullptr;
  Pattern pattern; // of the analysed matrix's lower triangle
  bool factorized = false;
  // Workspace reused by every solve (cholmod_l_solve2).
  mutable cholmod_dense* x = nullptr;
  mutable cholmod_dense* y = nullptr;
  mutable cholmod_dense* e = nullptr;
  // Our block solve's plan and work space (fem/supernodal_solve.hpp), made at its first use
  // after a factorisation.
  mutable std::unique_ptr<SupernodalSolver> own_solver;

  explicit Impl(const CholeskyOptions& o) : options(o) {
    cholmod_l_start(&common);
    common.print = 0; // errors come back as exceptions, not text on stdout
    common.supernodal = CHOLMOD_SUPERNODAL;
    // Supernodes of more than nrelax[2] (48) columns are merged only when that adds no
    // zeros (CHOLMOD's default allows 5 %): the largest supernodes hold most of the factor.
    common.zrelax[2] = o.large_supernode_zeros;
    if (o.ordering != CholeskyOrdering::automatic) {
      common.nmethods = 1;
      common.method[0].ordering = cholmod_ordering(o.ordering);
    }
  }
  ~Impl() {
    // Everything CHOLMOD allocated goes back before cholmod_l_finish.
    cholmod_l_free_dense(&x, &common);
    cholmod_l_free_dense(&y, &common);
    cholmod_l_free_dense(&e, &common);
    cholmod_l_free_factor(&factor, &common);
    cholmod_l_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void check(const char* step) const {
    if (common.status < 0)
      throw std::runtime_error(std::string("sparse Cholesky ") + step +
                               " failed: " + status_text(common.status));
  }

  // A fill-reducing ordering of A computed on the graph of its groups (e.g. the nodes of a
  // finite-element mesh, whose DOFs share one adjacency), expanded to the equations: the
  // groups in the graph ordering, the equations of each group in ascending order.
  std::vector<Long> group_ordering(const Eigen::SparseMatrix<double>& A,
                                   const std::vector<int>& groups, int ordering) {
    const Long n = A.cols();
    if (n == 0) return {};
    // Group numbers are labels: number the groups that occur 0 .. num_groups-1 (fixed nodes
    // leave gaps in fem::DofMap's node positions).
    std::vector<int> labels(groups);
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
    const auto num_groups = static_cast<Long>(labels.size());
    std::vector<int> group(n);
    for (Long i = 0; i < n; ++i)
      group[i] = static_cast<int>(std::lower_bound(labels.begin(), labels.end(), groups[i]) -
                                  labels.begin());
    labels = {};
    // Both directions of every coupling: A may hold only one triangle, and group numbers
    // need not grow with the equation numbers.
    std::vector<Eigen::Triplet<double, int>> edges;
    edges.reserve(2 * static_cast<std::size_t>(A.nonZeros()));
    for (Long j = 0; j < n; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) {
        edges.emplace_back(group[it.row()], group[j], 1.0);
        edges.emplace_back(group[j], group[it.row()], 1.0);
      }
    Eigen::SparseMatrix<double> G(num_groups, num_groups);
    G.setFromTriplets(edges.begin(), edges.end());
    edges = {};
    SparsePtr graph(lower_triangle(G), FreeSparse{&common});
    G = {};
    std::vector<Long> order(num_groups);
    if (ordering == CHOLMOD_NESDIS) {
      std::vector<Long> parent(num_groups), member(num_groups);
      cholmod_l_nested_dissection(graph.get(), nullptr, 0, order.data(), parent.data(),
                                  member.data(), &common);
    } else if (ordering == CHOLMOD_AMD) {
      cholmod_l_amd(graph.get(), nullptr, 0, order.data(), &common);
    } else {
      cholmod_l_metis(graph.get(), nullptr, 0, 1, order.data(), &common);
    }
    graph.reset();
    check("ordering");
    std::vector<Long> start(num_groups + 1, 0);
    for (int g : group)
      ++start[static_cast<std::size_t>(g) + 1];
    std::vector<Long> first(num_groups + 1, 0); // first position of each group in the ordering
    for (Long k = 0; k < num_groups; ++k)
      first[k + 1] = first[k] + start[order[k] + 1];
    std::vector<Long> slot(num_groups);
    for (Long k = 0; k < num_groups; ++k)
      slot[order[k]] = first[k];
    std::vector<Long> perm(n);
    for (Long i = 0; i < n; ++i)
      perm[slot[group[i]]++] = i;
    return perm;
  }

  // Symbolic factorisation, with CHOLMOD's ordering (perm null) or a given one.
  cholmod_factor* symbolic(cholmod_sparse* lower, Long* perm) {
    cholmod_factor* L = nullptr;
    if (perm == nullptr) {
      L = cholmod_l_analyze(lower, &common);
    } else {
      const int saved_nmethods = common.nmethods;
      const int saved_ordering = common.method[0].ordering;
      common.nmethods = 1;
      common.method[0].ordering = CHOLMOD_GIVEN;
      L = cholmod_l_analyze_p(lower, perm, nullptr, 0, &common);
      common.nmethods = saved_nmethods;
      common.method[0].ordering = saved_ordering;
    }
    if (L == nullptr) {
      check("analysis");
      throw std::runtime_error("sparse Cholesky analysis failed");
    }
    return L;
  }

  // The prediction for a symbolic factor just computed (CHOLMOD's lnz and fl are those of the
  // last analysis).
  CholeskyAnalysis describe(const cholmod_factor& L, std::string ordering) const {
    CholeskyAnalysis a;
    a.rows = static_cast<std::int64_t>(L.n);
    a.factor_nonzeros = common.lnz;
    a.flops = common.fl;
    a.ordering = std::move(ordering);
    if (L.is_super) {
      a.factor_entries = static_cast<double>(L.xsize);
      // Values, and the update-matrix workspace of the numeric factorisation; the integer
      // parts (s, super, pi, px) already exist after the analysis.
      a.factor_bytes = 8.0 * (static_cast<double>(L.xsize) + static_cast<double>(L.maxcsize));
    } else {
      a.factor_entries = a.factor_nonzeros;
      a.factor_bytes = 16.0 * a.factor_nonzeros; // values and row indices
    }
    return a;
  }

  // The lower triangle of A as a packed, sorted CHOLMOD matrix with 64-bit indices; the
  // caller frees it.
  cholmod_sparse* lower_triangle(const Eigen::SparseMatrix<double>& A) {
    if (A.rows() != A.cols())
      throw std::invalid_argument("sparse Cholesky: the matrix is " + std::to_string(A.rows()) +
                                  " x " + std::to_string(A.cols()) + ", not square");
    const Long n = A.cols();
    Long count = 0;
    for (Long j = 0; j < n; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
        if (it.row() >= j) ++count;
    cholmod_sparse* L = cholmod_l_allocate_sparse(n, n, count, 1, 1, -1, CHOLMOD_REAL, &common);
    check("matrix copy");
    if (L == nullptr) throw std::runtime_error("sparse Cholesky: could not copy the matrix");
    auto* p = static_cast<Long*>(L->p);
    auto* i = static_cast<Long*>(L->i);
    auto* x = static_cast<double*>(L->x);
    Long k = 0;
    for (Long j = 0; j < n; ++j) {
      p[j] = k;
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
        if (it.row() >= j) {
          i[k] = it.row();
          x[k] = it.value();
          ++k;
        }
    }
    p[n] = k;
    return L;
  }
};

NotPositiveDefinite::NotPositiveDefinite(std::int64_t equation, std::int64_t rows)
    : std::domain_error("sparse Cholesky: the matrix is not positive definite (the "
                        "factorisation broke down at equation " +
                        std::to_string(equation) + ", counted from 0, of " + std::to_string(rows) +
                        ")"),
      equation_(equation) {}

SparseCholesky::SparseCholesky(CholeskyOptions options) : impl_(std::make_unique<Impl>(options)) {}

SparseCholesky::~SparseCholesky() = default;

const CholeskyAnalysis& SparseCholesky::analyze(const Eigen::SparseMatrix<double>& A,
                                                const std::vector<int>& groups) {
  Impl& m = *impl_;
  cholmod_l_free_factor(&m.factor, &m.common);
  m.factorized = false;
  m.own_solver.reset();
  const SparsePtr lower(m.lower_triangle(A), FreeSparse{&m.common});
  if (!groups.empty() && static_cast<Long>(groups.size()) != static_cast<Long>(A.cols()))
    throw std::invalid_argument("sparse Cholesky: " + std::to_string(groups.size()) +
                                " group numbers for " + std::to_string(A.cols()) + " equations");
  // Candidates: CHOLMOD's own choice on the equations (0), or orderings of the group graph.
  // `automatic` with groups tries METIS and NESDIS on the groups and CHOLMOD's default on the
  // equations, and keeps the factor that needs least memory: the analyses are cheap next to
  // the factorisation, and which wins depends on the mesh (node-wise won by 23 % on a
  // 10⁵-DOF frame lattice and lost on a small random cube). A candidate that fails (e.g. out
  // of memory in the partitioner) is skipped while another succeeds.
  std::vector<int> candidates{0};
  if (!groups.empty())
    candidates = m.options.ordering == CholeskyOrdering::automatic
                     ? std::vector<int>{CHOLMOD_METIS, CHOLMOD_NESDIS, 0}
                     : std::vector<int>{cholmod_ordering(m.options.ordering)};
  FactorPtr best(nullptr, FreeFactor{&m.common});
  CholeskyAnalysis best_analysis;
  std::string errors;
  for (int ordering : candidates) {
    try {
      FactorPtr candidate(nullptr, FreeFactor{&m.common});
      std::string name;
      if (ordering == 0) {
        candidate.reset(m.symbolic(lower.get(), nullptr));
        name = ordering_name(candidate->ordering);
      } else {
        std::vector<Long> perm = m.group_ordering(A, groups, ordering);
        candidate.reset(m.symbolic(lower.get(), perm.data()));
        name = ordering_name(ordering) + " on groups";
      }
      CholeskyAnalysis a = m.describe(*candidate, std::move(name));
      if (!best || a.factor_bytes < best_analysis.factor_bytes) {
        best = std::move(candidate);
        best_analysis = std::move(a);
      }
    } catch (const std::invalid_argument&) {
      throw; // bad input: no ordering will do better
    } catch (const std::exception& e) {
      errors += std::string(errors.empty() ? "" : "; ") + e.what();
    }
  }
  if (!best) throw std::runtime_error(errors);
  m.factor = best.release();
  m.analysis = std::move(best_analysis);
  m.pattern = pattern_of(*lower);
  return m.analysis;
}

void SparseCholesky::factorize(const Eigen::SparseMatrix<double>& A) {
  Impl& m = *impl_;
  if (m.factor == nullptr) analyze(A);
  if (A.rows() != m.analysis.rows || A.cols() != m.analysis.rows)
    throw std::invalid_argument("sparse Cholesky: factorize got a " + std::to_string(A.rows()) +
                                " x " + std::to_string(A.cols()) + " matrix, analysed " +
                                std::to_string(m.analysis.rows));
  m.factorized = false;
  m.own_solver.reset();
  const SparsePtr lower(m.lower_triangle(A), FreeSparse{&m.common});
  if (!(pattern_of(*lower) == m.pattern))
    throw std::invalid_argument("sparse Cholesky: factorize got a matrix whose nonzero pattern "
                                "differs from the analysed one; analyse it again");
  if (m.options.max_memory_fraction > 0.0) {
    // The factor's values (unless a previous factorisation allocated them) and workspace, and
    // CHOLMOD's permuted copy of the lower triangle (values and indices, like ours).
    const cholmod_factor& L = *m.factor;
    const double values_held = L.is_super && L.x != nullptr ? 8.0 * L.xsize : 0.0;
    const double copy = 16.0 * static_cast<double>(lower->nzmax) + 8.0 * (L.n + 1);
    const double need = m.analysis.factor_bytes - values_held + copy;
    const double available = available_memory_bytes();
    if (available > 0.0 && need > m.options.max_memory_fraction * available)
      throw std::runtime_error("sparse Cholesky: the factor of the " +
                               std::to_string(m.analysis.rows) + "-equation matrix needs about " +
                               gib(need) + " (" +
                               std::to_string(static_cast<long long>(m.analysis.factor_entries)) +
                               " values stored, " + m.analysis.ordering + " ordering), but only " +
                               gib(available) + " of memory is available");
  }
  cholmod_l_factorize(lower.get(), m.factor, &m.common);
  m.check("factorisation");
  const cholmod_factor& L = *m.factor;
  if (m.common.status == CHOLMOD_NOT_POSDEF || L.minor < L.n) {
    // L.minor counts columns of the permuted matrix; name the caller's equation.
    const auto column = static_cast<Long>(L.minor);
    const Long equation = L.Perm != nullptr ? static_cast<const Long*>(L.Perm)[column] : column;
    throw NotPositiveDefinite(equation, static_cast<std::int64_t>(L.n));
  }
  m.factorized = true;
}

void SparseCholesky::solve(const double* b, double* x) const {
  solve(b, x, 1);
}

void SparseCholesky::solve(const double* b, double* x, std::int64_t columns) const {
  const Impl& m = *impl_;
  if (!m.factorized) throw std::logic_error("sparse Cholesky: solve before factorize");
  if (columns < 0)
    throw std::invalid_argument("sparse Cholesky: solve with " + std::to_string(columns) +
                                " right-hand sides");
  if (columns == 0) return;
  const cholmod_factor& L = *m.factor;
  const int own_from = m.options.own_solve_columns >= 0   ? m.options.own_solve_columns
                       : m.analysis.factor_entries >= 2e6 ? 2
                                                          : 0;
  if (own_from > 0 && columns >= own_from && L.is_super && L.xtype == CHOLMOD_REAL &&
      L.dtype == CHOLMOD_DOUBLE) {
    static_assert(sizeof(Long) == sizeof(std::int64_t));
    if (!m.own_solver) {
      SupernodalFactorView view;
      view.n = static_cast<std::int64_t>(L.n);
      view.supernodes = static_cast<std::int64_t>(L.nsuper);
      view.first_column = static_cast<const std::int64_t*>(L.super);
      view.row_pointer = static_cast<const std::int64_t*>(L.pi);
      view.value_pointer = static_cast<const std::int64_t*>(L.px);
      view.rows = static_cast<const std::int64_t*>(L.s);
      view.values = static_cast<const double*>(L.x);
      view.permutation = static_cast<const std::int64_t*>(L.Perm); // null: the identity
      const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
      m.own_solver = std::make_unique<SupernodalSolver>(
          view, m.options.own_solve_threads > 0 ? m.options.own_solve_threads : cores);
    }
    m.own_solver->solve(b, x, columns);
    return;
  }
  const auto n = static_cast<std::size_t>(m.analysis.rows);
  const auto count = n * static_cast<std::size_t>(columns);
  cholmod_dense rhs{};
  rhs.nrow = n;
  rhs.ncol = static_cast<std::size_t>(columns);
  rhs.nzmax = count;
  rhs.d = n;
  rhs.x = const_cast<double*>(b); // read only
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  // The workspace (x, y, e) is kept between calls and resized by CHOLMOD when the number of
  // columns changes.
  if (!cholmod_l_solve2(CHOLMOD_A, m.factor, &rhs, nullptr, &m.x, nullptr, &m.y, &m.e, &m.common)) {
    m.check("solve");
    throw std::runtime_error("sparse Cholesky solve failed");
  }
  const auto* result = static_cast<const double*>(m.x->x);
  std::copy(result, result + count, x);
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& B) const {
  if (B.rows() != rows())
    throw std::invalid_argument("sparse Cholesky: solve with a " + std::to_string(B.rows()) +
                                "-row block for a matrix of " + std::to_string(rows()) + " rows");
  Eigen::MatrixXd X(B.rows(), B.cols());
  solve(B.data(), X.data(), B.cols());
  return X;
}

void SparseCholesky::set_own_solve_columns(int columns) {
  impl_->options.own_solve_columns = columns;
}

std::int64_t SparseCholesky::rows() const {
  return impl_->analysis.rows;
}

const CholeskyAnalysis& SparseCholesky::analysis() const {
  return impl_->analysis;
}

double SparseCholesky::peak_memory_bytes() const {
  return static_cast<double>(impl_->common.memory_usage);
}

} // namespace jointid::fem
