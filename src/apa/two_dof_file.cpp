#include "piezobench/apa/two_dof_file.hpp"

#include <map>

#include "piezobench/core/error.hpp"
#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"

namespace piezobench::apa {
namespace {

TwoDofParams from_table(const toml::table& table, const std::string& source) {
  const io::TomlReader r(table, source);
  std::map<std::string, double> values;
  for (const auto& [key, node] : table) {
    const std::string name(key.str());
    // Unknown keys first, so that a misspelt key is reported as such whatever its value.
    TwoDofParams probe;
    try {
      probe.set(name, 0.0, source);
    } catch (const InputError& e) {
      throw e.with_source(r.where(&node));
    }
    values[name] = r.number_at(node, name);  // SI units
  }
  return two_dof_params_from_map(values, source);
}

}  // namespace

TwoDofParams read_two_dof_params(const std::filesystem::path& file) {
  return from_table(io::read_toml_file(file), file.string());
}

TwoDofParams parse_two_dof_params(const std::string& text, const std::string& source) {
  return from_table(io::parse_toml(text, source), source);
}

}  // namespace piezobench::apa
