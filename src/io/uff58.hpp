#pragma once
// The time histories of a Universal File Format dataset 58 file (uff58.cpp), for the time-series
// reader (timeseries.cpp), which checks and converts them like any other record.
#include <Eigen/Dense>
#include <filesystem>
#include <string>
#include <vector>

#include "piezobench/dsp/frf.hpp"

namespace piezobench::io::detail {

// An FRF as a file stores it: H in the units the file states, one unit text per output ("um/V",
// "(m/s^2)/(N)"; "" = none stated). frf_file.cpp converts it (read_frf_file).
struct StatedFrf {
  dsp::Frf frf;
  std::vector<std::string> units;
};
[[nodiscard]] StatedFrf read_uff58_frf(const std::filesystem::path& file);

struct UffTimeHistories {
  std::vector<std::string> names;  // one per record, unique (docs/formats.md, "UFF58 time histories")
  std::vector<std::string> units;  // record 9 units label per record ("" = NONE; an accelerometer's g is m/s^2 already)
  Eigen::MatrixXd data;            // samples x records, as stored (g converted to m/s^2)
  double increment_s = 0.0;        // evenly spaced records: the abscissa increment (s); 0 when uneven
  Eigen::VectorXd t;               // unevenly spaced records: the abscissa values (s); else empty
  double time_scale = 1.0;         // s per abscissa unit as stored (ms: 1e-3)
};

// Every dataset 58 of function type 1 (time response) or abscissa type 17 (time) of the file, ASCII
// or binary 58b; other datasets (FRFs, geometry, units) are skipped. The records must share their
// number of values and abscissa (InputError naming the dataset and record otherwise), hold real
// values, and there must be one at least.
[[nodiscard]] UffTimeHistories read_uff58_time_histories(const std::filesystem::path& file);

}  // namespace piezobench::io::detail
