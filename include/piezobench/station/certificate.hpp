#pragma once
// What the station database shows (docs/station.md, "Certificates and control charts"):
//   - a unit's certificate: one printable, offline HTML page with the verdict and the deciding
//     phase and measurement, every phase try with its measurements, limits and verdicts, a gauge
//     per limited measurement, and the provenance (software version, station and bench files with
//     their SHA-256, every raw file with its SHA-256). Made only from the database's rows, so the
//     same records give the same bytes: `db certificate` regenerates the one `qualify` wrote, and
//     its SHA-256 is stored with the qualification.
//   - control charts across units and batches: per quantity (stroke, stiffness, capacitances,
//     resonance, anti-resonance, hysteresis width) the value of every unit's latest complete
//     qualification in qualification order, the spec limits, the batch's mean and mean +- 3 sigma,
//     and the number of marginal and failed units.
#include <optional>
#include <string>
#include <vector>

#include "piezobench/station/record_store.hpp"

namespace piezobench::station {

std::string certificate_html(const QualificationRow& q, const std::vector<PhaseTryRow>& tries);

struct ControlChart {
  std::string quantity, unit;
  std::vector<HistoryPoint> points;      // in qualification order
  std::optional<double> min, max;        // the spec limits (the newest point's)
  double mean = 0.0, sigma = 0.0;        // of the values (sigma: sample standard deviation)
  int marginal = 0, failed = 0;
};

// The quantities charted by default.
const std::vector<std::string>& control_chart_quantities();
std::vector<ControlChart> control_charts(const RecordStore& store, const std::string& batch,
                                         const std::vector<std::string>& quantities = control_chart_quantities());
// One offline HTML page with an SVG chart per quantity.
std::string control_charts_html(const std::vector<ControlChart>& charts, const std::string& title);

}  // namespace piezobench::station
