# SPDX-License-Identifier: Apache-2.0
# Reruns the estimator tuning and fails on any difference from the committed
# header. Variables: TUNER, EST, COMMITTED, OUT.
if(NOT EXISTS ${TUNER})
  message(FATAL_ERROR "${TUNER} is missing (the release_tuner fixture builds it)")
endif()
execute_process(COMMAND ${TUNER} --est ${EST} --out ${OUT} RESULT_VARIABLE rc OUTPUT_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${TUNER} --est ${EST} failed (exit ${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${COMMITTED} ${OUT} RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  execute_process(COMMAND diff -u ${COMMITTED} ${OUT})
  message(FATAL_ERROR "${COMMITTED} differs from a fresh tuning: run `make tune` and commit")
endif()
message(STATUS "${COMMITTED} is up to date")
