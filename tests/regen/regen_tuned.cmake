# SPDX-License-Identifier: Apache-2.0
# Reruns the estimator tuning up to its checkpoint (br_tune_est --checkpoint:
# the first search's first evaluations, a short run) and fails when its
# checkpoint line differs from the committed header's: the header then did
# not come from this tuner's objective, plants and start (`make tune` reruns
# the whole search and rewrites the header). Variables: TUNER, EST, COMMITTED, OUT.
if(NOT EXISTS ${TUNER})
  message(FATAL_ERROR "${TUNER} is missing (the release_tuner fixture builds it)")
endif()
execute_process(COMMAND ${TUNER} --est ${EST} --checkpoint --out ${OUT} RESULT_VARIABLE rc OUTPUT_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${TUNER} --est ${EST} --checkpoint failed (exit ${rc})")
endif()
file(STRINGS ${OUT} fresh REGEX "^/\\* checkpoint ")
file(STRINGS ${COMMITTED} committed REGEX "^/\\* checkpoint ")
if(NOT fresh)
  message(FATAL_ERROR "${OUT} has no checkpoint line")
endif()
if(NOT fresh STREQUAL committed)
  message(FATAL_ERROR "${COMMITTED}'s checkpoint line\n  ${committed}\ndiffers from a fresh tuning's\n  ${fresh}\n"
                      "run `make tune` and commit")
endif()
message(STATUS "${COMMITTED} has this tuner's checkpoint")
