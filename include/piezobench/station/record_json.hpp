#pragma once
// The station database's rows as JSON: the documents of `db list --json`, `db show --json` and the
// station page's /api endpoints (docs/station.md), one layout for all of them.
#include <nlohmann/json.hpp>
#include <vector>

#include "piezobench/station/certificate.hpp"
#include "piezobench/station/record_store.hpp"

namespace piezobench::station {

nlohmann::json measurements_json(const std::vector<MeasurementRow>& rows);
// A qualification with its tries (pass {} for the list's summary).
nlohmann::json qualification_json(const QualificationRow& q, const std::vector<PhaseTryRow>& tries);
// Control charts: quantity, unit, limits, mean, sigma, counts, points (serial, batch, value, verdict).
nlohmann::json control_charts_json(const std::vector<ControlChart>& charts);

}  // namespace piezobench::station
