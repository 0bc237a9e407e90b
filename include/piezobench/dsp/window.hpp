#pragma once
// Tapering windows for spectral estimation, sample for sample equal to scipy.signal.get_window.
//
// Names and what they equal (w[n], n = 0..M-1; "symmetric" means w[n] = w[M-1-n]):
//   "rectangular"        w = 1                         scipy "boxcar"
//   "hann-periodic"      0.5 - 0.5 cos(2 pi n / M)     scipy "hann" (its default, fftbins=True),
//                                                     Octave hann(M, "periodic"), MATLAB hann(M, 'periodic')
//   "hann-symmetric"     0.5 - 0.5 cos(2 pi n / (M-1)) scipy hann(M, sym=True), Octave 7 hann(M) and
//                                                     hanning(M) (both with zero end points), MATLAB hann(M).
//                                                     NOT MATLAB's hanning(M), which is "hanning" below.
//   "hanning"            0.5 - 0.5 cos(2 pi (n+1) / (M+1))  MATLAB hanning(M) = hann(M+2)(2:end-1)
//   "hamming-periodic"   0.54 - 0.46 cos(2 pi n / M)   scipy "hamming", Octave/MATLAB hamming(M, "periodic")
//   "hamming-symmetric"  0.54 - 0.46 cos(2 pi n / (M-1)) scipy hamming(M, sym=True), Octave/MATLAB hamming(M)
//   "flattop-periodic"   sum_k (-1)^k a_k cos(2 pi k n / M)     scipy "flattop"
//   "flattop-symmetric"  sum_k (-1)^k a_k cos(2 pi k n / (M-1)) scipy flattop(M, sym=True), MATLAB flattopwin(M)
// with scipy's (= MATLAB's) flat-top coefficients a = {0.21557895, 0.41663158, 0.277263158,
// 0.083578947, 0.006947368}. Octave's flattopwin uses other coefficients ({1, 1.93, 1.29, 0.388,
// 0.0322} / 4.6402) and differs from these by about 1e-4.
// A window of length 1 is {1} for every type (as scipy and Octave).
// Other programs' names are accepted too, in any case: "hann" (= hann-periodic, scipy's "hann" and
// its Welch default), "hamming" (= hamming-periodic), "flattop" (= flattop-periodic), "flattopwin"
// (= flattop-symmetric, MATLAB's), "boxcar", "rectwin", "rect" (= rectangular). The command line
// and the campaign file both read window names through window_type_from_string.
// See docs/dsp-conventions.md.
#include <Eigen/Dense>
#include <string>

namespace piezobench::dsp {

enum class WindowType {
  kRectangular,
  kHanning,  // MATLAB hanning(M)
  kHannPeriodic,
  kHannSymmetric,
  kHammingPeriodic,
  kHammingSymmetric,
  kFlatTopPeriodic,
  kFlatTopSymmetric,
};

// The names listed above.
std::string to_string(WindowType type);
// The names above and the aliases (any case); InputError (field "window") for an unknown name, the
// message lists the known names.
WindowType window_type_from_string(const std::string& name);

// The window of `length` samples (length >= 1, else InputError field "window length").
Eigen::VectorXd make_window(WindowType type, Eigen::Index length);

}  // namespace piezobench::dsp
