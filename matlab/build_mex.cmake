# Builds the MEX functions (matlab/*.c) with GNU Octave's mkoctfile --mex
# against libtexel.so (the C ABI), for the tests (tests/capi/CMakeLists.txt).
# MATLAB's own `mex` takes the same sources and flags (docs/matlab.md).
#   cmake -DMKOCTFILE=<mkoctfile> -DSOURCE=<matlab/> -DINCLUDE=<dir of texel.h>
#         -DLIBRARY=<libtexel.so> -DOUT=<dir> -P build_mex.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
get_filename_component(libdir ${LIBRARY} DIRECTORY)
# Plain C99 with warnings (mkoctfile takes CFLAGS from the environment); any
# warning fails the build below. texel_mex.h is a header of static helpers
# each MEX file uses some of: unused ones are not a warning.
set(ENV{CFLAGS} "-O2 -std=c99 -Wall -Wextra -pedantic -Wno-unused-function")
string(TIMESTAMP start "%s%f")
foreach(fn texel_render texel_encode texel_decode texel_spectrum texel_reference texel_render2d texel_swipe2d texel_encode2d)
  execute_process(
    COMMAND ${MKOCTFILE} --mex -I${INCLUDE} -I${SOURCE} -o ${OUT}/${fn}.mex ${SOURCE}/${fn}.c -L${libdir} -ltexel
            -Wl,-rpath,${libdir}
    WORKING_DIRECTORY ${OUT} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "mkoctfile --mex ${fn}.c failed (${rc}):\n${out}")
  endif()
  if(out MATCHES "warning")
    message(FATAL_ERROR "mkoctfile --mex ${fn}.c warns:\n${out}")
  endif()
endforeach()
string(TIMESTAMP end "%s%f")
math(EXPR ms "(${end} - ${start}) / 1000")
message(STATUS "built 8 MEX functions in ${ms} ms into ${OUT}")
