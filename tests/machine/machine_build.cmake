# SPDX-License-Identifier: Apache-2.0
# Builds and checks the firmware for another machine (tests/machine/CMakeLists.txt).
# Variables: SOURCE_DIR, BUILD_DIR, MACHINE, PYTHON, GENERATOR, C_COMPILER.

# what git reports about the source tree: the tracked files' state (and the
# content of any local edit), and the untracked files outside .gitignore
function(tree_state out)
  execute_process(COMMAND git -C ${SOURCE_DIR} status --porcelain --untracked-files=all
                  OUTPUT_VARIABLE st RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "git status failed in ${SOURCE_DIR}: the check needs a git checkout")
  endif()
  execute_process(COMMAND git -C ${SOURCE_DIR} diff HEAD OUTPUT_VARIABLE diff)
  string(SHA256 h "${diff}")
  set(${out} "${st}diff ${h}\n" PARENT_SCOPE)
endfunction()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (exit ${rc}): ${ARGN}")
  endif()
endfunction()

tree_state(before)
string(TIMESTAMP t0 "%s")
file(REMOVE_RECURSE ${BUILD_DIR})
run("configure" ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BUILD_DIR} -G ${GENERATOR}
    -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_BUILD_TYPE=Release "-DCMAKE_C_FLAGS_RELEASE=-O2 -DNDEBUG"
    -DBR_MACHINE=${MACHINE} -DBR_PYTHON=${PYTHON})
run("build" ${CMAKE_COMMAND} --build ${BUILD_DIR} --target br_checks_unit_closedloop)
string(TIMESTAMP t1 "%s")
run("the unit and closed-loop tests" ${CMAKE_CTEST_COMMAND} --test-dir ${BUILD_DIR} -L "unit|closedloop"
    --output-on-failure --no-tests=error -j2)
string(TIMESTAMP t2 "%s")
math(EXPR tb "${t1} - ${t0}")
math(EXPR tt "${t2} - ${t1}")
message(STATUS "${MACHINE}: configured and built in ${tb} s, unit and closed-loop tests passed in ${tt} s")

# the generated headers are in the build tree, and nothing in the source tree changed
foreach(h machine/br_machine.h ctrl/br_hinf_gains.h est/br_est_machine.h est/br_pf_tuned.h est/br_ukf_tuned.h)
  if(NOT EXISTS ${BUILD_DIR}/gen/bristle_gen/${h})
    message(FATAL_ERROR "${BUILD_DIR}/gen/bristle_gen/${h} was not generated")
  endif()
endforeach()
tree_state(after)
if(NOT after STREQUAL before)
  message(FATAL_ERROR "building for ${MACHINE} changed the source tree:\nbefore:\n${before}after:\n${after}")
endif()
message(STATUS "source tree unchanged")
