# The library-graph check must fail when the table and the build disagree:
# runs check_library_graph.cmake on a copy of architecture.md whose plot row
# has lost its PUBLIC link to texel::spectrum, and fails unless the check
# fails naming that row.
# Usage: as check_library_graph.cmake, plus -DOUT=<scratch file>.
cmake_minimum_required(VERSION 3.25)
file(READ ${DOC} doc)
string(REPLACE "| `texel::plot` | `texel::texel`, `texel::spectrum` |" "| `texel::plot` | `texel::texel` |" drifted "${doc}")
if(drifted STREQUAL doc)
  message(FATAL_ERROR "${DOC}: the plot row to mutate is not there; update check_detects_drift.cmake")
endif()
file(WRITE ${OUT} "${drifted}")
execute_process(COMMAND ${CMAKE_COMMAND} -DGRAPH=${GRAPH} -DDOC=${OUT} -DINCLUDE_DIR=${INCLUDE_DIR}
                        -P ${CMAKE_CURRENT_LIST_DIR}/check_library_graph.cmake
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "the check passed a table that lost texel::plot's link to texel::spectrum")
endif()
string(REGEX REPLACE "[ \t\n]+" " " err "${err}")  # messages are wrapped
if(NOT err MATCHES "texel::plot: the build links public \\[texel::spectrum, texel::texel\\], the table says \\[texel::texel\\]")
  message(FATAL_ERROR "the check failed without naming the drifted row:\n${err}")
endif()
message(STATUS "a drifted table is reported: texel::plot's public links")
