// Internal: helpers that let long loops and sorts call a cancellation poll every few milliseconds
// (the progress callback, which may throw Cancelled, is only called from the computing thread).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "dcg/progress.h"

namespace dcg::internal {

/// A poll for long loops: reports `stage` at `fraction` through `progress` at most every 10 ms
/// (the first call always reports); Cancelled when the callback asks to stop.
inline std::function<void()> throttled_poll(const Progress& progress, std::string stage,
                                            double fraction) {
  using Clock = std::chrono::steady_clock;
  return [&progress, stage = std::move(stage), fraction, last = Clock::time_point()]() mutable {
    const auto now = Clock::now();
    if (now - last < std::chrono::milliseconds(10)) return;
    last = now;
    progress.report(stage, fraction);
  };
}

/// std::sort of `v` in chunks of 2^18 entries merged pairwise, calling `poll` (if set) between
/// the steps: the same order as one std::sort (for entries that compare equal only when they are
/// equal), for vectors of millions of entries that would keep a cancel request waiting.
template <class T>
void sort_polling(std::vector<T>& v, const std::function<void()>& poll) {
  constexpr std::size_t kChunk = std::size_t{1} << 18;
  const std::size_t n = v.size();
  if (!poll || n <= kChunk) {
    std::sort(v.begin(), v.end());
    return;
  }
  for (std::size_t b = 0; b < n; b += kChunk) {
    std::sort(v.begin() + b, v.begin() + std::min(n, b + kChunk));
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
