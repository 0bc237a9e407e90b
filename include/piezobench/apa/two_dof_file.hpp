#pragma once
// 2-DoF parameters in a TOML file (`model 2dof --params`): keys m, k1, c1, ke, ce, ka, ca, ga, gs
// (SI), each a number; missing keys keep the report's defaults; unknown keys, non-numbers and
// invalid values are InputErrors naming the file and the key. Parsed by io/toml_table.hpp.
#include <filesystem>
#include <string>

#include "piezobench/apa/two_dof.hpp"

namespace piezobench::apa {

TwoDofParams read_two_dof_params(const std::filesystem::path& file);
// Same, from TOML text; `source` names it in errors.
TwoDofParams parse_two_dof_params(const std::string& text, const std::string& source);

}  // namespace piezobench::apa
