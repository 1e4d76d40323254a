#include "fem/supernodal_solve.hpp"

#include "fem/assert.hpp"

#include <algorithm>
#include <array>
#include <barrier>
#include <cstring>
#include <new>
#include <thread>
#include <type_traits>
#include <vector>

namespace jointid::fem {

namespace {

using Long = std::int64_t;

// Four and eight doubles (AVX and AVX-512 registers where the CPU has them, split into smaller
// ones otherwise). The file is compiled with -ffp-contract=fast (fem/CMakeLists.txt), so
// a * b + c becomes a fused multiply-add where the CPU has one. A scalar times a vector is
// broadcast by the compiler (one instruction; a vector written out of 8 equal scalars was
// compiled as 8 masked inserts).
typedef double v4 __attribute__((vector_size(32)));
typedef double v8 __attribute__((vector_size(64)));

#define JOINTID_KERNEL [[gnu::always_inline]] inline

template <class V> JOINTID_KERNEL V load(const double* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class V> JOINTID_KERNEL void store(double* p, V v) {
  std::memcpy(p, &v, sizeof v);
}

// Right-hand sides per kernel vector: a row of the work arrays holds a multiple of 8.
constexpr Long chunk = 8;
// Columns of a supernode taken at a time: the panel's triangle, then the rows below it.
constexpr Long panel = 256;
// Rows a kernel updates (forward) or reads (backward) while G columns of the factor go by:
// 256 rows of 8 right-hand sides (16 KiB) stay in the L1 cache.
constexpr Long row_block = 256;
// Top supernodes smaller than this (values) are done by one core: sharing them costs more in
// synchronisation than it saves.
constexpr Long shared_values = Long{1} << 16;
// What a barrier costs, in factor values one core reads in that time (~2 µs at ~0.5 ns a
// value), for choosing the cut.
constexpr double barrier_values = 4000.0;
// At most this much of the next supernode's values is prefetched (a quarter of a 1 MiB L2).
constexpr Long prefetch_bytes = Long{1} << 18;

// Thread t's share of `count` items out of `threads`, from the start; rounded down to a
// multiple of `align` except at the end.
Long share(Long count, int t, int threads, Long align) {
  if (t >= threads) return count;
  return count * t / threads / align * align;
}

// Doubles on a 64-byte boundary (a row of 8 right-hand sides is one cache line).
class Buffer {
public:
  void resize(Long size) {
    if (size <= size_) return;
    data_.reset(new (std::align_val_t(64)) double[static_cast<std::size_t>(size)]);
    size_ = size;
  }
  double* data() { return data_.get(); }

private:
  struct Free {
    void operator()(double* p) const { ::operator delete[](p, std::align_val_t(64)); }
  };
  std::unique_ptr<double[], Free> data_;
  Long size_ = 0;
};

// One supernode: its values L (nsrow × nscol, column-major, leading dimension nsrow) and the
// right-hand sides of its rows Y (nsrow × wp, row-major; wp a multiple of 8, the extra
// columns zero).
struct Block {
  const double* L;
  double* Y;
  Long nscol, nsrow, wp;
};

// The G columns j … j + G − 1 of a supernode's values.
template <int G> JOINTID_KERNEL std::array<const double*, G> columns(const Block& b, Long j) {
  std::array<const double*, G> l;
#pragma GCC unroll 8
  for (int k = 0; k < G; ++k)
    l[k] = b.L + (j + k) * b.nsrow;
  return l;
}

// Calls kernel(std::integral_constant<int, g>{}, j) for the columns [j0, j1) in groups of g = G,
// the rest in groups of 4, 2 and 1.
template <int G, class Kernel>
JOINTID_KERNEL void column_groups(Long j0, Long j1, Kernel&& kernel) {
  Long j = j0;
  for (; j + G <= j1; j += G)
    kernel(std::integral_constant<int, G>{}, j);
  if constexpr (G > 4)
    for (; j + 4 <= j1; j += 4)
      kernel(std::integral_constant<int, 4>{}, j);
  if constexpr (G > 2)
    for (; j + 2 <= j1; j += 2)
      kernel(std::integral_constant<int, 2>{}, j);
  for (; j < j1; ++j)
    kernel(std::integral_constant<int, 1>{}, j);
}

// Y(r, :) −= Σ_k L(r, j + k) Y(j + k, :) for the G columns j … j + G − 1 and rows r in
// [r0, r1): the G columns of L are read as G streams, each value once for all right-hand
// sides; two sums, so that a row's chain of fused multiply-adds is half as long.
template <int G> JOINTID_KERNEL void subtract_columns(const Block& b, Long j, Long r0, Long r1) {
  const Long wp = b.wp;
  const auto l = columns<G>(b, j);
  for (Long c = 0; c < wp; c += chunk) {
    v8 x[G];
#pragma GCC unroll 8
    for (int k = 0; k < G; ++k)
      x[k] = load<v8>(b.Y + (j + k) * wp + c);
    double* y = b.Y + c;
    for (Long r = r0; r < r1; ++r) {
      v8 a = load<v8>(y + r * wp), e{};
#pragma GCC unroll 8
      for (int k = 0; k < G; k += 2) {
        a -= l[k][r] * x[k];
        if (k + 1 < G) e += l[k + 1][r] * x[k + 1];
      }
      store(y + r * wp, a - e);
    }
  }
}

// Y(j + k, :) −= Σ_r L(r, j + k) Y(r, :) over rows r in [r0, r1), for the G columns j … j + G − 1.
template <int G> JOINTID_KERNEL void gather_columns(const Block& b, Long j, Long r0, Long r1) {
  const Long wp = b.wp;
  const auto l = columns<G>(b, j);
  for (Long c = 0; c < wp; c += chunk) {
    v8 s[G];
#pragma GCC unroll 8
    for (int k = 0; k < G; ++k)
      s[k] = v8{};
    const double* y = b.Y + c;
    for (Long r = r0; r < r1; ++r) {
      const v8 v = load<v8>(y + r * wp);
#pragma GCC unroll 8
      for (int k = 0; k < G; ++k)
        s[k] += l[k][r] * v;
    }
#pragma GCC unroll 8
    for (int k = 0; k < G; ++k) {
      double* t = b.Y + (j + k) * wp + c;
      store(t, load<v8>(t) - s[k]);
    }
  }
}

// Forward: the rows [r0, r1) below a solved panel (columns p0 … p0 + pb − 1), a block of rows
// at a time, G of the panel's columns at a time.
template <int G>
JOINTID_KERNEL void update_below(const Block& b, Long p0, Long pb, Long r0, Long r1) {
  for (Long rb = r0; rb < r1; rb += row_block) {
    const Long re = std::min(r1, rb + row_block);
    column_groups<G>(
        p0, p0 + pb, [&](auto g, Long j) __attribute__((always_inline)) {
          subtract_columns<g()>(b, j, rb, re);
        });
  }
}

// Backward: the panel's columns [j0, j1) less the products with the solved rows r0 … nsrow − 1.
template <int G> JOINTID_KERNEL void update_panel(const Block& b, Long j0, Long j1, Long r0) {
  for (Long rb = r0; rb < b.nsrow; rb += row_block) {
    const Long re = std::min(b.nsrow, rb + row_block);
    column_groups<G>(
        j0, j1, [&](auto g, Long j) __attribute__((always_inline)) {
          gather_columns<g()>(b, j, rb, re);
        });
  }
}

// The panel's own triangle, L(p0:p0+pb, p0:p0+pb) y = Y(p0:p0+pb, :), forward, for the
// right-hand sides 4 q0 … 4 q1 − 1 (the cores share them, four at a time).
JOINTID_KERNEL void triangle_forward(const Block& b, Long p0, Long pb, Long q0, Long q1) {
  const Long ld = b.nsrow, wp = b.wp;
  for (Long q = q0; q < q1; ++q)
    for (Long j = p0; j < p0 + pb; ++j) {
      const double* l = b.L + j * ld;
      double* yj = b.Y + j * wp + 4 * q;
      const v4 v = load<v4>(yj) / l[j];
      store(yj, v);
      for (Long i = j + 1; i < p0 + pb; ++i) {
        double* yi = b.Y + i * wp + 4 * q;
        store(yi, load<v4>(yi) - l[i] * v);
      }
    }
}

// The panel's own triangle transposed, L(p0:p0+pb, p0:p0+pb)ᵀ y = Y(p0:p0+pb, :), backward.
JOINTID_KERNEL void triangle_backward(const Block& b, Long p0, Long pb, Long q0, Long q1) {
  const Long ld = b.nsrow, wp = b.wp, end = p0 + pb;
  for (Long q = q0; q < q1; ++q)
    for (Long j = end - 1; j >= p0; --j) {
      const double* l = b.L + j * ld;
      const double* y = b.Y + 4 * q;
      v4 s0{}, s1{};
      Long i = j + 1;
      for (; i + 2 <= end; i += 2) {
        s0 += l[i] * load<v4>(y + i * wp);
        s1 += l[i + 1] * load<v4>(y + (i + 1) * wp);
      }
      if (i < end) s0 += l[i] * load<v4>(y + i * wp);
      double* yj = b.Y + j * wp + 4 * q;
      store(yj, (load<v4>(yj) - (s0 + s1)) / l[j]);
    }
}

} // namespace

struct SupernodalSolver::Plan {
  SupernodalFactorView F;
  int threads = 1;
  std::vector<Long> inverse; // inverse[equation] = row of L; empty for the identity
  // The cut: the subtrees each core does alone (supernodes ascending: children first), and the
  // top above them (ascending).
  std::vector<std::vector<Long>> local;
  std::vector<Long> top;
  std::vector<Long> top_row;     // per column of L: its row in the top buffers, −1 below the cut
  std::vector<Long> top_columns; // the top's columns, in that order
  Long widest = 0;

  Buffer work;                     // the permuted right-hand sides, n × wp, row-major
  std::vector<Buffer> gather;      // per core: a supernode's rows, widest × wp
  std::vector<Buffer> top_updates; // per core t ≥ 1: its subtrees' updates of the top rows

  Long values(Long s) const {
    return (F.first_column[s + 1] - F.first_column[s]) * (F.row_pointer[s + 1] - F.row_pointer[s]);
  }
  bool shared(Long s) const { return threads > 1 && values(s) >= shared_values; }

  Plan(const SupernodalFactorView& factor, int cores);
  void cut();
};

SupernodalSolver::Plan::Plan(const SupernodalFactorView& factor, int cores)
    : F(factor), threads(std::max(1, cores)) {
  // CHOLMOD's supernodal layout, which every kernel indexes without checks: the supernodes'
  // columns partition 0 … n, each holds at least its own triangle's rows, the pointers ascend.
  JOINTID_ASSERT(F.supernodes == 0 || (F.first_column[0] == 0 && F.row_pointer[0] == 0 &&
                                       F.first_column[F.supernodes] == F.n),
                 "the supernodes' columns partition the factor's");
  for (Long s = 0; s < F.supernodes; ++s)
    JOINTID_ASSERT(F.first_column[s] < F.first_column[s + 1] &&
                       F.row_pointer[s + 1] - F.row_pointer[s] >=
                           F.first_column[s + 1] - F.first_column[s] &&
                       F.value_pointer[s + 1] - F.value_pointer[s] >=
                           (F.first_column[s + 1] - F.first_column[s]) *
                               (F.row_pointer[s + 1] - F.row_pointer[s]),
                   "a supernode holds its columns' rows, at least its triangle, densely");
  if (F.permutation) {
    inverse.resize(static_cast<std::size_t>(F.n));
    for (Long k = 0; k < F.n; ++k) {
      JOINTID_ASSERT(F.permutation[k] >= 0 && F.permutation[k] < F.n,
                     "the permutation maps rows of L to equations");
      inverse[static_cast<std::size_t>(F.permutation[k])] = k;
    }
  }
  for (Long s = 0; s < F.supernodes; ++s)
    widest = std::max(widest, F.row_pointer[s + 1] - F.row_pointer[s]);
  local.resize(static_cast<std::size_t>(threads));
  top_row.assign(static_cast<std::size_t>(F.n), -1);
  cut();
  for (Long s : top)
    for (Long c = F.first_column[s]; c < F.first_column[s + 1]; ++c) {
      top_row[static_cast<std::size_t>(c)] = static_cast<Long>(top_columns.size());
      top_columns.push_back(c);
    }
  gather.resize(static_cast<std::size_t>(threads));
  top_updates.resize(static_cast<std::size_t>(threads));
}

// Chooses the cut. The supernodal elimination tree (a supernode's parent holds the first row
// below its own columns) is cut from the root down: the heaviest subtree (by factor values)
// moves its root to the top, its children become subtrees, and the subtrees are dealt to the
// cores, heaviest first to the least loaded (LPT). Of the first 256 such cuts the one with the
// least predicted time is kept: the most loaded core's subtrees, plus the top's supernodes
// (shared ones divided among the cores, small ones on one), plus their barriers.
void SupernodalSolver::Plan::cut() {
  const Long S = F.supernodes;
  auto all_local = [&] {
    local.assign(static_cast<std::size_t>(threads), {});
    top.clear();
    for (Long s = 0; s < S; ++s)
      local[0].push_back(s);
  };
  if (threads == 1 || S == 0) return all_local();

  std::vector<Long> super_of(static_cast<std::size_t>(F.n));
  for (Long s = 0; s < S; ++s)
    std::fill(super_of.begin() + F.first_column[s], super_of.begin() + F.first_column[s + 1], s);
  std::vector<Long> parent(static_cast<std::size_t>(S), -1);
  std::vector<double> weight(static_cast<std::size_t>(S)); // of the subtree
  for (Long s = 0; s < S; ++s) {
    const Long nscol = F.first_column[s + 1] - F.first_column[s];
    if (F.row_pointer[s + 1] - F.row_pointer[s] > nscol)
      parent[s] = super_of[static_cast<std::size_t>(F.rows[F.row_pointer[s] + nscol])];
    // A parent before its child would break the order the cores work in; CHOLMOD's supernodes
    // never do that, but then the whole tree is the top and nothing is lost but speed.
    if (parent[s] != -1 && parent[s] <= s) {
      all_local();
      local[0].clear();
      for (Long u = 0; u < S; ++u)
        top.push_back(u);
      return;
    }
  }
  for (Long s = 0; s < S; ++s) {
    weight[s] += static_cast<double>(values(s));
    if (parent[s] != -1) weight[parent[s]] += weight[s];
  }
  std::vector<Long> child_start(static_cast<std::size_t>(S + 1), 0),
      children(static_cast<std::size_t>(S));
  for (Long s = 0; s < S; ++s)
    if (parent[s] != -1) ++child_start[parent[s] + 1];
  for (Long s = 0; s < S; ++s)
    child_start[s + 1] += child_start[s];
  {
    std::vector<Long> next(child_start.begin(), child_start.end() - 1);
    for (Long s = 0; s < S; ++s)
      if (parent[s] != -1) children[next[parent[s]]++] = s;
  }

  auto top_cost = [&](Long s) {
    const double v = static_cast<double>(values(s));
    if (!shared(s)) return v + barrier_values;
    const Long nscol = F.first_column[s + 1] - F.first_column[s];
    return v / threads +
           barrier_values * static_cast<double>(3 + 4 * ((nscol + panel - 1) / panel));
  };
  // LPT: the subtrees dealt to the cores; returns the largest load, fills `bin` if given.
  auto deal = [&](std::vector<Long> roots, std::vector<int>* bin) {
    std::sort(roots.begin(), roots.end(), [&](Long a, Long b) { return weight[a] > weight[b]; });
    std::vector<double> load(static_cast<std::size_t>(threads), 0.0);
    for (Long r : roots) {
      const auto t = std::min_element(load.begin(), load.end()) - load.begin();
      load[t] += weight[r];
      if (bin) (*bin)[r] = static_cast<int>(t);
    }
    return *std::max_element(load.begin(), load.end());
  };

  std::vector<Long> roots;
  for (Long s = 0; s < S; ++s)
    if (parent[s] == -1) roots.push_back(s);
  const std::vector<Long> first_roots = roots;
  double top_time = 0.0;
  double best = deal(roots, nullptr);
  int best_steps = 0;
  constexpr int max_steps = 256;
  for (int step = 1; step <= max_steps && !roots.empty(); ++step) {
    const auto heaviest = std::max_element(roots.begin(), roots.end(),
                                           [&](Long a, Long b) { return weight[a] < weight[b]; });
    const Long s = *heaviest;
    roots.erase(heaviest);
    roots.insert(roots.end(), children.begin() + child_start[s],
                 children.begin() + child_start[s + 1]);
    top_time += top_cost(s);
    const double time = top_time + (roots.empty() ? 0.0 : deal(roots, nullptr));
    if (time < best) best = time, best_steps = step;
  }

  // Replay the best cut.
  std::vector<char> in_top(static_cast<std::size_t>(S), 0);
  roots = first_roots;
  for (int step = 1; step <= best_steps; ++step) {
    const auto heaviest = std::max_element(roots.begin(), roots.end(),
                                           [&](Long a, Long b) { return weight[a] < weight[b]; });
    const Long s = *heaviest;
    roots.erase(heaviest);
    roots.insert(roots.end(), children.begin() + child_start[s],
                 children.begin() + child_start[s + 1]);
    in_top[s] = 1;
  }
  std::vector<int> owner(static_cast<std::size_t>(S), -1);
  deal(roots, &owner);
  local.assign(static_cast<std::size_t>(threads), {});
  top.clear();
  for (Long s = S - 1; s >= 0; --s)
    if (!in_top[s] && owner[s] == -1) owner[s] = owner[parent[s]]; // parents come first here
  for (Long s = 0; s < S; ++s) {
    if (in_top[s])
      top.push_back(s);
    else
      local[static_cast<std::size_t>(owner[s])].push_back(s);
  }
}

namespace {

// One solve: every core runs run(t).
template <int G> struct Solve {
  const SupernodalFactorView& F;
  const std::vector<std::vector<Long>>& local;
  const std::vector<Long>& top;
  const std::vector<Long>& top_row;
  const std::vector<Long>& top_columns;
  double* X;                    // n × wp, row-major
  std::vector<double*> gather;  // per core
  std::vector<double*> updates; // per core t ≥ 1: top rows × wp; null for core 0
  Long wp;
  int threads;
  std::barrier<>* sync;

  void wait() {
    if (threads > 1) sync->arrive_and_wait();
  }
  Block block(Long s, double* Y) const {
    return {F.values + F.value_pointer[s], Y, F.first_column[s + 1] - F.first_column[s],
            F.row_pointer[s + 1] - F.row_pointer[s], wp};
  }
  // Where row r of the right-hand sides lives for a core: its own top buffer for the top's
  // rows while the cores do their subtrees (forward), else the work array.
  double* row(Long r, double* D) const {
    const Long k = D ? top_row[static_cast<std::size_t>(r)] : -1;
    return k >= 0 ? D + k * wp : X + r * wp;
  }
  void gather_rows(Long s, const Block& b, Long i0, Long i1, double* D) const {
    const Long* rows = F.rows + F.row_pointer[s];
    for (Long i = i0; i < i1; ++i)
      std::memcpy(b.Y + i * wp, row(rows[i], D), static_cast<std::size_t>(wp) * sizeof(double));
  }
  void scatter_rows(Long s, const Block& b, Long i0, Long i1, double* D) const {
    const Long* rows = F.rows + F.row_pointer[s];
    for (Long i = i0; i < i1; ++i)
      std::memcpy(row(rows[i], D), b.Y + i * wp, static_cast<std::size_t>(wp) * sizeof(double));
  }

  // Core t of T's part of a supernode's forward (L y = b) or backward (Lᵀ x = y) step.
  JOINTID_KERNEL void forward(const Block& b, int t, int T) {
    const Long quarters = wp / 4;
    for (Long p0 = 0; p0 < b.nscol; p0 += panel) {
      const Long pb = std::min(panel, b.nscol - p0);
      triangle_forward(b, p0, pb, share(quarters, t, T, 1), share(quarters, t + 1, T, 1));
      if (T > 1) wait();
      const Long r0 = p0 + pb, below = b.nsrow - r0;
      update_below<G>(b, p0, pb, r0 + share(below, t, T, 1), r0 + share(below, t + 1, T, 1));
      if (T > 1) wait();
    }
  }
  JOINTID_KERNEL void backward(const Block& b, int t, int T) {
    const Long quarters = wp / 4;
    for (Long p0 = (b.nscol - 1) / panel * panel; p0 >= 0; p0 -= panel) {
      const Long pb = std::min(panel, b.nscol - p0);
      const Long r0 = p0 + pb;
      if (r0 < b.nsrow)
        update_panel<G>(b, p0 + share(pb, t, T, G), p0 + share(pb, t + 1, T, G), r0);
      if (T > 1) wait();
      triangle_backward(b, p0, pb, share(quarters, t, T, 1), share(quarters, t + 1, T, 1));
      if (T > 1) wait();
    }
  }

  // A supernode below the cut, by core t alone.
  JOINTID_KERNEL void alone(Long s, int t, bool down) {
    double* D = down ? updates[static_cast<std::size_t>(t)] : nullptr;
    const Block b = block(s, gather[static_cast<std::size_t>(t)]);
    gather_rows(s, b, 0, b.nsrow, D);
    if (down)
      forward(b, 0, 1);
    else
      backward(b, 0, 1);
    scatter_rows(s, b, 0, down ? b.nsrow : b.nscol, D);
  }

  // A top supernode: shared by all cores when large, else by core 0 alone (the others go on to
  // the next shared one and wait there for it).
  JOINTID_KERNEL void together(Long s, int t, bool down) {
    const Block b = block(s, gather[0]);
    if (!self_shared(b)) {
      if (t != 0) return;
      gather_rows(s, b, 0, b.nsrow, nullptr);
      if (down)
        forward(b, 0, 1);
      else
        backward(b, 0, 1);
      scatter_rows(s, b, 0, down ? b.nsrow : b.nscol, nullptr);
      return;
    }
    wait(); // core 0's supernodes before this one are done
    gather_rows(s, b, share(b.nsrow, t, threads, 1), share(b.nsrow, t + 1, threads, 1), nullptr);
    wait();
    if (down)
      forward(b, t, threads);
    else
      backward(b, t, threads);
    const Long changed = down ? b.nsrow : b.nscol;
    scatter_rows(s, b, share(changed, t, threads, 1), share(changed, t + 1, threads, 1), nullptr);
    wait();
  }
  bool self_shared(const Block& b) const {
    return threads > 1 && b.nscol * b.nsrow >= shared_values;
  }

  // Everything core t does: L y = P b (its subtrees, the cores' updates of the top added up,
  // the top), then Lᵀ x = y in reverse (the top, then its subtrees).
  // Asks the memory for supernode s's values and row indices (into L2) while the core works on
  // the one before: a small supernode's columns are too short for the hardware prefetchers.
  void prefetch(Long s) const {
    const char* v = reinterpret_cast<const char*>(F.values + F.value_pointer[s]);
    const Long bytes =
        std::min<Long>((F.value_pointer[s + 1] - F.value_pointer[s]) * 8, prefetch_bytes);
    for (Long o = 0; o < bytes; o += 64)
      __builtin_prefetch(v + o, 0, 2);
    const char* r = reinterpret_cast<const char*>(F.rows + F.row_pointer[s]);
    const Long row_bytes =
        std::min<Long>((F.row_pointer[s + 1] - F.row_pointer[s]) * 8, prefetch_bytes);
    for (Long o = 0; o < row_bytes; o += 64)
      __builtin_prefetch(r + o, 0, 2);
  }

  JOINTID_KERNEL void run(int t) {
    const auto& mine = local[static_cast<std::size_t>(t)];
    const std::size_t count = mine.size();
    for (std::size_t i = 0; i < count; ++i) {
      if (i + 1 < count) prefetch(mine[i + 1]);
      alone(mine[i], t, true);
    }
    wait();
    if (threads > 1) {
      const Long count = static_cast<Long>(top_columns.size());
      for (Long k = share(count, t, threads, 1); k < share(count, t + 1, threads, 1); ++k) {
        double* x = X + top_columns[static_cast<std::size_t>(k)] * wp;
        for (int u = 1; u < threads; ++u) {
          const double* d = updates[static_cast<std::size_t>(u)] + k * wp;
          for (Long c = 0; c < wp; ++c)
            x[c] += d[c];
        }
      }
      wait();
    }
    for (Long s : top)
      together(s, t, true);
    wait();
    for (auto s = top.rbegin(); s != top.rend(); ++s)
      together(*s, t, false);
    wait();
    for (std::size_t i = count; i-- > 0;) {
      if (i > 0) prefetch(mine[i - 1]);
      alone(mine[i], t, false);
    }
  }
};

#if defined(__x86_64__)
__attribute__((target("avx512f,avx512vl,avx2,fma"))) void run_avx512(Solve<8>& solve, int t) {
  solve.run(t);
}
__attribute__((target("avx2,fma"))) void run_avx2(Solve<4>& solve, int t) {
  solve.run(t);
}
#endif
void run_generic(Solve<2>& solve, int t) {
  solve.run(t);
}

enum class Kernels { generic, avx2, avx512 };

Kernels kernels() {
#if defined(__x86_64__)
  static const Kernels k =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? Kernels::avx512
      : __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")       ? Kernels::avx2
                                                                              : Kernels::generic;
  return k;
#else
  return Kernels::generic;
#endif
}

} // namespace

SupernodalSolver::SupernodalSolver(const SupernodalFactorView& factor, int threads)
    : plan_(std::make_unique<Plan>(factor, threads)) {}

SupernodalSolver::~SupernodalSolver() = default;

void SupernodalSolver::solve(const double* B, double* Xout, Long columns) {
  Plan& p = *plan_;
  const SupernodalFactorView& F = p.F;
  if (columns <= 0 || F.n == 0) return;
  const Long n = F.n, wp = (columns + chunk - 1) / chunk * chunk;
  const int T = p.threads;
  p.work.resize(n * wp);
  double* X = p.work.data();
  const Long top_rows = static_cast<Long>(p.top_columns.size());
  std::vector<double*> gather(static_cast<std::size_t>(T)),
      updates(static_cast<std::size_t>(T), nullptr);
  for (int t = 0; t < T; ++t) {
    p.gather[t].resize(std::max<Long>(1, p.widest) * wp);
    gather[t] = p.gather[t].data();
    if (t > 0 && top_rows > 0) {
      p.top_updates[t].resize(top_rows * wp);
      updates[t] = p.top_updates[t].data();
      std::fill(updates[t], updates[t] + top_rows * wp, 0.0);
    }
  }

  // The permuted right-hand sides into the work array (one cache line per row written), then
  // back: equation i of A is row inverse[i] of L.
  auto permute = [&](int t, bool in) {
    for (Long i = share(n, t, T, 1); i < share(n, t + 1, T, 1); ++i) {
      double* x = X + (p.inverse.empty() ? i : p.inverse[static_cast<std::size_t>(i)]) * wp;
      if (in) {
        for (Long c = 0; c < columns; ++c)
          x[c] = B[i + c * n];
        for (Long c = columns; c < wp; ++c)
          x[c] = 0.0;
      } else {
        for (Long c = 0; c < columns; ++c)
          Xout[i + c * n] = x[c];
      }
    }
  };
  std::barrier<> sync(T);
  auto body = [&](auto& solve, int t) {
    permute(t, true);
    solve.wait();
    if constexpr (std::is_same_v<std::decay_t<decltype(solve)>, Solve<8>>) {
#if defined(__x86_64__)
      run_avx512(solve, t);
#endif
    } else if constexpr (std::is_same_v<std::decay_t<decltype(solve)>, Solve<4>>) {
#if defined(__x86_64__)
      run_avx2(solve, t);
#endif
    } else {
      run_generic(solve, t);
    }
    solve.wait();
    permute(t, false);
  };
  auto launch = [&](auto& solve) {
    std::vector<std::jthread> pool;
    for (int t = 1; t < T; ++t)
      pool.emplace_back([&body, &solve, t] { body(solve, t); });
    body(solve, 0);
  };
  auto make = [&](auto tag) {
    using S = typename decltype(tag)::type;
    return S{F, p.local, p.top, p.top_row, p.top_columns, X, gather, updates, wp, T, &sync};
  };
  switch (kernels()) {
  case Kernels::avx512: {
    auto s = make(std::type_identity<Solve<8>>{});
    launch(s);
    break;
  }
  case Kernels::avx2: {
    auto s = make(std::type_identity<Solve<4>>{});
    launch(s);
    break;
  }
  case Kernels::generic: {
    auto s = make(std::type_identity<Solve<2>>{});
    launch(s);
    break;
  }
  }
}

} // namespace jointid::fem
