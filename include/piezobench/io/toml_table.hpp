#pragma once
// The one TOML reader of piezobench: campaign files, LTI files (--plant / --controller), 2-DoF
// parameters (model 2dof --params) and super-element descriptions all parse through here.
//
// Before toml++ sees the text it is checked against limits (toml++'s own depth limit covers
// arrays and inline tables only: a table header or dotted key with 100,000 parts recursed 30,000
// frames deep), so a hostile file is an InputError (exit 3) naming the file and the line:
//   - size at most TomlLimits::max_bytes (1 MiB: a campaign is a few KB);
//   - a dotted key or table header has at most max_key_parts parts (64);
//   - arrays and inline tables nest at most max_nesting deep (32).
// Syntax errors are InputErrors "FILE: line L, column C: expected valid TOML, found WHY".
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include <toml++/toml.h>

#include "piezobench/io/toml_describe.hpp"

namespace piezobench::io {

struct TomlLimits {
  std::size_t max_bytes = std::size_t{1} << 20;
  std::size_t max_key_parts = 64;
  std::size_t max_nesting = 32;
};

// Parses `text`; `source` names it in errors.
toml::table parse_toml(const std::string& text, const std::string& source, const TomlLimits& limits = {});
// Reads a file's text: InputError when it is missing, a directory, unreadable or larger than
// limits.max_bytes (checked before reading it).
std::string read_toml_text(const std::filesystem::path& file, const TomlLimits& limits = {});
// read_toml_text, then parse_toml.
toml::table read_toml_file(const std::filesystem::path& file, const TomlLimits& limits = {});

// The value of a number node as a double: floats as they are, integers to the nearest double (so
// 9223372036854775807 is a number, 9.223372036854776e18); nullopt for anything else.
std::optional<double> toml_number(const toml::node& node);

}  // namespace piezobench::io
