#pragma once
/// A parallel map over independent jobs on the machine's cores (the simulations of sine tests,
/// the candidates of a discovery step, the tests of one re-simulation). Jobs must not share
/// mutable state.
///
/// Maps may nest (a candidate's job re-simulates its tests with a map of its own). The threads
/// they start together never exceed the cores: a map starts only the threads that are free
/// (hardware_concurrency() − 1 in all, the calling thread being one of the cores) and gives each
/// back as soon as it finds no job left (the calling thread's too, while it waits), so an inner map
/// runs in its caller's thread alone while the outer map keeps every core busy, and takes the cores
/// its siblings leave as they finish (the last of a step's refinements re-simulates on all of
/// them).
#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <optional>
#include <thread>
#include <vector>

namespace jointid::fem {

namespace detail {

/// The threads a map may still start.
inline std::atomic<int>& free_threads() {
  static std::atomic<int> n{static_cast<int>(std::max(1u, std::thread::hardware_concurrency())) -
                            1};
  return n;
}

/// Takes up to `wanted` of the free threads; returns how many it took.
inline int take_threads(int wanted) {
  std::atomic<int>& free = free_threads();
  int have = free.load();
  int got = 0;
  do {
    got = std::min(have, wanted);
    if (got <= 0) return 0;
  } while (!free.compare_exchange_weak(have, have - got));
  return got;
}

} // namespace detail

/// Runs every job, on the calling thread and up to hardware_concurrency() − 1 more (fewer when
/// other maps hold them), and returns their results in the order of the list. Once a job has
/// thrown, no further job is started (jobs start in list order, so none before it is left out);
/// the first exception in list order is rethrown after the running ones have finished. An
/// interrupt thrown from one job's progress callback so stops the whole map after the jobs in
/// progress.
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
  const int extra = jobs.size() > 1 ? detail::take_threads(static_cast<int>(jobs.size()) - 1) : 0;
  std::vector<std::thread> pool;
  for (int t = 0; t < extra; ++t)
    pool.emplace_back([&] {
      worker();
      ++detail::free_threads(); // free for other maps while this one's last jobs run
    });
  worker();
  // The calling thread, with no job left, is free too while it waits; it takes a thread back
  // to go on (one that another map took meanwhile is given back when that map's thread ends).
  if (!pool.empty()) ++detail::free_threads();
  for (auto& t : pool)
    t.join();
  if (!pool.empty())
    while (detail::take_threads(1) == 0)
      std::this_thread::yield();
  std::vector<T> out;
  out.reserve(jobs.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (errors[i]) std::rethrow_exception(errors[i]);
    out.push_back(std::move(*results[i]));
  }
  return out;
}

} // namespace jointid::fem
