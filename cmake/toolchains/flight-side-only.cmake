# Project include for flight-side cross builds (aarch64 preset: CMAKE_PROJECT_INCLUDE).
# Skips the test folders that cannot be built there:
#   - tests/<x> for which ground/<x> exists (ground-equipment tests) when ROCKSTEADY_BUILD_GROUND=OFF;
#   - tests/fuzz (libFuzzer binaries built with the host's clang++) and bench/ (host timing
#     benchmarks, Google Benchmark) when cross-compiling.
# Everything else (gnc, hal, fsw, lcmtypes and their tests) is added as usual. Interim: drop this file
# once tests/CMakeLists.txt and the top level skip those folders themselves.
macro(add_subdirectory _rs_dir)
  get_filename_component(_rs_abs "${_rs_dir}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(_rs_parent "${_rs_abs}" DIRECTORY)
  get_filename_component(_rs_name "${_rs_abs}" NAME)
  set(_rs_skip OFF)
  if(CMAKE_CROSSCOMPILING AND _rs_abs STREQUAL "${PROJECT_SOURCE_DIR}/bench")
    set(_rs_skip ON)
  elseif(_rs_parent STREQUAL "${PROJECT_SOURCE_DIR}/tests")
    if(NOT ROCKSTEADY_BUILD_GROUND AND IS_DIRECTORY "${PROJECT_SOURCE_DIR}/ground/${_rs_name}")
      set(_rs_skip ON)
    elseif(CMAKE_CROSSCOMPILING AND _rs_name STREQUAL "fuzz")
      set(_rs_skip ON)
    endif()
  endif()
  if(_rs_skip)
    file(RELATIVE_PATH _rs_rel "${PROJECT_SOURCE_DIR}" "${_rs_abs}")
    message(STATUS "Rocksteady flight-side build: skipping ${_rs_rel}")
  else()
    _add_subdirectory(${ARGV})
  endif()
endmacro()
