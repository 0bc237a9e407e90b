#pragma once
// The metrology module: flatness, capacitance (with batch outliers), stroke and hysteresis, static
// stiffness.
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/flatness.hpp"
#include "piezobench/metrology/stiffness.hpp"
#include "piezobench/metrology/stroke.hpp"
