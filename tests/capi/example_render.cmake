# Runs examples/c/render and `texel render` with the same parameters and
# requires byte-identical .bin files.
#   cmake -DEXAMPLE=... -DTEXEL=... -DOUT=<dir> -P example_render.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${EXAMPLE} ${OUT}/example.bin RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "examples/c/render failed (${rc}): ${out}")
endif()
execute_process(COMMAND ${TEXEL} render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 --device tpad
                        -o ${OUT}/cli.bin RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "texel render failed (${rc}): ${out}")
endif()
file(SHA256 ${OUT}/example.bin a)
file(SHA256 ${OUT}/cli.bin b)
file(SIZE ${OUT}/example.bin size)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "examples/c/render wrote ${size} bytes (sha256 ${a}); texel render wrote sha256 ${b}")
endif()
message(STATUS "examples/c/render == texel render (${size} bytes, sha256 ${a})")
