#pragma once
// Order statistics shared by the modules (the campaign's batch statistics and super-element fit,
// metrology's robust outliers).
#include <vector>

namespace piezobench::core {

// The median of `values`: the middle value, or the mean of the two middle values for an even
// count; NaN for no values. NaN entries are not allowed (they have no order).
double median(std::vector<double> values);

}  // namespace piezobench::core
