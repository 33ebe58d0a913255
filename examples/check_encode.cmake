# Runs examples/cpp/encode on the recording examples/cpp/play wrote: the
# central pitch comes back within 1.5 dB of 10 dB, the decoded texture feels
# like the recording (model distance < 1 JND), the bitstream is a few bytes
# and `texel decode` renders it.
#   cmake -DEXAMPLE=... -DTEXEL=... -DRECORDING=<wav> -DOUT=<dir> -P check_encode.cmake
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
execute_process(COMMAND ${EXAMPLE} ${RECORDING} 100 ${OUT}/recording.texel RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "examples/cpp/encode failed (${rc}): ${out}")
endif()
message(STATUS "${out}")
if(NOT out MATCHES "central pitch (-?[0-9.]+) dB")
  message(FATAL_ERROR "examples/cpp/encode printed no central pitch: ${out}")
endif()
set(pitch ${CMAKE_MATCH_1})
# Within 1.5 dB: the recording is the player's vibration output (zero-mean,
# band-limited by its output filter), not the map, and the perceptual fit
# decides; measured 11.02 dB with the model distance at 0.27 JND.
if(pitch LESS 8.5 OR pitch GREATER 11.5)
  message(FATAL_ERROR "examples/cpp/encode: central pitch ${pitch} dB; the recording was rendered at 10 dB")
endif()
if(NOT out MATCHES "model distance ([0-9.]+) JND" OR CMAKE_MATCH_1 GREATER 1)
  message(FATAL_ERROR "examples/cpp/encode: the decoded texture does not feel like the recording (want < 1 JND): ${out}")
endif()
file(SIZE ${OUT}/recording.texel size)
if(size LESS 4 OR size GREATER 64)
  message(FATAL_ERROR "examples/cpp/encode: bitstream of ${size} bytes; expected a few")
endif()
execute_process(COMMAND ${TEXEL} decode ${OUT}/recording.texel --device tpad -o ${OUT}/decoded.bin RESULT_VARIABLE rc
                OUTPUT_VARIABLE dec ERROR_VARIABLE dec)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "texel decode of the example's bitstream failed (${rc}): ${dec}")
endif()
message(STATUS "examples/cpp/encode: central pitch ${pitch} dB in ${size} bytes; texel decode read it")
