#pragma once
// LTI systems described in TOML files (the --plant / --controller files of the CLI).
//
// A file holds exactly one of three forms, plus optional keys:
//   transfer function:  num = [0.64, 0.0]          den = [1.0, 2.5]          (descending powers)
//   zpk:                zeros = [0.0, [-1.0, 2.0]] poles = [-3.0, [-1.0, -2.0], [-1.0, 2.0]]  gain = 2.0
//                       (a real number or [re, im]; rad/s; complex values in conjugate pairs)
//   state space:        A = [[0.0, 1.0], [-4.0, -0.4]]  B = [[0.0], [1.0]]  C = [[1.0, 0.0]]  D = [[0.0]]
//                       (matrices as lists of rows; D may be omitted = zeros)
//   optional:           delay = 200e-6   (s; on the input of a tf/zpk, or on every input of a state space)
//                       sample_time = 1e-4  (s; absent or 0 = continuous)
//                       description = "any text"
// Unknown keys, missing keys, a mix of forms, wrong types or shapes and non-finite values are
// InputErrors naming the file and the key (and the line for TOML syntax errors). The text goes
// through io/toml_table.hpp (size and nesting limits); an array holds at most kMaxLtiOrder + 1
// entries, so a file never describes a system of more than kMaxLtiOrder states.
#include <cstddef>
#include <filesystem>
#include <string>

#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"

namespace piezobench::io {

inline constexpr std::size_t kMaxLtiOrder = 200;

enum class LtiForm { kTransferFunction, kZpk, kStateSpace };
std::string to_string(LtiForm form);  // "tf", "zpk", "ss"

struct LtiFile {
  lti::StateSpace system;
  LtiForm form = LtiForm::kStateSpace;
  std::string description;
};

LtiFile read_lti_toml(const std::filesystem::path& path);
// Same, from TOML text; `source` names it in errors.
LtiFile parse_lti_toml(const std::string& text, const std::string& source);

// A transfer function in the tf form above (num, den, delay when > 0, sample_time when discrete,
// description), numbers with round-trip precision; read_lti_toml reads it back.
std::string to_lti_toml(const lti::TransferFunction& tf, const std::string& description = "");
void write_lti_toml(const lti::TransferFunction& tf, const std::filesystem::path& path, const std::string& description = "");

}  // namespace piezobench::io
