#pragma once
// results.json (CLI.md keys) from the typed results of a campaign (results.hpp). The same document
// is written as results.mat (io/mat_struct.hpp) and printed by `run --json` / `demo --json`, and
// the report's acceptance table shows it. Values are in the units their keys name (_um, _uF,
// _N_per_um, _Hz, ...); absent analyses are null.
#include <nlohmann/json.hpp>

#include "piezobench/campaign/results.hpp"

namespace piezobench::campaign {

// One unit's entry of results.json (with `accepted` and `reasons`).
nlohmann::json unit_json(const UnitAnalysis& unit);

// The whole results.json document.
nlohmann::json results_json(const CampaignResult& result);

}  // namespace piezobench::campaign
