#pragma once
// The lti module: state space, transfer function and zpk forms; conversions; poles and zeros;
// frequency responses; interconnections; discretization; delays; root locus.
#include "piezobench/lti/analysis.hpp"
#include "piezobench/lti/conversions.hpp"
#include "piezobench/lti/delay.hpp"
#include "piezobench/lti/discretize.hpp"
#include "piezobench/lti/freqresp.hpp"
#include "piezobench/lti/interconnect.hpp"
#include "piezobench/lti/rlocus.hpp"
#include "piezobench/lti/state_space.hpp"
#include "piezobench/lti/transfer_function.hpp"
