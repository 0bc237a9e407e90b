#pragma once
// The apa module: the amplified piezoelectric actuator models (piezo stack constants, the 2-DoF
// model of report section 3 and its tuning to measured FRFs).
#include "piezobench/apa/piezo.hpp"
#include "piezobench/apa/tuning.hpp"
#include "piezobench/apa/two_dof.hpp"
#include "piezobench/apa/two_dof_file.hpp"
