#pragma once
// JSON encodings shared by every command: complex numbers as [re, im], vectors as arrays,
// non-finite numbers as the strings "inf", "-inf" and "nan" (JSON has no such numbers).
// Units: the caller's (a number is written as given; the key that holds it names its unit).
#include <Eigen/Dense>
#include <complex>
#include <optional>
#include <nlohmann/json.hpp>
#include <vector>

#include "piezobench/core/fit_covariance.hpp"

namespace piezobench::io {

nlohmann::json to_json(double value);
// value times `scale` as above, null when absent.
nlohmann::json to_json(const std::optional<double>& value, double scale = 1.0);
nlohmann::json to_json(std::complex<double> value);
nlohmann::json to_json(const Eigen::VectorXd& values);
nlohmann::json to_json(const Eigen::VectorXcd& values);
nlohmann::json to_json(const std::vector<double>& values);
// A matrix as a list of rows.
nlohmann::json to_json(const Eigen::MatrixXd& values);
// A fit's standard errors as results.json and --json print them: {"standard_errors": {name: se},
// "correlation": rows in the order of "names", "high_correlations": ["a/b 0.97"], "condition_number",
// "chi2_per_dof", "from": "frf variance" | "residual scatter"}; null when empty.
nlohmann::json to_json(const core::ParameterUncertainty& u);

}  // namespace piezobench::io
