#pragma once
// A super element on a bench: where its matrices come from, and the boundary conditions, masses,
// stack force pairs and outputs that put it to work (structural_model.hpp). One description and
// one load() for every user: `piezobench superelement` (the command line), the campaign's
// [superelement] table and the virtual bench's super-element TOML.
#include <filesystem>
#include <string>
#include <vector>

#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"

namespace piezobench::fem {

struct SuperElementSetup {
  std::string source;             // where the set-up was read, for messages ("" for the command line)
  std::string format = "auto";    // auto (detect_format), ansys, calculix, matrix-market
  std::filesystem::path k_file, m_file, nodes_file;
  std::filesystem::path coordinates_file;  // optional (read_super_element)
  ModelOptions model;             // fixed nodes, masses, forces (inputs), outputs, damping
  // The option or key each item came from, for messages; when a list is shorter than its items,
  // the rest are named "forces[i]", "outputs[i]", "masses[i]".
  std::string fix_field = "fix";
  std::vector<std::string> force_fields, output_fields, mass_fields;

  // The format named by `format`; InputError(source, "format") for an unknown name.
  [[nodiscard]] SuperElementFormat resolved_format() const;
  // Reads the element and checks every node and DOF of `model` against it, then validates the
  // options (ModelOptions::validate). InputError naming `source` and the field of the culprit.
  [[nodiscard]] SuperElement load(const ImportOptions& options = {}) const;
};

}  // namespace piezobench::fem
