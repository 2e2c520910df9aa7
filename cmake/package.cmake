# SPDX-License-Identifier: Apache-2.0
# cmake --install: the library (bristle::firmware), the shared STM32 driver
# (bristle::hal_stm32) and the STM32H7 and STM32G4 ports (bristle::hal_stm32h7,
# bristle::hal_stm32g4), their public headers, the generated headers of the
# machine the build is for, the version header, and the CMake package that
# find_package(bristle [VERSION]) loads (docs/integration.md).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(BR_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/bristle CACHE STRING
    "where cmake --install puts bristle's CMake package")

# the version header configured in the firmware's build folder (firmware/CMakeLists.txt)
get_target_property(_br_firmware_bin bristle BINARY_DIR)
install(TARGETS bristle br_hal_stm32 br_hal_stm32h7 br_hal_stm32g4 EXPORT bristleTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/firmware/include/bristle
                  ${PROJECT_SOURCE_DIR}/hal/stm32/include/bristle
                  ${PROJECT_SOURCE_DIR}/hal/stm32h7/include/bristle
                  ${PROJECT_SOURCE_DIR}/hal/stm32g4/include/bristle
                  ${_br_firmware_bin}/version/bristle
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${BR_GEN_ROOT}/bristle_gen DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
install(EXPORT bristleTargets NAMESPACE bristle:: DESTINATION ${BR_INSTALL_CMAKEDIR})

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/bristleConfig.cmake.in
  ${PROJECT_BINARY_DIR}/bristleConfig.cmake INSTALL_DESTINATION ${BR_INSTALL_CMAKEDIR})
# 0.x: a minor version may break the API, so only the same MAJOR.MINOR matches.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bristleConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bristleConfig.cmake ${PROJECT_BINARY_DIR}/bristleConfigVersion.cmake
        DESTINATION ${BR_INSTALL_CMAKEDIR})
