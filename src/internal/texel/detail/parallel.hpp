// Fork–join over a few threads for bit-exact work (detfft's out-of-core
// passes, the direct reference sum), and the one thread-count policy of the
// library (write_map's chunks too). Internal to Texel.
//
// Only work whose results do not depend on where or in which order it runs
// is spread: independent butterfly groups, blocks, runs of output samples,
// each computed by exactly the operations of the one-thread code. So the
// thread count changes speed, never a bit (TEXEL_THREADS=1 runs everything on
// the calling thread; the tests compare both). Threads are started per call
// and joined before it returns: nothing outlives a call, no pool, no locks
// held across user code.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace texel::detail {

/// The processors this process may run on (Linux: its affinity mask, so
/// taskset and a container's cpuset count; elsewhere the hardware's), >= 1.
int available_processors();
/// How many threads a bit-exact job may spread over: TEXEL_THREADS (a number
/// >= 1, read once) if set, else available_processors() up to `cap`. Every
/// worker holds its own buffers, so callers cap by memory: the reference
/// synthesis at 2 (detfft.hpp's ChirpMemory), write_map's chunks at 4.
int worker_threads(int cap = 2);

/// Runs fn(worker, task) for every task in [0, tasks): worker i < workers
/// takes the tasks [tasks·i/n, tasks·(i+1)/n) in order (n = min(workers,
/// tasks); so with tasks <= workers, task i runs on worker i), worker 0 on
/// the calling thread. Returns when all have run; rethrows the exception of
/// the first worker (in worker order) that threw. A thread that cannot be
/// started leaves its tasks to the calling thread.
template <class Fn>
void parallel_tasks(int workers, std::size_t tasks, const Fn& fn) {
  const std::size_t n = workers < 1 ? 1 : std::min(static_cast<std::size_t>(workers), tasks);
  if (n <= 1) {
    for (std::size_t t = 0; t < tasks; ++t) fn(std::size_t{0}, t);
    return;
  }
  std::vector<std::exception_ptr> errors(n);
  const auto range = [&](std::size_t i) {
    try {
      for (std::size_t t = tasks * i / n; t < tasks * (i + 1) / n; ++t) fn(i, t);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(n - 1);
  std::size_t started = 1;
  try {
    for (; started < n; ++started) threads.emplace_back(range, started);
  } catch (const std::system_error&) {
    // No more threads: the rest run here.
  }
  range(0);
  for (std::size_t i = started; i < n; ++i) range(i);
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace texel::detail
