#include "fem/supernodal_solve.hpp"

#include <algorithm>
#include <barrier>
#include <cstring>
#include <thread>
#include <vector>

namespace jointid::fem {

namespace {

using Long = std::int64_t;

// Four doubles (one AVX register where the CPU has it, two SSE2 ones otherwise). The file is
// compiled with -ffp-contract=fast (fem/CMakeLists.txt), so a * b + c becomes a fused
// multiply-add in the AVX2 version.
typedef double v4 __attribute__((vector_size(32)));

#define JOINTID_KERNEL [[gnu::always_inline]] inline

JOINTID_KERNEL v4 load(const double* p) {
  v4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
JOINTID_KERNEL void store(double* p, v4 v) {
  std::memcpy(p, &v, sizeof v);
}
JOINTID_KERNEL v4 splat(double s) {
  return v4{s, s, s, s};
}
JOINTID_KERNEL double sum(v4 v) {
  return (v[0] + v[1]) + (v[2] + v[3]);
}

// Columns of a supernode taken at a time: the panel's triangle is solved on one core, then the
// rows below it are shared; 256 columns of 8 right-hand sides (16 KiB) stay in the L1 cache.
constexpr Long panel = 256;
// Rows the back substitution's products read at a time, so that their right-hand sides
// (256 × 8 doubles) stay in the L1 cache while the panel's columns go by.
constexpr Long row_block = 256;
// Supernodes smaller than this (values) are done by one core: sharing them costs more in
// synchronisation than it saves.
constexpr Long shared_values = Long{1} << 16;

// One supernode: its values L (nsrow × nscol, column-major, leading dimension nsrow) and the
// right-hand sides of its rows Y (nsrow × wp, column-major, leading dimension nsrow; wp is the
// number of right-hand sides rounded up to 4, the extra columns zero).
struct Block {
  const double* L;
  double* Y;
  Long nscol, nsrow;
  int wp;
};

// Y(r, :) −= L(r, p0:p0+pb) Y(p0:p0+pb, :) for rows r in [r0, r1): the rows below a solved
// panel, 8 rows by 4 right-hand sides at a time in registers.
JOINTID_KERNEL void update_below(const Block& b, Long p0, Long pb, Long r0, Long r1) {
  const Long ld = b.nsrow;
  const double* L = b.L + p0 * ld;
  const double* Z = b.Y + p0;
  Long r = r0;
  for (; r + 8 <= r1; r += 8)
    for (int c0 = 0; c0 < b.wp; c0 += 4) {
      v4 a0{}, a1{}, a2{}, a3{}, e0{}, e1{}, e2{}, e3{};
      const double* z = Z + c0 * ld;
      const double* l = L + r;
      for (Long j = 0; j < pb; ++j, l += ld) {
        // The next tile's rows of this column, which no hardware prefetcher foresees (one
        // cache line in each of pb columns).
        if (c0 == 0) __builtin_prefetch(l + 8);
        const v4 lo = load(l), hi = load(l + 4);
        const v4 z0 = splat(z[j]), z1 = splat(z[j + ld]), z2 = splat(z[j + 2 * ld]),
                 z3 = splat(z[j + 3 * ld]);
        a0 += lo * z0;
        e0 += hi * z0;
        a1 += lo * z1;
        e1 += hi * z1;
        a2 += lo * z2;
        e2 += hi * z2;
        a3 += lo * z3;
        e3 += hi * z3;
      }
      double* y = b.Y + r + c0 * ld;
      store(y, load(y) - a0);
      store(y + 4, load(y + 4) - e0);
      y += ld;
      store(y, load(y) - a1);
      store(y + 4, load(y + 4) - e1);
      y += ld;
      store(y, load(y) - a2);
      store(y + 4, load(y + 4) - e2);
      y += ld;
      store(y, load(y) - a3);
      store(y + 4, load(y + 4) - e3);
    }
  for (; r + 4 <= r1; r += 4)
    for (int c0 = 0; c0 < b.wp; c0 += 4) {
      v4 a0{}, a1{}, a2{}, a3{};
      const double* z = Z + c0 * ld;
      const double* l = L + r;
      for (Long j = 0; j < pb; ++j, l += ld) {
        const v4 lo = load(l);
        a0 += lo * splat(z[j]);
        a1 += lo * splat(z[j + ld]);
        a2 += lo * splat(z[j + 2 * ld]);
        a3 += lo * splat(z[j + 3 * ld]);
      }
      double* y = b.Y + r + c0 * ld;
      store(y, load(y) - a0);
      store(y + ld, load(y + ld) - a1);
      store(y + 2 * ld, load(y + 2 * ld) - a2);
      store(y + 3 * ld, load(y + 3 * ld) - a3);
    }
  for (; r < r1; ++r)
    for (int c = 0; c < b.wp; ++c) {
      double s = 0.0;
      for (Long j = 0; j < pb; ++j)
        s += L[r + j * ld] * Z[j + c * ld];
      b.Y[r + c * ld] -= s;
    }
}

// Y(j, :) −= L(r0:, j)ᵀ Y(r0:, :) for the panel's columns j in [j0, j1): a column of L read
// once for 8 right-hand sides, the rows in blocks that stay in the cache.
JOINTID_KERNEL void update_panel(const Block& b, Long j0, Long j1, Long r0) {
  const Long ld = b.nsrow;
  for (Long rb = r0; rb < b.nsrow; rb += row_block) {
    const Long re = std::min(b.nsrow, rb + row_block);
    for (Long j = j0; j < j1; ++j) {
      const double* l = b.L + j * ld;
      int c0 = 0;
      for (; c0 + 8 <= b.wp; c0 += 8) {
        const double* y = b.Y + c0 * ld;
        v4 a0{}, a1{}, a2{}, a3{}, a4{}, a5{}, a6{}, a7{};
        Long r = rb;
        for (; r + 4 <= re; r += 4) {
          if ((r & 7) == 0) __builtin_prefetch(l + r + ld); // the next column's rows
          const v4 lv = load(l + r);
          a0 += lv * load(y + r);
          a1 += lv * load(y + r + ld);
          a2 += lv * load(y + r + 2 * ld);
          a3 += lv * load(y + r + 3 * ld);
          a4 += lv * load(y + r + 4 * ld);
          a5 += lv * load(y + r + 5 * ld);
          a6 += lv * load(y + r + 6 * ld);
          a7 += lv * load(y + r + 7 * ld);
        }
        double s[8] = {sum(a0), sum(a1), sum(a2), sum(a3), sum(a4), sum(a5), sum(a6), sum(a7)};
        for (; r < re; ++r)
          for (int q = 0; q < 8; ++q)
            s[q] += l[r] * y[r + q * ld];
        for (int q = 0; q < 8; ++q)
          b.Y[j + (c0 + q) * ld] -= s[q];
      }
      for (; c0 < b.wp; c0 += 4) {
        const double* y = b.Y + c0 * ld;
        v4 a0{}, a1{}, a2{}, a3{};
        Long r = rb;
        for (; r + 4 <= re; r += 4) {
          const v4 lv = load(l + r);
          a0 += lv * load(y + r);
          a1 += lv * load(y + r + ld);
          a2 += lv * load(y + r + 2 * ld);
          a3 += lv * load(y + r + 3 * ld);
        }
        double s[4] = {sum(a0), sum(a1), sum(a2), sum(a3)};
        for (; r < re; ++r)
          for (int q = 0; q < 4; ++q)
            s[q] += l[r] * y[r + q * ld];
        for (int q = 0; q < 4; ++q)
          b.Y[j + (c0 + q) * ld] -= s[q];
      }
    }
  }
}

// The panel's own triangle, L(p0:p0+pb, p0:p0+pb) y = Y(p0:p0+pb, c0:c1), forward (the
// right-hand sides are independent: the cores share them).
JOINTID_KERNEL void triangle_forward(const Block& b, Long p0, Long pb, Long c0, Long c1) {
  const Long ld = b.nsrow;
  for (Long j = p0; j < p0 + pb; ++j) {
    const double* l = b.L + j * ld;
    for (Long c = c0; c < c1; ++c) {
      double* y = b.Y + c * ld;
      const double v = y[j] / l[j];
      y[j] = v;
      for (Long i = j + 1; i < p0 + pb; ++i)
        y[i] -= l[i] * v;
    }
  }
}

// The panel's own triangle transposed, L(p0:p0+pb, p0:p0+pb)ᵀ y = Y(p0:p0+pb, c0:c1), backward.
JOINTID_KERNEL void triangle_backward(const Block& b, Long p0, Long pb, Long c0, Long c1) {
  const Long ld = b.nsrow;
  for (Long j = p0 + pb - 1; j >= p0; --j) {
    const double* l = b.L + j * ld;
    for (Long c = c0; c < c1; ++c) {
      double* y = b.Y + c * ld;
      v4 a{};
      Long i = j + 1;
      for (; i + 4 <= p0 + pb; i += 4)
        a += load(l + i) * load(y + i);
      double s = sum(a);
      for (; i < p0 + pb; ++i)
        s += l[i] * y[i];
      y[j] = (y[j] - s) / l[j];
    }
  }
}

// Thread t's share of `count` items out of `threads`, from the start; rounded down to a
// multiple of `align` except at the end.
Long share(Long count, int t, int threads, Long align) {
  if (t >= threads) return count;
  return count * t / threads / align * align;
}

struct Solve {
  const SupernodalFactorView& F;
  double* X; // the permuted right-hand sides, n × w, column-major
  Long w;
  int wp;
  int threads;
  std::barrier<>* sync;
  std::vector<double> Y; // the gathered rows of the current supernode

  Block block(Long s) {
    const Long nscol = F.first_column[s + 1] - F.first_column[s];
    const Long nsrow = F.row_pointer[s + 1] - F.row_pointer[s];
    return {F.values + F.value_pointer[s], Y.data(), nscol, nsrow, wp};
  }
  // Rows of the supernode into Y, right-hand sides c0 … c1 − 1 (those ≥ w: zeros).
  void gather(Long s, const Block& b, Long c0, Long c1) {
    const Long* rows = F.rows + F.row_pointer[s];
    for (Long c = c0; c < std::min(c1, w); ++c) {
      const double* x = X + c * F.n;
      double* y = Y.data() + c * b.nsrow;
      for (Long i = 0; i < b.nsrow; ++i)
        y[i] = x[rows[i]];
    }
    for (Long c = std::max(c0, w); c < c1; ++c)
      std::fill(Y.data() + c * b.nsrow, Y.data() + (c + 1) * b.nsrow, 0.0);
  }
  // Writes back the first `count` rows of the supernode.
  void scatter(Long s, const Block& b, Long count, Long c0, Long c1) {
    const Long* rows = F.rows + F.row_pointer[s];
    for (Long c = c0; c < std::min(c1, w); ++c) {
      double* x = X + c * F.n;
      const double* y = Y.data() + c * b.nsrow;
      for (Long i = 0; i < count; ++i)
        x[rows[i]] = y[i];
    }
  }
  void wait() {
    if (threads > 1) sync->arrive_and_wait();
  }
  bool shared(const Block& b) const { return threads > 1 && b.nscol * b.nsrow >= shared_values; }

  JOINTID_KERNEL void forward(const Block& b, int t, int T) {
    for (Long p0 = 0; p0 < b.nscol; p0 += panel) {
      const Long pb = std::min(panel, b.nscol - p0);
      triangle_forward(b, p0, pb, share(b.wp, t, T, 1), share(b.wp, t + 1, T, 1));
      if (T > 1) wait();
      const Long r0 = p0 + pb, below = b.nsrow - r0;
      update_below(b, p0, pb, r0 + share(below, t, T, 8), r0 + share(below, t + 1, T, 8));
      if (T > 1) wait();
    }
  }
  JOINTID_KERNEL void backward(const Block& b, int t, int T) {
    for (Long p0 = (b.nscol - 1) / panel * panel; p0 >= 0; p0 -= panel) {
      const Long pb = std::min(panel, b.nscol - p0);
      const Long r0 = p0 + pb;
      if (r0 < b.nsrow) update_panel(b, p0 + share(pb, t, T, 1), p0 + share(pb, t + 1, T, 1), r0);
      if (T > 1) wait();
      triangle_backward(b, p0, pb, share(b.wp, t, T, 1), share(b.wp, t + 1, T, 1));
      if (T > 1) wait();
    }
  }

  // Thread t's part of supernode s: forward (L y = b) or backward (Lᵀ x = y), which changes
  // only the supernode's own rows.
  JOINTID_KERNEL void supernode(Long s, int t, bool down) {
    const Block b = block(s);
    const Long changed = down ? b.nsrow : b.nscol;
    if (!shared(b)) {
      if (t != 0) return;
      gather(s, b, 0, wp);
      if (down)
        forward(b, 0, 1);
      else
        backward(b, 0, 1);
      scatter(s, b, changed, 0, w);
      return;
    }
    wait(); // thread 0's supernodes before this one are done
    const Long c0 = share(wp, t, threads, 1), c1 = share(wp, t + 1, threads, 1);
    gather(s, b, c0, c1);
    wait();
    if (down)
      forward(b, t, threads);
    else
      backward(b, t, threads);
    scatter(s, b, changed, c0, c1);
    wait();
  }

  // Everything thread t does: L y = P b supernode by supernode, then Lᵀ x = y in reverse.
  JOINTID_KERNEL void run(int t) {
    for (Long s = 0; s < F.supernodes; ++s)
      supernode(s, t, true);
    wait();
    for (Long s = F.supernodes - 1; s >= 0; --s)
      supernode(s, t, false);
    wait();
  }
};

#if defined(__x86_64__)
__attribute__((target("avx2,fma"))) void run_avx2(Solve& solve, int t) {
  solve.run(t);
}
#endif
void run_generic(Solve& solve, int t) {
  solve.run(t);
}

void run(Solve& solve, int t) {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2) return run_avx2(solve, t);
#endif
  run_generic(solve, t);
}

} // namespace

void supernodal_solve(const SupernodalFactorView& F, const double* B, double* X, Long columns,
                      int threads) {
  if (columns <= 0 || F.n == 0) return;
  const Long n = F.n;
  std::vector<double> work(static_cast<std::size_t>(n * columns));
  for (Long c = 0; c < columns; ++c)
    for (Long k = 0; k < n; ++k)
      work[k + c * n] = B[(F.permutation ? F.permutation[k] : k) + c * n];
  Long widest = 0;
  for (Long s = 0; s < F.supernodes; ++s)
    widest = std::max(widest, F.row_pointer[s + 1] - F.row_pointer[s]);
  const int wp = static_cast<int>((columns + 3) / 4 * 4);
  threads = std::max(1, threads);
  std::barrier<> sync(threads);
  Solve solve{F,
              work.data(),
              columns,
              wp,
              threads,
              &sync,
              std::vector<double>(static_cast<std::size_t>(widest * wp))};
  std::vector<std::jthread> pool;
  for (int t = 1; t < threads; ++t)
    pool.emplace_back([&solve, t] { run(solve, t); });
  run(solve, 0);
  pool.clear(); // joins
  for (Long c = 0; c < columns; ++c)
    for (Long k = 0; k < n; ++k)
      X[(F.permutation ? F.permutation[k] : k) + c * n] = work[k + c * n];
}

} // namespace jointid::fem
