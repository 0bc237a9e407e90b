#pragma once
// The ident module: vector fitting, FRF features (static gain, resonances, anti-resonances,
// non-minimum-phase zeros, high-pass corner, second-order fits), modal parameters (peak picking,
// LSCF with a stabilization diagram).
#include "piezobench/ident/dominant_pole.hpp"
#include "piezobench/ident/features.hpp"
#include "piezobench/ident/modal.hpp"
#include "piezobench/ident/plant_fit.hpp"
#include "piezobench/ident/vector_fitting.hpp"
