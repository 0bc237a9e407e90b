#pragma once
// An identified hysteresis and creep model (ident::HysteresisModel) as a TOML file: what
// `piezobench hysteresis fit` writes and `rt --feedforward` / `measure tracking --feedforward` read.
//
//   format = "piezobench-hysteresis-1"
//   gain_m_per_V = -1.46e-06          # d_e per effective volt
//   offset_m = 2.1e-08                # d_e at rest
//   reference_slope = 1.62            # effective V per command V of the compensated actuator
//   reference_intercept_V = -14.3
//   input_min_V = -15.0               # range of Va in the identification record
//   input_max_V = 145.0
//   [hysteresis]                      # H[v] = v + sum_i weights[i] P_{thresholds_V[i]}[v]
//   thresholds_V = [4.0, 12.0, ...]
//   weights = [0.07, 0.2, ...]
//   [creep]                           # optional: sum_j coefficients[j] F_j[v] (first-order states)
//   time_constants_s = [1.0, 10.0]
//   coefficients = [0.01, 0.012]
//   [fit]                             # optional, informative (ignored when read)
//   rms_residual_m = ..., relative_residual = ..., samples = ..., source = "file.mat", good = true
// Unknown keys, missing keys, wrong types and an invalid model (HysteresisModel::validate) are
// InputErrors naming the file and the key.
#include <filesystem>
#include <optional>
#include <string>

#include "piezobench/ident/hysteresis.hpp"

namespace piezobench::io {

// The TOML text of a model, with the fit's figures when given (`source`: the record it came from).
std::string hysteresis_model_toml(const ident::HysteresisModel& model, const ident::HysteresisFit* fit = nullptr,
                                  const std::string& source = "");
// Writes it atomically (io/atomic_file.hpp); InputError when the file cannot be written.
void write_hysteresis_model(const std::filesystem::path& path, const ident::HysteresisModel& model,
                            const ident::HysteresisFit* fit = nullptr, const std::string& source = "");

ident::HysteresisModel read_hysteresis_model(const std::filesystem::path& path);
// Same, from TOML text; `source` names it in errors.
ident::HysteresisModel parse_hysteresis_model(const std::string& text, const std::string& source);

}  // namespace piezobench::io
