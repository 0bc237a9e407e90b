#pragma once
// A command-line value that is valid but refused after a look at the input (e.g. a mesh size that
// would need more memory than the machine has): exit code 2, like CLI11's usage errors. Its
// message names the option that overrides the refusal.
#include "piezobench/core/error.hpp"

namespace piezobench {

class UsageError : public Error {
 public:
  using Error::Error;
  [[nodiscard]] ExitCode exit_code() const override { return ExitCode::kUsage; }
};

}  // namespace piezobench
