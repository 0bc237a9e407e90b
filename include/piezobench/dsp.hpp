#pragma once
// The dsp module: windows, detrending, excitations, Welch spectra and FRF estimates.
#include "piezobench/dsp/detrend.hpp"
#include "piezobench/dsp/excitation.hpp"
#include "piezobench/dsp/frf.hpp"
#include "piezobench/dsp/frf_variance.hpp"
#include "piezobench/dsp/leakage_covariance.hpp"
#include "piezobench/dsp/resolution_kernel.hpp"
#include "piezobench/dsp/unwrap.hpp"
#include "piezobench/dsp/welch.hpp"
#include "piezobench/dsp/window.hpp"
