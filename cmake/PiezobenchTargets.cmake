# Shared compile settings and the helpers that declare modules, tests and benchmarks.

add_library(piezobench_options INTERFACE)
add_library(piezobench::options ALIAS piezobench_options)
target_compile_features(piezobench_options INTERFACE cxx_std_20)
target_compile_options(piezobench_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Wunused
  -Woverloaded-virtual -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough
  $<$<BOOL:${PIEZOBENCH_WERROR}>:-Werror>)
if(PIEZOBENCH_SANITIZE)
  # AddressSanitizer and UndefinedBehaviorSanitizer, no recovery. Four UBSan checks are left out
  # because on Eigen-heavy code they nearly triple the compile time (126 s -> 47 s for
  # src/lti/spectral.cpp at -O1 -g1) and the other tools already cover them: a null dereference
  # is a SEGV that ASan reports with its stack; `alignment` and `object-size` overlap ASan's
  # bounds checks; `vptr` needs RTTI checks on every polymorphic access and we have few virtuals.
  # GCC's `undefined` group leaves out checks that clang's has: `float-cast-overflow` (a double
  # out of an integer's range, or NaN, converted to it: a campaign `id = 92233720368547758e07`,
  # issue 35) is added. `float-divide-by-zero` stays off: IEEE 754 defines x / 0.0 (+-inf, NaN)
  # and the numerical code relies on it, checking the result with std::isfinite. `bounds-strict`
  # (trailing arrays too) is not on yet: no sanitizer run of the suite with it so far.
  set(_pb_sanitize -fsanitize=address,undefined,float-cast-overflow
      -fno-sanitize=alignment,null,vptr,object-size -fno-sanitize-recover=all)
  target_compile_options(piezobench_options INTERFACE ${_pb_sanitize} -fno-omit-frame-pointer)
  target_link_options(piezobench_options INTERFACE ${_pb_sanitize})
endif()

if(PIEZOBENCH_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "PIEZOBENCH_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++-14")
  endif()
  # The modules that hold a reader the fuzz targets drive (fuzz/: the files, TOML documents,
  # datagrams and HTTP requests piezobench parses, and what each target runs on the result) are
  # instrumented for libFuzzer's coverage (fuzzer-no-link: counters and comparison hooks; without
  # libFuzzer linked, the sanitizer runtime's empty hooks take them), on top of the sanitizers above;
  # only the fuzz targets link libFuzzer (fuzz/). The numerical modules below them (core, dsp, lti,
  # ident, control, plant, metrology, report), the app and the test programs are not: the same tree
  # runs the test suite (scripts/setup.sh test --sanitize), and the hooks on every comparison of the
  # numerical loops made its tests 1.5-1.9 times as long (docs/performance.md, "Build time"). clang's
  # `undefined` group already holds float-cast-overflow; it has no bounds-strict.
  set(PIEZOBENCH_FUZZ_COVERAGE_MODULES io fem apa bench campaign rt station web)
endif()

# Build time (docs/performance.md, "Build time"): CI builds everything cold, twice. Each module,
# test program, the app and the Python module compile their sources in unity batches (one compiler
# run parses Eigen, GoogleTest and the project headers once for several files and instantiates
# their templates once), and the test programs share one precompiled header of the third-party
# headers they all include. -DPIEZOBENCH_UNITY_BUILD=OFF -DPIEZOBENCH_PCH=OFF compile every file
# alone (to check that a file includes what it uses).
option(PIEZOBENCH_UNITY_BUILD "Compile the sources of each target in unity batches" ON)
# ccache caches no compile that uses a precompiled header unless it is configured for them
# (sloppiness pch_defines,time_macros): with ccache as the compiler launcher the default is OFF.
if(CMAKE_CXX_COMPILER_LAUNCHER MATCHES "ccache")
  set(_pb_pch_default OFF)
else()
  set(_pb_pch_default ON)
endif()
option(PIEZOBENCH_PCH "Precompile the third-party headers of the test programs once" ${_pb_pch_default})
# Batch size: a cold build (CI) spends most of its time parsing Eigen and instantiating the same
# templates in each batch, so big batches cost less CPU: lti_tests + campaign_tests and what they
# link, cold, built side by side, 534 s of CPU with 4 files a batch, 456 s with 16; 64 cost the
# same as 16 and leave fewer jobs to run in parallel (docs/performance.md, "Build time").
# With ccache (a developer's tree) a small batch recompiles less after an edit.
if(CMAKE_CXX_COMPILER_LAUNCHER MATCHES "ccache")
  set(_pb_unity_batch_default 4)
else()
  set(_pb_unity_batch_default 16)
endif()
set(PIEZOBENCH_UNITY_BATCH_SIZE ${_pb_unity_batch_default} CACHE STRING "Source files per unity batch")

# The test programs' own code compiles at -O1 in a Release tree; the modules they test keep -O3.
# A test file is GoogleTest macros and Eigen expressions instantiated once, where -O3's inlining and
# vectorization cost compile time and buy nothing: tests/lti's unity batch (11 files) took 58.5 s
# of CPU at -O3 and 40.4 s at -O1 (-31 %; docs/performance.md, "Build time"). GCC does not change
# a floating-point result between the two (no -ffast-math, no FMA in the baseline x86-64 ISA).
# The sanitizer tree (RelWithDebInfo, -O1 -g1) is left as it is.
set(PIEZOBENCH_TEST_COMPILE_OPTIONS "$<$<CONFIG:Release>:-O1>")

# piezobench_unity_build(<target>)
function(piezobench_unity_build target)
  if(PIEZOBENCH_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${PIEZOBENCH_UNITY_BATCH_SIZE})
  endif()
endfunction()

# piezobench_module(<name> LAYER <n> [DEPS <modules...>] [DIR <folder>] [WRAPS <headers...>])
# One row of the module map (cmake/PiezobenchModules.cmake, which says what each argument means;
# DIR and WRAPS are for scripts/check_module_deps.py).
function(piezobench_module name)
  cmake_parse_arguments(ARG "" "LAYER;DIR" "DEPS;WRAPS" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS OR NOT DEFINED ARG_LAYER)
    message(FATAL_ERROR "piezobench_module(${name}): expected LAYER <n> [DEPS <modules...>] [DIR <folder>] [WRAPS <headers...>]")
  endif()
  foreach(dep IN LISTS ARG_DEPS)
    get_property(dep_layer GLOBAL PROPERTY PIEZOBENCH_LAYER_${dep})
    if(dep_layer STREQUAL "")
      message(FATAL_ERROR "piezobench_module(${name}): ${dep} is not declared above it")
    endif()
    if(NOT dep_layer LESS ARG_LAYER)
      message(FATAL_ERROR "piezobench_module(${name}) at layer ${ARG_LAYER} uses ${dep} at layer ${dep_layer}: a module uses lower layers only")
    endif()
  endforeach()
  set_property(GLOBAL PROPERTY PIEZOBENCH_LAYER_${name} ${ARG_LAYER})
  set_property(GLOBAL PROPERTY PIEZOBENCH_DEPS_${name} ${ARG_DEPS})
  set_property(GLOBAL PROPERTY PIEZOBENCH_DECLARED_${name} TRUE)
endfunction()

# piezobench_add_module(NAME <name> SOURCES <files...> [DEPS <third-party targets...>])
# Declares the library piezobench_<name> with the alias piezobench::<name>. Its public headers live
# in include/piezobench/<name>/; its sources and private headers in src/<name>/ (its folder in the
# module map), which only this module sees. It links the piezobench modules the map
# (cmake/PiezobenchModules.cmake) lists for it; DEPS names third-party libraries only.
function(piezobench_add_module)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPS" ${ARGN})
  get_property(declared GLOBAL PROPERTY PIEZOBENCH_DECLARED_${ARG_NAME})
  if(NOT declared)
    message(FATAL_ERROR "module ${ARG_NAME} is not in the module map (cmake/PiezobenchModules.cmake)")
  endif()
  foreach(dep IN LISTS ARG_DEPS)
    if(dep MATCHES "^piezobench::")
      message(FATAL_ERROR "module ${ARG_NAME}: ${dep} in DEPS; the module map (cmake/PiezobenchModules.cmake) lists the modules it uses")
    endif()
  endforeach()
  get_property(module_deps GLOBAL PROPERTY PIEZOBENCH_DEPS_${ARG_NAME})
  list(TRANSFORM module_deps PREPEND "piezobench::")
  set(target piezobench_${ARG_NAME})
  add_library(${target} STATIC ${ARG_SOURCES})
  add_library(piezobench::${ARG_NAME} ALIAS ${target})
  target_include_directories(${target}
    PUBLIC "$<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>" "$<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>"
           "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>"
    PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}")
  # The warnings and sanitizer flags are for this build only; an installed module asks for C++20.
  target_link_libraries(${target} PUBLIC "$<BUILD_INTERFACE:piezobench::options>" ${module_deps} ${ARG_DEPS})
  target_compile_features(${target} PUBLIC cxx_std_20)
  if(PIEZOBENCH_FUZZ AND ARG_NAME IN_LIST PIEZOBENCH_FUZZ_COVERAGE_MODULES)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON EXPORT_NAME ${ARG_NAME})
  piezobench_unity_build(${target})
  set_property(GLOBAL APPEND PROPERTY PIEZOBENCH_MODULES ${target})
  install(TARGETS ${target} EXPORT piezobenchTargets ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}")
endfunction()

# piezobench_install_package()
# After every module is declared: piezobench::piezobench (all modules), the headers, the version
# header, and the CMake package (find_package(piezobench) in lib/cmake/piezobench).
function(piezobench_install_package)
  get_property(modules GLOBAL PROPERTY PIEZOBENCH_MODULES)
  add_library(piezobench_library INTERFACE)
  add_library(piezobench::piezobench ALIAS piezobench_library)
  target_link_libraries(piezobench_library INTERFACE ${modules})
  set_target_properties(piezobench_library PROPERTIES EXPORT_NAME piezobench)
  install(TARGETS piezobench_library EXPORT piezobenchTargets)
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
  install(FILES "${PROJECT_BINARY_DIR}/generated/piezobench/version.hpp" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/piezobench")
  set(config_dir "${CMAKE_INSTALL_LIBDIR}/cmake/piezobench")
  install(EXPORT piezobenchTargets NAMESPACE piezobench:: DESTINATION "${config_dir}")
  include(CMakePackageConfigHelpers)
  configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/piezobenchConfig.cmake.in"
    "${PROJECT_BINARY_DIR}/piezobenchConfig.cmake" INSTALL_DESTINATION "${config_dir}")
  write_basic_package_version_file("${PROJECT_BINARY_DIR}/piezobenchConfigVersion.cmake" COMPATIBILITY SameMinorVersion)
  install(FILES "${PROJECT_BINARY_DIR}/piezobenchConfig.cmake" "${PROJECT_BINARY_DIR}/piezobenchConfigVersion.cmake"
                "${PROJECT_SOURCE_DIR}/cmake/FindFFTW3.cmake"
          DESTINATION "${config_dir}")
endfunction()

# piezobench_add_test(NAME <name> SOURCES <files...> DEPS <targets...>)
# One GoogleTest executable per module; each TEST becomes a CTest test. The tests of tests/<module>/
# see that module's private headers (src/<module>/) and no other module's.
function(piezobench_add_test)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  get_filename_component(tested_module "${CMAKE_CURRENT_SOURCE_DIR}" NAME)
  target_include_directories(${ARG_NAME} PRIVATE "${PROJECT_SOURCE_DIR}/tests")
  if(IS_DIRECTORY "${PROJECT_SOURCE_DIR}/src/${tested_module}")
    target_include_directories(${ARG_NAME} PRIVATE "${PROJECT_SOURCE_DIR}/src/${tested_module}")
  endif()
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} piezobench::testutil GTest::gtest GTest::gmock GTest::gtest_main)
  target_compile_definitions(${ARG_NAME} PRIVATE
    PIEZOBENCH_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    PIEZOBENCH_FIXTURE_DIR="${PROJECT_SOURCE_DIR}/tests/fixtures"
    PIEZOBENCH_SHARED_DATA_DIR="${PIEZOBENCH_SHARED_DATA_DIR}"
    PIEZOBENCH_BINARY="$<TARGET_FILE:piezobench>")
  target_compile_options(${ARG_NAME} PRIVATE ${PIEZOBENCH_TEST_COMPILE_OPTIONS})
  piezobench_unity_build(${ARG_NAME})
  if(TARGET piezobench_test_pch)
    target_precompile_headers(${ARG_NAME} REUSE_FROM piezobench_test_pch)
  endif()
  gtest_discover_tests(${ARG_NAME} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
