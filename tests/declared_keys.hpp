#pragma once
// Test helpers for checking a JSON document against a field declaration (core/fields.hpp): the keys
// io::results_object writes for a declared struct, and the keys an object holds.
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "piezobench/core/fields.hpp"

namespace piezobench::test {

// The results keys of S's declared fields that appear in results.json-style documents (a dotted key
// whole, e.g. "frf_error.de").
template <class S> std::set<std::string> declared_keys() {
  std::set<std::string> keys;
  core::for_each_field<S>([&](const auto& f) {
    if (f.in(core::kResults)) keys.insert(core::results_key(f));
  });
  return keys;
}

// The keys of a JSON object.
inline std::set<std::string> keys_of(const nlohmann::json& object) {
  std::set<std::string> keys;
  for (const auto& [k, v] : object.items()) keys.insert(k);
  return keys;
}

}  // namespace piezobench::test
