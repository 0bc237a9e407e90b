#pragma once
// The metrology module: flatness (per interface too), capacitance (with batch outliers), stroke and
// hysteresis, static stiffness, conformity decisions with uncertainty and the static tests' budgets.
#include "piezobench/metrology/capacitance.hpp"
#include "piezobench/metrology/conformity.hpp"
#include "piezobench/metrology/flatness.hpp"
#include "piezobench/metrology/interface_flatness.hpp"
#include "piezobench/metrology/stiffness.hpp"
#include "piezobench/metrology/stroke.hpp"
#include "piezobench/metrology/uncertainty_budget.hpp"
