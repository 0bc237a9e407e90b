#pragma once
// The factors from SI to the units results.json and the report show, for the campaign's figures
// that no declared field carries (curves, specs, sentences): each is core/fields.hpp's one table's
// (core::shown), so a unit is converted by one factor written once.
#include "piezobench/core/fields.hpp"

namespace piezobench::campaign::shown_units {

inline constexpr double kUm = core::shown::kMetreAsUm.per_si;                   // m -> um
inline constexpr double kUmPerV = core::shown::kMetrePerVoltAsUmPerV.per_si;    // m/V -> um/V
inline constexpr double kNPerUm = core::shown::kNewtonPerMetreAsNPerUm.per_si;  // N/m -> N/um
inline constexpr double kUf = core::shown::kFaradAsUf.per_si;                   // F -> uF

}  // namespace piezobench::campaign::shown_units
