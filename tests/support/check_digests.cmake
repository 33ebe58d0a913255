# check_digests(GOLDEN DIR PATTERN WHAT [ACCEPTED <dir> FORMAT <u16le|f64le>]):
# compares the SHA-256 of every file the golden list names (sha256sum format:
# "<digest>  <file>", relative to DIR) and fails on a differing digest, a
# missing file, an empty list, or a file in DIR matching PATTERN that the list
# does not review. WHAT names the files in the messages ("demo",
# "reference"). Shared by the golden tests (tests/cli/golden_demo.cmake,
# tests/reference/golden_references.cmake).
#
# Saying what differs, not two hashes: the list holds digests only, so every
# file that matches its digest is kept in ACCEPTED (a folder of the build
# tree). When a digest later differs and ACCEPTED holds that file with the
# golden digest, the message gives the first differing sample, both values,
# how many samples differ and the largest |difference|
# (tests/support/golden_diff.py, samples encoded as FORMAT). A build tree
# where the test never passed has no accepted copy, and says so.
function(check_digests GOLDEN DIR PATTERN WHAT)
  cmake_parse_arguments(ARG "" "ACCEPTED;FORMAT" "" ${ARGN})
  if(ARG_ACCEPTED)
    find_program(TEXEL_PYTHON3 python3)
  endif()
  file(STRINGS ${GOLDEN} lines)
  set(failures 0)
  set(listed "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^([0-9a-f]+)  (.+)$")
      set(want ${CMAKE_MATCH_1})
      set(name ${CMAKE_MATCH_2})
      list(APPEND listed ${name})
      if(NOT EXISTS ${DIR}/${name})
        message(SEND_ERROR "missing: ${name}")
        math(EXPR failures "${failures} + 1")
        continue()
      endif()
      file(SHA256 ${DIR}/${name} got)
      if(NOT got STREQUAL want)
        set(where "SHA-256 ${got}, golden ${want}")
        if(ARG_ACCEPTED)
          set(accepted ${ARG_ACCEPTED}/${name})
          set(accepted_sha "")
          if(EXISTS ${accepted})
            file(SHA256 ${accepted} accepted_sha)
          endif()
          if(accepted_sha STREQUAL want AND TEXEL_PYTHON3)
            execute_process(COMMAND ${TEXEL_PYTHON3} ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/golden_diff.py ${ARG_FORMAT}
                                    ${accepted} ${DIR}/${name} OUTPUT_VARIABLE diff OUTPUT_STRIP_TRAILING_WHITESPACE)
            set(where "${diff} (against the accepted copy ${accepted})")
          else()
            string(APPEND where " (no accepted copy with the golden digest in ${ARG_ACCEPTED} to compare samples with: "
                                "one is kept each time this file matches)")
          endif()
        endif()
        message(SEND_ERROR "${name}: ${where}")
        math(EXPR failures "${failures} + 1")
      elseif(ARG_ACCEPTED)
        file(MAKE_DIRECTORY ${ARG_ACCEPTED})
        file(COPY_FILE ${DIR}/${name} ${ARG_ACCEPTED}/${name})
      endif()
    elseif(NOT line STREQUAL "")
      message(FATAL_ERROR "${GOLDEN}: unreadable line '${line}'")
    endif()
  endforeach()
  list(LENGTH listed n)
  if(n EQUAL 0)
    message(FATAL_ERROR "${GOLDEN} lists no files")
  endif()
  file(GLOB produced RELATIVE ${DIR} ${DIR}/${PATTERN})
  foreach(name IN LISTS produced)
    if(NOT name IN_LIST listed)
      message(SEND_ERROR "${name} is not in ${GOLDEN}: review its digest and add it")
      math(EXPR failures "${failures} + 1")
    endif()
  endforeach()
  if(failures GREATER 0)
    message(FATAL_ERROR "${failures} ${WHAT} file(s) differ from the golden digests")
  endif()
  message(STATUS "${n} ${WHAT} files match ${GOLDEN}")
endfunction()
