#pragma once
// The report document of a campaign (the layout of report/html_report.hpp): the acceptance table
// comes from results.units; the figures are composed here:
//   Frequency responses  u -> d_e and u -> Vs, magnitude, phase and coherence, all units overlaid,
//                        with the tuned 2-DoF model (dashed) and the IFF plant fit (eq. 2.3)
//   Hysteresis           d_e against Va for every amplitude, one figure per unit with loops
//   Static stiffness     d_e against time with the creep fit, all units
//   Stroke               d_e against Va on the slow ramp, all units
//   Integral Force Feedback  root locus of the fitted plant with the controller (eq. 2.4) and the
//                        poles of the measured damped plants; damped-plant FRFs with their fits
//   Flexible modes       hammer FRFs
//   Batch                capacitance, stiffness, flatness and stroke per unit against the limits
//   Super element        its u -> d_e against the measured ones (when given)
#include <nlohmann/json.hpp>
#include <vector>

#include "piezobench/campaign/results.hpp"

namespace piezobench::campaign {

// The report document of a campaign's typed results; its `results` entry is results.json
// (results_json.hpp).
nlohmann::json report_document(const CampaignResult& result);

}  // namespace piezobench::campaign
