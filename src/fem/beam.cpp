#include "piezobench/fem/beam.hpp"

#include <cmath>
#include <vector>

#include "piezobench/core/file.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/text.hpp"
#include "piezobench/core/error.hpp"

namespace piezobench::fem {

BeamSection BeamSection::parse(const std::string& text, const std::string& field) {
  const std::string form = "E,nu,rho,AREA (Pa, -, kg/m^3, m^2), e.g. 48e9,0.31,7800,1e-4";
  std::vector<double> v;
  std::string_view rest(text);
  for (;;) {
    const auto comma = rest.find(',');
    const auto x = text::parse_double(text::trim(rest.substr(0, comma)));
    if (!x || !std::isfinite(*x)) throw InputError("", field, form, "'" + text + "'");
    v.push_back(*x);
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  if (v.size() != 4) throw InputError("", field, form, "'" + text + "'");
  if (!(v[0] > 0.0) || !(v[1] > -1.0 && v[1] < 0.5) || !(v[2] > 0.0) || !(v[3] > 0.0)) {
    throw InputError("", field, "E > 0, -1 < nu < 0.5, rho > 0, AREA > 0", "'" + text + "'");
  }
  return {v[0], v[1], v[2], v[3]};
}

BeamMatrices beam_matrices(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const BeamSection& s) {
  using Mat12 = Eigen::Matrix<double, 12, 12>;
  BeamMatrices out;
  const Eigen::Vector3d axis = b - a;
  const double L = axis.norm();
  out.length = L;
  const double E = s.youngs_modulus, G = E / (2.0 * (1.0 + s.poisson_ratio)), A = s.area;
  const double I = A * A / 12.0;       // square section, both axes
  const double J = 0.1406 * A * A;     // Saint-Venant torsion constant of a square
  const double EA = E * A, EI = E * I, GJ = G * J;
  out.axial_stiffness = EA / L;

  Mat12 k = Mat12::Zero(), m = Mat12::Zero();
  const auto put2 = [](Mat12& t, int i, int j, double c, double d) {  // c [2 1; 1 2]-like pattern [c d; d c]
    t(i, i) += c;
    t(j, j) += c;
    t(i, j) += d;
    t(j, i) += d;
  };
  put2(k, 0, 6, EA / L, -EA / L);
  put2(k, 3, 9, GJ / L, -GJ / L);
  const double mass = s.density * A * L;
  put2(m, 0, 6, mass / 3.0, mass / 6.0);
  put2(m, 3, 9, s.density * 2.0 * I * L / 3.0, s.density * 2.0 * I * L / 6.0);
  // Bending: (v, rz) in the local x-y plane and (w, ry) in the x-z plane; the second has the
  // rotation's sign reversed (a positive ry lowers w ahead of the node).
  const double L2 = L * L;
  const double kb[4][4] = {{12, 6 * L, -12, 6 * L}, {6 * L, 4 * L2, -6 * L, 2 * L2}, {-12, -6 * L, 12, -6 * L}, {6 * L, 2 * L2, -6 * L, 4 * L2}};
  const double mb[4][4] = {{156, 22 * L, 54, -13 * L}, {22 * L, 4 * L2, 13 * L, -3 * L2}, {54, 13 * L, 156, -22 * L}, {-13 * L, -3 * L2, -22 * L, 4 * L2}};
  const int xy[4] = {1, 5, 7, 11};
  const int xz[4] = {2, 4, 8, 10};
  const double sign[4] = {1, -1, 1, -1};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      k(xy[i], xy[j]) += EI / (L2 * L) * kb[i][j];
      m(xy[i], xy[j]) += mass / 420.0 * mb[i][j];
      k(xz[i], xz[j]) += sign[i] * sign[j] * EI / (L2 * L) * kb[i][j];
      m(xz[i], xz[j]) += sign[i] * sign[j] * mass / 420.0 * mb[i][j];
    }
  }
  // Local axes: x along the beam, y from the global axis least aligned with it.
  const Eigen::Vector3d ex = axis / L;
  Eigen::Index least = 0;
  ex.cwiseAbs().minCoeff(&least);
  Eigen::Vector3d ey = Eigen::Vector3d::Unit(least);
  ey = (ey - ey.dot(ex) * ex).normalized();
  const Eigen::Vector3d ez = ex.cross(ey);
  Eigen::Matrix3d R;
  R.row(0) = ex.transpose();
  R.row(1) = ey.transpose();
  R.row(2) = ez.transpose();
  Mat12 T = Mat12::Zero();
  for (int b3 = 0; b3 < 4; ++b3) T.block<3, 3>(3 * b3, 3 * b3) = R;
  out.K = T.transpose() * k * T;
  out.M = T.transpose() * m * T;
  return out;
}

void add_node(SuperElement& se, long node, const Eigen::Vector3d& position_m) {
  if (se.has_node(node)) throw InputError(se.source, "node " + std::to_string(node), "a new node number", "a node of the element");
  const Index n = se.size(), at = se.nodal_dofs();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + 6, n + 6), M = Eigen::MatrixXd::Zero(n + 6, n + 6);
  // Old rows/columns [0, at) stay, [at, n) move to [at + 6, n + 6).
  const auto spread = [&](const Eigen::MatrixXd& from, Eigen::MatrixXd& to) {
    const Index tail = n - at;
    to.topLeftCorner(at, at) = from.topLeftCorner(at, at);
    to.topRightCorner(at, tail) = from.topRightCorner(at, tail);
    to.bottomLeftCorner(tail, at) = from.bottomLeftCorner(tail, at);
    to.bottomRightCorner(tail, tail) = from.bottomRightCorner(tail, tail);
  };
  spread(se.K, K);
  spread(se.M, M);
  se.K = std::move(K);
  se.M = std::move(M);
  std::vector<DofLabel> dofs(se.dofs.begin(), se.dofs.begin() + at);
  for (int d = 1; d <= 6; ++d) dofs.push_back(DofLabel::nodal(node, static_cast<Direction>(d)));
  dofs.insert(dofs.end(), se.dofs.begin() + at, se.dofs.end());
  se.dofs = std::move(dofs);
  se.coordinates[node] = position_m;
}

BeamMatrices add_beam(SuperElement& se, long node_a, long node_b, const BeamSection& s, const std::string& field) {
  const auto position = [&](long node) {
    const auto it = se.coordinates.find(node);
    if (it == se.coordinates.end()) throw InputError(se.source, field, "a node with coordinates", "node " + std::to_string(node));
    return it->second;
  };
  const Eigen::Vector3d a = position(node_a), b = position(node_b);
  if (!((b - a).norm() > 0.0)) throw InputError(se.source, field, "two distinct positions", "coincident nodes");
  Index rows[12];
  for (int d = 0; d < 6; ++d) {
    rows[d] = se.index_of(node_a, static_cast<Direction>(d + 1), se.source, field);
    rows[6 + d] = se.index_of(node_b, static_cast<Direction>(d + 1), se.source, field);
  }
  const BeamMatrices bm = beam_matrices(a, b, s);
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      se.K(rows[i], rows[j]) += bm.K(i, j);
      se.M(rows[i], rows[j]) += bm.M(i, j);
    }
  }
  return bm;
}

}  // namespace piezobench::fem
