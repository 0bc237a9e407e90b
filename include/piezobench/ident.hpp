#pragma once
// The ident module: vector fitting, FRF features (static gain, resonances, anti-resonances,
// non-minimum-phase zeros, high-pass corner, second-order fits), modal parameters (peak picking,
// LSCF with a stabilization diagram), Prandtl-Ishlinskii hysteresis and creep (identification, exact inverse),
// the analysis of an actuator's FRFs u -> [d_e, Vs].
#include "piezobench/ident/actuator_frf.hpp"
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/hysteresis.hpp"
#include "piezobench/ident/modal.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/ident/vector_fitting.hpp"
