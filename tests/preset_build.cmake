# ctest fixture setup (br_add_preset_build in tests/CMakeLists.txt): configures
# a preset and builds one of its targets from the source tree, as
#   cmake --preset PRESET && cmake --build --preset PRESET --target TARGET
# Incremental: a second or two when the target is up to date. Variables:
# SRC (source dir), PRESET, TARGET. The output is shown only on failure.
foreach(step configure build)
  if(step STREQUAL "configure")
    set(cmd ${CMAKE_COMMAND} --preset ${PRESET})
  else()
    set(cmd ${CMAKE_COMMAND} --build --preset ${PRESET} --target ${TARGET})
  endif()
  execute_process(COMMAND ${cmd} WORKING_DIRECTORY ${SRC} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${step} of preset ${PRESET} (target ${TARGET}) failed:\n${out}")
  endif()
endforeach()
message(STATUS "preset ${PRESET}: ${TARGET} is built")
