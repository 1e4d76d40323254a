// fem::parallel_map: results in list order, the first exception in list order, no job
// started after one has thrown (what lets an interrupt stop a map of long jobs), and maps inside
// maps never run more jobs at once than the machine has cores.
#include "fem/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

namespace jointid::fem {
namespace {

TEST(ParallelMap, ResultsInTheOrderOfTheList) {
  std::vector<std::function<int()>> jobs;
  for (int i = 0; i < 100; ++i)
    jobs.push_back([i] { return i * i; });
  const std::vector<int> out = parallel_map(jobs);
  ASSERT_EQ(out.size(), 100u);
  for (int i = 0; i < 100; ++i)
    EXPECT_EQ(out[i], i * i);
}

TEST(ParallelMap, TheFirstExceptionInListOrderIsRethrown) {
  // Jobs 3 and 7 throw; 7 may throw first in time, 3 is rethrown (both have started: 3 < 7).
  std::vector<std::function<int()>> jobs;
  for (int i = 0; i < 8; ++i)
    jobs.push_back([i]() -> int {
      if (i == 3) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        throw std::runtime_error("job 3");
      }
      if (i == 7) throw std::runtime_error("job 7");
      return i;
    });
  try {
    parallel_map(jobs);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "job 3");
  }
}

TEST(ParallelMap, NoJobStartsAfterOneHasThrown) {
  // Job 0 throws; every other job waits until it has, then a millisecond more (for the map to
  // see it), before returning: the threads then take no further job. Without that rule all
  // 1000 would run.
  std::atomic<int> started{0};
  std::atomic<bool> thrown{false};
  std::vector<std::function<int()>> jobs;
  for (int i = 0; i < 1000; ++i)
    jobs.push_back([i, &started, &thrown]() -> int {
      ++started;
      if (i == 0) {
        thrown = true;
        throw std::runtime_error("stop");
      }
      while (!thrown)
        std::this_thread::yield();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      return i;
    });
  EXPECT_THROW(parallel_map(jobs), std::runtime_error);
  EXPECT_LT(started.load(), 1000);
  EXPECT_LE(started.load(),
            2 * static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

TEST(ParallelMap, MapsInsideMapsNeverRunMoreJobsAtOnceThanThereAreCores) {
  // Three levels of four jobs: each of the 64 innermost ones counts the jobs running with it.
  // Each level starting its own threads would run up to cores³ of them at once (8 on two
  // cores); the maps share the cores instead. The results still come back in order.
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::atomic<int> running{0}, most{0};
  const auto leaf = [&](int i) {
    const int now = ++running;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    --running;
    return i;
  };
  const auto level = [](int base, const std::function<int(int)>& inner) {
    std::vector<std::function<int()>> jobs;
    for (int i = 0; i < 4; ++i)
      jobs.push_back([=] { return inner(4 * base + i); });
    int sum = 0;
    for (int v : parallel_map(jobs))
      sum += v;
    return sum;
  };
  const int total =
      level(0, [&](int a) { return level(a, [&](int b) { return level(b, leaf); }); });
  EXPECT_EQ(total, 63 * 64 / 2); // the leaves 0 … 63, each once
  EXPECT_LE(most.load(), cores);
  EXPECT_GE(most.load(), 1);
  // Every thread a map took is given back.
  EXPECT_EQ(detail::free_threads().load(), cores - 1);
}

} // namespace
} // namespace jointid::fem
