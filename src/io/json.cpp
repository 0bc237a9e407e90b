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

}  // namespace piezobench::io
