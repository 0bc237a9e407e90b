#include "piezobench/fem/superelement_setup.hpp"

#include "piezobench/core/error.hpp"

namespace piezobench::fem {
namespace {

std::string field_of(const std::vector<std::string>& fields, std::size_t i, const char* list) {
  return i < fields.size() ? fields[i] : std::string(list) + "[" + std::to_string(i) + "]";
}

}  // namespace

SuperElementFormat SuperElementSetup::resolved_format() const {
  if (format == "auto") return detect_format(k_file);
  const auto f = super_element_format_from_string(format);
  if (!f) throw InputError(source, "format", "auto, ansys, calculix or matrix-market", "'" + format + "'");
  return *f;
}

SuperElement SuperElementSetup::load(const ImportOptions& options) const {
  const SuperElementFormat f = resolved_format();
  SuperElement se;
  try {
    se = read_super_element(f, k_file, m_file, nodes_file, coordinates_file, options);
  } catch (const InputError& e) {
    // The reader names the matrix file; say which set-up asked for it.
    if (source.empty()) throw;
    throw InputError(source + ": super element: " + e.what());
  }
  for (long n : model.fixed_nodes) {
    if (!se.has_node(n)) (void)se.index_of(n, Direction::kX, source, fix_field);
  }
  for (std::size_t i = 0; i < model.forces.size(); ++i) {
    const ForcePair& p = model.forces[i];
    const std::string field = field_of(force_fields, i, "forces");
    if (p.node_a >= 0) (void)se.index_of(p.node_a, p.direction, source, field);
    (void)se.index_of(p.node_b, p.direction, source, field);
  }
  for (std::size_t i = 0; i < model.outputs.size(); ++i) {
    const DisplacementOutput& o = model.outputs[i];
    const std::string field = field_of(output_fields, i, "outputs");
    if (o.node_a >= 0) (void)se.index_of(o.node_a, o.direction, source, field);
    (void)se.index_of(o.node_b, o.direction, source, field);
  }
  for (std::size_t i = 0; i < model.masses.size(); ++i) {
    (void)se.index_of(model.masses[i].node, Direction::kX, source, field_of(mass_fields, i, "masses"));
  }
  try {
    model.validate(se);
  } catch (const InputError& e) {
    if (source.empty()) throw;
    throw e.with_source(source);
  }
  return se;
}

}  // namespace piezobench::fem
