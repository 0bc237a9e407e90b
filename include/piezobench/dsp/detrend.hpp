#pragma once
// Removal of a trend from a segment before it is windowed (as scipy.signal.detrend and the
// per-segment detrending of Octave's pwelch: "mean" and "linear").
#include <Eigen/Dense>
#include <string>

namespace piezobench::dsp {

enum class Detrend {
  kNone,    // "none": data used as is (scipy detrend=False, Octave "none"/"no-strip")
  kMean,    // "mean": the segment mean is removed (scipy "constant", Octave "mean")
  kLinear,  // "linear": the least-squares straight line is removed (scipy and Octave "linear")
};

std::string to_string(Detrend detrend);
// InputError (field "detrend") for an unknown name.
Detrend detrend_from_string(const std::string& name);

// Removes the trend from x in place (any length; a length-1 segment becomes 0 for kMean/kLinear).
void detrend_in_place(Eigen::Ref<Eigen::VectorXd> x, Detrend detrend);

}  // namespace piezobench::dsp
