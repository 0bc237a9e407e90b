#pragma once
// The fem module: super elements (reading, Craig-Bampton reduction), structural models and their
// frequency responses, the STEP-to-super-element pipeline (beams for the stacks, the setup shared by
// the CLI, the bench and the campaign).
#include "piezobench/fem/beam.hpp"
#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/from_step.hpp"
#include "piezobench/fem/matrix_io.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/fem/superelement_setup.hpp"
