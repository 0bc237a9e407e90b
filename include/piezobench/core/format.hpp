#pragma once
// Numbers in messages (errors, warnings, progress): the one formatter of the project.
#include <string>

namespace piezobench {

// `value` as printf's %g with `significant_digits` digits: 6 (the default) is what a person reads;
// 10 tells neighbouring values apart (sample times, delays); 17 round-trips a double. "nan", "inf"
// and "-inf" for the non-finite values. significant_digits is clamped to [1, 17].
std::string format_number(double value, int significant_digits = 6);

}  // namespace piezobench
