# The third-party libraries of each Texel component, looked up only when
# that component is wanted. One list, used twice: by the build
# (src/CMakeLists.txt) and by the installed texelConfig.cmake, so that a
# consumer's find_package(texel) re-creates exactly the imported targets
# (PkgConfig::TEXEL_CAIRO, kissfft::kissfft-float, ...) that the exported
# static libraries name in their link interfaces.
#
# Trade-off: Texel installs static libraries, and a static library's private
# dependencies are still needed when the consumer links. Header-only private
# dependencies (nlohmann-json, Boost.Math, Boost.Beast) are linked as
# $<BUILD_INTERFACE:...>, so they are looked up for the build only (BUILD)
# and an installed Texel never asks for them (no public header includes
# them: the experiment headers hand out JSON as text).
#
#   texel_find_dependencies(<component> <missing-var> [BUILD])
#
# Components: core, controller, spectrum, plot, player, io, codec,
# experiment, studio, capi. Sets <missing-var> to the Debian packages that
# were not found (empty when everything is there).

# _texel_pkg_module(<PREFIX> <pkg-config module> <debian package>): the
# imported target PkgConfig::<PREFIX>, created once.
macro(_texel_pkg_module prefix module debian)
  if(NOT TARGET PkgConfig::${prefix})
    find_package(PkgConfig QUIET)
    if(PKG_CONFIG_FOUND)
      pkg_check_modules(${prefix} QUIET IMPORTED_TARGET ${module})
    endif()
  endif()
  if(NOT TARGET PkgConfig::${prefix})
    list(APPEND _texel_missing ${debian})
  endif()
endmacro()

# _texel_package(<debian package> <found variable> <find_package arguments...>)
macro(_texel_package debian found)
  find_package(${ARGN} QUIET)
  if(NOT ${found})
    list(APPEND _texel_missing ${debian})
  endif()
endmacro()

function(texel_find_dependencies component missing_var)
  set(_texel_missing "")
  set(for_build OFF)
  if("BUILD" IN_LIST ARGN)
    set(for_build ON)
  endif()
  if(component STREQUAL "core")
    # std::thread (write_map's chunk workers, the reference synthesis's workers).
    _texel_package(libc6-dev Threads_FOUND Threads)
    if(for_build)
      _texel_package(nlohmann-json3-dev nlohmann_json_FOUND nlohmann_json 3.10)
    endif()
  elseif(component STREQUAL "spectrum")
    # Only the shared build of KISS FFT is packaged: ask for it explicitly.
    _texel_package(libkissfft-dev kissfft_FOUND kissfft CONFIG COMPONENTS SHARED)
  elseif(component STREQUAL "plot")
    _texel_pkg_module(TEXEL_CAIRO cairo libcairo2-dev)
  elseif(component STREQUAL "surface2d")
    # Friction bitmaps and coarse-profile images (PNG).
    _texel_pkg_module(TEXEL_PNG libpng libpng-dev)
  elseif(component STREQUAL "player")
    _texel_package(libc6-dev Threads_FOUND Threads)
    _texel_pkg_module(TEXEL_SNDFILE sndfile libsndfile1-dev)
    _texel_pkg_module(TEXEL_PORTAUDIO portaudio-2.0 portaudio19-dev)
  elseif(component STREQUAL "io")
    _texel_pkg_module(TEXEL_MATIO matio libmatio-dev)
    _texel_package(zlib1g-dev ZLIB_FOUND ZLIB)
    _texel_pkg_module(TEXEL_SNDFILE sndfile libsndfile1-dev)
    if(for_build)
      # .hjif and glTF interchange (src/io/hjif.cpp, gltf.cpp); private.
      _texel_package(nlohmann-json3-dev nlohmann_json_FOUND nlohmann_json 3.10)
    endif()
  elseif(component STREQUAL "codec")
    _texel_pkg_module(TEXEL_ZSTD libzstd libzstd-dev)
  elseif(component STREQUAL "experiment")
    _texel_package(libsqlite3-dev SQLite3_FOUND SQLite3)
    # libpq: the PostgreSQL store (src/experiment/store_pg.cpp); its shipper thread.
    _texel_pkg_module(TEXEL_LIBPQ libpq libpq-dev)
    _texel_package(libc6-dev Threads_FOUND Threads)
    if(for_build)
      _texel_package(nlohmann-json3-dev nlohmann_json_FOUND nlohmann_json 3.10)
      _texel_package(libboost-dev Boost_FOUND Boost 1.74)
    endif()
  elseif(component STREQUAL "studio")
    _texel_package(libc6-dev Threads_FOUND Threads)
    if(for_build)
      _texel_package(nlohmann-json3-dev nlohmann_json_FOUND nlohmann_json 3.10)
      _texel_package(libboost-dev Boost_FOUND Boost 1.74)
    endif()
  elseif(component STREQUAL "controller" OR component STREQUAL "capi")
    # Nothing beyond other Texel components.
  else()
    message(FATAL_ERROR "texel_find_dependencies: unknown component '${component}'")
  endif()
  list(REMOVE_DUPLICATES _texel_missing)
  set(${missing_var} "${_texel_missing}" PARENT_SCOPE)
endfunction()

# The Texel components each component needs (its link interface), in an
# order where every component comes after the ones it needs. The options'
# checks in cmake/TexelComponents.cmake state the same graph; keep them in
# step (tests/consumer loads one component and checks what comes along).
set(TEXEL_COMPONENTS core controller spectrum plot player io surface2d codec experiment studio capi)
set(TEXEL_COMPONENT_NEEDS_core "")
set(TEXEL_COMPONENT_NEEDS_controller core)
set(TEXEL_COMPONENT_NEEDS_spectrum core)
set(TEXEL_COMPONENT_NEEDS_plot core spectrum)
set(TEXEL_COMPONENT_NEEDS_player core controller spectrum)
set(TEXEL_COMPONENT_NEEDS_io core)
set(TEXEL_COMPONENT_NEEDS_surface2d core io spectrum)
set(TEXEL_COMPONENT_NEEDS_codec core io spectrum surface2d)
set(TEXEL_COMPONENT_NEEDS_experiment core codec player plot spectrum surface2d)
set(TEXEL_COMPONENT_NEEDS_studio core codec experiment player plot spectrum)
# The C library is whole in itself (libtexel.so, libtexel.a: src/capi), built
# from core, codec and player but needing none of their targets installed.
set(TEXEL_COMPONENT_NEEDS_capi "")
