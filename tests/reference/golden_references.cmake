# Renders the reviewed reference documents tests/golden/references/*.texel.json
# with texel-golden (every amplitude as float64, OUT/references/<stem>.f64) and
# compares each file's SHA-256 with the golden list (sha256sum format:
# "<digest>  <file>"). The v2-* documents' digests are the bytes Texel rendered
# before version 3 (direct synthesis) and must never change; the v3-* ones are
# the chirp-z synthesis. Fails on a differing digest, a missing file, or a
# file the list does not review.
# Usage: cmake -DGOLDEN_BIN=<texel-golden> -DDOCS=<dir> -DGOLDEN=<references.sha256> -DOUT=<dir> -P golden_references.cmake
cmake_minimum_required(VERSION 3.25)
foreach(v GOLDEN_BIN DOCS GOLDEN OUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "golden_references.cmake: -D${v}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(GLOB docs ${DOCS}/*.texel.json)
list(SORT docs)
execute_process(COMMAND ${GOLDEN_BIN} ${OUT} ${docs} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "texel-golden failed (${rc}): ${err}")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/../support/check_digests.cmake)
# Files that match are kept in OUT-accepted, so a later failure names the
# first differing sample (check_digests.cmake).
check_digests(${GOLDEN} ${OUT}/references "*.f64" reference ACCEPTED ${OUT}-accepted FORMAT f64le)
