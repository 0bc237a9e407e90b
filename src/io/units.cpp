#include "piezobench/io/units.hpp"

#include <array>

#include "piezobench/core/error.hpp"
#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"

namespace piezobench::io {

namespace {

struct Entry {
  const char* symbol;
  Quantity quantity;
  double to_si;
  const char* si;
  bool listed;  // shown in known_units() (aliases are not)
};

// The one unit table (see units.hpp). Micro: ASCII "u", the micro sign U+00B5 and the Greek
// letter mu U+03BC, as spreadsheets and DAQ software write all three.
constexpr std::array kUnitTable = {
    Entry{"nm", Quantity::kLength, 1e-9, "m", true},
    Entry{"um", Quantity::kLength, 1e-6, "m", true},
    Entry{"\xC2\xB5m", Quantity::kLength, 1e-6, "m", false},
    Entry{"\xCE\xBCm", Quantity::kLength, 1e-6, "m", false},
    Entry{"mm", Quantity::kLength, 1e-3, "m", true},
    Entry{"cm", Quantity::kLength, 1e-2, "m", true},
    Entry{"m", Quantity::kLength, 1.0, "m", true},
    Entry{"us", Quantity::kTime, 1e-6, "s", true},
    Entry{"\xC2\xB5s", Quantity::kTime, 1e-6, "s", false},
    Entry{"\xCE\xBCs", Quantity::kTime, 1e-6, "s", false},
    Entry{"ms", Quantity::kTime, 1e-3, "s", true},
    Entry{"s", Quantity::kTime, 1.0, "s", true},
    Entry{"sec", Quantity::kTime, 1.0, "s", false},
    Entry{"min", Quantity::kTime, 60.0, "s", true},
    Entry{"uV", Quantity::kVoltage, 1e-6, "V", true},
    Entry{"\xC2\xB5V", Quantity::kVoltage, 1e-6, "V", false},
    Entry{"\xCE\xBCV", Quantity::kVoltage, 1e-6, "V", false},
    Entry{"mV", Quantity::kVoltage, 1e-3, "V", true},
    Entry{"V", Quantity::kVoltage, 1.0, "V", true},
    Entry{"kV", Quantity::kVoltage, 1e3, "V", true},
    Entry{"mN", Quantity::kForce, 1e-3, "N", true},
    Entry{"N", Quantity::kForce, 1.0, "N", true},
    Entry{"kN", Quantity::kForce, 1e3, "N", true},
    Entry{"Hz", Quantity::kFrequency, 1.0, "Hz", true},
    Entry{"hz", Quantity::kFrequency, 1.0, "Hz", false},
    Entry{"kHz", Quantity::kFrequency, 1e3, "Hz", true},
    Entry{"pF", Quantity::kCapacitance, 1e-12, "F", true},
    Entry{"nF", Quantity::kCapacitance, 1e-9, "F", true},
    Entry{"uF", Quantity::kCapacitance, 1e-6, "F", true},
    Entry{"\xC2\xB5"
          "F",
          Quantity::kCapacitance, 1e-6, "F", false},
    Entry{"\xCE\xBC"
          "F",
          Quantity::kCapacitance, 1e-6, "F", false},
    Entry{"F", Quantity::kCapacitance, 1.0, "F", true},
    Entry{"uA", Quantity::kCurrent, 1e-6, "A", true},
    Entry{"\xC2\xB5"
          "A",
          Quantity::kCurrent, 1e-6, "A", false},
    Entry{"\xCE\xBC"
          "A",
          Quantity::kCurrent, 1e-6, "A", false},
    Entry{"mA", Quantity::kCurrent, 1e-3, "A", true},
    Entry{"A", Quantity::kCurrent, 1.0, "A", true},
    Entry{"g", Quantity::kMass, 1e-3, "kg", true},
    Entry{"kg", Quantity::kMass, 1.0, "kg", true},
    Entry{"um/s", Quantity::kVelocity, 1e-6, "m/s", true},
    Entry{"mm/s", Quantity::kVelocity, 1e-3, "m/s", true},
    Entry{"m/s", Quantity::kVelocity, 1.0, "m/s", true},
    Entry{"m/s^2", Quantity::kAcceleration, 1.0, "m/s^2", true},
    Entry{"m/s2", Quantity::kAcceleration, 1.0, "m/s^2", false},
    Entry{"-", Quantity::kDimensionless, 1.0, "", true},
    Entry{"1", Quantity::kDimensionless, 1.0, "", true},
};

}  // namespace

std::string to_string(Quantity q) {
  switch (q) {
    case Quantity::kLength: return "length";
    case Quantity::kTime: return "time";
    case Quantity::kVoltage: return "voltage";
    case Quantity::kForce: return "force";
    case Quantity::kFrequency: return "frequency";
    case Quantity::kCapacitance: return "capacitance";
    case Quantity::kCurrent: return "current";
    case Quantity::kMass: return "mass";
    case Quantity::kVelocity: return "velocity";
    case Quantity::kAcceleration: return "acceleration";
    case Quantity::kDimensionless: return "dimensionless";
  }
  return "dimensionless";
}

std::optional<Unit> find_unit(std::string_view symbol) {
  symbol = text::trim(symbol);
  for (const Entry& e : kUnitTable) {
    if (symbol == e.symbol) return Unit{e.symbol, e.quantity, e.to_si, e.si};
  }
  return std::nullopt;
}

std::string known_units() {
  std::string out;
  for (const Entry& e : kUnitTable) {
    if (!e.listed) continue;
    if (!out.empty()) out += ", ";
    out += e.symbol;
  }
  return out;
}

Unit unit_from_string(std::string_view symbol, const std::string& source, const std::string& field) {
  if (std::optional<Unit> u = find_unit(symbol)) return *u;
  throw InputError(source, field, "a known unit (" + known_units() + ")", "unit " + text::quote(text::trim(symbol)));
}

}  // namespace piezobench::io
