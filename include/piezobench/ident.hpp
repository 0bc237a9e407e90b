#pragma once
// The ident module: vector fitting, FRF features (static gain, resonances, anti-resonances,
// non-minimum-phase zeros, high-pass corner, second-order fits), modal parameters (peak picking,
// LSCF with a stabilization diagram), Prandtl-Ishlinskii hysteresis and creep (identification, exact inverse),
// the analyses of a measurement: an actuator's FRFs u -> [d_e, Vs], the low-frequency high-pass, an
// IFF damped plant, a hammer test's modes, the added-mass test.
#include "piezobench/ident/actuator_frf.hpp"
#include "piezobench/ident/added_mass.hpp"
#include "piezobench/ident/damped_plant.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/flexible_modes.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/ident/hysteresis_model_choice.hpp"
#include "piezobench/ident/low_frequency_high_pass.hpp"
#include "piezobench/ident/modal.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/ident/vector_fit_uncertainty.hpp"
#include "piezobench/ident/vector_fitting.hpp"
