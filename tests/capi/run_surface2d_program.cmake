# tests/capi/surface2d_program.c as a C user builds it: copied into an empty
# folder, compiled there with the C compiler alone (strict C99) against
# texel.h and the built libtexel.so, and run against what the CLI wrote for
# the same 2-D document.
#   cmake -DWORK=<dir> -DCC=<cc> [-DCFLAGS=<flags>] -DINCLUDE=<include dir> -DLIBRARY=<libtexel.so> -DTEXEL=<texel>
#         -DSOURCE=<tests/capi> -P run_surface2d_program.cmake
cmake_minimum_required(VERSION 3.25)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "${cmd} exited ${rc}:\n${out}${err}")
  endif()
  message(STATUS "${out}")
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(COPY ${SOURCE}/surface2d_program.c ${SOURCE}/surface2d-disc.texel.json DESTINATION ${WORK})
get_filename_component(libdir ${LIBRARY} DIRECTORY)
separate_arguments(cflags UNIX_COMMAND "${CFLAGS}")  # e.g. the sanitizers of a sanitized library
run(${CC} -std=c99 -pedantic -Wall -Wextra -Werror ${cflags} -I${INCLUDE} ${WORK}/surface2d_program.c -o ${WORK}/program
    -L${libdir} -ltexel -lm -Wl,-rpath,${libdir})
set(doc ${WORK}/surface2d-disc.texel.json)
run(${TEXEL} render ${doc} --surface 2d -o ${WORK}/cli.npy)
run(${TEXEL} render ${doc} --surface 2d -o ${WORK}/cli.png)
run(${TEXEL} swipe ${doc} --path circle --radius 1 --start 2 --start-y 1.2 --speed 50 --duration 0.2 --wav-format float
    -o ${WORK}/cli-circle.wav)
run(${WORK}/program ${doc} ${WORK}/cli.npy ${WORK}/cli.png ${WORK}/cli-circle.wav ${WORK})
