#pragma once
// Units of measured channels: the one table piezobench converts with. Every reader (CSV headers,
// .mat `units`, campaign channel units) converts samples to SI on read with it and records the SI
// symbol; a unit not in the table is refused (InputError listing the known ones), never ignored.
//
//   length       nm, um (also µm, μm), mm, cm, m          -> m
//   time         us (also µs, μs), ms, s, min             -> s
//   voltage      uV (also µV, μV), mV, V, kV              -> V
//   force        mN, N, kN                                -> N
//   frequency    Hz, kHz                                  -> Hz
//   capacitance  pF, nF, uF (also µF, μF), F              -> F
//   current      uA (also µA, μA), mA, A                  -> A
//   mass         g, kg                                    -> kg
//   velocity     um/s, mm/s, m/s                          -> m/s
//   acceleration m/s^2 (also m/s2, m/s²)                  -> m/s^2
//   pressure     Pa, kPa, MPa, mbar, bar                  -> Pa
//   ratio        "-", "1" (dimensionless)                 -> ""
// Symbols are case-sensitive (mV and MV differ), apart from the spellings "sec", "Hz"/"hz".
//
// Compound units: products and quotients of the symbols above, with parentheses and integer
// powers, as FRF and UFF files write them: `um/V`, `m/s^2/N`, `(1/N)*(m/s^2)`, `N*m`, `N.m`,
// `m/s2`, `m/s²`, `1/s`. They are parsed into an SI factor and a dimension (exponents of m, kg,
// s, A), never refused for being compound; their SI symbol is the SI symbols of their factors,
// numerator first (`(1/N)*(m/s^2)` -> `m/N/s^2`, factor 1). A compound whose dimension is one of
// the quantities above gets that quantity (`1/s` is a frequency), else Quantity::kCompound.
#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace piezobench::io {

enum class Quantity {
  kLength, kTime, kVoltage, kForce, kFrequency, kCapacitance, kCurrent, kMass, kVelocity, kAcceleration, kPressure,
  kDimensionless, kCompound
};
// Exponents of the SI base units m, kg, s, A (volt: {2, 1, -3, -1}).
using Dimension = std::array<int, 4>;
[[nodiscard]] std::string to_string(Quantity q);  // "length", "time", ...

struct Unit {
  std::string symbol;     // as written in the table ("um")
  Quantity quantity = Quantity::kDimensionless;
  double to_si = 1.0;     // value_SI = value * to_si
  std::string si_symbol;  // "m", "s", "V", "N", "Hz", "F", "A", "kg", "m/s", "m/s^2", "Pa", "" (dimensionless), "m/V", ...
  Dimension dimension{};  // exponents of m, kg, s, A
};

// The unit of a quotient `numerator / denominator` (an FRF's unit from its output's and input's):
// factors divide, dimensions subtract, symbol "num/den" ("" parts dropped: "m" / "" = "m").
[[nodiscard]] Unit divide(const Unit& numerator, const Unit& denominator);

// The unit of a symbol (from the table or a compound of its symbols), or nullopt when it is
// neither.
[[nodiscard]] std::optional<Unit> find_unit(std::string_view symbol);
// The same; InputError (source, field) listing the known units when it is not in the table.
[[nodiscard]] Unit unit_from_string(std::string_view symbol, const std::string& source, const std::string& field);
// "nm, um, mm, cm, m, us, ms, s, min, ..." (for messages and help texts).
[[nodiscard]] std::string known_units();

}  // namespace piezobench::io
