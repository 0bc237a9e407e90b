#pragma once
// The report module: the self-contained HTML report.
#include "piezobench/report/html_report.hpp"
#include "piezobench/report/embedded_assets.hpp"
