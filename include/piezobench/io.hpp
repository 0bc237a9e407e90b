#pragma once
// The io module: time series and FRF files (.mat, CSV, UFF), JSON encodings, TOML models (LTI,
// hysteresis) the one TOML parser with limits and its typed reader, atomic writes and staged result folders.
#include "piezobench/io/atomic_file.hpp"
#include "piezobench/io/frf_file.hpp"
#include "piezobench/io/hysteresis_toml.hpp"
#include "piezobench/io/fields_json.hpp"
#include "piezobench/io/json.hpp"
#include "piezobench/io/lti_toml.hpp"
#include "piezobench/io/mat_struct.hpp"
#include "piezobench/io/output_dir.hpp"
#include "piezobench/io/timeseries.hpp"
#include "piezobench/io/toml_describe.hpp"
#include "piezobench/io/toml_reader.hpp"
#include "piezobench/io/toml_table.hpp"
#include "piezobench/io/units.hpp"
