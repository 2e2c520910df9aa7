# SPDX-License-Identifier: Apache-2.0
# ctest fixture setup (br_add_preset_build in tests/CMakeLists.txt): configures
# a preset and builds some of its targets from the source tree, as
#   cmake --preset PRESET && cmake --build --preset PRESET --target T1 T2 ...
# Incremental: a second or two when the targets are up to date. Variables:
# SRC (source dir), PRESET, TARGETS (comma-separated). The output is shown
# only on failure.
string(REPLACE "," ";" targets "${TARGETS}")
foreach(step configure build)
  if(step STREQUAL "configure")
    set(cmd ${CMAKE_COMMAND} --preset ${PRESET})
  else()
    set(cmd ${CMAKE_COMMAND} --build --preset ${PRESET} --target ${targets})
  endif()
  execute_process(COMMAND ${cmd} WORKING_DIRECTORY ${SRC} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${step} of preset ${PRESET} (${TARGETS}) failed:\n${out}")
  endif()
endforeach()
message(STATUS "preset ${PRESET}: ${TARGETS} built")
