// Progress reporting and cancellation for long computations.
#pragma once

#include <functional>
#include <string>

#include "dcg/errors.h"

namespace dcg {

/// Called with the current stage's name and the fraction of the whole pipeline done (0..1).
/// Return false to cancel: the computation then throws dcg::Cancelled at its next check.
/// It may be called from the computing thread only (never from TBB workers).
using ProgressCallback = std::function<bool(const std::string& stage, double fraction)>;

/// Reports progress through an optional callback; throws Cancelled when it returns false.
class Progress {
 public:
  explicit Progress(ProgressCallback callback = {}) : callback_(std::move(callback)) {}
  /// Stage `stage` is at `fraction` of the whole run.
  void report(const std::string& stage, double fraction) const {
    if (callback_ && !callback_(stage, fraction)) throw Cancelled();
  }

 private:
  ProgressCallback callback_;
};

}  // namespace dcg
