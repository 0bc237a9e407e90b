#include "piezobench/io/json.hpp"

#include <cmath>

namespace piezobench::io {

nlohmann::json to_json(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

nlohmann::json to_json(const std::optional<double>& value, double scale) {
  return value ? to_json(*value * scale) : nlohmann::json(nullptr);
}

nlohmann::json to_json(std::complex<double> value) {
  return nlohmann::json::array({to_json(value.real()), to_json(value.imag())});
}

nlohmann::json to_json(const Eigen::VectorXd& values) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < values.size(); ++i) out.push_back(to_json(values(i)));
  return out;
}

nlohmann::json to_json(const Eigen::VectorXcd& values) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < values.size(); ++i) out.push_back(to_json(values(i)));
  return out;
}

nlohmann::json to_json(const std::vector<double>& values) {
  nlohmann::json out = nlohmann::json::array();
  for (const double v : values) out.push_back(to_json(v));
  return out;
}

nlohmann::json to_json(const Eigen::MatrixXd& values) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < values.rows(); ++i) out.push_back(to_json(Eigen::VectorXd(values.row(i).transpose())));
  return out;
}

nlohmann::json to_json(const core::ParameterUncertainty& u) {
  if (u.empty()) return nullptr;
  nlohmann::json se = nlohmann::json::object();
  for (std::size_t i = 0; i < u.names.size(); ++i) se[u.names[i]] = to_json(u.standard_error(static_cast<Eigen::Index>(i)));
  return {{"names", u.names},
          {"standard_errors", se},
          {"correlation", to_json(u.correlation)},
          {"high_correlations", u.high_correlations},
          {"condition_number", to_json(u.condition_number)},
          {"chi2_per_dof", to_json(u.chi2_per_dof)},
          {"from", u.from_data_variance ? "frf variance" : "residual scatter"}};
}

}  // namespace piezobench::io
