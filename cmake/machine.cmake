# The machine the build is for (docs/machine-file.md): BR_MACHINE, a machine
# description. The reference machine (machines/reference.json, the default)
# builds with the headers committed under firmware/gen/. Any other machine's
# headers are generated at build time into ${CMAKE_BINARY_DIR}/gen/bristle_gen/
# (machine, H-inf gains, estimator settings, the noise table), which is then
# the only generated-header root on the include path: configuring another
# machine writes into the build tree only.
#
# Sets BR_GEN_ROOT (the include root of "bristle_gen/...") and
# BR_MACHINE_IS_REFERENCE; firmware/CMakeLists.txt adds the generation rules.
set(BR_MACHINE "${PROJECT_SOURCE_DIR}/machines/reference.json" CACHE FILEPATH
    "machine description (JSON, docs/machine-file.md)")
# Python interpreter of the project-local virtual environment (cmake/setup-deps.sh).
set(BR_PYTHON "${PROJECT_SOURCE_DIR}/.venv/bin/python" CACHE FILEPATH "Python with numpy")

get_filename_component(BR_MACHINE_PATH "${BR_MACHINE}" REALPATH BASE_DIR "${PROJECT_SOURCE_DIR}")
get_filename_component(_br_reference "${PROJECT_SOURCE_DIR}/machines/reference.json" REALPATH)
if(NOT EXISTS "${BR_MACHINE_PATH}")
  message(FATAL_ERROR "BR_MACHINE=${BR_MACHINE}: no such file")
endif()
if(BR_MACHINE_PATH STREQUAL _br_reference)
  set(BR_MACHINE_IS_REFERENCE ON)
  set(BR_GEN_ROOT "${PROJECT_SOURCE_DIR}/firmware/gen")
else()
  set(BR_MACHINE_IS_REFERENCE OFF)
  set(BR_GEN_ROOT "${CMAKE_BINARY_DIR}/gen")
  if(NOT EXISTS "${BR_PYTHON}")
    message(FATAL_ERROR "BR_MACHINE=${BR_MACHINE} needs its headers generated, and BR_PYTHON=${BR_PYTHON} "
                        "does not exist: run cmake/setup-deps.sh or pass -DBR_PYTHON=...")
  endif()
endif()
message(STATUS "machine: ${BR_MACHINE_PATH} (generated headers: ${BR_GEN_ROOT})")
