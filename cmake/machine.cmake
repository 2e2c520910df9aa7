# SPDX-License-Identifier: Apache-2.0
# The machine the build is for (docs/machine-file.md): BR_MACHINE, a machine
# description. The reference machine (machines/reference.json, the default)
# builds with the headers committed under firmware/gen/. Any other machine's
# headers are generated at build time into <build>/gen/bristle_gen/
# (machine, H-inf gains, estimator settings, the noise table), which is then
# the only generated-header root on the include path: configuring another
# machine writes into the build tree only.
#
# Sets BR_GEN_ROOT (the include root of "bristle_gen/...") and
# BR_MACHINE_IS_REFERENCE; firmware/CMakeLists.txt adds the generation rules.
# Paths are relative to bristle's own root (this file's folder's parent), so
# that firmware/ can be added to another project (docs/integration.md).
get_filename_component(_br_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set(BR_MACHINE "${_br_root}/machines/reference.json" CACHE FILEPATH
    "machine description (JSON, docs/machine-file.md)")
# Python interpreter of the project-local virtual environment (cmake/setup-deps.sh).
# Needed only to generate another machine's headers (and by the tests), so a
# project that adds bristle is not given a cache entry: it may pass -DBR_PYTHON.
if(PROJECT_IS_TOP_LEVEL AND PROJECT_NAME STREQUAL "bristle")
  set(BR_PYTHON "${_br_root}/.venv/bin/python" CACHE FILEPATH "Python with numpy")
elseif(NOT BR_PYTHON)
  set(BR_PYTHON "${_br_root}/.venv/bin/python")
endif()

# A newline or a carriage return in the path: no build rule can name the file
# (Ninja's paths are one line); a ';' splits it (CMake's list separator).
# Refused here with the reason, not at build time (docs/tools.md).
string(FIND "${BR_MACHINE}" "\n" _br_nl)
string(FIND "${BR_MACHINE}" "\r" _br_cr)
string(FIND "${BR_MACHINE}" ";" _br_sc)
if(NOT _br_nl EQUAL -1 OR NOT _br_cr EQUAL -1 OR NOT _br_sc EQUAL -1)
  message(FATAL_ERROR "BR_MACHINE: the machine file's path holds a newline, a carriage return or a ';', "
                      "which no build rule can name: move or rename the file (docs/tools.md)")
endif()
get_filename_component(BR_MACHINE_PATH "${BR_MACHINE}" REALPATH BASE_DIR "${_br_root}")
get_filename_component(_br_reference "${_br_root}/machines/reference.json" REALPATH)
if(NOT EXISTS "${BR_MACHINE_PATH}")
  message(FATAL_ERROR "BR_MACHINE=${BR_MACHINE}: no such file")
endif()
if(BR_MACHINE_PATH STREQUAL _br_reference)
  set(BR_MACHINE_IS_REFERENCE ON)
  set(BR_GEN_ROOT "${_br_root}/firmware/gen")
else()
  set(BR_MACHINE_IS_REFERENCE OFF)
  set(BR_GEN_ROOT "${CMAKE_CURRENT_BINARY_DIR}/gen")
  if(NOT EXISTS "${BR_PYTHON}")
    message(FATAL_ERROR "BR_MACHINE=${BR_MACHINE} needs its headers generated, and BR_PYTHON=${BR_PYTHON} "
                        "does not exist: run cmake/setup-deps.sh or pass -DBR_PYTHON=...")
  endif()
endif()
message(STATUS "machine: ${BR_MACHINE_PATH} (generated headers: ${BR_GEN_ROOT})")
