#include "piezobench/core/error.hpp"

#include <utility>

namespace piezobench {
namespace {

std::string format_input_error(const std::string& source, const std::string& field,
                               const std::string& expected, const std::string& found) {
  std::string message;
  if (!source.empty()) message += source + ": ";
  if (!field.empty()) message += field + ": ";
  message += "expected " + expected + ", found " + found;
  return message;
}

std::string format_numerical_error(const std::string& method, const std::string& why,
                                   bool retry_may_help) {
  std::string message = method + " failed: " + why;
  if (retry_may_help) message += " (other settings may succeed)";
  return message;
}

}  // namespace

InputError::InputError(std::string source, std::string field, std::string expected, std::string found)
    : Error(format_input_error(source, field, expected, found)),
      source_(std::move(source)),
      field_(std::move(field)),
      expected_(std::move(expected)),
      found_(std::move(found)) {}

InputError::InputError(const std::string& message) : Error(message) {}

InputError InputError::with_source(const std::string& source) const {
  if (!expected_.empty() || !found_.empty()) return InputError(source, field_, expected_, found_);
  return InputError(source + ": " + what());
}

NumericalError::NumericalError(std::string method, std::string why, bool retry_may_help)
    : Error(format_numerical_error(method, why, retry_may_help)),
      method_(std::move(method)),
      retry_may_help_(retry_may_help) {}

}  // namespace piezobench
