# SPDX-License-Identifier: Apache-2.0
# The project's one version: the VERSION file at the repository root, one line
# MAJOR.MINOR.PATCH (the Python package reads the same file). Sets BR_VERSION
# and BR_VERSION_MAJOR / _MINOR / _PATCH; included before project() by the
# root and by firmware/ when it is added on its own (add_subdirectory).
get_filename_component(_br_version_file "${CMAKE_CURRENT_LIST_DIR}/../VERSION" ABSOLUTE)
file(STRINGS "${_br_version_file}" BR_VERSION LIMIT_COUNT 1)
string(STRIP "${BR_VERSION}" BR_VERSION)
if(NOT BR_VERSION MATCHES "^([0-9]+)\\.([0-9]+)\\.([0-9]+)$")
  message(FATAL_ERROR "${_br_version_file}: '${BR_VERSION}' is not MAJOR.MINOR.PATCH")
endif()
set(BR_VERSION_MAJOR ${CMAKE_MATCH_1})
set(BR_VERSION_MINOR ${CMAKE_MATCH_2})
set(BR_VERSION_PATCH ${CMAKE_MATCH_3})
# reconfigure when the version changes
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${_br_version_file}")
