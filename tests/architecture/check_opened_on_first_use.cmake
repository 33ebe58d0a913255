# The front doors do not link the libraries Texel opens on first use
# (docs/architecture.md §2, src/internal/texel/detail/shared_object.hpp):
# linked, Cairo, libpq, libsndfile, libmatio and PortAudio brought some fifty
# shared libraries into every command's start-up, `texel --version` included.
# A link added back (a target_link_libraries, or a call that bypasses the
# function table and makes the linker look for the library) fails here,
# naming the file and the library.
#   cmake -DREADELF=... -DFILES="a;b" -P check_opened_on_first_use.cmake
set(opened_on_first_use libcairo libpq libsndfile libmatio libportaudio)
set(problems "")
foreach(file IN LISTS FILES)
  execute_process(COMMAND ${READELF} -d ${file} OUTPUT_VARIABLE dyn RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "readelf -d ${file} failed: ${err}")
  endif()
  string(REGEX MATCHALL "NEEDED\\)[^\n]*\\[[^]]+\\]" needed "${dyn}")
  string(REGEX REPLACE "NEEDED\\)[^[]*\\[([^]]+)\\]" "\\1" needed "${needed}")
  if(NOT needed)
    message(FATAL_ERROR "${file} needs no shared library at all: not the dynamically linked front door this test expects")
  endif()
  foreach(lib IN LISTS needed)
    foreach(name IN LISTS opened_on_first_use)
      if(lib MATCHES "^${name}[.-]")
        string(APPEND problems "\n  ${file} links ${lib}; it is opened on first use")
      endif()
    endforeach()
  endforeach()
  list(LENGTH needed n)
  message(STATUS "${file}: ${n} shared libraries needed: ${needed}")
endforeach()
if(problems)
  message(FATAL_ERROR "a front door links a library Texel opens on first use:${problems}")
endif()
