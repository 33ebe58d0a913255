# A plain C program (tests/consumer/project/render.c) built against an
# installed Texel four ways, each from an empty folder, and run: the bytes it
# writes must be `texel render`'s (tests/consumer/CMakeLists.txt).
#   find_package.shared   project(app C), find_package(texel COMPONENTS capi), texel::c
#   find_package.static   the same with texel::c_static
#   pkg-config.shared     cc app.c $(pkg-config --cflags --libs texel)
#   pkg-config.static     cc with `pkg-config --static --libs texel`, -ltexel taken from libtexel.a
# Shared programs must need libtexel.so.<ABI> and no libstdc++; static ones
# must not need libtexel at all.
#   cmake -DWORK=<dir> -DTEXEL_BUILD=<build> -DTEXEL_CLI=<texel> -DCONSUMER=<tests/consumer> -DGENERATOR=... -DBUILD_TYPE=...
#         -DCC=<C compiler> -DREADELF=<readelf> -DSONAME=<libtexel.so.N> -P run_c_consumer.cmake
cmake_minimum_required(VERSION 3.25)

include(${CMAKE_CURRENT_LIST_DIR}/consumer_common.cmake)

function(now var)
  string(TIMESTAMP t "%s%f")
  set(${var} ${t} PARENT_SCOPE)
endfunction()

function(report label start)
  now(end)
  math(EXPR ms "(${end} - ${start}) / 1000")
  message(STATUS "${label}: ${ms} ms")
endfunction()

# The program `exe` wrote the CLI's bytes and links libtexel the way `how` says.
function(check exe how)
  run(${exe} ${exe}.bin)
  file(SHA256 ${exe}.bin got)
  file(SHA256 ${WORK}/cli.bin want)
  if(NOT got STREQUAL want)
    message(FATAL_ERROR "${exe} wrote sha256 ${got}; texel render wrote ${want}")
  endif()
  execute_process(COMMAND ${READELF} -d ${exe} OUTPUT_VARIABLE dyn)
  if(how STREQUAL "shared")
    if(NOT dyn MATCHES "\\[${SONAME}\\]")
      message(FATAL_ERROR "${exe} does not need ${SONAME}:\n${dyn}")
    endif()
    if(dyn MATCHES "libstdc\\+\\+")
      message(FATAL_ERROR "${exe} needs libstdc++; libtexel.so carries its own:\n${dyn}")
    endif()
  elseif(dyn MATCHES "libtexel")
    message(FATAL_ERROR "${exe} was to link libtexel.a but needs libtexel.so:\n${dyn}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(prefix ${WORK}/prefix)
now(t)
# The C library, the core (find_package(texel) always loads it) and the
# package files: what a C user's package would hold.
foreach(component capi core Unspecified)
  run(${CMAKE_COMMAND} --install ${TEXEL_BUILD} --prefix ${prefix} --component ${component})
endforeach()
report("install (components capi, core and the package files)" ${t})
run(${TEXEL_CLI} render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 --device tpad -o ${WORK}/cli.bin)

foreach(link shared static)
  now(t)
  run(${CMAKE_COMMAND} -S ${CONSUMER}/c_project -B ${WORK}/cmake-${link} -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${BUILD_TYPE}
      -DCMAKE_C_COMPILER=${CC} -DCMAKE_PREFIX_PATH=${prefix} -DCONSUMER_LINK=${link})
  run(${CMAKE_COMMAND} --build ${WORK}/cmake-${link})
  check(${WORK}/cmake-${link}/app ${link})
  report("find_package ${link}: configure, build, run" ${t})
endforeach()

# pkg-config: what a Makefile or a shell would do.
file(GLOB_RECURSE pc ${prefix}/*/texel.pc)
if(NOT pc)
  message(FATAL_ERROR "texel.pc is not installed under ${prefix}")
endif()
get_filename_component(pcdir ${pc} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pcdir})
run(pkg-config --static --libs texel)
string(STRIP "${last_output}" static_libs)
message(STATUS "pkg-config --static --libs texel: ${static_libs}")
if(NOT static_libs MATCHES "-ltexel -lkissfft-float -lzstd -lz -lstdc\\+\\+ -lm")
  message(FATAL_ERROR "pkg-config --static --libs texel does not list libtexel.a's libraries: ${static_libs}")
endif()
set(source ${CONSUMER}/project/render.c)
foreach(link shared static)
  now(t)
  file(MAKE_DIRECTORY ${WORK}/pc-${link})
  if(link STREQUAL "shared")
    set(cmd "${CC} -std=c99 ${source} -o app $(pkg-config --cflags --libs texel) -Wl,-rpath,$(pkg-config --variable=libdir texel)")
  else()
    set(cmd "${CC} -std=c99 ${source} -o app $(pkg-config --cflags texel) $(pkg-config --static --libs texel | sed 's/-ltexel /-Wl,-Bstatic -ltexel -Wl,-Bdynamic /')")
  endif()
  message(STATUS "${cmd}")
  execute_process(COMMAND sh -c "${cmd}" WORKING_DIRECTORY ${WORK}/pc-${link} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${cmd}\nfailed (${rc}):\n${out}")
  endif()
  check(${WORK}/pc-${link}/app ${link})
  report("pkg-config ${link}: build, run" ${t})
endforeach()
