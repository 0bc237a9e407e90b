#include "piezobench/ident/added_mass.hpp"

#include "piezobench/core/error.hpp"

namespace piezobench::ident {

Eigen::VectorXd added_weight_N(const Eigen::Ref<const Eigen::VectorXd>& t_s, const Eigen::Ref<const Eigen::VectorXd>& mass_log_kg,
                               double t_on_s, double t_off_s, double added_mass_kg, double gravity_m_s2) {
  const bool log = mass_log_kg.size() > 0;
  Eigen::VectorXd weight(t_s.size());
  for (Eigen::Index k = 0; k < t_s.size(); ++k) {
    const double m = log ? mass_log_kg(k) : (t_s(k) >= t_on_s && t_s(k) < t_off_s ? added_mass_kg : 0.0);
    weight(k) = m * gravity_m_s2;
  }
  return weight;
}

AddedMassAnalysis analyze_added_mass(const Eigen::Ref<const Eigen::VectorXd>& t_s, const Eigen::Ref<const Eigen::VectorXd>& de_m,
                                     const Eigen::Ref<const Eigen::VectorXd>& mass_log_kg, double sample_rate_Hz,
                                     const AddedMassOptions& options) {
  AddedMassAnalysis out;
  const metrology::StaticStiffnessOptions& o = options.stiffness;
  out.stiffness = metrology::static_stiffness(t_s, de_m, mass_log_kg, o, options.source);
  out.mass_log = mass_log_kg.size() > 0;
  const Eigen::VectorXd weight = added_weight_N(t_s, mass_log_kg, out.stiffness.t_on, out.stiffness.t_off, o.added_mass, o.gravity);
  try {
    out.creep = fit_creep({weight.data(), static_cast<std::size_t>(weight.size())}, {de_m.data(), static_cast<std::size_t>(de_m.size())},
                          sample_rate_Hz);
  } catch (const NumericalError& e) {
    out.failed.push_back(std::string("creep fit: ") + e.what());
  }
  return out;
}

}  // namespace piezobench::ident
