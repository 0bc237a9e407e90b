#pragma once
// A command-line value that is refused: exit code 2, like CLI11's own usage errors. Either a value
// the option cannot take ("--rate: expected a rate > 0 Hz, found -1") or a valid value refused after
// a look at the input (e.g. a mesh size that would need more memory than the machine has), whose
// message names the option that overrides the refusal.
#include <string>

#include "piezobench/core/error.hpp"

namespace piezobench {

class UsageError : public Error {
 public:
  using Error::Error;
  // "OPTION: expected EXPECTED, found FOUND" (OPTION as typed, e.g. "--rate").
  UsageError(const std::string& option, const std::string& expected, const std::string& found)
      : Error(option + ": expected " + expected + ", found " + found) {}
  [[nodiscard]] ExitCode exit_code() const override { return ExitCode::kUsage; }
};

}  // namespace piezobench
