#pragma once
// Tapering windows for spectral estimation, sample for sample equal to scipy.signal.get_window.
//
// Names and what they equal (w[n], n = 0..M-1; "symmetric" means w[n] = w[M-1-n]):
//   "rectangular"        w = 1                         scipy "boxcar"
//   "hann-periodic"      0.5 - 0.5 cos(2 pi n / M)     scipy "hann" (its default, fftbins=True),
//                                                     Octave hann(M, "periodic"), MATLAB hann(M, 'periodic')
//   "hann-symmetric"     0.5 - 0.5 cos(2 pi n / (M-1)) scipy hann(M, sym=True), Octave 7 hann(M) and
//                                                     hanning(M) (both with zero end points), MATLAB hann(M).
//                                                     NOT MATLAB's hanning(M), which is hann(M+2)(2:end-1).
//   "hamming-periodic"   0.54 - 0.46 cos(2 pi n / M)   scipy "hamming", Octave/MATLAB hamming(M, "periodic")
//   "hamming-symmetric"  0.54 - 0.46 cos(2 pi n / (M-1)) scipy hamming(M, sym=True), Octave/MATLAB hamming(M)
//   "flattop-periodic"   sum_k (-1)^k a_k cos(2 pi k n / M)     scipy "flattop"
//   "flattop-symmetric"  sum_k (-1)^k a_k cos(2 pi k n / (M-1)) scipy flattop(M, sym=True), MATLAB flattopwin(M)
// with scipy's (= MATLAB's) flat-top coefficients a = {0.21557895, 0.41663158, 0.277263158,
// 0.083578947, 0.006947368}. Octave's flattopwin uses other coefficients ({1, 1.93, 1.29, 0.388,
// 0.0322} / 4.6402) and differs from these by about 1e-4.
// A window of length 1 is {1} for every type (as scipy and Octave).
// See docs/dsp-conventions.md.
#include <Eigen/Dense>
#include <string>

namespace piezobench::dsp {

enum class WindowType {
  kRectangular,
  kHannPeriodic,
  kHannSymmetric,
  kHammingPeriodic,
  kHammingSymmetric,
  kFlatTopPeriodic,
  kFlatTopSymmetric,
};

// The names listed above.
std::string to_string(WindowType type);
// InputError (field "window") for an unknown name; the message lists the known names. The bare
// "hann" is rejected on purpose: say which of the two you mean.
WindowType window_type_from_string(const std::string& name);

// The window of `length` samples (length >= 1, else InputError field "window length").
Eigen::VectorXd make_window(WindowType type, Eigen::Index length);

}  // namespace piezobench::dsp
