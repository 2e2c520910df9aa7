# SPDX-License-Identifier: Apache-2.0
# Builds the consumer project (tests/package/consumer) against bristle as an
# integrator would (docs/integration.md). Variables: SRC (bristle's root),
# WORK (a scratch folder), MODE:
#   host:   configure bristle alone (BR_BUILD_TESTING=OFF), build and install
#           the library, then find_package(bristle VERSION) from the consumer,
#           build it and run it; a request for a version the package is not
#           must fail;
#   arm:    the same with cmake/arm-none-eabi-cortex-m7.cmake (built and
#           linked, not run);
#   subdir: the consumer adds bristle's firmware/ with add_subdirectory; built
#           and run; no cmocka, no simulator and no BR_PYTHON come with it.
# The consumer compiles with -ffast-math: the exported usage requirements must
# undo it (consumer/main.c checks) and pass -ffp-contract=off (checked here).
cmake_minimum_required(VERSION 3.21)
foreach(v SRC WORK MODE)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "package_test.cmake: -D${v}=... is required")
  endif()
endforeach()
file(STRINGS ${SRC}/VERSION version LIMIT_COUNT 1)
string(STRIP "${version}" version)
set(consumer_src ${SRC}/tests/package/consumer)
file(REMOVE_RECURSE ${WORK})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (exit ${rc}):\n${out}\n${err}")
  endif()
  set(run_out "${out}" PARENT_SCOPE)
endfunction()

set(toolchain "")
if(MODE STREQUAL "arm")
  set(toolchain -DCMAKE_TOOLCHAIN_FILE=${SRC}/cmake/arm-none-eabi-cortex-m7.cmake)
endif()
set(consumer_flags -G Ninja -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DBR_EXPECT_VERSION=${version} ${toolchain})

if(MODE STREQUAL "subdir")
  run("configure the consumer (add_subdirectory)" ${CMAKE_COMMAND} -S ${consumer_src} -B ${WORK}/consumer
      ${consumer_flags} -DBR_CONSUMER_MODE=subdirectory -DBRISTLE_SOURCE_DIR=${SRC})
  file(READ ${WORK}/consumer/CMakeCache.txt cache)
  foreach(unwanted CMOCKA_LIBRARY BR_PYTHON BR_BUILD_TESTING)
    if(cache MATCHES "\n${unwanted}:")
      message(FATAL_ERROR "add_subdirectory(firmware) put ${unwanted} into the consumer's cache")
    endif()
  endforeach()
else()
  run("configure bristle" ${CMAKE_COMMAND} -S ${SRC} -B ${WORK}/bristle -G Ninja -DCMAKE_BUILD_TYPE=Release
      -DBR_BUILD_TESTING=OFF ${toolchain})
  file(READ ${WORK}/bristle/CMakeCache.txt cache)
  if(cache MATCHES "\nCMOCKA_LIBRARY:" OR EXISTS ${WORK}/bristle/sim)
    message(FATAL_ERROR "BR_BUILD_TESTING=OFF still configured the simulator or the tests (cmocka)")
  endif()
  run("build bristle" ${CMAKE_COMMAND} --build ${WORK}/bristle)
  run("install bristle" ${CMAKE_COMMAND} --install ${WORK}/bristle --prefix ${WORK}/prefix)
  foreach(f lib/libbristle.a lib/libbr_hal_stm32h7.a include/bristle/br_version.h include/bristle/br_app.h
            include/bristle/br_stm32h7.h include/bristle_gen/machine/br_machine.h
            lib/cmake/bristle/bristleConfig.cmake lib/cmake/bristle/bristleConfigVersion.cmake)
    if(NOT EXISTS ${WORK}/prefix/${f})
      message(FATAL_ERROR "cmake --install did not install ${f}")
    endif()
  endforeach()
  # the version file refuses a version the package is not
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${consumer_src} -B ${WORK}/consumer-wrong ${consumer_flags}
                          -DBR_EXPECT_VERSION=99.0 -DCMAKE_PREFIX_PATH=${WORK}/prefix
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "compatible with requested version")
    message(FATAL_ERROR "find_package(bristle 99.0) did not fail on the version (exit ${rc}):\n${err}")
  endif()
  run("configure the consumer (find_package)" ${CMAKE_COMMAND} -S ${consumer_src} -B ${WORK}/consumer
      ${consumer_flags} -DCMAKE_PREFIX_PATH=${WORK}/prefix)
endif()
run("build the consumer" ${CMAKE_COMMAND} --build ${WORK}/consumer)

file(READ ${WORK}/consumer/compile_commands.json commands)
if(NOT commands MATCHES "main\\.c" OR NOT commands MATCHES "-ffp-contract=off[^\n]*main\\.c")
  message(FATAL_ERROR "consumer/main.c was not compiled with -ffp-contract=off (the usage requirements):\n${commands}")
endif()
if(MODE STREQUAL "arm")
  if(NOT commands MATCHES "mcpu=cortex-m7[^\n]*main\\.c")
    message(FATAL_ERROR "consumer/main.c was not compiled for the Cortex-M7:\n${commands}")
  endif()
  if(NOT EXISTS ${WORK}/consumer/consumer)
    message(FATAL_ERROR "no consumer image")
  endif()
else()
  run("run the consumer" ${WORK}/consumer/consumer)
  if(NOT run_out MATCHES "^bristle ${version}: ")
    message(FATAL_ERROR "the consumer printed: ${run_out}")
  endif()
endif()
message(STATUS "${MODE}: ${run_out}")
