#include "piezobench/campaign/superelement_update.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "piezobench/core/eigen_solvers.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"
#include "piezobench/fem/structural_model.hpp"

namespace piezobench::campaign {
namespace {

const char* const kUpdateSource = "superelement update";
constexpr int kFeatures = 2;  // ln f_r, ln f_a

// The element's stiffness as K_rest + sum scale_p K_p.
struct Parts {
  Eigen::MatrixXd rest;
  std::vector<Eigen::MatrixXd> parts;
  std::vector<std::optional<double>> modulus_Pa;  // at scale 1
};

// The beam's 12 x 12 stiffness placed on the element's DOF.
Eigen::MatrixXd beam_stiffness(const fem::SuperElement& se, const StackBeam& b) {
  const std::string field = fmt::format("stack {}:{}", b.node_a, b.node_b);
  const auto a = se.coordinates.find(b.node_a), c = se.coordinates.find(b.node_b);
  if (a == se.coordinates.end() || c == se.coordinates.end()) {
    throw InputError(se.source, field, "two nodes of the element with coordinates", "a node without them");
  }
  const fem::BeamMatrices m = fem::beam_matrices(a->second, c->second, b.section);
  std::vector<Eigen::Index> rows;
  for (const long node : {b.node_a, b.node_b}) {
    for (int d = 1; d <= 6; ++d) rows.push_back(se.index_of(node, static_cast<fem::Direction>(d), se.source, field));
  }
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(se.size(), se.size());
  for (std::size_t i = 0; i < 12; ++i) {
    for (std::size_t j = 0; j < 12; ++j) k(rows[i], rows[j]) += m.K(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
  }
  return k;
}

Parts split(const fem::SuperElement& se, const SuperElementUpdateOptions& o) {
  std::vector<Eigen::MatrixXd> beams;
  Eigen::MatrixXd all_beams = Eigen::MatrixXd::Zero(se.size(), se.size());
  for (const StackBeam& b : o.stacks) {
    beams.push_back(beam_stiffness(se, b));
    all_beams += beams.back();
  }
  Parts p;
  p.rest = se.K;
  for (const std::string& name : o.parameters) {
    if (name == "shell") {
      p.parts.push_back(se.K - all_beams);
      p.modulus_Pa.push_back(o.shell_modulus_Pa > 0.0 ? std::optional<double>(o.shell_modulus_Pa) : std::nullopt);
    } else if (name == "stacks") {
      p.parts.push_back(all_beams);
      const double e = o.stacks.front().section.youngs_modulus;
      const bool same = std::all_of(o.stacks.begin(), o.stacks.end(), [e](const StackBeam& b) { return b.section.youngs_modulus == e; });
      p.modulus_Pa.push_back(same ? std::optional<double>(e) : std::nullopt);
    } else {  // stack:A:B (validated)
      for (std::size_t i = 0; i < o.stacks.size(); ++i) {
        if (name == fmt::format("stack:{}:{}", o.stacks[i].node_a, o.stacks[i].node_b)) {
          p.parts.push_back(beams[i]);
          p.modulus_Pa.push_back(o.stacks[i].section.youngs_modulus);
        }
      }
    }
    p.rest -= p.parts.back();
  }
  return p;
}

fem::SuperElement scaled(const fem::SuperElement& se, const Parts& p, const Eigen::VectorXd& theta) {
  fem::SuperElement out = se;
  out.K = p.rest;
  for (std::size_t i = 0; i < p.parts.size(); ++i) out.K += std::exp(theta(static_cast<Eigen::Index>(i))) * p.parts[i];
  return out;
}

Eigen::Vector2d log_features(const BenchFeatures& f) { return {std::log(f.resonance_Hz), std::log(f.antiresonance_Hz)}; }

}  // namespace

StackBeam StackBeam::parse(const std::string& text, const std::string& field) {
  const auto c1 = text.find(':');
  const auto c2 = c1 == std::string::npos ? std::string::npos : text.find(':', c1 + 1);
  if (c2 == std::string::npos) throw InputError(kUpdateSource, field, "NODE_A:NODE_B:E,nu,rho,AREA", "'" + text + "'");
  StackBeam b;
  try {
    std::size_t used_a = 0, used_b = 0;
    b.node_a = std::stol(text.substr(0, c1), &used_a);
    b.node_b = std::stol(text.substr(c1 + 1, c2 - c1 - 1), &used_b);
    if (used_a != c1 || used_b != c2 - c1 - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw InputError(kUpdateSource, field, "NODE_A:NODE_B:E,nu,rho,AREA with node numbers", "'" + text + "'");
  }
  if (b.node_a < 0 || b.node_b < 0 || b.node_a == b.node_b) throw InputError(kUpdateSource, field, "two distinct node numbers >= 0", "'" + text + "'");
  b.section = fem::BeamSection::parse(text.substr(c2 + 1), field);
  return b;
}

void SuperElementUpdateOptions::validate() const {
  bench.validate();
  if (stacks.empty()) throw InputError(kUpdateSource, "stacks", "the element's stacks (NODE_A:NODE_B:E,nu,rho,AREA)", "none");
  if (parameters.empty()) throw InputError(kUpdateSource, "parameters", "at least one of shell, stacks, stack:A:B", "none");
  std::set<std::string> seen;
  bool stacks_whole = false, stack_one = false;
  for (const std::string& p : parameters) {
    if (!seen.insert(p).second) throw InputError(kUpdateSource, "parameters", "each parameter once", "'" + p + "' twice");
    const bool known_stack = std::any_of(stacks.begin(), stacks.end(), [&p](const StackBeam& b) { return p == fmt::format("stack:{}:{}", b.node_a, b.node_b); });
    if (p == "stacks") stacks_whole = true;
    else if (known_stack) stack_one = true;
    else if (p != "shell") throw InputError(kUpdateSource, "parameters", "shell, stacks or stack:A:B of a given stack", "'" + p + "'");
  }
  if (stacks_whole && stack_one) throw InputError(kUpdateSource, "parameters", "either stacks or single stacks (the parts overlap)", "both");
  if (!(shell_modulus_Pa >= 0.0 && std::isfinite(shell_modulus_Pa))) throw InputError(kUpdateSource, "shell_modulus_Pa", "a modulus >= 0 Pa", fmt::format("{}", shell_modulus_Pa));
  if (!(rank_tolerance > 0.0 && rank_tolerance < 1.0)) throw InputError(kUpdateSource, "rank_tolerance", "a fraction in (0, 1)", fmt::format("{}", rank_tolerance));
  if (max_iterations < 1) throw InputError(kUpdateSource, "max_iterations", "at least 1", fmt::format("{}", max_iterations));
}

BenchFeatures bench_features(const fem::SuperElement& se, const fem::SuperElementSetup& setup, const SuperElementFitOptions& options) {
  const fem::StructuralModel model = superelement_bench_model(se, setup, options);
  const fem::Modes modes = fem::modes(model.K, model.M);
  const Eigen::VectorXd lambda = (kTwoPi * modes.frequencies_Hz).array().square();
  const Eigen::VectorXd phi_f = modes.shapes.transpose() * model.F.col(0);
  const Eigen::VectorXd phi_d = modes.shapes.transpose() * model.T.row(0).transpose();
  const Eigen::VectorXd phi_s = modes.shapes.transpose() * model.T.row(1).transpose();
  // The measured resonance is the peak of u -> d_e: the mode of largest static participation.
  Eigen::Index r = -1;
  double best = 0.0;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    if (!(modes.frequencies_Hz(i) > 0.0)) continue;
    const double w = std::abs(phi_d(i) * phi_f(i)) / lambda(i);
    if (w > best) best = w, r = i;
  }
  if (r < 0) throw NumericalError("super element features", "no mode of the bench model is seen by the output", false);
  BenchFeatures out;
  out.resonance_Hz = modes.frequencies_Hz(r);
  // Undamped force -> sensor extension: continuous between poles; its first sign change below f_r
  // that no pole separates is the anti-resonance (bisection to 1e-10 relative).
  const auto hs = [&](double f) {
    const double w2 = std::pow(kTwoPi * f, 2);
    return (phi_s.array() * phi_f.array() / (lambda.array() - w2)).sum();
  };
  const auto pole_between = [&](double a, double b) {
    return ((modes.frequencies_Hz.array() > a) && (modes.frequencies_Hz.array() < b)).any();
  };
  const int n = 600;
  double lo = 0.0, hi = 0.0;
  for (int k = n - 1; k > 0 && hi == 0.0; --k) {  // the sign change closest below f_r
    const double a = out.resonance_Hz * (0.02 + 0.979 * (k - 1) / (n - 1)), b = out.resonance_Hz * (0.02 + 0.979 * k / (n - 1));
    if (!pole_between(a, b) && hs(a) * hs(b) < 0.0) lo = a, hi = b;
  }
  if (hi == 0.0) throw NumericalError("super element features", "no anti-resonance of the sensor below the resonance", false);
  double flo = hs(lo);
  for (int it = 0; it < 200 && hi - lo > 1e-10 * hi; ++it) {
    const double mid = 0.5 * (lo + hi), fm = hs(mid);
    if (fm * flo > 0.0) lo = mid, flo = fm;
    else hi = mid;
  }
  out.antiresonance_Hz = 0.5 * (lo + hi);
  return out;
}

namespace {

// J = d ln feature / d ln scale by central differences.
Eigen::MatrixXd jacobian(const fem::SuperElement& se, const fem::SuperElementSetup& setup, const SuperElementUpdateOptions& o,
                         const Parts& p, const Eigen::VectorXd& theta) {
  const double h = 1e-4;
  Eigen::MatrixXd J(kFeatures, theta.size());
  for (Eigen::Index j = 0; j < theta.size(); ++j) {
    Eigen::VectorXd tp = theta, tm = theta;
    tp(j) += h;
    tm(j) -= h;
    J.col(j) = (log_features(bench_features(scaled(se, p, tp), setup, o.bench)) - log_features(bench_features(scaled(se, p, tm), setup, o.bench))) / (2.0 * h);
  }
  return J;
}

// Refuses parameter sets the features do not determine (see the header).
void check_rank(const Eigen::MatrixXd& J, const SuperElementUpdateOptions& o, SuperElementUpdate& out) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
  out.singular_values = svd.singularValues();
  const double smax = out.singular_values.size() > 0 ? out.singular_values(0) : 0.0;
  out.rank = static_cast<int>((out.singular_values.array() > o.rank_tolerance * smax).count());
  out.condition = out.rank > 0 ? smax / out.singular_values(out.rank - 1) : 0.0;
  const auto p = static_cast<int>(J.cols());
  if (out.rank == p && smax > 0.0) return;
  // The parameter with the largest share of the least determined direction.
  const Eigen::VectorXd v = svd.matrixV().col(p - 1).cwiseAbs();
  Eigen::Index worst = 0;
  v.maxCoeff(&worst);
  std::string sv;
  for (Eigen::Index i = 0; i < out.singular_values.size(); ++i)
    sv += (i ? ", " : "") + format_number(out.singular_values(i), 3);
  throw InputError(
      kUpdateSource, "parameters",
      fmt::format(
          "parameters the resonance and anti-resonance determine (at most {}: the rank of d ln feature / d ln scale, "
          "singular values above {} x the largest)",
          out.rank, format_number(o.rank_tolerance)),
      fmt::format("{} parameters, singular values {}: '{}' is not determined by the data", p, sv,
                  o.parameters[static_cast<std::size_t>(worst)]));
}

std::vector<Eigen::Vector2d> target_features(const std::vector<UpdateTarget>& targets) {
  if (targets.empty()) throw InputError(kUpdateSource, "units", "at least one unit with a resonance and an anti-resonance", "none");
  std::vector<Eigen::Vector2d> y;
  for (const UpdateTarget& t : targets) {
    if (!(std::isfinite(t.resonance_Hz) && std::isfinite(t.antiresonance_Hz) && t.antiresonance_Hz > 0.0 && t.resonance_Hz > t.antiresonance_Hz)) {
      throw InputError(kUpdateSource, t.unit, "0 < anti-resonance < resonance, Hz", fmt::format("{} and {}", t.antiresonance_Hz, t.resonance_Hz));
    }
    y.emplace_back(std::log(t.resonance_Hz), std::log(t.antiresonance_Hz));
  }
  return y;
}

// Standard errors and correlation of the scales from the units' scatter (see the header).
void uncertainty(const std::vector<Eigen::Vector2d>& y, const Eigen::Vector2d& mean, SuperElementUpdate& out) {
  const auto n = static_cast<double>(y.size());
  if (y.size() < 2) {
    out.warnings.push_back("one unit: no scatter to give the updated parameters standard errors");
    return;
  }
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& v : y) S += (v - mean) * (v - mean).transpose();
  S /= (n - 1.0);
  const Eigen::MatrixXd& J = out.sensitivity;
  const Eigen::MatrixXd G = (J.transpose() * J).ldlt().solve(J.transpose());
  const Eigen::MatrixXd cov = G * (S / n) * G.transpose();
  const auto p = cov.rows();
  out.correlation.resize(p, p);
  for (Eigen::Index i = 0; i < p; ++i) {
    out.parameters[static_cast<std::size_t>(i)].standard_error = out.parameters[static_cast<std::size_t>(i)].scale * std::sqrt(cov(i, i));
    for (Eigen::Index j = 0; j < p; ++j) out.correlation(i, j) = cov(i, j) / std::sqrt(cov(i, i) * cov(j, j));
  }
}

}  // namespace

SuperElementUpdate update_superelement(const fem::SuperElement& se, const fem::SuperElementSetup& setup, const std::vector<UpdateTarget>& targets,
                                       const SuperElementUpdateOptions& options) {
  options.validate();
  const std::vector<Eigen::Vector2d> y = target_features(targets);
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& v : y) mean += v / static_cast<double>(y.size());
  const Parts parts = split(se, options);
  SuperElementUpdate out;
  out.units = static_cast<int>(y.size());
  out.target_resonance_Hz = std::exp(mean(0));
  out.target_antiresonance_Hz = std::exp(mean(1));
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(parts.parts.size()));
  const BenchFeatures f0 = bench_features(se, setup, options.bench);
  out.initial_resonance_Hz = f0.resonance_Hz;
  out.initial_antiresonance_Hz = f0.antiresonance_Hz;
  check_rank(jacobian(se, setup, options, parts, theta), options, out);

  // Gauss-Newton with step halving.
  Eigen::Vector2d r = log_features(f0) - mean;
  bool converged = false;
  for (out.iterations = 1; out.iterations <= options.max_iterations && !converged; ++out.iterations) {
    const Eigen::MatrixXd J = jacobian(se, setup, options, parts, theta);
    const Eigen::VectorXd step = J.completeOrthogonalDecomposition().solve(-r);
    double t = 1.0;
    for (int halving = 0; halving < 30; ++halving, t *= 0.5) {
      const Eigen::VectorXd trial = theta + t * step;
      const Eigen::Vector2d rt = log_features(bench_features(scaled(se, parts, trial), setup, options.bench)) - mean;
      if (rt.norm() < r.norm() || t < 1e-6) {
        theta = trial;
        converged = (t * step).norm() < 1e-9 || rt.norm() < 1e-10 || std::abs(r.norm() - rt.norm()) < 1e-13;
        r = rt;
        break;
      }
    }
  }
  if (!converged) {
    throw NumericalError("super element update",
                         fmt::format("no convergence in {} iterations (residual {} in ln f)", options.max_iterations,
                                     format_number(r.norm(), 3)),
                         false);
  }
  out.element = scaled(se, parts, theta);
  const BenchFeatures f1 = bench_features(out.element, setup, options.bench);
  out.resonance_Hz = f1.resonance_Hz;
  out.antiresonance_Hz = f1.antiresonance_Hz;
  out.sensitivity = jacobian(se, setup, options, parts, theta);
  for (std::size_t i = 0; i < parts.parts.size(); ++i) {
    UpdatedParameter u;
    u.name = options.parameters[i];
    u.scale = std::exp(theta(static_cast<Eigen::Index>(i)));
    if (parts.modulus_Pa[i]) u.modulus_Pa = u.scale * *parts.modulus_Pa[i];
    out.parameters.push_back(u);
  }
  if (r.norm() > 1e-3) {
    out.warnings.push_back(
        fmt::format("the updated model misses the features by {} % (least squares: more features than parameters)",
                    format_number(100.0 * r.cwiseAbs().maxCoeff(), 2)));
  }
  uncertainty(y, mean, out);
  return out;
}

}  // namespace piezobench::campaign
