#pragma once
// The rt module: the real-time IFF loop (backends, safety, logger, timing) and the damped-plant study.
#include "piezobench/rt/backend.hpp"
#include "piezobench/rt/damped_plant_study.hpp"
#include "piezobench/rt/logger.hpp"
#include "piezobench/rt/loop.hpp"
#include "piezobench/rt/replay_backend.hpp"
#include "piezobench/rt/safety.hpp"
#include "piezobench/rt/spsc_ring.hpp"
#include "piezobench/rt/timing.hpp"
#include "piezobench/rt/virtual_backend.hpp"
