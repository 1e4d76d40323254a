// fem::parallel_map: results in list order, the first exception in list order, and no job
// started after one has thrown (what lets an interrupt stop a map of long jobs).
#include "fem/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
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

} // namespace
} // namespace jointid::fem
