# Renders the demo set with the built CLI and compares each .bin file's SHA-256
# with the golden list (sha256sum format: "<digest>  <file>"). Fails on a
# differing digest, a missing file, or a .bin file the list does not review.
# Usage: cmake -DTEXEL=<texel> -DGOLDEN=<demo.sha256> -DOUT=<dir> -P golden_demo.cmake
cmake_minimum_required(VERSION 3.25)
foreach(v TEXEL GOLDEN OUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "golden_demo.cmake: -D${v}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${TEXEL} demo --no-plots --out ${OUT} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "texel demo failed (${rc}): ${err}")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/../support/check_digests.cmake)
# Files that match are kept in OUT-accepted, so a later failure names the
# first differing sample (check_digests.cmake).
check_digests(${GOLDEN} ${OUT} "*.bin" demo ACCEPTED ${OUT}-accepted FORMAT u16le)
