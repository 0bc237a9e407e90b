#pragma once
// The plant module: the report's model of the plant the IFF loop sees (eq. 2.3), below ident and control.
#include "piezobench/plant/iff_plant.hpp"
