#pragma once
// What a TOML value is, in words, for the "found" part of an InputError
// ("a string", "a number", "an array of 3", "a table", ...). Shared by every TOML reader.
#include <string>

#include <toml++/toml.h>

namespace piezobench::io {

std::string describe_toml(const toml::node& node);

}  // namespace piezobench::io
