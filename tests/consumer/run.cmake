# The consumer test (ctest install_and_consume): installs the build tree into WORK_DIR/prefix,
# checks that every public header is in its module's umbrella header, then configures, builds and
# runs tests/consumer against the installed package.
#   cmake -D BUILD_DIR=... -D SOURCE_DIR=... -D WORK_DIR=... -D GENERATOR=... -D CXX=... -P run.cmake
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    string(JOIN " " cmd ${ARGN})
    message(FATAL_ERROR "consumer: '${cmd}' failed (${rc}):\n${out}\n${err}")
  endif()
  message("${out}")
endfunction()

# Umbrella headers: piezobench/<module>.hpp includes every header of include/piezobench/<module>/.
file(GLOB modules LIST_DIRECTORIES true "${SOURCE_DIR}/include/piezobench/*")
foreach(dir IN LISTS modules)
  if(NOT IS_DIRECTORY "${dir}")
    continue()
  endif()
  get_filename_component(module "${dir}" NAME)
  set(umbrella "${SOURCE_DIR}/include/piezobench/${module}.hpp")
  if(NOT EXISTS "${umbrella}")
    message(FATAL_ERROR "consumer: no umbrella header include/piezobench/${module}.hpp")
  endif()
  file(READ "${umbrella}" text)
  file(GLOB headers RELATIVE "${dir}" "${dir}/*.hpp")
  foreach(h IN LISTS headers)
    string(FIND "${text}" "\"piezobench/${module}/${h}\"" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "consumer: include/piezobench/${module}.hpp does not include piezobench/${module}/${h}")
    endif()
  endforeach()
endforeach()

file(REMOVE_RECURSE "${WORK_DIR}")
run("${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/build" -G "${GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${CXX}" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix")
run("${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer")
