// Frequency response of a super element with a couple of thousand DOF, as `piezobench
// superelement` computes it: modal superposition (fem::frequency_response with the modes) against
// the dense complex LU per frequency (the peer, timed on a few frequencies and extrapolated), and
// their largest difference on those frequencies.
//
//   build/bench/fem_frf_bench tests/fixtures/fem/apa95ml_dump [--points 500] [--dense-points 5]
//
// The model: the dump's bottom remote point (769, 770) clamped, the stack pair 771:773 along x,
// the top (767) along y, modal damping 1 %.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "piezobench/core/error.hpp"
#include "program_main.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/lti/freqresp.hpp"

namespace {

using namespace piezobench;

using bench_program::seconds_since;

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: fem_frf_bench DUMP_STEM [--points N] [--dense-points N]\n");
    return 2;
  }
  const std::string stem = argv[1];
  int points = 500, dense_points = 5;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--points") {
      points = std::atoi(argv[i + 1]);
    } else if (key == "--dense-points") {
      dense_points = std::atoi(argv[i + 1]);
    } else {
      std::fprintf(stderr, "fem_frf_bench: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  const fem::SuperElement se = fem::read_calculix_super_element(stem + ".sti", stem + ".mas", stem + ".dof");
  fem::ModelOptions o;
  o.fixed_nodes = {769, 770};
  o.forces = {fem::ForcePair::parse("771:773:x", "bench")};
  o.outputs = {fem::DisplacementOutput::parse("767:y", "bench")};
  o.damping = fem::Damping::parse("modal:0.01", "bench");
  const fem::StructuralModel model = fem::assemble(se, o);
  const Eigen::VectorXd w = 2 * std::numbers::pi * lti::logspace(1.0, 4.0, points);

  auto t0 = std::chrono::steady_clock::now();
  const fem::Modes modes = fem::modes(model);
  const double t_modes = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  const std::vector<Eigen::MatrixXcd> modal = fem::frequency_response(model, modes, w).H;
  const double t_modal = seconds_since(t0);

  Eigen::VectorXd wd(dense_points);
  for (int k = 0; k < dense_points; ++k) wd(k) = w((static_cast<long>(k) * (points - 1)) / std::max(1, dense_points - 1));
  t0 = std::chrono::steady_clock::now();
  const std::vector<Eigen::MatrixXcd> dense = fem::frequency_response(model, wd).H;
  const double t_dense = seconds_since(t0);
  double worst = 0.0;
  for (int k = 0; k < dense_points; ++k) {
    const long i = (static_cast<long>(k) * (points - 1)) / std::max(1, dense_points - 1);
    worst = std::max(worst, std::abs(modal[static_cast<std::size_t>(i)](0, 0) / dense[static_cast<std::size_t>(k)](0, 0) - 1.0));
  }
  std::printf("%lld free DOF, %d points\n", static_cast<long long>(model.size()), points);
  std::printf("modes (dense generalized eigenproblem): %.2f s\n", t_modes);
  std::printf("modal superposition at %d points: %.3f s (modes + superposition: %.2f s)\n", points, t_modal, t_modes + t_modal);
  std::printf("dense LU at %d points: %.2f s, %.2f s per point, %.0f s for %d points\n", dense_points, t_dense,
              t_dense / dense_points, t_dense / dense_points * points, points);
  std::printf("largest relative difference on those points: %.2e\n", worst);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return piezobench::bench_program::guarded_main("fem_frf_bench", run, argc, argv); }
