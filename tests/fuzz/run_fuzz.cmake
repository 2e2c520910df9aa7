# SPDX-License-Identifier: Apache-2.0
# Runs one libFuzzer target for SECONDS from a fixed seed with its corpus in
# CORPUS (build tree); fails on any finding, which it writes beside the
# corpus (CORPUS.findings/), never into the working directory. Variables: FUZZER, CORPUS, SECONDS.
file(MAKE_DIRECTORY ${CORPUS} ${CORPUS}.findings)
execute_process(COMMAND ${FUZZER} -max_total_time=${SECONDS} -seed=1 -max_len=1024 -rss_limit_mb=2048
                        -print_final_stats=1
                        -artifact_prefix=${CORPUS}.findings/ ${CORPUS}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
string(REGEX MATCH "stat::number_of_executed_units: *[0-9]+" runs "${out}")
message(STATUS "${FUZZER}: ${runs}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${FUZZER} found a failure (exit ${rc}):\n${out}")
endif()
