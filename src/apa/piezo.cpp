#include "piezobench/apa/piezo.hpp"

#include <fmt/format.h>

#include <cmath>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::apa {

void PiezoConstants::validate(const std::string& source) const {
  const std::string src = source.empty() ? "piezo constants" : source;
  const struct {
    const char* name;
    double value;
    const char* unit;
  } fields[] = {{"d33", d33, "m/V"},  {"eps_t", eps_t, "F/m"},   {"s_d", s_d, "m^2/N"}, {"c_e", c_e, "N/m^2"},
                {"length", length, "m"}, {"area", area, "m^2"}, {"layers", layers, "layers"}};
  for (const auto& f : fields) {
    if (!(std::isfinite(f.value) && f.value > 0.0)) {
      throw InputError(src, f.name, fmt::format("a finite value > 0 in {}", f.unit), format_number_exact(f.value));
    }
  }
  if (layers < 1.0 || layers != std::floor(layers)) {
    throw InputError(src, "layers", "an integer number of layers >= 1", format_number_exact(layers));
  }
}

PiezoSensitivities piezo_sensitivities(const PiezoConstants& c) {
  c.validate();
  PiezoSensitivities s;
  s.ka = c.c_e * c.area / c.length;
  s.ga = c.d33 * c.layers * s.ka;
  s.gs = c.d33 / (c.eps_t * c.s_d * c.layers);
  // Products of finite positive numbers can still overflow (e.g. c_e = 1e300 and area = 1e300).
  if (!(std::isfinite(s.ka) && std::isfinite(s.ga) && std::isfinite(s.gs) && s.ga > 0.0 && s.gs > 0.0)) {
    throw InputError(
        "piezo constants", "c_e", "constants whose products ka, ga, gs are finite and nonzero",
        fmt::format("ka = {}, ga = {}, gs = {}", format_number(s.ka), format_number(s.ga), format_number(s.gs)));
  }
  return s;
}

}  // namespace piezobench::apa
