# Per-target settings shared by every Texel target: C++20, warnings, and the
# floating-point rules that keep renders bit-exact across compilers, -O levels
# and SIMD widths (no contraction into FMA, no fast-math).
function(texel_target_settings target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion -Wno-psabi $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict> -ffp-contract=off -fno-fast-math>)
  if(TEXEL_SANITIZE)
    # -Wno-pass-failed: at -O1 clang cannot vectorize every loop the release
    # build does once ASan instruments its accesses (spectrum/fft.cpp's
    # butterflies); that costs the sanitizer run time, not correctness.
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
                                             $<$<CXX_COMPILER_ID:Clang>:-Wno-pass-failed>)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(TEXEL_FUZZ)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()

# libFuzzer builds (docs/fuzzing.md; clang only): every target gets coverage
# instrumentation and the sanitizers, so the fuzz targets under tests/ see the
# library's branches, not only their own.
option(TEXEL_FUZZ "Instrument every target for libFuzzer (clang; implies TEXEL_SANITIZE)" OFF)
if(TEXEL_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "TEXEL_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++")
  endif()
  set(TEXEL_SANITIZE ON CACHE BOOL "Build with AddressSanitizer and UndefinedBehaviorSanitizer" FORCE)
endif()
