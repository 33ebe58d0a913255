# Builds and runs tests/consumer/project against Texel (ctest, see
# CMakeLists.txt next to this file).
#   cmake -DMODE=install|subdirectory -DWORK=<dir> -DCONSUMER=<project dir>
#         -DTEXEL_BUILD=<build to install> -DTEXEL_SOURCE=<checkout> -DTEXEL_CLI=<texel>
#         -DGENERATOR=... -DBUILD_TYPE=... -DCXX=... [-DCC=...] -P run_consumer.cmake
# install:      cmake --install TEXEL_BUILD into WORK/prefix; no installed
#               header may reach texel/detail/ or nlohmann-json; find_package(texel) with every component, with
#               COMPONENTS capi (nothing more is loaded) and with an unknown
#               component (configure must fail); the C++ and C consumers and
#               the installed CLI must write the same bytes.
# subdirectory: add_subdirectory(TEXEL_SOURCE) with every optional component
#               off, built Debug: only the core's dependencies are looked up,
#               and the embedded core renders the bytes TEXEL_CLI renders.
cmake_minimum_required(VERSION 3.25)

include(${CMAKE_CURRENT_LIST_DIR}/consumer_common.cmake)

function(expect_same_bytes a b)
  file(SHA256 ${a} ha)
  file(SHA256 ${b} hb)
  if(NOT ha STREQUAL hb)
    message(FATAL_ERROR "${a} (sha256 ${ha}) and ${b} (sha256 ${hb}) differ")
  endif()
endfunction()

set(compilers -DCMAKE_CXX_COMPILER=${CXX})
if(CC)
  list(APPEND compilers -DCMAKE_C_COMPILER=${CC})
endif()
set(configure ${CMAKE_COMMAND} -S ${CONSUMER} -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${BUILD_TYPE} ${compilers})
set(render_args render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 --device tpad)

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

if(MODE STREQUAL "install")
  set(prefix ${WORK}/prefix)
  run(${CMAKE_COMMAND} --install ${TEXEL_BUILD} --prefix ${prefix})

  file(GLOB_RECURSE headers RELATIVE ${prefix}/include ${prefix}/include/*)
  if(NOT "texel.h" IN_LIST headers OR NOT "texel/texture.hpp" IN_LIST headers)
    message(FATAL_ERROR "installed headers lack texel.h or texel/texture.hpp: ${headers}")
  endif()
  foreach(h IN LISTS headers)
    if(h MATCHES "detail/")
      message(FATAL_ERROR "internal header installed: include/${h}")
    endif()
    file(STRINGS ${prefix}/include/${h} includes REGEX "^[ \t]*#[ \t]*include")
    if(includes MATCHES "texel/detail/")
      message(FATAL_ERROR "installed include/${h} includes an internal header: ${includes}")
    endif()
    if(includes MATCHES "nlohmann")
      message(FATAL_ERROR "installed include/${h} includes nlohmann-json, a private dependency")
    endif()
  endforeach()
  list(LENGTH headers n)
  message(STATUS "installed ${n} headers, none internal")

  # Every component.
  run(${configure} -B ${WORK}/all -DCMAKE_PREFIX_PATH=${prefix})
  run(${CMAKE_COMMAND} --build ${WORK}/all)
  run(${WORK}/all/consumer ${WORK}/cpp.bin)
  message(STATUS "consumer: ${last_output}")
  run(${WORK}/all/consumer_c ${WORK}/c.bin)
  message(STATUS "consumer_c: ${last_output}")
  run(${prefix}/bin/texel ${render_args} -o ${WORK}/cli.bin)
  expect_same_bytes(${WORK}/cpp.bin ${WORK}/cli.bin)
  expect_same_bytes(${WORK}/c.bin ${WORK}/cli.bin)

  # One component: the C ABI loads what it needs (codec, player, ...) and
  # nothing else.
  run(${configure} -B ${WORK}/capi -DCMAKE_PREFIX_PATH=${prefix} -DCONSUMER_TEXEL_COMPONENTS=capi
      -DCONSUMER_ABSENT_TARGETS=texel::experiment,texel::studio,texel::plot)
  run(${CMAKE_COMMAND} --build ${WORK}/capi)
  run(${WORK}/capi/consumer_c ${WORK}/capi.bin)
  expect_same_bytes(${WORK}/capi.bin ${WORK}/cli.bin)

  # An unknown component is an error that names it.
  execute_process(COMMAND ${configure} -B ${WORK}/unknown -DCMAKE_PREFIX_PATH=${prefix}
                          -DCONSUMER_TEXEL_COMPONENTS=no_such_component
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(rc EQUAL 0 OR NOT out MATCHES "no_such_component is not installed")
    message(FATAL_ERROR "find_package(texel COMPONENTS no_such_component) should fail and name it:\n${out}")
  endif()
elseif(MODE STREQUAL "subdirectory")
  set(off)
  foreach(c CONTROLLER SPECTRUM PLOT SURFACE2D PLAYER IO CODEC EXPERIMENTS STUDIO CAPI PYTHON)
    list(APPEND off -DTEXEL_WITH_${c}=OFF)
  endforeach()
  # The embedded core is built at -O0 (Debug): compiling it is this test's
  # whole cost, and its bytes must equal the release CLI's all the same
  # (determinism across -O levels).
  run(${configure} -B ${WORK}/core -DCMAKE_BUILD_TYPE=Debug -DTEXEL_SOURCE_DIR=${TEXEL_SOURCE} ${off})
  # Only the core's dependency was looked up.
  file(STRINGS ${WORK}/core/CMakeCache.txt cache)
  foreach(other kissfft_DIR Boost_DIR SQLite3_INCLUDE_DIR TEXEL_CAIRO TEXEL_SNDFILE TEXEL_MATIO TEXEL_PORTAUDIO TEXEL_PNG)
    if(cache MATCHES "${other}")
      message(FATAL_ERROR "core-only configure looked up ${other}")
    endif()
  endforeach()
  run(${CMAKE_COMMAND} --build ${WORK}/core --target consumer)
  if(EXISTS ${WORK}/core/consumer_c)
    message(FATAL_ERROR "consumer_c was built although TEXEL_WITH_CAPI=OFF")
  endif()
  run(${WORK}/core/consumer ${WORK}/core.bin)
  message(STATUS "consumer: ${last_output}")
  run(${TEXEL_CLI} ${render_args} -o ${WORK}/cli.bin)
  expect_same_bytes(${WORK}/core.bin ${WORK}/cli.bin)
else()
  message(FATAL_ERROR "MODE must be install or subdirectory, not '${MODE}'")
endif()
