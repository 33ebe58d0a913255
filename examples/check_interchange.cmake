# Runs examples/cpp/interchange and compares its .hjif with `texel export` of
# the same document (byte for byte; the example exits 1 if the re-imported
# parameters do not transcode to the document's bitstream).
#   cmake -DEXAMPLE=... -DTEXEL=... -DOUT=<dir> -P check_interchange.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${EXAMPLE} ${OUT}/example.hjif RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "examples/cpp/interchange failed (${rc}): ${out}")
endif()
message(STATUS "${out}")
execute_process(COMMAND ${TEXEL} render --seed 7 -o ${OUT}/a.texel.json RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "texel render failed: ${err}")
endif()
execute_process(COMMAND ${TEXEL} export ${OUT}/a.texel.json -o ${OUT}/cli.hjif --date 2026-01-02 RESULT_VARIABLE rc
                OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "texel export failed: ${err}")
endif()
file(SHA256 ${OUT}/example.hjif a)
file(SHA256 ${OUT}/cli.hjif b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "examples/cpp/interchange wrote another .hjif than texel export")
endif()
