// The engine's exceptions. The Python module maps them: InputError -> ValueError,
// IoError -> OSError, Cancelled -> dcg.Cancelled. Nothing in the engine aborts or asserts on
// user data: every bad input ends in one of these, with a message a user can act on.
#pragma once

#include <stdexcept>
#include <string>

namespace dcg {

/// Bad input data or options (NaN coordinates, out-of-range indices, an open mesh with
/// repair = none, an option out of range...).
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A file that cannot be opened or parsed.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The progress callback asked to stop.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

}  // namespace dcg
