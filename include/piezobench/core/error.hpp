#pragma once
// The three kinds of failure and how the command line maps them to exit codes.
//
//  - InputError: the user's data or file is wrong (exit code 3). The message names the source (a
//    file, or "--plant" for a command-line value), the field, what was expected and what was found.
//  - NumericalError: a method failed on valid input (exit code 4). It says which method, why, and
//    whether retrying with other settings could help.
//  - A broken invariant inside piezobench is a bug: assert(), never an exception.
//
// Command-line usage errors (exit code 2) are CLI11's.
#include <stdexcept>
#include <string>

namespace piezobench {

enum class ExitCode : int { kOk = 0, kUsage = 2, kBadInput = 3, kNumerical = 4 };

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  [[nodiscard]] virtual ExitCode exit_code() const = 0;
};

class InputError : public Error {
 public:
  // "source: field: expected EXPECTED, found FOUND" (source omitted when empty).
  InputError(std::string source, std::string field, std::string expected, std::string found);
  // Free-form message for errors that do not fit field/expected/found; keep it specific.
  explicit InputError(const std::string& message);

  [[nodiscard]] ExitCode exit_code() const override { return ExitCode::kBadInput; }
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::string& field() const { return field_; }
  // Returns a copy whose message is prefixed with `source` (used when a reader that only knows
  // fields is called on a named file).
  [[nodiscard]] InputError with_source(const std::string& source) const;

 private:
  std::string source_, field_, expected_, found_;
};

class NumericalError : public Error {
 public:
  // "METHOD failed: WHY" and, when retry_may_help, a hint that other settings may succeed.
  NumericalError(std::string method, std::string why, bool retry_may_help);

  [[nodiscard]] ExitCode exit_code() const override { return ExitCode::kNumerical; }
  [[nodiscard]] const std::string& method() const { return method_; }
  [[nodiscard]] bool retry_may_help() const { return retry_may_help_; }

 private:
  std::string method_;
  bool retry_may_help_;
};

}  // namespace piezobench
