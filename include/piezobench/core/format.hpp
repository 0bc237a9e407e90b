#pragma once
// Numbers in messages (errors, warnings, progress): the one formatter of the project.
// Units: the caller's (a number is printed as given; the message names its unit).
#include <string>

namespace piezobench {

// `value` as printf's %g with `significant_digits` digits: 6 (the default) is what a person reads;
// 10 tells neighbouring values apart (sample times, delays); 17 round-trips a double. "nan", "inf"
// and "-inf" for the non-finite values. significant_digits is clamped to [1, 17].
std::string format_number(double value, int significant_digits = 6);

// The fewest significant digits (%g style, at least format_number's 6, so 150 stays "150") that read
// back as exactly `value`: what a user wrote in a file, shown back in an error ("1e-12", "0.1",
// "1.0000001", where format_number(v) gives "1" for the last). "nan", "inf", "-inf" for the
// non-finite values.
std::string format_number_exact(double value);

// `value` with `decimals` digits after the point (printf's %.*f): a value set beside a limit in the
// same unit ("stroke 158.3 um below the minimum 200.0 um"), where aligned decimals read better than
// significant digits. "nan", "inf", "-inf" for the non-finite values. decimals is clamped to [0, 17].
std::string format_number_fixed(double value, int decimals);

}  // namespace piezobench
