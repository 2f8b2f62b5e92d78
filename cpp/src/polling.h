// Internal: helpers that let long loops and sorts call a cancellation poll every few milliseconds
// (the progress callback, which may throw Cancelled, is only called from the computing thread).
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include "dcg/progress.h"

namespace dcg::internal {

/// Progress of one stage for long loops: operator()(fraction) reports `stage` at the fraction
/// mapped into [from, to], at most every 10 ms (the first call always reports); Cancelled when
/// the callback asks to stop.
class ThrottledProgress {
 public:
  ThrottledProgress(const Progress& progress, std::string stage, double from, double to)
      : progress_(progress), stage_(std::move(stage)), from_(from), to_(to) {}
  void operator()(double fraction) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(10)) return;
    last_ = now;
    progress_.report(stage_, from_ + (to_ - from_) * std::clamp(fraction, 0.0, 1.0));
  }
  /// The same, for a part [a, b] of the stage: a callable taking the part's own fraction.
  std::function<void(double)> part(double a, double b) {
    return [this, a, b](double f) { (*this)(a + (b - a) * f); };
  }

 private:
  const Progress& progress_;
  std::string stage_;
  double from_, to_;
  std::chrono::steady_clock::time_point last_{};
};

/// The threads the engine's parallel loops may use: the cores, or fewer under a
/// tbb::global_control limit (dcg.limit_threads).
inline int max_threads() {
  return static_cast<int>(std::min<std::size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
      static_cast<std::size_t>(tbb::this_task_arena::max_concurrency())));
}

/// `items` for each thread TBB may use: a chunk size for parallel_chunks that keeps every thread
/// busy and each chunk about as long on any machine.
inline int per_thread(int items) { return items * tbb::this_task_arena::max_concurrency(); }

/// tbb::parallel_for(blocked_range(0, n, grain), body) in chunks of `chunk` indices, calling
/// `at(fraction of the indices done)` (if set) on this thread before each chunk. For loops over
/// independent items, whose results do not depend on how the range is split: the same results as
/// one parallel_for, with a cancellation poll between the chunks.
template <class Index, class Body>
void parallel_chunks(Index n, Index chunk, Index grain, const std::function<void(double)>& at,
                     const Body& body) {
  for (Index first = 0; first < n; first += chunk) {
    if (at) at(static_cast<double>(first) / static_cast<double>(n));
    tbb::parallel_for(tbb::blocked_range<Index>(first, std::min(n, first + chunk), grain), body);
  }
}

/// Work finishing on another thread while this one keeps polling: the worker calls set() when
/// done; wait_polling returns as soon as it has, calling `poll` every `every` until then (from
/// this thread only). Whatever `poll` throws propagates at once; the worker is not stopped.
class Completion {
 public:
  void set() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    finished_.notify_all();
  }
  void wait_polling(const std::function<void()>& poll,
                    std::chrono::milliseconds every = std::chrono::milliseconds(10)) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!finished_.wait_for(lock, every, [this] { return done_; })) {
      lock.unlock();
      poll();
      lock.lock();
    }
  }

 private:
  std::mutex mutex_;
  std::condition_variable finished_;
  bool done_ = false;
};

/// A sort of `v` in chunks of 2^18 entries (each sorted in parallel, tbb::parallel_sort) merged
/// pairwise, calling `poll` (if set) between the steps: the same order as one std::sort (for
/// entries that compare equal only when they are equal), for vectors of millions of entries that
/// would keep a cancel request waiting. (The edge tables of stage 0 and 3: prepare on hand.obj
/// 10.3 -> 9.1 ms, horse.ply 309 -> 279 ms.)
template <class T>
void sort_polling(std::vector<T>& v, const std::function<void()>& poll) {
  constexpr std::size_t kChunk = std::size_t{1} << 18;
  const std::size_t n = v.size();
  if (!poll || n <= kChunk) {
    tbb::parallel_sort(v.begin(), v.end());
    return;
  }
  for (std::size_t b = 0; b < n; b += kChunk) {
    tbb::parallel_sort(v.begin() + b, v.begin() + std::min(n, b + kChunk));
    poll();
  }
  for (std::size_t w = kChunk; w < n; w *= 2) {
    for (std::size_t b = 0; b + w < n; b += 2 * w) {
      std::inplace_merge(v.begin() + b, v.begin() + b + w, v.begin() + std::min(n, b + 2 * w));
      poll();
    }
  }
}

}  // namespace dcg::internal
