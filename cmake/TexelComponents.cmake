# Texel's components: one option and one library each (docs/architecture.md).
# The core, texel::texel, is always built; every other component is on by
# default, looks up only its own third-party libraries
# (cmake/TexelDependencies.cmake), and needs the components listed with it.
option(TEXEL_WITH_CONTROLLER "texel::controller: the reference display controller and its POSIX host HAL" ON)
option(TEXEL_WITH_SPECTRUM "texel::spectrum: spectral analysis (KISS FFT)" ON)
option(TEXEL_WITH_PLOT "texel::plot: PNG/SVG figures (Cairo)" ON)
option(TEXEL_WITH_SURFACE2D "texel::surface2d: the 2-D model, friction bitmaps (libpng)" ON)
option(TEXEL_WITH_PLAYER "texel::player: the real-time player and its sinks (libsndfile, PortAudio)" ON)
option(TEXEL_WITH_IO "texel::io: .mat interchange and the signal loader (libmatio, libsndfile)" ON)
option(TEXEL_WITH_CODEC "texel::codec: encoder, .texel bitstream, decoder (zstd)" ON)
option(TEXEL_WITH_EXPERIMENTS "texel::experiment: procedures, session store, statistics (SQLite, Boost.Math, nlohmann-json)" ON)
option(TEXEL_WITH_STUDIO "texel::studio and texel::studio_server: Texel Studio's service and server (Boost.Beast)" ON)
option(TEXEL_WITH_CAPI "texel::c and texel::c_static: the C ABI (libtexel.so, libtexel.a), texel.h" ON)

# texel_component_requires(<option> <reason> <needed options...>)
function(texel_component_requires option reason)
  if(NOT ${option})
    return()
  endif()
  foreach(needed IN LISTS ARGN)
    if(NOT ${needed})
      message(FATAL_ERROR "${option}=ON needs ${needed}=ON (${reason}); turn ${needed} on or configure with -D${option}=OFF")
    endif()
  endforeach()
endfunction()
texel_component_requires(TEXEL_WITH_PLOT "spectrum figures" TEXEL_WITH_SPECTRUM)
texel_component_requires(TEXEL_WITH_SURFACE2D "scans of 2-D fields are measured with the spectrum tools; .mat and glTF maps"
                         TEXEL_WITH_SPECTRUM TEXEL_WITH_IO)
texel_component_requires(TEXEL_WITH_PLAYER "swipe spectra, the serial display protocol"
                         TEXEL_WITH_SPECTRUM TEXEL_WITH_CONTROLLER)
texel_component_requires(TEXEL_WITH_CODEC "the encoder's analysis and signal loading; the 2-D encoder"
                         TEXEL_WITH_SPECTRUM TEXEL_WITH_IO TEXEL_WITH_SURFACE2D)
texel_component_requires(TEXEL_WITH_EXPERIMENTS "trials encode, play and plot textures and scan 2-D surfaces"
                         TEXEL_WITH_CODEC TEXEL_WITH_PLAYER TEXEL_WITH_PLOT TEXEL_WITH_SURFACE2D)
texel_component_requires(TEXEL_WITH_STUDIO "the studio runs experiments and shows 2-D surfaces" TEXEL_WITH_EXPERIMENTS TEXEL_WITH_SURFACE2D)
texel_component_requires(TEXEL_WITH_CAPI "the C ABI encodes, plays and renders 2-D surfaces" TEXEL_WITH_CODEC TEXEL_WITH_PLAYER
                         TEXEL_WITH_SURFACE2D)

# The CLI, the tests and the benchmarks use every component.
set(TEXEL_COMPONENT_OPTIONS TEXEL_WITH_CONTROLLER TEXEL_WITH_SPECTRUM TEXEL_WITH_PLOT TEXEL_WITH_SURFACE2D TEXEL_WITH_PLAYER
    TEXEL_WITH_IO TEXEL_WITH_CODEC TEXEL_WITH_EXPERIMENTS TEXEL_WITH_STUDIO TEXEL_WITH_CAPI)
set(TEXEL_COMPONENTS_OFF "")
foreach(option IN LISTS TEXEL_COMPONENT_OPTIONS)
  if(NOT ${option})
    list(APPEND TEXEL_COMPONENTS_OFF ${option})
  endif()
endforeach()

# Components built and tested in the tree but not installed: Texel Studio's
# service and server are the `texel studio` command's insides (the installed
# CLI carries them); their headers are no public API. docs/architecture.md
# "What is installed"; cmake/TexelInstall.cmake skips them.
set(TEXEL_UNINSTALLED_COMPONENTS studio)
