#pragma once
// Piezo stacks in a super element (issue 15): each stack is a 3D Euler-Bernoulli beam between two
// 6-DOF nodes, as the report's FE model (and the Ansys APA95ML super element) have them, so that a
// stack touches the shell only where its end nodes are tied (remote points).
//
// The beam's axial stiffness is E A / L with L the distance between its nodes (for a piezo stack,
// k = c^E A / L of the report's Table 4.1); the section is a square of area A (bending I = A^2/12
// about both axes, torsion J = 0.1406 A^2, G = E / (2 (1 + nu))); the mass matrix is the
// consistent one (rho A L, rotary inertia of torsion rho (Iy + Iz) L).
//
// Since both ends are interface DOF of a Craig-Bampton super element, adding the beam to the
// reduced K and M is exactly the same as adding it to the full model before the reduction (the
// constraint modes and fixed-interface modes of the rest are unchanged).
#include <Eigen/Dense>
#include <string>

#include "piezobench/fem/superelement.hpp"

namespace piezobench::fem {

struct BeamSection {
  double youngs_modulus = 48e9;  // Pa (c^E of Table 4.1)
  double poisson_ratio = 0.31;   // -
  double density = 7800.0;       // kg/m^3
  double area = 1e-4;            // m^2 (square section)
  // "E,nu,rho,AREA" (SI); InputError naming `field` unless E > 0, -1 < nu < 0.5, rho > 0, AREA > 0.
  static BeamSection parse(const std::string& text, const std::string& field);
};

// 12 x 12 stiffness and consistent mass of the beam from a to b (m) in global axes; DOF order
// [u v w rx ry rz] at a, then at b. The local y axis is the global axis least aligned with the
// beam, made orthogonal to it (the section is square, so the choice does not matter).
struct BeamMatrices {
  Eigen::Matrix<double, 12, 12> K, M;
  double length = 0.0;           // m
  double axial_stiffness = 0.0;  // E A / L, N/m
};
[[nodiscard]] BeamMatrices beam_matrices(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const BeamSection& s);

// Adds a node with 6 DOF (no stiffness, no mass: tie it with add_beam) at `position_m`, after the
// other nodal DOF and before the modal ones. InputError when the node exists.
void add_node(SuperElement& se, long node, const Eigen::Vector3d& position_m);

// Adds the beam between two nodes of `se` (both with 6 DOF and coordinates) to K and M; returns
// its matrices. InputError naming `field` for a missing node, DOF or coordinate, or coincident ends.
BeamMatrices add_beam(SuperElement& se, long node_a, long node_b, const BeamSection& s, const std::string& field);

}  // namespace piezobench::fem
