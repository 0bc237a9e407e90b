#pragma once
// The campaign module: the campaign file, the analyses of every unit, the batch, the typed results
// and their documents (results.json, report), the demo campaign.
#include "piezobench/campaign/campaign_file.hpp"
#include "piezobench/campaign/demo.hpp"
#include "piezobench/campaign/field_reference.hpp"
#include "piezobench/campaign/field_table.hpp"
#include "piezobench/campaign/pipeline.hpp"
#include "piezobench/campaign/report_document.hpp"
#include "piezobench/campaign/results.hpp"
#include "piezobench/campaign/part.hpp"
#include "piezobench/campaign/results_json.hpp"
#include "piezobench/campaign/superelement_fit.hpp"
#include "piezobench/campaign/superelement_update.hpp"
#include "piezobench/campaign/twin.hpp"
#include "piezobench/campaign/unit_analysis.hpp"
