// How this machine's memory behaves when a large array is written for the first time and then
// read: the situation of a sparse factor (20 GiB at 10⁶ DOFs) just after the factorisation,
// before the first solve reads it. On a virtual machine whose host backs guest memory lazily the
// first read can cost several times a later one (docs/benchmarks.md, "Own block solve").
//
//   bench_memory_first_read GIB [--huge]
//
// Maps GIB GiB (fresh anonymous memory; with --huge, madvise(MADV_HUGEPAGE) first), writes every
// double once, then reads it 3 times on 2 threads and prints the seconds of each step as JSON.
#include <sys/mman.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double sum(const double* p, std::size_t first, std::size_t last) {
  double s = 0.0;
  for (std::size_t i = first; i < last; ++i)
    s += p[i];
  return s;
}

} // namespace

int main(int argc, char** argv) {
  const double gib = argc > 1 ? std::atof(argv[1]) : 0.0;
  const bool huge = argc > 2 && std::strcmp(argv[2], "--huge") == 0;
  if (!(gib > 0.0) || (argc > 2 && !huge) || argc > 3) {
    std::fprintf(stderr, "usage: bench_memory_first_read GIB [--huge]   (GIB > 0)\n");
    return 2;
  }
  const std::size_t n = static_cast<std::size_t>(gib * 1024 * 1024 * 1024 / sizeof(double));
  void* mapped =
      mmap(nullptr, n * sizeof(double), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapped == MAP_FAILED) {
    std::perror("bench_memory_first_read: mmap");
    return 1;
  }
  auto* p = static_cast<double*>(mapped);
  if (huge && madvise(mapped, n * sizeof(double), MADV_HUGEPAGE) != 0)
    std::perror("bench_memory_first_read: madvise(MADV_HUGEPAGE)");
  auto start = Clock::now();
  for (std::size_t i = 0; i < n; ++i)
    p[i] = static_cast<double>(i) * 1e-9;
  std::string out = "{\"gib\":" + std::to_string(gib) + ",\"huge\":" + (huge ? "true" : "false") +
                    ",\"write_s\":" + std::to_string(seconds_since(start)) + ",\"read_s\":[";
  double total = 0.0;
  for (int r = 0; r < 3; ++r) {
    start = Clock::now();
    double upper = 0.0;
    std::thread helper([&] { upper = sum(p, n / 2, n); });
    const double lower = sum(p, 0, n / 2);
    helper.join();
    total += lower + upper;
    out += (r ? "," : "") + std::to_string(seconds_since(start));
  }
  // The sums are printed so that the reads cannot be optimised away.
  std::printf("%s],\"checksum\":%.6e}\n", out.c_str(), total);
  munmap(mapped, n * sizeof(double));
  return 0;
}
