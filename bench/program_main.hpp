#pragma once
// What the stand-alone benchmark programs (fem_cb_bench, fem_frf_bench) share: wall-clock timing
// and a main() that reports an error on stderr and exits with its code (core/error.hpp).
#include <chrono>
#include <cstdio>
#include <exception>

#include "piezobench/core/error.hpp"

namespace piezobench::bench_program {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Returns run(argc, argv); a piezobench::Error exits with its code, any other exception with 1.
inline int guarded_main(const char* program, int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return static_cast<int>(e.exit_code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 1;
  }
}

}  // namespace piezobench::bench_program
