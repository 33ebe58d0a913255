# A golden digest failure must say where the samples differ, not only that
# two hashes do: builds an accepted file of 100 u16 samples and a render
# where sample 37 became 1000 and sample 80 became 79, lists the accepted
# file's digest as golden, and requires check_digests to fail with the first
# differing sample, both values, the count and the largest difference.
# Usage: cmake -DWORK=<scratch dir> -P check_golden_diff.cmake
cmake_minimum_required(VERSION 3.25)
find_program(PYTHON3 python3 REQUIRED)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/accepted ${WORK}/now)
execute_process(COMMAND ${PYTHON3} -c "
import struct
a = list(range(100))
n = list(a); n[37] = 1000; n[80] = 79
open('${WORK}/accepted/map.bin', 'wb').write(struct.pack('<100H', *a))
open('${WORK}/now/map.bin', 'wb').write(struct.pack('<100H', *n))
" COMMAND_ERROR_IS_FATAL ANY)
file(SHA256 ${WORK}/accepted/map.bin golden)
file(WRITE ${WORK}/golden.sha256 "${golden}  map.bin\n")
file(WRITE ${WORK}/run.cmake "cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/check_digests.cmake)
check_digests(${WORK}/golden.sha256 ${WORK}/now \"*.bin\" test ACCEPTED ${WORK}/accepted FORMAT u16le)\n")
execute_process(COMMAND ${CMAKE_COMMAND} -P ${WORK}/run.cmake RESULT_VARIABLE rc ERROR_VARIABLE err)
string(REGEX REPLACE "[ \t\n]+" " " err "${err}")  # messages are wrapped
if(rc EQUAL 0)
  message(FATAL_ERROR "check_digests accepted a file that differs from its golden digest")
endif()
set(want "map.bin: first differing sample 37: accepted 37, now 1000; 2 of 100 samples differ; max |delta| 963.0 at sample 37")
if(NOT err MATCHES "first differing sample 37: accepted 37, now 1000; 2 of 100 samples differ; max \\|delta\\| 963.0 at sample 37")
  message(FATAL_ERROR "check_digests did not say where the samples differ; wanted\n  ${want}\ngot\n  ${err}")
endif()
# A matching file is kept as the accepted copy.
file(COPY_FILE ${WORK}/accepted/map.bin ${WORK}/now/map.bin)
file(REMOVE ${WORK}/accepted/map.bin)
execute_process(COMMAND ${CMAKE_COMMAND} -P ${WORK}/run.cmake RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/accepted/map.bin)
  message(FATAL_ERROR "a matching file was not accepted and kept (${rc}): ${err}")
endif()
message(STATUS "a differing golden file is reported by sample: ${want}")
