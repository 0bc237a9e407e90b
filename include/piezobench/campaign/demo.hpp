#pragma once
// The demo campaign (`piezobench demo`): the report's batch of seven APA300ML simulated on the
// virtual bench (bench/virtual_bench.hpp; unit 3 defective as in the report), written as
// measurement files in the bench's format, with the campaign file that describes them and the
// bench's true values for comparison:
//
//   DIR/data/unitN_<experiment>.mat   flatness, capacitance, stroke, stiffness, frf-noise, hammer,
//                                     hysteresis_<A>V (one per amplitude), and for the IFF unit
//                                     iff_g<G> (one per gain), and for the tracking unit tracking
//                                     (bench/tracking.hpp, the feedforward being the PI model of
//                                     its largest hysteresis record, as the campaign identifies it)
//   DIR/data/truth.json               {seed, units: [bench::truth_json of every unit]}
//   DIR/superelement/                 the APA300ML super element shipped in the binary (docs/apa300ml.md):
//                                     apa300ml_K.mtx, apa300ml_M.mtx, apa300ml_dofs.txt, apa300ml.toml
//   DIR/campaign.toml                 the campaign (specs chosen from the datasheet and the report),
//                                     with a [superelement] table for report section 4
//
// Experiments are simulated in parallel (a pool over (unit, experiment) jobs). `fast` shortens the
// noise records (FRF 8 s instead of 20 s, IFF 4 s instead of 10 s) for tests.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "piezobench/campaign/unit_analysis.hpp"
#include "piezobench/core/fields.hpp"

namespace piezobench::campaign {

struct DemoOptions {
  std::uint64_t seed = 1;
  bool fast = false;
  std::vector<int> units = {1, 2, 3, 4, 5, 6, 7};
  std::vector<double> hysteresis_amplitudes = {4.0, 20.0, 40.0, 80.0};  // V around 65 V
  std::vector<double> iff_gains = {30e3, 60e3, 120e3, 240e3};            // controller gains g (optimum ~2.7e5)
  int iff_unit = 1;                                                      // the unit with IFF records
  int tracking_unit = 1;                                                 // the unit with a tracking record (0: none)
  int threads = 0;                                                       // 0 = all cores
  Log log;                                                               // progress (under a lock)
  void validate() const;                                                 // InputError (source "demo")
};

struct DemoFiles {
  std::filesystem::path campaign;  // DIR/campaign.toml
  std::filesystem::path truth;     // DIR/data/truth.json
  std::filesystem::path superelement;  // DIR/superelement/apa300ml.toml (with its K, M and DOF list)
  std::vector<std::filesystem::path> data;
};

constexpr auto describe(core::Type<DemoFiles>) {
  using S = DemoFiles;
  using namespace core::shown;
  return core::fields<S>("DemoFiles", "the files write_demo_campaign wrote (paths; Python: str)",
      core::field("campaign", &S::campaign, kNone, "DIR/campaign.toml"),
      core::field("truth", &S::truth, kNone, "DIR/data/truth.json"),
      core::field("superelement", &S::superelement, kNone, "DIR/superelement/apa300ml.toml (with its K, M and DOF list)"),
      core::field("data", &S::data, kNone, "the data files, one per record"));
}

// Simulates and writes everything under `dir` (created). InputError when a file cannot be written.
DemoFiles write_demo_campaign(const std::filesystem::path& dir, const DemoOptions& options = {});

}  // namespace piezobench::campaign
