#pragma once
// The campaign pipeline (`piezobench run`): every unit analysed (unit_analysis.hpp) on a pool of
// threads, then the batch: outliers and spread of the key figures, unit-to-unit similarity of the
// FRFs, the acceptance of every unit with the reason for each rejection, the IFF study (root locus
// of the fitted plant with the report's controller against the poles of the measured damped
// plants, optimal gain) and the super-element comparison when the campaign gives one.
//
// Acceptance rules (a limit the campaign does not set is not checked; an experiment that is not
// measured is reported as such and is no reason to reject):
//   flatness (spec method) <= flatness_um; capacitance of the sensor and of the actuator stacks
//   inside their ranges; stroke >= stroke_min_um; k1, k2 and the resonance stiffness inside
//   stiffness_N_per_um; each of these a check of value +- U (GUM budget, k = 2) against its limits
//   with a verdict pass / marginal / fail (ISO 14253-1, metrology/conformity.hpp; docs/uncertainty.md
//   section 7); with reject_outliers, no batch outlier in capacitance or stroke (robust z-score,
//   metrology/capacitance.hpp); every analysis that was run succeeded. Accepted: every check passes;
//   marginal: none fails, one is marginal; rejected otherwise. A unit that could not be analysed is
//   neither accepted nor rejected (CampaignResult::not_analysed).
//
// Outputs (write_outputs): OUT/results.mat, OUT/report.html and OUT/results.json, staged in a hidden
// folder inside OUT and renamed into place only when all three are written, results.json last, so
// results.json exists only when the run completed and a failed write leaves OUT as it was. Only these
// fixed names (and the staging folder and the .piezobench.lock of `run`, removed when the run ends) under OUT are written.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/results.hpp"
#include "piezobench/campaign/unit_analysis.hpp"

namespace piezobench::campaign {

struct PipelineOptions {
  int threads = 0;  // > 0 overrides analysis.threads
  Log log;          // progress lines (called under a lock; may be empty)
};

// Analyses every unit and the batch: finish_campaign(analyze_units(every unit)). A unit whose data
// cannot be analysed (a file missing or unreadable, bad data: analyze_unit) is reported as not
// analysed with its file and reason, neither accepted nor rejected, and left out of the batch: the
// other units' results are those of the campaign without it. A NumericalError inside an analysis is
// recorded in the unit's `failed` (the unit is then rejected), not thrown.
CampaignResult run_campaign(const Campaign& campaign, const PipelineOptions& options = {});

// The per-unit half: the units at `indices` into campaign.units, in that order, on a pool of
// threads (a part of a campaign split over machines, part.hpp). Errors as run_campaign.
std::vector<UnitAnalysis> analyze_units(const Campaign& campaign, const std::vector<std::size_t>& indices,
                                        const PipelineOptions& options = {});

// The batch half: acceptance, outliers and spread, similarity, the IFF study and the super element
// over `units` (every unit of the campaign, in its order; `merge` passes the parts' units).
CampaignResult finish_campaign(const Campaign& campaign, std::vector<UnitAnalysis> units, const PipelineOptions& options = {});

// Writes results.mat, report.html and results.json (results_json.hpp, report_document.hpp) into
// `out_dir` (created if needed); returns
// the paths written. InputError when a file cannot be written.
// All or nothing: the files are staged in a hidden folder inside out_dir and renamed into place
// only when all three are written (io/output_dir.hpp).
std::vector<std::filesystem::path> write_outputs(const CampaignResult& result, const std::filesystem::path& out_dir);

// Removes the result set of an earlier run from out_dir (a run that then fails leaves none).
void remove_outputs(const std::filesystem::path& out_dir);

}  // namespace piezobench::campaign
