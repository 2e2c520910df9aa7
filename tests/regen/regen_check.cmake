# SPDX-License-Identifier: Apache-2.0
# Regenerates one generated file into the build tree and fails on any difference
# from the committed copy. Variables: PYTHON, SCRIPT, COMMITTED, OUT, OUT_FLAG
# (--out: OUT is the file; --out-dir: OUT is a directory that receives files
# named like the committed ones; --gen-root: OUT is a generated-header root,
# the file is at COMMITTED's path below GEN_ROOT).
if(OUT_FLAG STREQUAL "--gen-root")
  file(RELATIVE_PATH rel ${GEN_ROOT} ${COMMITTED})
  set(generated ${OUT}/${rel})
elseif(OUT_FLAG STREQUAL "--out-dir")
  file(MAKE_DIRECTORY ${OUT})
  get_filename_component(name ${COMMITTED} NAME)
  set(generated ${OUT}/${name})
else()
  set(generated ${OUT})
endif()
execute_process(COMMAND ${PYTHON} ${SCRIPT} ${OUT_FLAG} ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${SCRIPT} failed (exit ${rc}); is the project venv set up (make deps)?")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${COMMITTED} ${generated} RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  execute_process(COMMAND diff -u ${COMMITTED} ${generated})
  message(FATAL_ERROR "${COMMITTED} differs from what ${SCRIPT} generates: run `make regen` and commit")
endif()
message(STATUS "${COMMITTED} is up to date")
