#pragma once
// Output files that are either complete or absent: the text is written to a temporary file in the
// target's directory and renamed over the target, so a failure never leaves half a file. The
// implementation is core's (core/file.hpp, shared with fem); io re-exports it.
#include "piezobench/core/file.hpp"

namespace piezobench::io {

using piezobench::write_text_atomically;

}  // namespace piezobench::io
