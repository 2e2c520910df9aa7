# Regenerates one generated file into the build tree and fails on any difference
# from the committed copy. Variables: PYTHON, SCRIPT, COMMITTED, OUT.
execute_process(COMMAND ${PYTHON} ${SCRIPT} --out ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${SCRIPT} failed (exit ${rc}); is the project venv set up (make deps)?")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${COMMITTED} ${OUT} RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  execute_process(COMMAND diff -u ${COMMITTED} ${OUT})
  message(FATAL_ERROR "${COMMITTED} differs from what ${SCRIPT} generates: run `make regen` and commit")
endif()
message(STATUS "${COMMITTED} is up to date")
