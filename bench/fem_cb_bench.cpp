// Craig-Bampton speed on a large CalculiX model (issue 4: "about 150,000 DOF with 12 interface DOF
// and 30 modes: under 40 s and 2.5 GB"). One run, as a whole process, so that /usr/bin/time -v
// gives the peak memory of reading the dump plus the reduction:
//
//   scripts/bench/make_cb_mesh.sh /tmp/cb 2            # gmsh + ccx: cb_dump.{sti,mas,dof}, peer timing
//   /usr/bin/time -v build/bench/fem_cb_bench /tmp/cb/cb_dump --modes 30
//
// The interface points are read from cb_interface.txt beside the dump (REF:ROT pairs written by
// the script) unless given with --interface. When cb_ref_modes.txt (ccx's *FREQUENCY with both
// remote points clamped: the same fixed-interface eigenproblem) is there, the program prints the
// largest relative difference of the fixed-interface frequencies.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "piezobench/core/error.hpp"
#include "program_main.hpp"
#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/matrix_io.hpp"

namespace {

namespace fs = std::filesystem;
using namespace piezobench;

using bench_program::seconds_since;

// Processor time of the process (all threads), s: on a shared machine it says more than wall time.
double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Resident memory now and its peak so far, MB (Linux /proc/self/status VmRSS, VmHWM; 0 elsewhere):
// printed at each stage, they say where the peak memory goes.
std::pair<double, double> memory_mb() {
  std::ifstream in("/proc/self/status");
  double rss = 0.0, hwm = 0.0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) rss = std::atof(line.c_str() + 6) / 1024.0;
    if (line.rfind("VmHWM:", 0) == 0) hwm = std::atof(line.c_str() + 6) / 1024.0;
  }
  return {rss, hwm};
}

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: fem_cb_bench DUMP_STEM [--modes N] [--interface REF:ROT,REF:ROT...]\n");
    return 2;
  }
  const fs::path stem = argv[1];
  int modes = 30;
  std::string interface_text;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--modes") {
      modes = std::atoi(argv[i + 1]);
    } else if (key == "--interface") {
      interface_text = argv[i + 1];
    } else {
      std::fprintf(stderr, "fem_cb_bench: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (interface_text.empty()) {
    std::ifstream in(stem.parent_path() / "cb_interface.txt");
    std::getline(in, interface_text);
  }
  std::vector<fem::InterfacePoint> interface;
  std::istringstream words(interface_text);
  for (std::string w; words >> w;) {
    for (std::size_t start = 0; start <= w.size();) {
      const std::size_t comma = std::min(w.find(',', start), w.size());
      if (comma > start) interface.push_back(fem::InterfacePoint::parse(w.substr(start, comma - start), "--interface"));
      start = comma + 1;
    }
  }

  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_seconds();
  fem::SparseModel model = fem::read_calculix_model(fs::path(stem.string() + ".sti"), fs::path(stem.string() + ".mas"),
                                                          fs::path(stem.string() + ".dof"));
  const double t_read = seconds_since(t0);
  const double c_read = cpu_seconds() - c0;
  std::printf("read: %lld DOF, K %lld nonzeros, M %lld nonzeros, %.2f s (CPU %.2f s), memory %.0f MB (peak %.0f MB)\n",
              static_cast<long long>(model.size()), static_cast<long long>(model.K.nonZeros()),
              static_cast<long long>(model.M.nonZeros()), t_read, c_read, memory_mb().first, memory_mb().second);

  fem::CraigBamptonOptions o;
  o.modes = modes;
  std::string last;
  const auto t1 = std::chrono::steady_clock::now();
  const double c1 = cpu_seconds();
  o.progress = [&](const std::string& step, double) {
    if (step.rfind("fixed-interface modes (", 0) == 0 || step == last) return;
    last = step;
    const auto [rss, hwm] = memory_mb();
    std::fprintf(stderr, "  %7.2f s (CPU %7.2f s)  memory %6.0f MB (peak %6.0f MB)  %s\n", seconds_since(t1), cpu_seconds() - c1, rss,
                 hwm, step.c_str());
  };
  const fem::CraigBamptonResult r = fem::craig_bampton(std::move(model), interface, o);
  const double t_cb = seconds_since(t1);
  const double c_cb = cpu_seconds() - c1;
  std::printf("craig_bampton: %lld interface DOF, %lld interior DOF, %d modes, %.2f s (CPU %.2f s; factor %lld entries, %lld "
              "Lanczos restarts, %lld solves)\n",
              static_cast<long long>(r.interface_dofs), static_cast<long long>(r.interior_dofs), modes, t_cb, c_cb,
              static_cast<long long>(r.factor_nonzeros), static_cast<long long>(r.eigensolver_iterations),
              static_cast<long long>(r.eigensolver_operations));
  std::printf("fixed-interface modes (Hz):");
  for (Eigen::Index i = 0; i < r.fixed_interface_Hz.size(); ++i) std::printf(" %.6g", r.fixed_interface_Hz(i));
  std::printf("\n");
  std::ifstream ref_in(stem.parent_path() / "cb_ref_modes.txt");
  std::vector<double> ref;
  for (double f = 0; ref_in >> f;) ref.push_back(f);
  if (!ref.empty()) {
    double worst = 0.0;
    const std::size_t n = std::min<std::size_t>(ref.size(), static_cast<std::size_t>(r.fixed_interface_Hz.size()));
    for (std::size_t i = 0; i < n; ++i) {
      worst = std::max(worst, std::abs(r.fixed_interface_Hz(static_cast<Eigen::Index>(i)) / ref[i] - 1.0));
    }
    std::printf("against ccx *FREQUENCY (%zu modes): largest relative difference %.2e\n", n, worst);
  }
  std::printf("total (read + reduction): %.2f s (CPU %.2f s)\n", t_read + t_cb, c_read + c_cb);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return piezobench::bench_program::guarded_main("fem_cb_bench", run, argc, argv); }
