# cli.start_up_loads_no_optional_library: the texel command must not load
# libmatio (and through HDF5 curl, TLS, Kerberos) or PortAudio (JACK, ALSA)
# at start-up; they are opened on first use (texel/detail/shared_object.hpp).
# Loading them was about half of every command's start-up time.
#   cmake -DTEXEL=path/to/texel -P start_up_libraries.cmake
execute_process(COMMAND ldd ${TEXEL} OUTPUT_VARIABLE loaded RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "ldd ${TEXEL} failed (${status})")
endif()
foreach(optional matio hdf5 portaudio jack curl)
  if(loaded MATCHES "lib${optional}[^ ]*")
    message(FATAL_ERROR "texel loads ${CMAKE_MATCH_0} at start-up; it should be opened on first use:\n${loaded}")
  endif()
endforeach()
# ...and the command still reads and writes .mat files (through dlopen).
set(dir ${CMAKE_CURRENT_BINARY_DIR}/start-up-libraries)
file(MAKE_DIRECTORY ${dir})
execute_process(COMMAND ${TEXEL} render --seed 2 --device generic -o ${dir}/map.mat RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0 OR NOT EXISTS ${dir}/map.mat)
  message(FATAL_ERROR "texel render -o map.mat failed (${status}): ${err}")
endif()
execute_process(COMMAND ${TEXEL} spectrum ${dir}/map.mat --json RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "texel spectrum map.mat failed (${status}): ${err}")
endif()
