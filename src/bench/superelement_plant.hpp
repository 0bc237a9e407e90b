#pragma once
// A super element as the actuator of the virtual bench (BenchOptions::superelement): the TOML
// description (keys in virtual_bench.hpp), the constrained and guided structural model, and its
// continuous bench plant (same inputs and outputs as plant.hpp) reduced to the modes below
// max_mode_Hz with a static correction for the others, so its static response is exact.
#include <filesystem>
#include <string>
#include <vector>

#include "plant.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/fem/superelement_setup.hpp"

namespace piezobench::bench::detail {

// The bench's super element: the set-up (fixed nodes; forces [actuator pair]; outputs [the moving
// interface (absolute), the sensor stack (relative)]) and the bench's constants.
struct SuperElementBench {
  std::filesystem::path file;      // the TOML file
  fem::SuperElementSetup setup;
  double ga = 23.2;                // N/V
  double gs = 4.9e6;               // V/m
  double modal_damping = 0.01;
  double max_mode_Hz = 20000.0;
  bool guided = true;
  [[nodiscard]] const fem::ForcePair& actuator() const { return setup.model.forces.at(0); }
  [[nodiscard]] const fem::DisplacementOutput& output() const { return setup.model.outputs.at(0); }
  [[nodiscard]] const fem::DisplacementOutput& sensor() const { return setup.model.outputs.at(1); }
};

// Reads and checks the TOML (InputError naming the file and the key). Does not read the matrices.
SuperElementBench read_superelement_spec(const std::filesystem::path& file);

struct SuperElementMechanics {
  SuperElementBench spec;
  fem::SuperElement se;
};
// Reads the TOML and the super element it names; checks the nodes against the element.
SuperElementMechanics load_superelement(const std::filesystem::path& file);

// The structural model on the bench: fixed nodes clamped, `moving_mass` (kg) on the output node,
// that node guided along the output direction when spec.guided; inputs [actuator pair, force on the
// output node along its direction], outputs [d_e, sensor extension].
fem::StructuralModel bench_structure(const SuperElementMechanics& mech, double moving_mass);

struct SuperElementPlantInfo {
  int kept_modes = 0;
  int total_modes = 0;
  double first_mode_Hz = 0.0;
  double last_kept_mode_Hz = 0.0;
};
// The continuous bench plant (states Va, modal displacements, modal velocities, high-pass state).
// ga is spec.ga * ga_factor (the unit's stroke factor). Vs = gs e_s through the first-order
// high-pass 1/(R C_sensor) (no electromechanical coupling: the super element's stacks are taken at
// their short-circuit stiffness), plus the parasitic term of electrics.ground_resistance.
ContinuousPlant superelement_plant(const SuperElementMechanics& mech, double moving_mass, double ga_factor,
                                   const Electrics& electrics, SuperElementPlantInfo* info = nullptr);

}  // namespace piezobench::bench::detail
