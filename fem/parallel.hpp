#pragma once
/// A parallel map over independent jobs on the machine's cores (the simulations of sine tests,
/// the candidates of a discovery step). Jobs must not share mutable state.
#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <optional>
#include <thread>
#include <vector>

namespace jointid::fem {

/// Runs every job, on up to hardware_concurrency() threads, and returns their results in the
/// order of the list. Once a job has thrown, no further job is started (jobs start in list
/// order, so none before it is left out); the first exception in list order is rethrown after
/// the running ones have finished. An interrupt thrown from one job's progress callback so stops
/// the whole map after the jobs in progress.
template <class T> std::vector<T> parallel_map(const std::vector<std::function<T()>>& jobs) {
  std::vector<std::optional<T>> results(jobs.size());
  std::vector<std::exception_ptr> errors(jobs.size());
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  auto worker = [&] {
    // A job is taken only while none has failed, and a job taken is run: jobs before a failed
    // one were taken before it, so they all run.
    while (!failed) {
      const std::size_t i = next++;
      if (i >= jobs.size()) return;
      try {
        results[i].emplace(jobs[i]());
      } catch (...) {
        errors[i] = std::current_exception();
        failed = true;
      }
    }
  };
  const std::size_t threads =
      std::min<std::size_t>(jobs.size(), std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t)
    pool.emplace_back(worker);
  worker();
  for (auto& t : pool)
    t.join();
  std::vector<T> out;
  out.reserve(jobs.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (errors[i]) std::rethrow_exception(errors[i]);
    out.push_back(std::move(*results[i]));
  }
  return out;
}

} // namespace jointid::fem
