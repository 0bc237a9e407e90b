#pragma once
// The station module (`piezobench qualify`, `db`; docs/station.md): the station and answers files,
// the measurements and their verdicts, the SQLite record store, the phase runner, certificates and
// control charts.
#include "piezobench/station/answers.hpp"
#include "piezobench/station/certificate.hpp"
#include "piezobench/station/measurements.hpp"
#include "piezobench/station/phase_runner.hpp"
#include "piezobench/station/record_json.hpp"
#include "piezobench/station/record_store.hpp"
#include "piezobench/station/station_file.hpp"
